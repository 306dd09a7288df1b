/* Harris's particle renderer: a frame (docs/particles.md). The sky renderer draws the
 * background; the clouds go far to near, each drawn from its impostor (Harris §3: made again
 * when the eye has moved round it by more than the tolerance angle or come so near that its
 * texels are too coarse) or, with impostors off or the eye within its sphere, splatted
 * particle by particle over the image. */
#include "render/harris_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The frame's aerial-perspective volume over the whole image, from the particles' nearest
 * to their farthest point (NULL: the kind's answers are closed forms, asked per particle). */
static const atmos__aerial *frame_aerial(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v)
{
    const atmos_camera *cam = &v->cam;
    if (!atmos__aerial_wanted(p->atm) || cam->type != ATMOS_CAMERA_PINHOLE) return NULL;
    double lo[3], hi[3], near2 = 0, far = 0;
    atmos__pcloud_bounds(&h->pc, lo, hi);
    for (int a = 0; a < 3; a++) {
        const double e = cam->position[a] < lo[a] ? lo[a] - cam->position[a] : (cam->position[a] > hi[a] ? cam->position[a] - hi[a] : 0);
        const double f = fmax(fabs(lo[a] - cam->position[a]), fabs(hi[a] - cam->position[a]));
        near2 += e * e, far += f * f;
    }
    atmos__aerial_grid g;
    memset(&g, 0, sizeof g);
    memcpy(g.eye, cam->position, sizeof g.eye), memcpy(g.sun, v->sun, sizeof g.sun);
    memcpy(g.fwd, cam->forward, sizeof g.fwd), memcpy(g.right, cam->right, sizeof g.right);
    memcpy(g.up, cam->up, sizeof g.up);
    const double tn = cam->tan_half_fov, asp = (double)cam->width / cam->height;
    g.u0 = -asp * tn, g.u1 = asp * tn, g.v0 = -tn, g.v1 = tn;
    g.tmin = fmax(0.0, sqrt(near2) - 1.0), g.tmax = sqrt(far) + 1.0;
    g.crowd_far = cam->position[1] > hi[1];
    g.nd = ATMOS__AERIAL_SLICES;
    atmos__aerial_nodes(p->atm, &g);
    return atmos__aerial_build(&h->aerial, p->atm, &g, atmos__threads(p->ctx)) ? &h->aerial : NULL;
}

/* The air from the eye to the centres of particles idx[0..n) (ap: the frame's volume, or
 * NULL: ask the atmosphere). */
static void air(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__aerial *ap,
                const int *idx, int n)
{
    const int nw = h->o.nw;
#pragma omp parallel for schedule(dynamic, 256) num_threads(atmos__threads(p->ctx))
    for (int q = 0; q < n; q++) {
        const int i = idx[q];
        double d[3] = {h->pc.x[i] - v->cam.position[0], h->pc.y[i] - v->cam.position[1], h->pc.z[i] - v->cam.position[2]};
        const double t = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; a++) d[a] /= t > 0 ? t : 1.0;
        double L[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
        if (!ap || !atmos__aerial_eval(ap, d, t, L, T)) {
            atmos_atmosphere_inscatter(p->atm, v->cam.position, d, t, v->sun, L);
            atmos_atmosphere_transmittance(p->atm, v->cam.position, d, t, T);
        }
        for (int k = 0; k < nw; k++) h->air_l[(size_t)i * nw + k] = (float)L[k], h->air_t[(size_t)i * nw + k] = (float)T[k];
    }
}

/* Whether the sphere (c, r) meets cam's view: inside all four side planes of the frustum
 * within r (and not wholly behind the eye). */
static int visible(const atmos_camera *cam, const double c[3], double r)
{
    double X = 0, Y = 0, Z = 0;
    for (int i = 0; i < 3; i++) {
        const double rel = c[i] - cam->position[i];
        X += rel * cam->right[i], Y += rel * cam->up[i], Z += rel * cam->forward[i];
    }
    const double th = cam->tan_half_fov, tw = th * cam->width / cam->height;
    return Z > -r && fabs(X) - Z * tw <= r * sqrt(1 + tw * tw) && fabs(Y) - Z * th <= r * sqrt(1 + th * th);
}

/* How cloud k is drawn this frame: 0 not at all (out of view), 1 its particles, 2 a screen-sized
 * impostor (the eye inside it), 3 its impostor as it is, 4 its impostor made again. */
static int mode(const atmos_plan *p, const atmos__harris_plan *h, const atmos__view *v, int k)
{
    const atmos_scene_harris *hs = &p->scene.harris;
    const atmos__pclusters *c = &h->clouds;
    if (!visible(&v->cam, c->centre[k], c->radius[k])) return 0;
    if (!hs->impostors || v->cam.type != ATMOS_CAMERA_PINHOLE) return 1;
    const double *e = v->cam.position, f = v->cam.height / (2.0 * v->cam.tan_half_fov);
    double d2 = 0;
    for (int a = 0; a < 3; a++) d2 += (e[a] - c->centre[k][a]) * (e[a] - c->centre[k][a]);
    const double margin = 1.05 * c->radius[k]; /* an impostor's plane needs the eye well outside */
    if (d2 <= margin * margin) return 2;
    const double tol = hs->impostor_tolerance_deg * ATMOS_PI / 180.0;
    return atmos__pimpostor_serves(&h->imp[k], c->centre[k], c->radius[k], e, tol, f, hs->impostor_max_res) ? 3 : 4;
}

/* Makes the impostors of the clouds list[0..n) again, the clouds on the threads (each one's
 * splats on one: the result does not depend on the thread count). */
static atmos_status remake(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__aerial *ap,
                           const int *list, int n)
{
    const atmos__pclusters *c = &h->clouds;
    const atmos__plights L = {h->nlights, (const float *const *)h->light, (const float *const *)h->order,
                              (const double(*)[3])h->dir, (const double(*)[ATMOS_MAX_WAVELENGTHS])h->e, h->air_t, h->air_l};
    const double *e = v->cam.position, f = v->cam.height / (2.0 * v->cam.tan_half_fov);
    /* the air to all their particles in one pass on the threads */
    int total = 0;
    for (int q = 0; q < n; q++) total += c->start[list[q] + 1] - c->start[list[q]];
    int *all = malloc(sizeof(int) * (size_t)(total ? total : 1));
    if (!all) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    for (int q = 0, m = 0; q < n; q++)
        for (int i = c->start[list[q]]; i < c->start[list[q] + 1]; i++) all[m++] = c->idx[i];
    air(p, h, v, ap, all, total);
    free(all);
    atmos_status st = ATMOS_OK;
#pragma omp parallel for schedule(dynamic, 1) num_threads(atmos__threads(p->ctx))
    for (int q = 0; q < n; q++) {
        const int k = list[q], *idx = c->idx + c->start[k], m = c->start[k + 1] - c->start[k];
        double d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (e[a] - c->centre[k][a]) * (e[a] - c->centre[k][a]);
        const int res = atmos__pimpostor_res(c->radius[k], sqrt(d2), f, p->scene.harris.impostor_max_res);
        const atmos_status sk = atmos__pimpostor_make(p->ctx, &h->imp[k], &h->pc, &h->o, &L, idx, m, c->centre[k],
                                                      c->radius[k], e, res);
        if (sk != ATMOS_OK) {
#pragma omp critical
            st = sk;
        }
    }
    h->updates += n;
    return st;
}

/* Cloud k splatted particle by particle (how 1) or as a screen-sized impostor (how 2). */
static atmos_status draw(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__aerial *ap,
                         int k, int how, const int rect[4], atmos_image *out)
{
    const atmos__pclusters *c = &h->clouds;
    const int *idx = c->idx + c->start[k], n = c->start[k + 1] - c->start[k];
    const atmos__plights L = {h->nlights, (const float *const *)h->light, (const float *const *)h->order,
                              (const double(*)[3])h->dir, (const double(*)[ATMOS_MAX_WAVELENGTHS])h->e, h->air_t, h->air_l};
    if (how == 1) {
        air(p, h, v, ap, idx, n);
        int drawn = 0;
        atmos_status st = atmos__pcloud_splat(p->ctx, &h->pc, &h->o, &L, idx, n, &v->cam, rect, out, &drawn);
        h->drawn += drawn, h->direct++;
        return st;
    }
    if (how == 2) { /* the head in the cloud (§3.1): a screen-sized impostor at 1/4 resolution */
        air(p, h, v, ap, idx, n);
        h->direct++, h->updates++;
        return atmos__pimpostor_screen(p->ctx, &h->pc, &h->o, &L, idx, n, &v->cam, 4, rect, out);
    }
    return ATMOS_OK;
}

/* The clouds ord[q0..) drawn from their impostors (how 3, 4; those out of view skipped) up to
 * the next one drawn otherwise, in one pass; the index after them. */
static int draw_impostors(const atmos_plan *p, const atmos__harris_plan *h, const atmos__view *v, const atmos__keyed *ord,
                          const int *how, int q0, int nc, const int rect[4], atmos_image *out, const atmos__pimpostor **ims,
                          const double **cs, double *rs)
{
    int q = q0, n = 0;
    for (; q < nc && (how[ord[q].index] >= 3 || !how[ord[q].index]); q++) {
        const int k = ord[q].index;
        if (!how[k]) continue;
        ims[n] = &h->imp[k], cs[n] = h->clouds.centre[k], rs[n++] = h->clouds.radius[k];
    }
    atmos__pimpostor_draw(p->ctx, n, ims, cs, rs, &v->cam, rect, out);
    return q;
}

atmos_status atmos__harris_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out)
{
    atmos__harris_plan *h = p->harris;
    atmos_status st = atmos__sky_render(p->ctx, p->atm, v, r, out, p->sky_keep);
    if (st != ATMOS_OK) return st;
    if (!h->have_sun || memcmp(h->sun, v->sun, sizeof h->sun) != 0) {
        const double t0 = atmos__now();
        if ((st = atmos__harris_lights(p, h, v->sun)) != ATMOS_OK) return st;
        h->shade_s = atmos__now() - t0;
    }
    const int rect[4] = {r->x0, r->y0, r->x1, r->y1};
    const atmos__aerial *ap = frame_aerial(p, h, v);
    const int nc = h->clouds.n;
    atmos__keyed *ord = malloc(sizeof *ord * (size_t)(nc ? nc : 1));
    if (!ord) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    for (int k = 0; k < nc; k++) {
        double d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (v->cam.position[a] - h->clouds.centre[k][a]) * (v->cam.position[a] - h->clouds.centre[k][a]);
        ord[k].key = d2, ord[k].index = k;
    }
    atmos__keyed_sort(ord, (size_t)nc, 1);
    h->drawn = h->updates = h->direct = 0;
    const size_t cap = nc > 0 ? (size_t)nc : 1;
    int *how = malloc(sizeof(int) * 2 * cap), *stale = how ? how + cap : NULL, nstale = 0;
    const atmos__pimpostor **ims = malloc(sizeof *ims * cap);
    const double **cs = malloc(sizeof *cs * cap);
    double *rs = malloc(sizeof *rs * cap);
    if (!how || !ims || !cs || !rs) st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    for (int k = 0; k < nc && st == ATMOS_OK; k++)
        if ((how[k] = mode(p, h, v, k)) == 4) stale[nstale++] = k;
    if (st == ATMOS_OK) st = remake(p, h, v, ap, stale, nstale);
    for (int q = 0; q < nc && st == ATMOS_OK;) {
        const int k = ord[q].index;
        if (how[k] >= 3) q = draw_impostors(p, h, v, ord, how, q, nc, rect, out, ims, cs, rs);
        else if (how[k]) st = draw(p, h, v, ap, k, how[k], rect, out), q++;
        else q++;
    }
    free(how), free(ims), free(cs), free(rs);
    free(ord);
    p->stats.impostor_updates = h->updates;
    return st;
}
