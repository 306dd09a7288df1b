/* The lights, the fog and the objects of a scene (docs/scene-format.md, docs/beams.md): their
 * defaults and their checks, shared by the parser and atmos_scene_validate so that a value
 * refused in a file and the same value set from the command line give the same message. */
#include "scene/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void atmos__scene_light_defaults(atmos_scene_light *l)
{
    memset(l, 0, sizeof *l);
    l->type = ATMOS_LIGHT_POINT;
    l->direction[1] = -1;
    l->cone_deg = 30, l->edge_deg = 5;
    l->intensity_w_sr = 100;
    l->colour[0] = l->colour[1] = l->colour[2] = 1;
    l->range_m = 0; /* auto: atmos__lamp_auto_range */
}

void atmos__scene_object_defaults(atmos_scene_object *o)
{
    memset(o, 0, sizeof *o);
    o->scale[0] = o->scale[1] = o->scale[2] = 1;
    o->albedo[0] = o->albedo[1] = o->albedo[2] = 0.5;
    o->size_m = 1000;
}

/* Each of the three components of v at prefix/key/i within r. */
static atmos_status check3(atmos_context *ctx, const char *source, const char *prefix, const char *key,
                           const double v[3], const atmos__range *r)
{
    for (int a = 0; a < 3; a++) {
        char path[96];
        snprintf(path, sizeof path, "%s/%s/%d", prefix, key, a);
        atmos_status st = atmos__scene_check_range(ctx, source, path, v[a], r, NULL);
        if (st) return st;
    }
    return ATMOS_OK;
}

static atmos_status check1(atmos_context *ctx, const char *source, const char *prefix, const char *key, double v,
                           const atmos__range *r, const char *extra)
{
    char path[96];
    snprintf(path, sizeof path, "%s/%s", prefix, key);
    return atmos__scene_check_range(ctx, source, path, v, r, extra);
}

static atmos_status check_light(atmos_context *ctx, const char *source, const atmos_scene *s, int i)
{
    static const atmos__range r_cone = {0, 89, 0, 0}, r_edge = {0, 90, 0, 0}, r_intensity = {0, 1e9, 1, 0},
                              r_temp = {1000, 40000, 0, 0}, r_colour = {0, 1e3, 0, 0}, r_range = {0, 1e6, 0, 0};
    const atmos_scene_light *l = &s->lights[i];
    char at[48];
    snprintf(at, sizeof at, "/lights/%d", i);
    atmos_status st;
    if (l->type != ATMOS_LIGHT_POINT && l->type != ATMOS_LIGHT_SPOT)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, at, "type must be point or spot, got %d", (int)l->type);
    if ((st = check3(ctx, source, at, "position_m", l->position_m, &atmos__r_pos))) return st;
    if ((st = check1(ctx, source, at, "intensity_w_sr", l->intensity_w_sr, &r_intensity, NULL))) return st;
    if ((st = check1(ctx, source, at, "range_m", l->range_m, &r_range, NULL))) return st;
    if ((st = check3(ctx, source, at, "colour", l->colour, &r_colour))) return st;
    if (l->colour_temperature_k != 0 &&
        (st = check1(ctx, source, at, "colour_temperature_k", l->colour_temperature_k, &r_temp, " (0: colour)")))
        return st;
    if (l->colour_temperature_k == 0 && s->wavelengths != ATMOS_WAVELENGTHS_RGB &&
        (l->colour[0] != l->colour[1] || l->colour[1] != l->colour[2])) {
        char path[96];
        snprintf(path, sizeof path, "%s/colour", at);
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path,
                                 "rgb colours need rgb wavelengths; in spectral mode give colour_temperature_k");
    }
    if (l->image[0]) {
        char path[96];
        snprintf(path, sizeof path, "%s/image", at);
        if (!memchr(l->image, '\0', sizeof l->image))
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path, "the path is not terminated");
        if (l->type != ATMOS_LIGHT_SPOT)
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path,
                                     "an image is projected through a spot's cone: give \"type\": \"spot\"");
        if (s->wavelengths != ATMOS_WAVELENGTHS_RGB)
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path, "an image on a light needs rgb wavelengths");
    }
    if (l->type != ATMOS_LIGHT_SPOT) return ATMOS_OK;
    if ((st = check1(ctx, source, at, "cone_deg", l->cone_deg, &r_cone, NULL))) return st;
    if ((st = check1(ctx, source, at, "edge_deg", l->edge_deg, &r_edge, NULL))) return st;
    if (l->cone_deg + l->edge_deg > 90) {
        char path[96];
        snprintf(path, sizeof path, "%s/edge_deg", at);
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path,
                                 "cone_deg + edge_deg must be at most 90 (a spot lights a half space at most), got %g",
                                 l->cone_deg + l->edge_deg);
    }
    const double n = atmos__scene_norm3(l->direction);
    if (!(n > 0) || !isfinite(n) || (st = check3(ctx, source, at, "direction", l->direction, &atmos__r_look))) {
        char path[96];
        snprintf(path, sizeof path, "%s/direction", at);
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path, "must be a nonzero finite vector");
    }
    return ATMOS_OK;
}

/* A terrain's values (atmos_terrain_desc's ranges); the file itself is read by the plan. */
static atmos_status check_terrain(atmos_context *ctx, const char *source, const char *at, const atmos_scene_object *o)
{
    static const atmos__range r_size = {0, 1e7, 1, 0}, r_height = {0, 1e5, 0, 0}, r_hscale = {-1e5, 1e5, 0, 0},
                              r_samples = {2, 4097, 0, 0}, r_stride = {0, 1e6, 0, 0},
                              r_tris = {0, ATMOS_MESH_MAX_TRIANGLES, 0, 0};
    atmos_status st;
    if ((st = check1(ctx, source, at, "size_m", o->size_m, &r_size, NULL))) return st;
    if ((st = check1(ctx, source, at, "height_m", o->height_m, &r_height, " (0: height_scale)"))) return st;
    if ((st = check1(ctx, source, at, "height_scale", o->height_scale, &r_hscale, NULL))) return st;
    if (o->samples && (st = check1(ctx, source, at, "samples", o->samples, &r_samples, " (or 0: 257)"))) return st;
    if ((st = check1(ctx, source, at, "stride", o->stride, &r_stride, " (0: automatic)"))) return st;
    if ((st = check1(ctx, source, at, "max_triangles", o->max_triangles, &r_tris, " (0: 1000000)"))) return st;
    if (strncmp(o->terrain, "generate:", 9)) return ATMOS_OK;
    if (strcmp(o->terrain + 9, "ridges") && strcmp(o->terrain + 9, "city"))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, at,
                                 "terrain \"%.64s\" is no generator (known: generate:ridges, generate:city)", o->terrain);
    if (!(o->height_m > 0))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, at, "a generated terrain needs height_m > 0");
    return ATMOS_OK;
}

static atmos_status check_object(atmos_context *ctx, const char *source, const atmos_scene *s, int i)
{
    static const atmos__range r_scale = {-1e6, 1e6, 0, 0}, r_rot = {-3600, 3600, 0, 0}, r_albedo = {0, 1, 0, 0};
    const atmos_scene_object *o = &s->objects[i];
    char at[48];
    snprintf(at, sizeof at, "/objects/%d", i);
    atmos_status st;
    if (!memchr(o->mesh, '\0', sizeof o->mesh) || !memchr(o->terrain, '\0', sizeof o->terrain) ||
        !o->mesh[0] == !o->terrain[0])
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, at,
                                 "needs either \"mesh\" (builtin:NAME or an OBJ file) or \"terrain\" (a height map file or "
                                 "generate:ridges), not both");
    if (o->terrain[0] && (st = check_terrain(ctx, source, at, o))) return st;
    if (!strncmp(o->mesh, "builtin:", 8)) {
        int known = 0;
        for (const char *const *n = atmos_mesh_builtin_names(); *n; n++) known |= !strcmp(o->mesh + 8, *n);
        if (!known)
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, at,
                                     "mesh \"%.64s\" is no built-in (known: builtin:sphere, builtin:box, builtin:plane, "
                                     "builtin:aircraft)", o->mesh);
    }
    if ((st = check3(ctx, source, at, "position_m", o->position_m, &atmos__r_pos))) return st;
    if ((st = check3(ctx, source, at, "scale", o->scale, &r_scale))) return st;
    const int uniform = o->scale[0] == o->scale[1] && o->scale[1] == o->scale[2]; /* one number, or three alike */
    for (int a = 0; a < 3; a++)
        if (o->scale[a] == 0) {
            char path[96];
            snprintf(path, sizeof path, uniform ? "%s/scale" : "%s/scale/%d", at, a);
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path, "must not be zero");
        }
    if ((st = check3(ctx, source, at, "rotation_deg", o->rotation_deg, &r_rot))) return st;
    return check3(ctx, source, at, "albedo", o->albedo, &r_albedo);
}

atmos_status atmos__scene_validate_lights(atmos_context *ctx, const char *source, const atmos_scene *s)
{
    static const atmos__range r_ext = {0, 10, 1, 0}, r_g = {-1, 1, 1, 1}, r_fog_h = {0, 1e5, 0, 0};
    atmos_status st;
    if (s->light_count < 0 || s->light_count > ATMOS_SCENE_MAX_LIGHTS)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/lights", "at most %d lights, got %d",
                                 ATMOS_SCENE_MAX_LIGHTS, s->light_count);
    if (s->object_count < 0 || s->object_count > ATMOS_SCENE_MAX_OBJECTS)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/objects", "at most %d objects, got %d",
                                 ATMOS_SCENE_MAX_OBJECTS, s->object_count);
    for (int i = 0; i < s->light_count; i++)
        if ((st = check_light(ctx, source, s, i))) return st;
    for (int i = 0; i < s->object_count; i++)
        if ((st = check_object(ctx, source, s, i))) return st;
    if (s->fog.enabled) {
        const atmos__range r_sca = {0, s->fog.extinction_per_m, 0, 0};
        if ((st = atmos__scene_check_range(ctx, source, "/fog/extinction_per_m", s->fog.extinction_per_m, &r_ext, NULL)))
            return st;
        if ((st = atmos__scene_check_range(ctx, source, "/fog/scattering_per_m", s->fog.scattering_per_m, &r_sca,
                                           " (at most the extinction)")))
            return st;
        if ((st = atmos__scene_check_range(ctx, source, "/fog/g", s->fog.g, &r_g, NULL))) return st;
        atmos_particle_desc pd;
        if (s->fog.particle[0] && atmos_scene_particle(NULL, s, s->fog.particle, &pd) != ATMOS_OK)
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/fog/particle",
                                     "'%s' is neither in the scene's \"particles\" nor a preset (atmos phase lists them)",
                                     s->fog.particle);
        if ((st = atmos__scene_check_range(ctx, source, "/fog/height_m", s->fog.height_m, &r_fog_h, " (0: uniform)")) ||
            (st = atmos__scene_check_range(ctx, source, "/fog/base_m", s->fog.base_m, &atmos__r_pos, NULL)))
            return st;
        if (s->fog.height_m > 0 && s->light_count > 0)
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/fog/height_m",
                                     "a height-dependent fog is lit by the sun alone: point and spot lights need a "
                                     "uniform fog (height_m 0)");
    }
    if (s->renderer != ATMOS_RENDERER_BEAMS) return ATMOS_OK;
    if (s->light_count < 1 && !s->beams.sun)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/lights",
                                 "the beams renderer draws the light of \"lights\" (and of the sun with beams/sun): the "
                                 "scene has neither");
    if (s->camera.type != ATMOS_CAMERA_PINHOLE)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/camera/type",
                                 "the beams renderer supports pinhole cameras only (its sampling planes face the view)");
    return ATMOS_OK;
}
