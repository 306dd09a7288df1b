/* Plans and frames (include/atmos/plan.h): a scene becomes a plan once (the atmosphere, the
 * volume placed, its optics, each renderer's tables and buffers); a frame becomes a view and
 * is rendered from the plan, redoing only what changed since the last frame. */
#include "core/finite.h"
#include "render/plan_internal.h"
#include "scene/scene_internal.h"
#include "volume/volume_grid.h"

#include <limits.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ creation */

/* The scene as the plan checks it: a volume given by the caller stands for the one the scene
 * would name, and one placed by an explicit offset needs no placement from the scene. */
static atmos_status check_scene(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                const atmos_plan_desc *d)
{
    atmos_scene s = *scene;
    if (volume && s.renderer != ATMOS_RENDERER_SKY && !s.volume.source[0])
        snprintf(s.volume.source, sizeof s.volume.source, "(a volume given to the plan)");
    if (volume && d->offset_given) s.volume.placed = 1;
    return atmos_scene_validate(ctx, &s, "scene");
}

static atmos_status plan_volume(atmos_plan *p, const atmos_volume *volume, const atmos_plan_desc *d)
{
    atmos_context *ctx = p->ctx;
    if (p->renderer == ATMOS_RENDERER_SKY) return ATMOS_OK;
    if (volume) {
        if (!volume->finalized)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render %s: volume is not finalized",
                                atmos_renderer_name(p->renderer));
        p->volume = volume;
        atmos_scene_volume_offset(&p->scene, volume, p->offset);
    } else if (p->scene.volume.source[0]) {
        atmos_status st = atmos_scene_load_volume(ctx, &p->scene, &p->own_volume, p->offset);
        if (st != ATMOS_OK) return st;
        p->volume = p->own_volume;
    }
    if (d->offset_given) memcpy(p->offset, d->offset_m, sizeof p->offset);
    for (int a = 0; a < 3; a++)
        if (!isfinite(p->offset[a])) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "plan: the volume's offset must be finite");
    if (!p->volume) return ATMOS_OK;
    if (d->optics) {
        p->optics = d->optics;
    } else {
        atmos_status st = atmos_volume_optics_build(ctx, &p->scene, p->volume, p->renderer == ATMOS_RENDERER_SLICE ||
                                                                                 p->renderer == ATMOS_RENDERER_HARRIS ||
                                                                                 (p->renderer == ATMOS_RENDERER_NISHITA &&
                                                                                  p->scene.nishita.diffuse),
                                                    &p->own_optics);
        if (st != ATMOS_OK) return st;
        p->optics = &p->own_optics;
    }
    if (p->optics->count != atmos_volume_field_count(p->volume))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "plan: optics for %d fields, the volume has %d", p->optics->count,
                            atmos_volume_field_count(p->volume));
    atmos__scene_volume_warnings(ctx, &p->scene, p->volume, p->optics, p->offset);
    return ATMOS_OK;
}

/* The fog, the lights and the objects are drawn by the beam renderer and the path tracer only:
 * a scene that gives them to another renderer is told so rather than silently drawn without. */
/* names[0..n) as "a, b and c" into out (cap bytes). */
static void join_names(const char *const *names, int n, char *out, size_t cap)
{
    out[0] = '\0';
    for (int i = 0; i < n; i++)
        snprintf(out + strlen(out), cap - strlen(out), "%s%s", i ? (i == n - 1 ? " and " : ", ") : "", names[i]);
}

static void warn_unused_parts(atmos_context *ctx, const atmos_scene *s)
{
    if (s->renderer == ATMOS_RENDERER_BEAMS || s->renderer == ATMOS_RENDERER_PATH) return;
    const char *in_list[3];
    int n = 0;
    if (s->fog.enabled) in_list[n++] = "fog";
    if (s->light_count > 0) in_list[n++] = "lights";
    if (s->object_count > 0 && s->renderer != ATMOS_RENDERER_HARRIS) in_list[n++] = "objects"; /* Harris draws them */
    char list[64];
    join_names(in_list, n, list, sizeof list);
    if (!list[0]) return;
    /* with a cloud volume neither the beam renderer nor the path tracer draws them (docs/path.md) */
    const int volume = s->volume.source[0] != '\0';
    const char *who = !volume ? "the beam renderer and the path tracer do: \"renderer\": \"beams\" or \"path\""
                      : n == 1 && s->object_count > 0
                          ? "the harris renderer draws objects among its clouds: \"renderer\": \"harris\"; the "
                            "beam renderer and the path tracer draw them without a cloud volume"
                          : "the beam renderer and the path tracer draw them, but not with a cloud volume yet";
    atmos__log(ctx, ATMOS_LOG_WARN, "the %s renderer does not draw the scene's %s (%s)",
               atmos_renderer_name(s->renderer), list, who);
}

/* A round model without aerosols ("aerosol": "none") reads none of the keys that set their
 * amount or profile: a scene that sets them is told, as the flat models' are. */
static void warn_no_aerosol(atmos_context *ctx, const atmos_atmosphere_desc *a, const atmos_atmosphere_desc *d)
{
    const char *names[3];
    int n = 0;
    if (a->visibility_km != d->visibility_km) names[n++] = "visibility_km";
    if (a->turbidity != d->turbidity) names[n++] = "turbidity";
    if (a->aerosol_scale_height_m != d->aerosol_scale_height_m) names[n++] = "aerosol_scale_height_m";
    char list[100];
    join_names(names, n, list, sizeof list);
    if (n)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "\"aerosol\": \"none\" leaves the air without aerosols: %s set%s nothing (they set the "
                   "aerosols' amount and height)",
                   list, n > 1 ? "" : "s");
}

/* The flat models (riley, homogeneous) read none of the round ones' air (aerosols, ozone, the
 * planet): a scene that sets them is told, not silently given the flat sky. */
static void warn_unused_air(atmos_context *ctx, const atmos_scene *s)
{
    const atmos_atmosphere_desc *a = &s->atmosphere;
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    if (a->kind == ATMOS_ATMOSPHERE_SPHERICAL || a->kind == ATMOS_ATMOSPHERE_DOBASHI) {
        if (a->aerosol == ATMOS_AEROSOL_NONE) warn_no_aerosol(ctx, a, &d);
        return;
    }
    if (a->kind != ATMOS_ATMOSPHERE_RILEY && a->kind != ATMOS_ATMOSPHERE_HOMOGENEOUS) return;
    const char *names[9];
    int n = 0;
    if (a->aerosol != d.aerosol) names[n++] = "aerosol";
    if (a->aerosol_scale_height_m != d.aerosol_scale_height_m) names[n++] = "aerosol_scale_height_m";
    if (a->visibility_km != d.visibility_km) names[n++] = "visibility_km";
    if (a->turbidity != d.turbidity) names[n++] = "turbidity";
    if (a->no_ozone) names[n++] = "ozone";
    if (a->ozone_du != d.ozone_du) names[n++] = "ozone_du";
    if (a->rayleigh_scale_height_m != d.rayleigh_scale_height_m) names[n++] = "rayleigh_scale_height_m";
    if (a->planet_radius_m != d.planet_radius_m) names[n++] = "planet_radius_m";
    if (a->top_m != d.top_m) names[n++] = "top_m";
    char list[200];
    join_names(names, n, list, sizeof list);
    const char *kind = a->kind == ATMOS_ATMOSPHERE_RILEY ? "riley" : "homogeneous";
    if (n)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "the %s atmosphere model does not use %s (the round-planet models do: \"model\": \"spherical\" "
                   "or \"dobashi\")",
                   kind, list);
    if (s->camera.position[1] > 100e3) /* above the Karman line: a user looking for the planet */
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "the %s atmosphere model is a flat earth: from %.0f km up it shows an endless plane; the "
                   "round-planet models draw the Earth from space (\"model\": \"spherical\" or \"dobashi\")",
                   kind, s->camera.position[1] / 1000.0);
}

atmos_status atmos_plan_create(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                               const atmos_plan_desc *desc, atmos_plan **out)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "plan: missing scene or output");
    *out = NULL;
    atmos_plan_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    atmos_status st = check_scene(ctx, scene, volume, &d);
    if (st != ATMOS_OK) return st;
    warn_unused_parts(ctx, scene);
    warn_unused_air(ctx, scene);
    atmos_plan *p = calloc(1, sizeof *p);
    if (!p) return atmos__error(ctx, ATMOS_E_NOMEM, "plan: out of memory");
    p->ctx = ctx;
    p->scene = *scene;
    p->renderer = scene->renderer;
    p->reference = d.reference;
    if ((st = atmos_scene_wavelengths(ctx, scene, &p->wl)) != ATMOS_OK) goto fail;
    if ((st = atmos_scene_atmosphere_create(ctx, scene, &p->wl, &p->atm)) != ATMOS_OK) goto fail;
    if ((st = plan_volume(p, volume, &d)) != ATMOS_OK) goto fail;
    if ((p->renderer == ATMOS_RENDERER_SLICE || p->renderer == ATMOS_RENDERER_NISHITA || p->renderer == ATMOS_RENDERER_HARRIS) &&
        !p->volume) {
        st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "plan: the %s renderer needs a volume", atmos_renderer_name(p->renderer));
        goto fail;
    }
    if (p->renderer != ATMOS_RENDERER_PATH) p->sky_keep = atmos__sky_keep_create(); /* NULL: per frame */
    if (p->renderer == ATMOS_RENDERER_SLICE) st = atmos__slice_plan_create(p, &p->slice);
    else if (p->renderer == ATMOS_RENDERER_PATH) st = atmos__path_plan_create(p, &p->path);
    else if (p->renderer == ATMOS_RENDERER_NISHITA) st = atmos__nishita_plan_create(p, &p->nishita);
    else if (p->renderer == ATMOS_RENDERER_HARRIS) st = atmos__harris_plan_create(p, &p->harris);
    else if (p->renderer == ATMOS_RENDERER_BEAMS) st = atmos__beams_plan_create(p, &p->beams);
    if (st != ATMOS_OK) goto fail;
    *out = p;
    return ATMOS_OK;
fail:
    atmos_plan_destroy(p);
    return st;
}

void atmos_plan_destroy(atmos_plan *p)
{
    if (!p) return;
    atmos__slice_plan_destroy(p->slice);
    atmos__path_plan_destroy(p->path);
    atmos__nishita_plan_destroy(p->nishita);
    atmos__harris_plan_destroy(p->harris);
    atmos__beams_plan_destroy(p->beams);
    atmos__sky_keep_destroy(p->sky_keep);
    atmos_volume_optics_free(&p->own_optics);
    atmos_volume_destroy(p->own_volume);
    atmos_atmosphere_destroy(p->atm);
    free(p->last_pixels);
    free(p);
}

atmos_renderer_kind atmos_plan_renderer(const atmos_plan *p) { return p->renderer; }
const atmos_wavelengths *atmos_plan_wavelengths(const atmos_plan *p) { return &p->wl; }
const atmos_atmosphere *atmos_plan_atmosphere(const atmos_plan *p) { return p->atm; }

const atmos_volume_optics *atmos_plan_optics(const atmos_plan *p) { return p->optics; }

const atmos_volume *atmos_plan_volume(const atmos_plan *p, double offset_m[3])
{
    if (offset_m) memcpy(offset_m, p->offset, sizeof p->offset);
    return p->volume;
}

void atmos_plan_get_stats(const atmos_plan *p, atmos_plan_stats *out) { *out = p->stats; }

/* ------------------------------------------------------------------ frames */

atmos_status atmos_frame_from_scene(atmos_context *ctx, const atmos_scene *scene, atmos_frame *out)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: missing scene or output");
    memset(out, 0, sizeof *out);
    out->camera = scene->camera;
    out->width = scene->width, out->height = scene->height;
    out->samples_per_pixel = scene->samples_per_pixel;
    out->spp = scene->path.spp;
    out->slices = scene->slice.slices;
    out->eye_scale = scene->slice.eye_scale;
    out->tonemap = scene->tonemap;
    return atmos_scene_sun_direction(ctx, scene, out->sun_dir, NULL, NULL);
}

/* p rotated by degrees clockwise seen from above (north toward east) about the vertical
 * axis through c (c NULL: a direction, rotated about the origin). */
static void orbit_point(double p[3], const double c[3], double degrees)
{
    const double a = degrees * ATMOS_DEG2RAD, cs = cos(a), sn = sin(a);
    const double x = p[0] - (c ? c[0] : 0), z = p[2] - (c ? c[2] : 0);
    p[0] = (c ? c[0] : 0) + x * cs - z * sn;
    p[2] = (c ? c[2] : 0) + x * sn + z * cs;
}

void atmos_frame_orbit(atmos_frame *f, const atmos_plan *plan, double degrees)
{
    atmos_camera_desc *c = &f->camera;
    double pivot[3];
    memcpy(pivot, c->look_at, sizeof pivot);
    if (plan && plan->volume) {
        double lo[3], hi[3];
        atmos_volume_bounds(plan->volume, lo, hi);
        for (int a = 0; a < 3; a++) pivot[a] = 0.5 * (lo[a] + hi[a]) + plan->offset[a];
    }
    orbit_point(c->position, pivot, degrees);
    orbit_point(c->look_at, pivot, degrees);
    orbit_point(c->up, NULL, degrees);
}

atmos_status atmos_plan_image_create(const atmos_plan *p, const atmos_frame *f, atmos_image **out)
{
    if (!p || !f || !out) return atmos__error(p ? p->ctx : NULL, ATMOS_E_INVALID_ARG, "plan image: missing argument");
    return atmos_image_create(p->ctx, f->width, f->height, p->wl.count + 1, out);
}

/* The frame for the renderers, with the scene's values where the frame says 0. */
static atmos_status resolve_view(atmos_plan *p, const atmos_frame *f, atmos__view *v)
{
    atmos_context *ctx = p->ctx;
    memset(v, 0, sizeof *v);
    if (f->width < 1 || f->width > ATMOS_SCENE_MAX_DIM || f->height < 1 || f->height > ATMOS_SCENE_MAX_DIM)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: size %dx%d outside 1..%d", f->width, f->height,
                            ATMOS_SCENE_MAX_DIM);
    atmos_status st = atmos_camera_init(ctx, &f->camera, f->width, f->height, &v->cam);
    if (st != ATMOS_OK) return st;
    const double l = sqrt(f->sun_dir[0] * f->sun_dir[0] + f->sun_dir[1] * f->sun_dir[1] + f->sun_dir[2] * f->sun_dir[2]);
    if (!(l > 0.5 && l < 2.0)) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: sun_dir must be a unit vector");
    for (int a = 0; a < 3; a++) v->sun[a] = l == 1.0 ? f->sun_dir[a] : f->sun_dir[a] / l;
    v->samples_per_pixel = f->samples_per_pixel ? f->samples_per_pixel : p->scene.samples_per_pixel;
    v->spp = f->spp ? f->spp : p->scene.path.spp;
    v->slices = f->slices ? f->slices : p->scene.slice.slices;
    v->eye_scale = f->eye_scale != 0 ? f->eye_scale : p->scene.slice.eye_scale;
    v->light_size = f->light_size;
    if (f->light_size < 0 || f->light_size > 8192)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: light_size must be in [0, 8192] (0: the scene's), got %d",
                            f->light_size);
    v->sky_step = f->sky_step > 1 ? f->sky_step : 1;
    v->sky_table = f->sky_table != 0;
    v->no_air_shadows = f->no_air_shadows != 0;
    v->warm_field = f->warm_field != 0;
    v->hold_field = f->hold_field != 0;
    v->impostor_budget = f->impostor_budget;
    v->screen_layer_px = f->screen_layer_px;
    if (!(f->screen_layer_px == 0 || (f->screen_layer_px >= 1 && f->screen_layer_px <= 1000)))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: screen_layer_px must be 0 (off) or in [1, 1000], got %g",
                            f->screen_layer_px);
    if (f->impostor_budget < 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: impostor_budget must be >= 0 (0: no limit), got %d",
                            f->impostor_budget);
    if (f->sky_step < 0 || f->sky_step > 16)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: sky_step must be in [0, 16], got %d", f->sky_step);
    if (v->samples_per_pixel < 1 || v->samples_per_pixel > 256)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: samples_per_pixel must be in [1, 256], got %d",
                            v->samples_per_pixel);
    if (v->spp < 1 || v->spp > ATMOS_PATH_MAX_SPP)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: spp must be in [1, %d], got %d", ATMOS_PATH_MAX_SPP, v->spp);
    if (v->slices < 0 || v->slices > 8192)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: slices must be in [0, 8192] (0: chosen from the volume), got %d",
                            v->slices);
    if (!(v->eye_scale > 0 && (v->eye_scale <= 1 || v->eye_scale == 2)))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "frame: eye_scale must be in (0, 1] or 2, got %g", v->eye_scale);
    if (p->renderer == ATMOS_RENDERER_SLICE && v->cam.type != ATMOS_CAMERA_PINHOLE)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED, "render slice: only pinhole cameras are supported");
    return ATMOS_OK;
}

static atmos_status resolve_rect(atmos_context *ctx, const atmos_region *region, int w, int h, atmos__rect *r)
{
    *r = (atmos__rect){0, 0, w, h};
    if (!region) return ATMOS_OK;
    if (region->x0 < 0 || region->y0 < 0 || region->x1 > w || region->y1 > h || region->x0 >= region->x1 ||
        region->y0 >= region->y1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render: region [%d, %d) x [%d, %d) is empty or outside %dx%d",
                            region->x0, region->x1, region->y0, region->y1, w, h);
    *r = (atmos__rect){region->x0, region->y0, region->x1, region->y1};
    return ATMOS_OK;
}

/* ------------------------------------------------------------------ rendering */

static int same_view(const atmos__view *a, const atmos__view *b)
{
    return !memcmp(&a->cam, &b->cam, sizeof a->cam) && !memcmp(a->sun, b->sun, sizeof a->sun) &&
           a->samples_per_pixel == b->samples_per_pixel && a->slices == b->slices && a->eye_scale == b->eye_scale &&
           a->light_size == b->light_size &&
           a->sky_step == b->sky_step && a->sky_table == b->sky_table && a->no_air_shadows == b->no_air_shadows &&
           a->hold_field == b->hold_field && a->warm_field == b->warm_field && a->screen_layer_px == b->screen_layer_px;
}

static int rect_inside(const atmos__rect *a, const atmos__rect *b)
{
    return a->x0 >= b->x0 && a->y0 >= b->y0 && a->x1 <= b->x1 && a->y1 <= b->y1;
}

/* Copies the pixels of r between two images of the frame's size (C channels). */
static void copy_rect(float *dst, const float *src, int W, int C, const atmos__rect *r)
{
    for (int y = r->y0; y < r->y1; y++)
        memcpy(dst + ((size_t)y * W + r->x0) * C, src + ((size_t)y * W + r->x0) * C,
               sizeof(float) * (size_t)(r->x1 - r->x0) * C);
}

/* No valid scene may give a NaN or an infinity (DESIGN §5): a renderer that does has a
 * bug, and an image holding one is refused here, whatever the renderer, rather than
 * written with exit status 0. With keep (a sky, slice, Nishita, Harris or beams frame, not
 * atmos_frame.no_keep), the rendered pixels are kept for the next call in the same pass
 * (atmos__copy_not_finite: one load a value, the copy streamed from it; a copy, not a reference:
 * the caller may write into its image before the next call): rows on the threads (one pass
 * over a 1280 x 720 frame instead of two serial ones; the count and the first bad pixel do not
 * depend on the thread count). A frame not kept with no_check is not read
 * here: the caller checks it (atmos_frame.no_check). The view is remembered either way (what
 * the next frame changed). */
static atmos_status check_and_keep(atmos_plan *p, const atmos__view *v, const atmos__rect *r, const atmos_image *out,
                                   int keep, int no_check)
{
    const int W = out->width, C = out->channels;
    const size_t need = (size_t)out->width * out->height * out->channels, n = (size_t)(r->x1 - r->x0) * C;
    p->have_last = p->have_pixels = 0;
    if (!keep && no_check) { /* the caller checks the frame in its display pass */
        p->last_view = *v, p->have_last = 1;
        return ATMOS_OK;
    }
    if (keep && need > p->last_cap) { /* the old contents are not needed: have_pixels is 0 */
        free(p->last_pixels);
        p->last_pixels = atmos__big_alloc(sizeof(float) * need); /* on 2 MB pages where large */
        p->last_cap = p->last_pixels ? need : 0;
        if (!p->last_pixels) keep = 0; /* no cache: the next frame is rendered again */
    }
    size_t bad = 0;
    long long first = LLONG_MAX; /* y W C + i of the first bad value */
#pragma omp parallel for schedule(static) reduction(+ : bad) reduction(min : first) num_threads(atmos__threads(p->ctx))
    for (int y = r->y0; y < r->y1; y++) {
        const float *row = out->pixels + ((size_t)y * W + r->x0) * C;
        const size_t b = atmos__copy_not_finite(keep ? p->last_pixels + ((size_t)y * W + r->x0) * C : NULL, row, n);
        if (b) {
            const long long at = (long long)y * W * C + (long long)atmos__first_not_finite(row, n);
            first = first < at ? first : at;
            bad += b;
        }
    }
    if (bad)
        return atmos__error(p->ctx, ATMOS_E_UNSUPPORTED,
                            "render: %zu of %zu pixel values are NaN or infinite (the first at pixel %lld, %lld): a "
                            "renderer bug for this scene; the image is not written, please report the scene",
                            bad, (size_t)(r->y1 - r->y0) * n, r->x0 + (first % ((long long)W * C)) / C,
                            first / ((long long)W * C));
    p->last_view = *v, p->have_last = 1;
    if (keep) p->last_rect = *r, p->have_pixels = 1;
    return ATMOS_OK;
}

static void set_meta(const atmos_plan *p, const atmos__view *v, double seconds, atmos_image *out)
{
    static const char *const names[] = {"sky (the atmosphere model alone: atmos:atmosphere)",
                                        "slice (Riley et al. 2004, half-angle slicing)",
                                        "path (spectral Monte Carlo volumetric path tracing)",
                                        "nishita (Nishita et al. 1996, orders 1-3 and sky light by a light field)",
                                        "harris (Harris 2002, particle clouds: multiple forward scattering, splats)",
                                        ("beams (Dobashi et al. 2002, light beams: sampling planes, pre-integrated table, "
                                         "sub-planes, shadow maps)")};
    char buf[384];
    double el = 0, az = 0;
    atmos_direction_to_angles(v->sun, &el, &az);
    atmos_image_set_meta(out, "atmos:version", atmos_version());
    atmos_image_set_meta(out, "atmos:scene", p->scene.name);
    atmos_image_set_meta(out, "atmos:renderer", names[p->renderer]);
    static const char *const airs[] = {"riley", "vacuum", "homogeneous", "dobashi", "spherical"};
    const unsigned kind = (unsigned)p->scene.atmosphere.kind;
    atmos_image_set_meta(out, "atmos:atmosphere", kind < 5u ? airs[kind] : "?");
    snprintf(buf, sizeof buf, "%.6f", el);
    atmos_image_set_meta(out, "atmos:sun_elevation_deg", buf);
    snprintf(buf, sizeof buf, "%.6f", az);
    atmos_image_set_meta(out, "atmos:sun_azimuth_deg", buf);
    static const char *const cams[] = {"pinhole", "fisheye", "equirect"};
    const atmos_camera *c = &v->cam;
    snprintf(buf, sizeof buf, "%s at (%.3f, %.3f, %.3f) m, forward (%.6f, %.6f, %.6f), up (%.6f, %.6f, %.6f), fov %.4f deg",
             cams[(unsigned)c->type < 3u ? (int)c->type : 0], c->position[0], c->position[1], c->position[2], c->forward[0], c->forward[1],
             c->forward[2], c->up[0], c->up[1], c->up[2], c->fov_deg);
    atmos_image_set_meta(out, "atmos:camera", buf);
    snprintf(buf, sizeof buf, "%s, %d samples", p->wl.mode == ATMOS_WAVELENGTHS_RGB ? "rgb" : "spectral", p->wl.count);
    atmos_image_set_meta(out, "atmos:wavelengths", buf);
    snprintf(buf, sizeof buf, "%.6f", seconds);
    atmos_image_set_meta(out, "atmos:render_seconds", buf);
    snprintf(buf, sizeof buf, "%d", atmos__threads(p->ctx));
    atmos_image_set_meta(out, "atmos:threads", buf);
    if (p->renderer == ATMOS_RENDERER_SLICE) {
        atmos__slice_describe(p, v, buf, sizeof buf);
        atmos_image_set_meta(out, "atmos:slice", buf);
    } else if (p->renderer == ATMOS_RENDERER_PATH) {
        atmos__path_describe(p, buf, sizeof buf);
        atmos_image_set_meta(out, "atmos:path", buf);
        snprintf(buf, sizeof buf, "%.6g", p->stats.path.mean_rel_error);
        atmos_image_set_meta(out, "atmos:path_mean_rel_error", buf);
    } else if (p->renderer == ATMOS_RENDERER_NISHITA) {
        atmos__nishita_describe(p, buf, sizeof buf);
        atmos_image_set_meta(out, "atmos:nishita", buf);
    } else if (p->renderer == ATMOS_RENDERER_HARRIS) {
        atmos__harris_describe(p, buf, sizeof buf);
        atmos_image_set_meta(out, "atmos:harris", buf);
    } else if (p->renderer == ATMOS_RENDERER_BEAMS) {
        atmos__beams_describe(p, buf, sizeof buf);
        atmos_image_set_meta(out, "atmos:beams", buf);
    }
}

atmos_status atmos_plan_render(atmos_plan *p, const atmos_frame *f, const atmos_region *region, atmos_image *out,
                               atmos_render_info *info)
{
    if (!p || !f || !out) return atmos__error(p ? p->ctx : NULL, ATMOS_E_INVALID_ARG, "render: missing argument");
    const double t0 = atmos__now();
    atmos_context *ctx = p->ctx;
    atmos__view v;
    atmos__rect r;
    atmos_status st = resolve_view(p, f, &v);
    if (st != ATMOS_OK) return st;
    if (out->width != f->width || out->height != f->height || out->channels != p->wl.count + 1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render: the image is %dx%d x %d channels, the frame needs %dx%d x %d",
                            out->width, out->height, out->channels, f->width, f->height, p->wl.count + 1);
    if ((st = resolve_rect(ctx, region, f->width, f->height, &r)) != ATMOS_OK) return st;
    atmos_plan_stats *stats = &p->stats;
    const atmos_plan_stats prev = *stats;
    memset(stats, 0, sizeof *stats);
    stats->camera_changed = !p->have_last || memcmp(&v.cam, &p->last_view.cam, sizeof v.cam) != 0;
    stats->sun_changed = !p->have_last || memcmp(v.sun, p->last_view.sun, sizeof v.sun) != 0;
    if (p->renderer != ATMOS_RENDERER_PATH && p->have_pixels && same_view(&v, &p->last_view) && rect_inside(&r, &p->last_rect)) {
        copy_rect(out->pixels, p->last_pixels, out->width, out->channels, &r);
        stats->reused = 1;
        stats->slice = prev.slice;
    } else if (p->renderer == ATMOS_RENDERER_SKY) {
        st = atmos__sky_render(ctx, p->atm, &v, &r, out, p->sky_keep);
    } else if (p->renderer == ATMOS_RENDERER_SLICE) {
        st = atmos__slice_render(p, &v, &r, out, &stats->slice);
    } else if (p->renderer == ATMOS_RENDERER_NISHITA) {
        st = atmos__nishita_render(p, &v, &r, out);
    } else if (p->renderer == ATMOS_RENDERER_HARRIS) {
        st = atmos__harris_render(p, &v, &r, out);
    } else if (p->renderer == ATMOS_RENDERER_BEAMS) {
        st = atmos__beams_render_spp(p, &v, &r, out);
    } else {
        st = atmos__path_render(p, &v, &r, out, &stats->path);
    }
    /* a frame the impostor budget left unfinished is not kept: the same frame again finishes it */
    if (st == ATMOS_OK && !stats->reused)
        st = check_and_keep(p, &v, &r, out, p->renderer != ATMOS_RENDERER_PATH && !stats->impostors_held && !stats->impostors_coarse && !f->no_keep,
                            f->no_check);
    if (st != ATMOS_OK) {
        p->have_last = p->have_pixels = 0;
        return st;
    }
    if (p->renderer == ATMOS_RENDERER_PATH) p->last_view = v, p->have_last = 1;
    const double secs = atmos__now() - t0;
    set_meta(p, &v, secs, out);
    if (info) {
        info->seconds = secs;
        atmos_direction_to_angles(v.sun, &info->sun_elevation_deg, &info->sun_azimuth_deg);
    }
    return ATMOS_OK;
}

atmos_status atmos_plan_path_variance(const atmos_plan *p, atmos_image **out)
{
    if (!p || !out || p->renderer != ATMOS_RENDERER_PATH || !p->path)
        return atmos__error(p ? p->ctx : NULL, ATMOS_E_INVALID_ARG, "path variance: not a path tracer's plan");
    return atmos__path_variance(p, out);
}

atmos_status atmos_plan_path_order(const atmos_plan *p, atmos_image **out)
{
    if (!p || !out || p->renderer != ATMOS_RENDERER_PATH || !p->path)
        return atmos__error(p ? p->ctx : NULL, ATMOS_E_INVALID_ARG, "path order: not a path tracer's plan");
    return atmos__path_order(p, out);
}
