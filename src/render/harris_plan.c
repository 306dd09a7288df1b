/* Harris 2002's particle-cloud renderer ("renderer": "harris", docs/particles.md), the plan's
 * part: the plan's volume becomes a particle cloud once (src/particles/), grouped into clouds
 * for the impostors; the light passes run when the sun moves (the sun and, as Harris §2.3.1
 * lights clouds at sunset with several coloured lights, sky lights from directions over the
 * upper hemisphere whose colour the atmosphere gives). */
#include "render/harris_internal.h"
#include "particles/pphase.h"

#include "atmosphere/atmosphere_check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The sky lights' directions: one at the zenith and sky_lights - 1 at 30 degrees elevation
 * evenly in azimuth, half a step off the sun's azimuth (so that none looks at the sun), each
 * standing for an equal share of the upper hemisphere. */
static void sky_dirs(int n, const double sun[3], double (*d)[3])
{
    if (n <= 0) return;
    double el, az;
    atmos_direction_to_angles(sun, &el, &az);
    d[0][0] = 0, d[0][1] = 1, d[0][2] = 0;
    for (int i = 1; i < n; i++) atmos_direction_from_angles(30.0, fmod(az + 360.0 * (i - 0.5) / (n - 1), 360.0), d[i]);
}

/* The light passes of the pairs q0 .. q1 (pair q: light q / clouds, cloud q % clouds), each light
 * and each cloud on its own (clouds do not shade one another, as in Harris's passes), on the
 * threads (the result does not depend on the count); the objects' vertices' light into
 * probe[(q - q0) nv nw ..]. */
static atmos_status light_pairs(atmos_plan *p, atmos__harris_plan *h, int q0, int q1, float *probe)
{
    atmos_status st = ATMOS_OK;
    const atmos__pclusters *cl = &h->clouds;
    const int nv = h->obj ? h->obj->nv : 0, nw = h->o.nw;
#pragma omp parallel for schedule(dynamic, 1) num_threads(atmos__threads(p->ctx))
    for (int q = q0; q < q1; q++) {
        const int j = q / cl->n, k = q % cl->n;
        const atmos__pprobes pr = {nv, h->obj ? h->obj->xyz : NULL, probe + (size_t)(q - q0) * nv * nw};
        /* the sky's light is soft: its buffers have texels three times as wide */
        const atmos_status sj = atmos__pcloud_shade_probes(p->ctx, &h->pc, cl->idx + cl->start[k],
                                                           cl->start[k + 1] - cl->start[k], &h->o, h->dir[j],
                                                           p->scene.harris.light_size, j ? 3.0 : 1.0, h->light[j],
                                                           h->order[j], nv ? &pr : NULL);
        if (sj != ATMOS_OK) {
#pragma omp critical
            st = sj;
        }
    }
    return st;
}

atmos_status atmos__harris_lights(atmos_plan *p, atmos__harris_plan *h, const double sun[3])
{
    double lo[3], hi[3], c[3];
    atmos__pcloud_bounds(&h->pc, lo, hi);
    for (int a = 0; a < 3; a++) c[a] = 0.5 * (lo[a] + hi[a]);
    atmos__atm_onto_ground(p->atm, c, c); /* the sky seen from above the ground */
    memcpy(h->dir[0], sun, sizeof h->dir[0]);
    atmos_atmosphere_sunlight(p->atm, c, sun, h->e[0]);
    const int sky = p->scene.harris.sky_lights;
    h->nlights = 1 + sky;
    sky_dirs(sky, sun, h->dir + 1);
    for (int j = 1; j < h->nlights; j++) {
        atmos_atmosphere_hit info;
        atmos_atmosphere_radiance(p->atm, c, h->dir[j], sun, h->e[j], &info);
        if (info.in_sun_disk) { /* the sun is the first light: its disk is not the sky's */
            double disk[ATMOS_MAX_WAVELENGTHS];
            atmos_atmosphere_sun_radiance(p->atm, c, sun, disk);
            for (int k = 0; k < h->o.nw; k++) h->e[j][k] = fmax(0.0, h->e[j][k] - disk[k]);
        }
        for (int k = 0; k < h->o.nw; k++) h->e[j][k] *= 2.0 * ATMOS_PI / sky; /* radiance x its share of the sky */
    }
    /* the objects' vertices read every pass as particles would: the light each pair leaves them,
     * the pairs in batches that keep that within 64 MB */
    const atmos__pclusters *cl = &h->clouds;
    const int pairs = h->nlights * cl->n, nv = h->obj ? h->obj->nv : 0, nw = h->o.nw;
    const size_t per = (size_t)nv * nw, fit = per ? ((size_t)64 << 20) / (sizeof(float) * per) : (size_t)pairs;
    const int batch = pairs < 1 ? 1 : (fit < 1 ? 1 : (fit < (size_t)pairs ? (int)fit : pairs));
    float *probe = nv ? malloc(sizeof(float) * (size_t)batch * per) : NULL;
    if (nv && !probe) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory for the objects' light");
    for (int j = 0; j < h->nlights && nv; j++)
        for (size_t i = 0; i < per; i++) h->obj->light[j][i] = 1.0f;
    atmos_status st = ATMOS_OK;
    for (int q0 = 0; q0 < pairs && st == ATMOS_OK; q0 += batch) {
        const int q1 = q0 + batch < pairs ? q0 + batch : pairs;
        st = light_pairs(p, h, q0, q1, probe);
        /* a vertex gets what every cloud leaves of each light (in the clouds' order: the same
         * product whatever the threads) */
        for (int q = q0; q < q1 && nv && st == ATMOS_OK; q++)
            for (size_t i = 0; i < per; i++) h->obj->light[q / cl->n][i] *= probe[(size_t)(q - q0) * per + i];
    }
    free(probe);
    if (st != ATMOS_OK) return st;
    memcpy(h->sun, sun, sizeof h->sun);
    h->have_sun = 1;
    for (int k = 0; k < h->clouds.n; k++) h->imp[k].valid = 0; /* lit anew */
    for (int k = 0; h->split && k < 2 * h->clouds.n; k++) h->split[k].valid = 0;
    h->spreading = 0; /* a make spread over frames was lit by the old sun */
    return ATMOS_OK;
}

size_t atmos__harris_pphase_max_bytes = ATMOS__PPHASE_MAX_BYTES;

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
        /* the eye pass's Ams_n on the cosine (docs/viewer.md: within its stated error), under a
         * size cap; NULL (too large, or no memory): the exact look-up */
        h->o.ph[f] = atmos__pphase_make(h->o.ms[f], h->o.nw, atmos__harris_pphase_max_bytes);
        if (!h->o.ph[f])
            atmos__log(p->ctx, ATMOS_LOG_WARN,
                       "render harris: particle type %d's phase table (%zu MB; cap %zu MB) not made: "
                       "the exact look-up, slower", f,
                       atmos__pphase_bytes(h->o.ms[f], h->o.nw) >> 20, atmos__harris_pphase_max_bytes >> 20);
    }
    return ATMOS_OK;
}

/* The particles: a particle cloud's own (the scene's "generate": "harris_..."), or the
 * volume's made into particles. */
static atmos_status particles(atmos_plan *p, atmos__harris_plan *h)
{
    const atmos_scene_volume *sv = &p->scene.volume;
    const atmos_scene_harris *hs = &p->scene.harris;
    for (const char *const *g = atmos__pcloud_generator_names(); *g; g++)
        if (!strncmp(sv->source, "generate:", 9) && !strcmp(sv->source + 9, *g)) {
            double voxel;
            atmos_status st = atmos__pcloud_generate(p->ctx, *g, sv->seed, sv->scale > 0 ? sv->scale : 1.0,
                                                       p->scene.harris.spacing_m, &h->pc, &voxel);
            if (st != ATMOS_OK) return st;
            /* the grid the plan placed starts at the particles' box (atmos__pcloud_to_volume) */
            double lo[3], hi[3];
            atmos__pcloud_bounds(&h->pc, lo, hi);
            const double *org = atmos_volume_get_desc(p->volume)->origin_m;
            const float sx = (float)(p->offset[0] - lo[0] + org[0]), sy = (float)(p->offset[1] - lo[1] + org[1]),
                        sz = (float)(p->offset[2] - lo[2] + org[2]);
            for (int i = 0; i < h->pc.n; i++) h->pc.x[i] += sx, h->pc.y[i] += sy, h->pc.z[i] += sz;
            return ATMOS_OK;
        }
    return atmos__pcloud_from_volume(p->ctx, p->volume, p->offset, hs->spacing_m, hs->max_particles, &h->pc);
}

/* The scene's objects and what splitting the clouds' impostors about them needs (Harris §3.2). */
static atmos_status objects(atmos_plan *p, atmos__harris_plan *h)
{
    atmos_status st = atmos__harris_objects_create(p, &h->obj);
    if (st != ATMOS_OK) return st;
    const size_t nc = h->clouds.n ? (size_t)h->clouds.n : 1;
    h->split = calloc(2 * nc, sizeof *h->split);
    h->part = malloc(sizeof(int) * (size_t)(h->pc.n ? h->pc.n : 1));
    h->nfar = calloc(nc, sizeof *h->nfar);
    h->offset = calloc(nc, sizeof *h->offset);
    if (!h->split || !h->part || !h->nfar || !h->offset)
        return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory for the split impostors");
    return ATMOS_OK;
}

/* Each cloud's narrowest particle width (what its impostor's texels and its split need). */
static atmos_status narrowest(atmos_plan *p, atmos__harris_plan *h)
{
    h->smin = malloc(sizeof *h->smin * (size_t)(h->clouds.n ? h->clouds.n : 1));
    if (!h->smin) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    for (int k = 0; k < h->clouds.n; k++) {
        h->smin[k] = INFINITY;
        for (int q = h->clouds.start[k]; q < h->clouds.start[k + 1]; q++) h->smin[k] = fmin(h->smin[k], h->pc.s[h->clouds.idx[q]]);
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
    if (st == ATMOS_OK) st = particles(p, h);
    for (int i = 0; i < h->pc.n && st == ATMOS_OK; i++) h->pc.n0[i] *= (float)p->scene.volume.density_scale;
    if (st == ATMOS_OK) st = atmos__pcloud_cluster(p->ctx, &h->pc, 0.0, &h->clouds);
    if (st == ATMOS_OK && !(h->imp = calloc((size_t)(h->clouds.n ? h->clouds.n : 1), sizeof *h->imp)))
        st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    h->air_t = malloc(sizeof(float) * (size_t)(h->pc.n ? h->pc.n : 1) * h->o.nw);
    h->air_l = malloc(sizeof(float) * (size_t)(h->pc.n ? h->pc.n : 1) * h->o.nw);
    if (!h->air_t || !h->air_l) st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    for (int j = 0; j <= hs->sky_lights && st == ATMOS_OK; j++) {
        h->light[j] = malloc(sizeof(float) * (size_t)(h->pc.n ? h->pc.n : 1) * h->o.nw);
        h->order[j] = malloc(sizeof(float) * (size_t)(h->pc.n ? h->pc.n : 1));
        if (!h->light[j] || !h->order[j]) st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory");
    }
    if (st == ATMOS_OK) st = narrowest(p, h);
    if (st == ATMOS_OK && p->scene.object_count > 0) st = objects(p, h);
    if (st == ATMOS_OK) st = atmos__harris_diffuse_prepare(p, h);
    if (st != ATMOS_OK) {
        atmos__harris_plan_destroy(h);
        return st;
    }
    atmos__log(p->ctx, ATMOS_LOG_INFO, "render harris: %d particles in %d clouds", h->pc.n, h->clouds.n);
    if (hs->light_size > 1024) /* its own choice is at most 1024; the time grows as the texels */
        atmos__log(p->ctx, ATMOS_LOG_WARN,
                   "render harris: light_size %d: each of the %d lights' passes over %d cloud%s fills %d x %d "
                   "texels, %.0f times 1024's; expect minutes where 1024 takes seconds",
                   hs->light_size, hs->sky_lights + 1, h->clouds.n, h->clouds.n == 1 ? "" : "s", hs->light_size,
                   hs->light_size, (double)hs->light_size * hs->light_size / (1024.0 * 1024.0));
    *out = h;
    return ATMOS_OK;
}

void atmos__harris_plan_destroy(atmos__harris_plan *h)
{
    if (!h) return;
    for (int k = 0; h->imp && k < h->clouds.n; k++) atmos__pimpostor_free(&h->imp[k]);
    free(h->imp);
    atmos__pimpostor_free(&h->spread);
    for (int k = 0; h->split && k < 2 * h->clouds.n; k++) atmos__pimpostor_free(&h->split[k]);
    free(h->split), free(h->part), free(h->nfar), free(h->offset), free(h->smin);
    atmos__harris_objects_destroy(h->obj);
    atmos__pclusters_free(&h->clouds);
    atmos__pcloud_free(&h->pc);
    for (int f = 0; f < ATMOS_VOLUME_MAX_FIELDS; f++) atmos__pphase_free(h->o.ph[f]);
    for (int j = 0; j < ATMOS__HARRIS_MAX_LIGHTS; j++) free(h->light[j]), free(h->order[j]);
    free(h->air_t), free(h->air_l);
    atmos__aerial_free(&h->aerial);
    atmos__harris_diffuse_free(h);
    free(h);
}

void atmos__harris_describe(const atmos_plan *p, char *buf, size_t cap)
{
    const atmos__harris_plan *h = p->harris;
    snprintf(buf, cap, "%d particles in %d clouds (%d splatted, %d clouds direct), %d sky lights, light passes %.3f s, "
             "%d impostor updates%s", h->pc.n, h->clouds.n, h->drawn, h->direct, h->nlights - 1, h->shade_s, h->updates,
             h->diffuse ? ", diffuse field" : "");
    if (h->obj) {
        const size_t l = strlen(buf);
        snprintf(buf + l, cap - l, ", %d objects, %d clouds split at %.0f m", h->obj->n, h->splits, h->split_m);
    }
}
