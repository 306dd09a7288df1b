/* Harris 2002's particle-cloud renderer ("renderer": "harris", docs/particles.md): the plan's
 * volume becomes a particle cloud once (src/particles/), the light passes run when the sun
 * moves (the sun and, as Harris §2.3.1 lights clouds at sunset with several coloured lights,
 * sky lights from directions over the upper hemisphere whose colour the atmosphere gives),
 * and a frame is the sky renderer's image with the particles splatted over it back to front. */
#include "atmosphere/atmosphere_ops.h"
#include "particles/pcloud.h"
#include "render/plan_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LIGHTS 17

struct atmos__harris_plan {
    atmos__pcloud pc;
    atmos__poptics o;
    int nlights;                         /* the sun, then the sky lights */
    double dir[MAX_LIGHTS][3];           /* toward each light */
    double e[MAX_LIGHTS][ATMOS_MAX_WAVELENGTHS]; /* its irradiance outside the cloud */
    float *light[MAX_LIGHTS], *order[MAX_LIGHTS];
    float *air_t, *air_l;                /* the air from the eye to each particle, this frame */
    atmos__aerial aerial;
    double sun[3];
    int have_sun, drawn;
    double shade_s;
};

/* The sky lights' directions: sky_lights directions at 30 degrees elevation evenly in
 * azimuth (the first toward the sun's azimuth) and one at the zenith, each standing for an
 * equal share of the upper hemisphere. */
static void sky_dirs(int n, const double sun[3], double (*d)[3])
{
    if (n <= 0) return;
    double el, az;
    atmos_direction_to_angles(sun, &el, &az);
    d[0][0] = 0, d[0][1] = 1, d[0][2] = 0;
    for (int i = 1; i < n; i++) atmos_direction_from_angles(30.0, fmod(az + 360.0 * (i - 1) / (n - 1), 360.0), d[i]);
}

static atmos_status lights(atmos_plan *p, atmos__harris_plan *h, const double sun[3])
{
    double lo[3], hi[3], c[3];
    atmos__pcloud_bounds(&h->pc, lo, hi);
    for (int a = 0; a < 3; a++) c[a] = 0.5 * (lo[a] + hi[a]);
    memcpy(h->dir[0], sun, sizeof h->dir[0]);
    atmos_atmosphere_sunlight(p->atm, c, sun, h->e[0]);
    const int sky = p->scene.harris.sky_lights;
    h->nlights = 1 + sky;
    sky_dirs(sky, sun, h->dir + 1);
    for (int j = 1; j < h->nlights; j++) {
        atmos_atmosphere_hit info;
        atmos_atmosphere_radiance(p->atm, c, h->dir[j], sun, h->e[j], &info);
        for (int k = 0; k < h->o.nw; k++) h->e[j][k] *= 2.0 * ATMOS_PI / sky; /* radiance x its share of the sky */
    }
    /* the lights on the threads (each pass on one; the result does not depend on the count) */
    atmos_status st = ATMOS_OK;
#pragma omp parallel for schedule(dynamic, 1) num_threads(atmos__threads(p->ctx))
    for (int j = 0; j < h->nlights; j++) {
        /* the sky's light is soft: its buffers have texels three times as wide */
        const atmos_status sj = atmos__pcloud_shade(p->ctx, &h->pc, &h->o, h->dir[j], p->scene.harris.light_size,
                                                    j ? 3.0 : 1.0, h->light[j], h->order[j]);
        if (sj != ATMOS_OK) {
#pragma omp critical
            st = sj;
        }
    }
    if (st != ATMOS_OK) return st;
    memcpy(h->sun, sun, sizeof h->sun);
    h->have_sun = 1;
    return ATMOS_OK;
}

static atmos_status optics(atmos_plan *p, atmos__harris_plan *h)
{
    h->o.nw = p->wl.count;
    for (int f = 0; f < p->optics->count; f++) {
        for (int k = 0; k < h->o.nw; k++) {
            h->o.sigma_ext[f][k] = atmos_phase_table_sigma_ext(p->optics->phase[f], k);
            h->o.albedo[f][k] = atmos_phase_table_albedo(p->optics->phase[f], k);
        }
        h->o.ms[f] = p->optics->ms[f];
        if (!h->o.ms[f])
            return atmos__error(p->ctx, ATMOS_E_INVALID_ARG, "render harris: the optics need their Ams tables");
    }
    return ATMOS_OK;
}

atmos_status atmos__harris_plan_create(atmos_plan *p, atmos__harris_plan **out)
{
    *out = NULL;
    atmos__harris_plan *h = calloc(1, sizeof *h);
    if (!h) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    const atmos_scene_harris *hs = &p->scene.harris;
    atmos_status st = optics(p, h);
    if (st == ATMOS_OK)
        st = atmos__pcloud_from_volume(p->ctx, p->volume, p->offset, hs->spacing_m, hs->max_particles, &h->pc);
    for (int i = 0; i < h->pc.n && st == ATMOS_OK; i++) h->pc.n0[i] *= (float)p->scene.volume.density_scale;
    h->air_t = malloc(sizeof(float) * (size_t)(h->pc.n ? h->pc.n : 1) * h->o.nw);
    h->air_l = malloc(sizeof(float) * (size_t)(h->pc.n ? h->pc.n : 1) * h->o.nw);
    if (!h->air_t || !h->air_l) st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    for (int j = 0; j <= hs->sky_lights && st == ATMOS_OK; j++) {
        h->light[j] = malloc(sizeof(float) * (size_t)(h->pc.n ? h->pc.n : 1) * h->o.nw);
        h->order[j] = malloc(sizeof(float) * (size_t)(h->pc.n ? h->pc.n : 1));
        if (!h->light[j] || !h->order[j]) st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    }
    if (st != ATMOS_OK) {
        atmos__harris_plan_destroy(h);
        return st;
    }
    atmos__log(p->ctx, ATMOS_LOG_INFO, "render harris: %d particles", h->pc.n);
    *out = h;
    return ATMOS_OK;
}

void atmos__harris_plan_destroy(atmos__harris_plan *h)
{
    if (!h) return;
    atmos__pcloud_free(&h->pc);
    for (int j = 0; j < MAX_LIGHTS; j++) free(h->light[j]), free(h->order[j]);
    free(h->air_t), free(h->air_l);
    atmos__aerial_free(&h->aerial);
    free(h);
}

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

/* The air from the eye to every particle's centre. */
static void air(const atmos_plan *p, atmos__harris_plan *h, const atmos__view *v)
{
    const atmos__aerial *ap = frame_aerial(p, h, v);
    const int nw = h->o.nw;
#pragma omp parallel for schedule(dynamic, 256) num_threads(atmos__threads(p->ctx))
    for (int i = 0; i < h->pc.n; i++) {
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

atmos_status atmos__harris_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out)
{
    atmos__harris_plan *h = p->harris;
    atmos_status st = atmos__sky_render(p->ctx, p->atm, v, r, out, p->sky_keep);
    if (st != ATMOS_OK) return st;
    if (!h->have_sun || memcmp(h->sun, v->sun, sizeof h->sun) != 0) {
        const double t0 = atmos__now();
        if ((st = lights(p, h, v->sun)) != ATMOS_OK) return st;
        h->shade_s = atmos__now() - t0;
    }
    const int rect[4] = {r->x0, r->y0, r->x1, r->y1};
    air(p, h, v);
    /* the lights one after another over the same splats would composite each one's
     * transparency again: their colours are summed per particle instead */
    return atmos__pcloud_splat_lights(p->ctx, &h->pc, &h->o, h->nlights, (const float *const *)h->light,
                                      (const float *const *)h->order, (const double(*)[3])h->dir,
                                      (const double(*)[ATMOS_MAX_WAVELENGTHS])h->e, h->air_t, h->air_l, &v->cam, rect,
                                      out, &h->drawn);
}

void atmos__harris_describe(const atmos_plan *p, char *buf, size_t cap)
{
    const atmos__harris_plan *h = p->harris;
    snprintf(buf, cap, "%d particles (%d drawn), %d sky lights, light passes %.3f s", h->pc.n, h->drawn,
             h->nlights - 1, h->shade_s);
}
