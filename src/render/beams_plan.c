/* The beam renderer's plan (beams_internal.h): the scene's objects loaded and placed, its
 * lights with their spectra and shadow maps, and the fog's scattering table. Everything
 * here depends on the scene alone, so a frame (a camera move) redoes none of it. */
#include "render/beams_internal.h"
#include "core/vec.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static atmos_status make_light(atmos_context *ctx, const atmos_scene *s, int index, const atmos_wavelengths *wl,
                               atmos__beams_light *l)
{
    memset(l, 0, sizeof *l);
    atmos__lamp_make(&s->lights[index], wl, &l->L);
    if (!(l->L.range > 0)) { /* auto: from the fog's extinction where the light is */
        const atmos_scene_fog *f = &s->fog;
        const double above = fmax(0, l->L.pos[1] - f->base_m);
        const double sig = !f->enabled ? 0 : f->height_m > 0 ? f->extinction_per_m * exp(-above / f->height_m) : f->extinction_per_m;
        l->L.range = atmos__lamp_auto_range(sig);
    }
    return atmos__lamp_load_image(ctx, s, index, &l->L);
}

void atmos__beams_plan_destroy(atmos__beams_plan *b)
{
    if (!b) return;
    atmos__objects_free(&b->obj);
    for (int i = 0; i < b->nlights; i++) atmos__beams_shadow_free(&b->lights[i]), atmos__lamp_free(&b->lights[i].L);
    free(b->lights);
    atmos__beams_sun_free(&b->sun);
    atmos__beams_epi_free(&b->epi);
    atmos__beams_sky_free(&b->sky);
    atmos__beams_table_free(&b->table);
    atmos__fog_optics_free(&b->optics);
    for (int k = 0; k < ATMOS__BEAMS_KEPT_COUNT; k++) atmos__beams_kept_free(&b->kept[k]);
    free(b);
}

/* Every light's shadow maps, with progress from 0 to 1 (a city's take seconds). */
static atmos_status shadow_maps(atmos_plan *p, atmos__beams_plan *b, atmos__beams_progress *pr)
{
    const char *stage = "beams shadow maps";
    if (atmos__progress(p->ctx, stage, 0.0)) return atmos__error(p->ctx, ATMOS_E_CANCELLED, "render beams: cancelled");
    for (int i = 0; i < b->nlights; i++) {
        atmos_status st = atmos__beams_shadow_build(p->ctx, &b->lights[i], b->obj.mesh, b->obj.n, p->scene.beams.shadow_size, pr);
        if (st != ATMOS_OK) return st;
    }
    if (atmos__progress(p->ctx, stage, 1.0)) return atmos__error(p->ctx, ATMOS_E_CANCELLED, "render beams: cancelled");
    return ATMOS_OK;
}

/* The sun's map for the scene's own sun, made with the lights' maps (it depends on the scene
 * alone): a frame whose sun is the same (the bits of a frame from the scene, atmos_frame_from_scene,
 * as the frame resolves it) keeps it (atmos__beams_sun_frame), another makes its own as before. */
static atmos_status scene_sun_map(atmos_plan *p, atmos__beams_plan *b)
{
    double d[3];
    atmos_status st = atmos_scene_sun_direction(p->ctx, &p->scene, d, NULL, NULL);
    const double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (st != ATMOS_OK || !(l > 0.5 && l < 2.0)) return st; /* a frame's own sun is checked there */
    for (int a = 0; a < 3; a++) d[a] = l == 1.0 ? d[a] : d[a] / l;
    st = atmos__beams_sun_build(p->ctx, &b->sun, d, b->obj.mesh, b->obj.n, p->scene.beams.shadow_size);
    if (st == ATMOS_OK) atmos__beams_sun_warn_texel(p->ctx, &b->sun, b->obj.mesh, b->obj.n), b->sun.warned = 1;
    return st;
}

atmos_status atmos__beams_plan_create(atmos_plan *p, atmos__beams_plan **out)
{
    const atmos_scene *s = &p->scene;
    atmos_status st = atmos__beams_memory_check(p->ctx, s->width, s->height, p->wl.count);
    if (st != ATMOS_OK) return st;
    atmos__beams_plan *b = calloc(1, sizeof *b);
    if (!b) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory");
    st = atmos__objects_load(p->ctx, s, &p->wl, &b->obj);
    if (st == ATMOS_OK) atmos__objects_warn_dark_lights(p->ctx, s, &b->obj);
    if (st == ATMOS_OK && !(b->lights = calloc((size_t)s->light_count, sizeof *b->lights)))
        st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory");
    double range = 0;
    atmos__beams_progress pr = {0, 0, 0};
    for (int i = 0; st == ATMOS_OK && i < s->light_count; i++) {
        st = make_light(p->ctx, s, i, &p->wl, &b->lights[i]);
        b->nlights = i + 1;
        range = fmax(range, b->lights[i].L.range);
        pr.total += atmos__beams_shadow_faces(&b->lights[i].L, b->obj.n);
    }
    if (st == ATMOS_OK && pr.total > 0) st = shadow_maps(p, b, &pr);
    if (st == ATMOS_OK) st = atmos__fog_optics_build(p->ctx, s, &p->wl, &b->optics);
    const atmos__fog_optics *o = &b->optics;
    if (st == ATMOS_OK && s->fog.enabled && s->light_count > 0) { /* x = sigma_t v reaches sigma_t times the largest reach */
        b->sigma_t = o->sigma_t, b->sigma_s = o->sigma_s;
        st = atmos__beams_table_build(p->ctx, b->sigma_t, b->sigma_s, o,
                                      fmin(b->sigma_t * range, ATMOS__BEAMS_MAX_OPTICAL_RANGE), &b->table);
    }
    if (st == ATMOS_OK && s->fog.enabled) {
        const atmos__beams_fog f = {.sigma0 = o->sigma_t, .albedo = o->sigma_s / o->sigma_t, .g = o->g,
                                     .base_m = s->fog.base_m, .height_m = s->fog.height_m, .phase = o};
        b->fog = f;
    }
    b->sun_on = s->beams.sun;
    b->exact_shadows = s->beams.exact_shadows;
    if (st == ATMOS_OK && b->sun_on && b->obj.n > 0) st = scene_sun_map(p, b);
    if (st != ATMOS_OK) {
        atmos__beams_plan_destroy(b);
        return st;
    }
    *out = b;
    return ATMOS_OK;
}

/* The most samples the epipolar lines may take (4 bytes each, and their trees 8 more): beyond,
 * each ray walks the map's own tiles. */
#define EPI_MAX_SAMPLES ((size_t)8 << 20)

atmos_status atmos__beams_sun_frame(atmos_plan *p, const atmos__view *v)
{
    atmos__beams_plan *b = p->beams;
    atmos__beams_sun *sun = &b->sun;
    atmos_atmosphere_sunlight(p->atm, v->cam.position, v->sun, sun->E); /* the sun's colour where the eye is */
    atmos_status st = ATMOS_OK;
    if (!(sun->depth && !memcmp(sun->dir, v->sun, sizeof sun->dir)))
        st = atmos__beams_sun_build(p->ctx, sun, v->sun, b->obj.mesh, b->obj.n, p->scene.beams.shadow_size);
    if (st == ATMOS_OK && !sun->warned) atmos__beams_sun_warn_texel(p->ctx, sun, b->obj.mesh, b->obj.n), sun->warned = 1;
    /* the map along epipolar lines from the eye, for the fog's sunlight (none without fog) */
    if (st == ATMOS_OK && b->fog.sigma0 > 0 &&
        atmos__beams_epi_build(&b->epi, sun, v->cam.position, EPI_MAX_SAMPLES, atmos__threads(p->ctx)))
        st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory for the sun's epipolar lines");
    return st;
}

void atmos__beams_describe(const atmos_plan *p, char *buf, size_t cap)
{
    const atmos__beams_plan *b = p->beams;
    const atmos_scene_beams *s = &p->scene.beams;
    snprintf(buf, cap, "%d lights, %d objects, fog %g/m; plane spacing %g m (0: auto), epsilon %g, at most %d sub-planes, "
             "shadow maps %d, screen step %d%s, %s shadows on surfaces; centre ray: %d main planes, %d sub-planes; "
             "airlight evaluated at %ld of %ld pixels",
             b->nlights, b->obj.n, b->sigma_t, s->plane_spacing_m, s->epsilon, s->max_subplanes, s->shadow_size,
             s->interleave > 1 ? 1 : s->screen_step, s->interleave > 1 && s->screen_step > 1 ? " (interleaved: not subsampled)" : "",
             s->exact_shadows ? "exact" : "map-decided", b->centre_planes, b->centre_subplanes, b->air_evaluated,
             b->air_pixels);
}
