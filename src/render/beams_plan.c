/* The beam renderer's plan (beams_internal.h): the scene's objects loaded and placed, its
 * lights with their spectra and shadow maps, and the fog's scattering table. Everything
 * here depends on the scene alone, so a frame (a camera move) redoes none of it. */
#include "render/beams_internal.h"
#include "core/vec.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Planck's law up to constants: the spectral radiance of a black body at T (K), nm. */
static double planck(double nm, double T)
{
    const double c2 = 1.438776877e7; /* h c / k, nm K */
    const double l = nm * 1e-3;      /* micrometres, to keep the numbers moderate */
    return 1.0 / (l * l * l * l * l * expm1(c2 / (nm * T)));
}

/* A light's intensity_w_sr is its radiant intensity over 380-780 nm: the spectrum is the
 * black body's normalised over that band, or for an rgb colour a flat 1/400 nm^-1 per
 * channel times the channel's weight (atmos_scene_light). */
double atmos__beams_spectrum(const atmos_scene_light *l, const atmos_wavelengths *wl, int k)
{
    if (l->colour_temperature_k > 0) {
        double band = 0;
        for (int i = 0; i < 400; i++) band += planck(380.5 + i, l->colour_temperature_k);
        return l->intensity_w_sr * planck(wl->nm[k], l->colour_temperature_k) / band;
    }
    const double c = wl->mode == ATMOS_WAVELENGTHS_RGB ? l->colour[k < 3 ? k : 2] : l->colour[0];
    return l->intensity_w_sr * c / 400.0;
}

static void make_light(const atmos_scene_light *s, const atmos_wavelengths *wl, atmos__beams_light *l)
{
    memset(l, 0, sizeof *l);
    l->type = s->type;
    memcpy(l->pos, s->position_m, sizeof l->pos);
    memcpy(l->axis, s->direction, sizeof l->axis);
    atmos__normalize3(l->axis);
    l->cos_inner = cos(s->cone_deg * ATMOS_DEG2RAD);
    l->cos_outer = cos((s->cone_deg + s->edge_deg) * ATMOS_DEG2RAD);
    if (l->cos_inner <= l->cos_outer) l->cos_outer = l->cos_inner - 1e-9; /* a hard edge */
    l->range = s->range_m;
    for (int k = 0; k < wl->count; k++) {
        l->I[k] = atmos__beams_spectrum(s, wl, k);
        l->I_max = fmax(l->I_max, l->I[k]);
    }
}

static atmos_status load_terrain(atmos_context *ctx, const atmos_scene_object *o, atmos_mesh **out)
{
    atmos_terrain_desc d;
    memset(&d, 0, sizeof d);
    d.source = o->terrain, d.size_m = o->size_m, d.height_m = o->height_m, d.height_scale = o->height_scale;
    d.stride = o->stride, d.samples = o->samples, d.max_triangles = o->max_triangles, d.seed = o->seed;
    return atmos_mesh_terrain(ctx, &d, out);
}

static atmos_status load_objects(atmos_plan *p, atmos__beams_plan *b)
{
    const atmos_scene *s = &p->scene;
    b->mesh = calloc((size_t)(s->object_count ? s->object_count : 1), sizeof *b->mesh);
    b->albedo = calloc((size_t)(s->object_count ? s->object_count : 1), sizeof *b->albedo);
    if (!b->mesh || !b->albedo) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory");
    for (int i = 0; i < s->object_count; i++) {
        const atmos_scene_object *o = &s->objects[i];
        atmos_status st = o->terrain[0] ? load_terrain(p->ctx, o, &b->mesh[i]) : atmos_mesh_load(p->ctx, o->mesh, 0, &b->mesh[i]);
        if (st != ATMOS_OK) return st;
        b->nmesh = i + 1;
        atmos_mesh_transform t;
        memcpy(t.position_m, o->position_m, sizeof t.position_m);
        memcpy(t.scale, o->scale, sizeof t.scale);
        memcpy(t.rotation_deg, o->rotation_deg, sizeof t.rotation_deg);
        if ((st = atmos_mesh_apply_transform(p->ctx, b->mesh[i], &t)) != ATMOS_OK) return st;
        for (int k = 0; k < p->wl.count; k++)
            b->albedo[i][k] = p->wl.mode == ATMOS_WAVELENGTHS_RGB ? o->albedo[k < 3 ? k : 2]
                                                                : (o->albedo[0] + o->albedo[1] + o->albedo[2]) / 3;
    }
    return ATMOS_OK;
}

void atmos__beams_plan_destroy(atmos__beams_plan *b)
{
    if (!b) return;
    for (int i = 0; i < b->nmesh; i++) atmos_mesh_destroy(b->mesh[i]);
    for (int i = 0; i < b->nlights; i++) atmos__beams_shadow_free(&b->lights[i]);
    free(b->mesh);
    free(b->albedo);
    free(b->lights);
    atmos__beams_sun_free(&b->sun);
    atmos__beams_table_free(&b->table);
    free(b);
}

atmos_status atmos__beams_plan_create(atmos_plan *p, atmos__beams_plan **out)
{
    const atmos_scene *s = &p->scene;
    atmos__beams_plan *b = calloc(1, sizeof *b);
    if (!b) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory");
    atmos_status st = load_objects(p, b);
    if (st == ATMOS_OK && !(b->lights = calloc((size_t)s->light_count, sizeof *b->lights)))
        st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory");
    double range = 0;
    for (int i = 0; st == ATMOS_OK && i < s->light_count; i++) {
        make_light(&s->lights[i], &p->wl, &b->lights[i]);
        b->nlights = i + 1;
        range = fmax(range, b->lights[i].range);
        st = atmos__beams_shadow_build(p->ctx, &b->lights[i], b->mesh, b->nmesh, s->beams.shadow_size);
    }
    if (st == ATMOS_OK && s->fog.enabled && s->light_count > 0) { /* x = sigma_t v reaches sigma_t times the largest reach */
        b->sigma_t = s->fog.extinction_per_m, b->sigma_s = s->fog.scattering_per_m;
        st = atmos__beams_table_build(p->ctx, b->sigma_t, b->sigma_s, s->fog.g,
                                      fmin(b->sigma_t * range, ATMOS__BEAMS_MAX_OPTICAL_RANGE), &b->table);
    }
    if (s->fog.enabled) {
        const atmos__beams_fog f = {s->fog.extinction_per_m, s->fog.scattering_per_m / s->fog.extinction_per_m, s->fog.g,
                                    s->fog.base_m, s->fog.height_m};
        b->fog = f;
    }
    b->sun_on = s->beams.sun;
    if (st != ATMOS_OK) {
        atmos__beams_plan_destroy(b);
        return st;
    }
    *out = b;
    return ATMOS_OK;
}

atmos_status atmos__beams_sun_frame(atmos_plan *p, const atmos__view *v)
{
    atmos__beams_plan *b = p->beams;
    atmos__beams_sun *sun = &b->sun;
    atmos_atmosphere_sunlight(p->atm, v->cam.position, v->sun, sun->E); /* the sun's colour where the eye is */
    if (sun->depth && !memcmp(sun->dir, v->sun, sizeof sun->dir)) return ATMOS_OK;
    return atmos__beams_sun_build(p->ctx, sun, v->sun, b->mesh, b->nmesh, p->scene.beams.shadow_size);
}

void atmos__beams_describe(const atmos_plan *p, char *buf, size_t cap)
{
    const atmos__beams_plan *b = p->beams;
    const atmos_scene_beams *s = &p->scene.beams;
    snprintf(buf, cap, "%d lights, %d objects, fog %g/m; plane spacing %g m (0: auto), epsilon %g, at most %d sub-planes, "
             "shadow maps %d; centre ray: %d main planes, %d sub-planes",
             b->nlights, b->nmesh, b->sigma_t, s->plane_spacing_m, s->epsilon, s->max_subplanes, s->shadow_size,
             b->centre_planes, b->centre_subplanes);
}
