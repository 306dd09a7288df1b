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
 * NULL: ask the atmosphere), and the diffuse field's light toward the eye there. */
static void air(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__aerial *ap,
                const int *idx, int n)
{
    const int nw = h->o.nw, dv = atmos__harris_diffuse_eye(p, h, v->cam.position);
#pragma omp parallel for schedule(dynamic, 256) num_threads(atmos__threads(p->ctx))
    for (int q = 0; q < n; q++) {
        const int i = idx[q];
        if (dv) atmos__harris_diffuse_at(h, i); /* the diffuse field's light toward the eye */
        double d[3] = {h->pc.x[i] - v->cam.position[0], h->pc.y[i] - v->cam.position[1], h->pc.z[i] - v->cam.position[2]};
        const double t = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; a++) d[a] /= t > 0 ? t : 1.0;
        double L[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
        if (!(t > 0)) /* a particle at the eye: no air between (a zero direction is refused) */
            for (int k = 0; k < nw; k++) L[k] = 0, T[k] = 1;
        else if (!ap || !atmos__aerial_eval(ap, d, t, L, T)) {
            atmos_atmosphere_inscatter(p->atm, v->cam.position, d, t, v->sun, L);
            atmos_atmosphere_transmittance(p->atm, v->cam.position, d, t, T);
        }
        for (int k = 0; k < nw; k++) h->air_l[(size_t)i * nw + k] = (float)L[k], h->air_t[(size_t)i * nw + k] = (float)T[k];
    }
}

/* Whether the sphere (c, r) meets cam's view: inside all four side planes of the frustum
 * within r (and not wholly behind the eye); for a wide camera, holding the eye or falling on
 * the image. */
static int visible(const atmos_camera *cam, const double c[3], double r)
{
    if (cam->type != ATMOS_CAMERA_PINHOLE) {
        const int all[4] = {0, 0, cam->width, cam->height};
        int bb[4];
        double d2 = 0, Z;
        for (int i = 0; i < 3; i++) d2 += (c[i] - cam->position[i]) * (c[i] - cam->position[i]);
        return d2 <= r * r || atmos__pcloud_screen_box(cam, c, r, all, bb, &Z);
    }
    double X = 0, Y = 0, Z = 0;
    for (int i = 0; i < 3; i++) {
        const double rel = c[i] - cam->position[i];
        X += rel * cam->right[i], Y += rel * cam->up[i], Z += rel * cam->forward[i];
    }
    const double th = cam->tan_half_fov, tw = th * cam->width / cam->height;
    return Z > -r && fabs(X) - Z * tw <= r * sqrt(1 + tw * tw) && fabs(Y) - Z * th <= r * sqrt(1 + th * th);
}

/* The most texels cloud k's impostor needs: the scene's limit, or fewer where its narrowest
 * particle spans ATMOS__PIMPOSTOR_TEXELS_PER_WIDTH texels with fewer. */
static int max_res(const atmos_plan *p, const atmos__harris_plan *h, int k)
{
    return atmos__pimpostor_max_res(h->clouds.radius[k], h->smin[k], p->scene.harris.impostor_max_res);
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
    return atmos__pimpostor_serves(&h->imp[k], c->centre[k], c->radius[k], e, tol, f, max_res(p, h, k)) ? 3 : 4;
}

/* Whether a split cloud k's part impostor (pass 0 far, 1 near) still serves: as a whole one
 * does, and cut where the cloud is cut now (within half its narrowest particle's width). */
static int part_mode(const atmos_plan *p, const atmos__harris_plan *h, const atmos__view *v, int k, int pass)
{
    const atmos_scene_harris *hs = &p->scene.harris;
    const atmos__pimpostor *im = &h->split[2 * k + pass];
    const double f = v->cam.height / (2.0 * v->cam.tan_half_fov), tol = hs->impostor_tolerance_deg * ATMOS_PI / 180.0;
    /* the split may move by half the cloud's narrowest particle width (Harris's layers hold the
     * particles "approximately" behind and in front of the object) */
    const int cut = fabs(im->split - h->offset[k]) <= 0.5 * h->smin[k];
    return cut && atmos__pimpostor_serves(im, h->clouds.centre[k], h->clouds.radius[k], v->cam.position, tol, f,
                                          max_res(p, h, k)) ? 3 : 4;
}

/* The particles' lights and air for the splats. */
static atmos__plights plights(const atmos__harris_plan *h)
{
    const atmos__plights L = {h->nlights, (const float *const *)h->light, (const float *const *)h->order,
                              (const double(*)[3])h->dir, (const double(*)[ATMOS_MAX_WAVELENGTHS])h->e, h->air_t, h->air_l,
                              h->diffuse && h->field_ok ? h->dview : NULL};
    return L;
}

/* Above this many impostors to make a thread, remake makes one on each thread. */
#define REMAKE_ONE_A_THREAD 4

/* Makes list[q]'s impostor (remake's entry q: full up to nfull, coarse after). */
static atmos_status remake_one(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__plights *L,
                               const int *list, int q, int nfull)
{
    const atmos__pclusters *c = &h->clouds;
    const double *e = v->cam.position, f = v->cam.height / (2.0 * v->cam.tan_half_fov);
    const int k = list[q] / 3, part = list[q] % 3;
    const atmos__pimpostor *cim;
    const int *idx;
    int m;
    atmos__harris_piece(h, k, part ? part - 1 : 1, 3, part ? ATMOS__HARRIS_SPLIT : ATMOS__HARRIS_NEAR, &cim, &idx, &m);
    atmos__pimpostor *im = part ? &h->split[2 * k + part - 1] : &h->imp[k];
    double d2 = 0;
    for (int a = 0; a < 3; a++) d2 += (e[a] - c->centre[k][a]) * (e[a] - c->centre[k][a]);
    int res = atmos__pimpostor_res(c->radius[k], sqrt(d2), f, max_res(p, h, k));
    if (q >= nfull) res = 8 * ((res / 4 + 7) / 8);
    const atmos_status st = atmos__pimpostor_make(p->ctx, im, &h->pc, &h->o, L, idx, m, c->centre[k], c->radius[k], e, res);
    im->split = part ? h->offset[k] : 0;
    return st;
}

/* Makes the impostors list[0..n + nc) again (each k 3 + part: part 0 cloud k's whole impostor, 1
 * its far one, 2 its near one; the last nc whole ones at a quarter of the resolution the view
 * needs, rounded up to 8 texels): many on the threads, each one's splats on one; a few (the
 * frame's budget) one after the other, each one's particles and tiles on the threads, so that
 * neither thread waits for the other's larger one (the result does not depend on the thread
 * count). */
static atmos_status remake(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__aerial *ap,
                           const int *list, int nfull, int nc)
{
    const int n = nfull + nc;
    const atmos__pclusters *c = &h->clouds;
    const atmos__plights L = plights(h);
    /* the air to all their clouds' particles in one pass on the threads (a cloud's parts follow
     * each other in list) */
    int total = 0;
    for (int q = 0; q < n; q++)
        if (!q || list[q] / 3 != list[q - 1] / 3) total += c->start[list[q] / 3 + 1] - c->start[list[q] / 3];
    int *all = malloc(sizeof(int) * (size_t)(total ? total : 1));
    if (!all) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    for (int q = 0, m = 0; q < n; q++)
        if (!q || list[q] / 3 != list[q - 1] / 3)
            for (int i = c->start[list[q] / 3]; i < c->start[list[q] / 3 + 1]; i++) all[m++] = c->idx[i];
    air(p, h, v, ap, all, total);
    free(all);
    atmos_status st = ATMOS_OK;
    const int threads = atmos__threads(p->ctx);
    if (n > REMAKE_ONE_A_THREAD * threads) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
        for (int q = 0; q < n; q++) {
            const atmos_status sk = remake_one(p, h, v, &L, list, q, nfull);
            if (sk != ATMOS_OK) {
#pragma omp critical
                st = sk;
            }
        }
    } else /* not inside a parallel region: each make's own loops take the threads */
        for (int q = 0; q < n && st == ATMOS_OK; q++) st = remake_one(p, h, v, &L, list, q, nfull);
    h->updates += nfull, h->coarse += nc;
    return st;
}

/* Particles idx[0..n) splatted one by one (how 1) or as a screen-sized impostor (how 2). */
static atmos_status draw(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__aerial *ap,
                         const int *idx, int n, int how, const int rect[4], atmos_image *out)
{
    const atmos__plights L = plights(h);
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
        return atmos__pimpostor_screen(p->ctx, &h->pc, &h->o, &L, idx, n, &v->cam, 4, v->screen_layer_px, rect, out);
    }
    return ATMOS_OK;
}

/* How each cloud is drawn this frame (mode; a split cloud's parts in hp[2 k + pass]) and what
 * shows in one pass (0 before the objects, 1 after). */
typedef struct frame_plan {
    const int *how, *side, *hp;
} frame_plan;

static int piece(const atmos__harris_plan *h, const frame_plan *fp, int k, int pass, const atmos__pimpostor **im,
                 const int **idx, int *n)
{
    const int how = fp->side[k] == ATMOS__HARRIS_SPLIT && fp->how[k] >= 3 ? fp->hp[2 * k + pass] : fp->how[k];
    return atmos__harris_piece(h, k, pass, how, fp->side[k], im, idx, n);
}

/* One pass over the clouds far to near: runs of impostors (those out of view or showing nothing
 * skipped) in one pass each, the others splatted. */
static atmos_status draw_pass(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__aerial *ap,
                              const atmos__keyed *ord, const frame_plan *fp, int pass, const int rect[4], atmos_image *out,
                              const atmos__pimpostor **ims, const double **cs, double *rs)
{
    const int nc = h->clouds.n;
    atmos_status st = ATMOS_OK;
    for (int q = 0; q < nc && st == ATMOS_OK;) {
        const atmos__pimpostor *im;
        const int *idx;
        int n, m = 0, hw = piece(h, fp, ord[q].index, pass, &im, &idx, &n);
        if (hw && hw < 3) {
            st = draw(p, h, v, ap, idx, n, hw, rect, out), q++;
            continue;
        }
        for (; q < nc && (!(hw = piece(h, fp, ord[q].index, pass, &im, &idx, &n)) || hw >= 3); q++) {
            if (!hw) continue;
            const int k = ord[q].index;
            ims[m] = im, cs[m] = h->clouds.centre[k], rs[m++] = h->clouds.radius[k];
        }
        atmos__pimpostor_draw(p->ctx, m, ims, cs, rs, &v->cam, rect, out);
    }
    return st;
}

/* The texels a side of cloud k's impostor needs from eye e (f: the focal length in pixels). */
static int needed_res(const atmos_plan *p, const atmos__harris_plan *h, int k, const double e[3], double f)
{
    double d2 = 0;
    for (int a = 0; a < 3; a++) d2 += (e[a] - h->clouds.centre[k][a]) * (e[a] - h->clouds.centre[k][a]);
    return atmos__pimpostor_res(h->clouds.radius[k], sqrt(d2), f, max_res(p, h, k));
}

/* The frame's units of texels for the remakes (hold_to_budget's cap). */
static double texel_cap(const atmos__view *v)
{
    const double side = fmax(v->cam.height / 8.0, 32.0);
    return v->impostor_budget * side * side;
}

/* Holds the impostors to make (stale[0..n), entries 3 k + part) to the frame's budget B: split
 * clouds' parts are always made; then the whole-cloud impostors never made, the largest on the
 * screen first; then those out of date by the most pixels (the error over the tolerance times
 * the texels the view needs); B in all are made. The out-of-date ones left are drawn as they
 * are (how 3), the never-made ones left are made at a quarter of their resolution (a coarse
 * stand-in, out of date by its texels, so a later frame makes it in full). The out-of-date
 * ones also keep within B units of (max(H / 8, 32))^2 texels (H: the frame's height), the full
 * makes before them counted: one that would pass it is held unless nothing was taken yet and
 * it is out of date by twice the tolerance, or nothing else is made (a still view catches up).
 * So a large impostor is made again less often and alone. A make spread over frames (used 1,
 * its piece's texels0 this frame) takes its texels first, and no other is then made alone. Reorders stale: the
 * full makes first; returns their count, the coarse ones after them (*ncoarse). */
static int hold_to_budget(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, int *how, int *stale,
                          int n, atmos__keyed *key, int *ncoarse, int used, double texels0)
{
    const atmos_scene_harris *hs = &p->scene.harris;
    const double *e = v->cam.position, f = v->cam.height / (2.0 * v->cam.tan_half_fov);
    const double tol = hs->impostor_tolerance_deg * ATMOS_PI / 180.0;
    int m = 0, kept = 0, nfirst = 0;
    atmos__keyed *first = key + n; /* key has room for 2 n */
    for (int q = 0; q < n; q++) {
        const int k = stale[q] / 3, res = needed_res(p, h, k, e, f);
        const double err = stale[q] % 3 ? INFINITY
                                         : atmos__pimpostor_error(&h->imp[k], h->clouds.centre[k], h->clouds.radius[k], e,
                                                                  tol, f, max_res(p, h, k));
        if (!(stale[q] % 3) && !h->imp[k].valid) first[nfirst].key = res, first[nfirst++].index = stale[q];
        else if (isinf(err)) stale[kept++] = stale[q]; /* must be made */
        else key[m].key = err * res, key[m++].index = stale[q];
    }
    atmos__keyed_sort(first, (size_t)nfirst, 1);
    atmos__keyed_sort(key, (size_t)m, 1);
    const double cap = texel_cap(v);
    double texels = texels0;
    int taken = 0; /* never-made ones made in full: the first of first[] (their texels counted) */
    for (; taken < nfirst && kept + used < v->impostor_budget; taken++)
        stale[kept++] = first[taken].index, texels += first[taken].key * first[taken].key;
    for (int q = 0; q < m; q++) {
        const int res = needed_res(p, h, key[q].index / 3, e, f);
        const double t = (double)res * res, late = key[q].key / res; /* its error over the tolerance */
        if (kept + used < v->impostor_budget && ((kept + used == 0 && late >= 2) || texels + t <= cap))
            stale[kept++] = key[q].index, texels += t;
        else how[key[q].index / 3] = 3, h->held++;
    }
    if (kept + used == 0 && m > 0) /* nothing else to make: the most out of date, so a still view catches up */
        stale[kept++] = key[0].index, how[key[0].index / 3] = 4, h->held--;
    for (int q = taken; q < nfirst; q++) stale[kept + q - taken] = first[q].index; /* the coarse ones */
    *ncoarse = nfirst - taken;
    return kept;
}

/* Cuts the rows of a res-texel make of the cloud whose impostor is old into h->spread_pieces
 * pieces of about the same work (h->spread_cut): old's coverage summed over its rows (and a
 * little a row), the new rows at the same place on the plane. Returns 0 without memory. */
static int spread_cuts(atmos__harris_plan *h, const atmos__pimpostor *old, int res)
{
    const int R = old->res, C = old->img->channels, n = h->spread_pieces;
    double *cum = malloc(sizeof(double) * (size_t)(R + 1));
    if (!cum) return 0;
    cum[0] = 0;
    for (int y = 0; y < R; y++) {
        const float *row = old->img->pixels + (size_t)y * R * C;
        double a = 1e-3 * R;
        for (int x = 0; x < R; x++) a += row[(size_t)x * C + C - 1];
        cum[y + 1] = cum[y] + a;
    }
    h->spread_cut[0] = 0, h->spread_cut[n] = res;
    for (int j = 1, y = 0; j < n; j++) {
        const double want = cum[R] * j / n;
        while (y < R && cum[y + 1] < want) y++;
        const double oy = y + (want - cum[y]) / (cum[y + 1] - cum[y]); /* old rows, within row y */
        const int c = (int)lround(oy * res / R), lo = h->spread_cut[j - 1] + 1, hi = res - (n - j);
        h->spread_cut[j] = c < lo ? lo : (c > hi ? hi : c);
    }
    free(cum);
    return 1;
}

/* A whole-cloud impostor to make in full (stale[0..*nfull)) that has an old one to show, at
 * least half as fine as the view needs (not a coarse stand-in), and more texels than the
 * frame's cap is made over frames instead: the fewest pieces of rows of at
 * most the cap's texels each (at least 2, at most ATMOS__HARRIS_SPREAD_MAX), cut where the old
 * one's coverage says the work is alike (spread_cuts), a piece a frame, its old one drawn until
 * it is done. The first such one is taken out of stale (shifting the coarse ones after it)
 * unless a make is spread already; not with objects (what a particle shows then depends on more
 * of the frame's eye than its air and diffuse light, which the first frame computes for all the
 * rows). */
static void spread_start(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, int *how, int *stale,
                         int *nfull, int ncoarse)
{
    if (h->spreading || h->obj || v->impostor_budget <= 0) return;
    const double f = v->cam.height / (2.0 * v->cam.tan_half_fov), cap = texel_cap(v);
    for (int q = 0; q < *nfull; q++) {
        const int k = stale[q] / 3, res = needed_res(p, h, k, v->cam.position, f);
        if (stale[q] % 3 || !h->imp[k].valid || 2 * h->imp[k].res < res || (double)res * res <= cap) continue;
        const int pieces = (int)ceil((double)res * res / cap);
        h->spread_pieces = pieces < ATMOS__HARRIS_SPREAD_MAX ? pieces : ATMOS__HARRIS_SPREAD_MAX;
        if (!spread_cuts(h, &h->imp[k], res)) return;
        h->spreading = 1, h->spread_k = k, h->spread_res = res, h->spread_at = 0;
        memcpy(h->spread_eye, v->cam.position, sizeof h->spread_eye);
        memmove(stale + q, stale + q + 1, sizeof *stale * (size_t)(*nfull + ncoarse - q - 1));
        --*nfull, how[k] = 3, h->updates++;
        return;
    }
}

/* The next piece of the make spread over frames (its first frame: the air to its particles from
 * this frame's eye, the eye it is made from); once its last rows are made it replaces the
 * cloud's impostor. */
static atmos_status spread_step(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const atmos__aerial *ap)
{
    const int k = h->spread_k, j = h->spread_at, res = h->spread_res;
    const atmos__pimpostor *cim;
    const int *idx;
    int m;
    atmos__harris_piece(h, k, 1, 3, ATMOS__HARRIS_NEAR, &cim, &idx, &m);
    if (j == 0) air(p, h, v, ap, idx, m);
    const atmos__plights L = plights(h);
    const atmos_status st = atmos__pimpostor_make_rows(p->ctx, &h->spread, &h->pc, &h->o, &L, idx, m, h->clouds.centre[k],
                                                       h->clouds.radius[k], h->spread_eye, res, h->spread_cut[j],
                                                       h->spread_cut[j + 1]);
    if (st != ATMOS_OK) return h->spreading = 0, st;
    if (++h->spread_at < h->spread_pieces) return ATMOS_OK;
    const atmos__pimpostor done = h->spread; /* the old image kept for the next spread make */
    h->spread = h->imp[k], h->imp[k] = done;
    h->imp[k].split = 0, h->spread.valid = 0, h->spreading = 0;
    return ATMOS_OK;
}

/* The modes of the clouds (how), the split (side, hp) and the impostors to make (stale: the
 * full makes, returned, then *ncoarse coarse ones). A make spread over frames goes on while its
 * cloud is drawn whole from an impostor (its old one meanwhile, how 3), within the budget. */
static int modes(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v, const int rect[4], int *how,
                 int *side, int *hp, int *stale, int *ncoarse)
{
    const int nc = h->clouds.n;
    int nstale = 0;
    *ncoarse = 0;
    for (int k = 0; k < nc; k++) how[k] = mode(p, h, v, k);
    atmos__harris_split(h, v, rect, how, side);
    for (int k = 0; k < nc; k++) {
        if (side[k] != ATMOS__HARRIS_SPLIT || how[k] < 3) {
            if (how[k] == 4) stale[nstale++] = 3 * k;
            continue;
        }
        for (int pass = 0; pass < 2; pass++)
            if ((hp[2 * k + pass] = part_mode(p, h, v, k, pass)) == 4) stale[nstale++] = 3 * k + 1 + pass;
    }
    const int k = h->spread_k;
    if (h->spreading && (v->impostor_budget <= 0 || how[k] < 3 || side[k] == ATMOS__HARRIS_SPLIT)) h->spreading = 0;
    if (h->spreading) { /* its old impostor drawn as it is */
        int q = 0;
        while (q < nstale && stale[q] != 3 * k) q++;
        if (q < nstale) memmove(stale + q, stale + q + 1, sizeof *stale * (size_t)(--nstale - q));
        how[k] = 3;
    }
    if (v->impostor_budget <= 0 || (!h->spreading && nstale <= v->impostor_budget)) return nstale;
    atmos__keyed *key = malloc(sizeof *key * 2 * (size_t)(nstale ? nstale : 1));
    if (!key) return nstale; /* no room to choose: every stale one made */
    nstale = hold_to_budget(p, h, v, how, stale, nstale, key, ncoarse, h->spreading,
                            h->spreading ? (double)h->spread_res * h->spread_res / h->spread_pieces : 0.0);
    free(key);
    return nstale;
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
    if ((st = atmos__harris_diffuse_sun(p, h, v)) != ATMOS_OK) return st;
    h->eye_done = 0; /* the field turned toward this eye when a particle is splatted (air) */
    const int rect[4] = {r->x0, r->y0, r->x1, r->y1};
    const atmos__aerial *ap = frame_aerial(p, h, v);
    if (h->obj && (st = atmos__harris_objects_frame(p, h, h->obj, v, ap, rect)) != ATMOS_OK) return st;
    const int nc = h->clouds.n;
    atmos__keyed *ord = malloc(sizeof *ord * (size_t)(nc ? nc : 1));
    if (!ord) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    for (int k = 0; k < nc; k++) {
        double d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (v->cam.position[a] - h->clouds.centre[k][a]) * (v->cam.position[a] - h->clouds.centre[k][a]);
        ord[k].key = d2, ord[k].index = k;
    }
    atmos__keyed_sort(ord, (size_t)nc, 1);
    h->drawn = h->updates = h->direct = h->held = h->coarse = 0;
    const size_t cap = nc > 0 ? (size_t)nc : 1;
    int *how = malloc(sizeof(int) * 7 * cap), *side = how ? how + cap : NULL, *hp = how ? how + 2 * cap : NULL;
    int *stale = how ? how + 4 * cap : NULL;
    const atmos__pimpostor **ims = malloc(sizeof *ims * cap);
    const double **cs = malloc(sizeof *cs * cap);
    double *rs = malloc(sizeof *rs * cap);
    if (!how || !ims || !cs || !rs) st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    const frame_plan fp = {how, side, hp};
    if (st == ATMOS_OK) {
        int ncoarse = 0;
        int nfull = modes(p, h, v, rect, how, side, hp, stale, &ncoarse);
        spread_start(p, h, v, how, stale, &nfull, ncoarse);
        st = remake(p, h, v, ap, stale, nfull, ncoarse);
        if (st == ATMOS_OK && h->spreading) st = spread_step(p, h, v, ap);
    }
    /* far to near: the far layer, the objects, the near layer (without objects: the near alone) */
    if (st == ATMOS_OK && h->split_m < INFINITY) st = draw_pass(p, h, v, ap, ord, &fp, 0, rect, out, ims, cs, rs);
    if (st == ATMOS_OK && h->split_m < INFINITY) atmos__harris_objects_over(p->ctx, h->obj, h->o.nw, &v->cam, out);
    if (st == ATMOS_OK) st = draw_pass(p, h, v, ap, ord, &fp, 1, rect, out, ims, cs, rs);
    free(how), free(ims), free(cs), free(rs);
    free(ord);
    h->held += h->spreading; /* an old impostor drawn while its new one is being made */
    p->stats.impostor_updates = h->updates, p->stats.impostors_held = h->held;
    p->stats.impostors_coarse = h->coarse;
    return st;
}
