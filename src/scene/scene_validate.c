/* Scene validation: value ranges, cross-field rules and the message format.
 * The parser uses the same functions, so a JSON file and a scene modified in code
 * (CLI overrides) are held to identical rules and get identical messages.
 */
#include "scene/scene_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Sines below this count as parallel: the camera basis would be numerically
 * meaningless (about 0.2 arc seconds). */
#define PARALLEL_SIN 1e-6

static atmos_status check_vec(atmos_context *ctx, const char *source, const char *name,
                              const double v[3], const atmos__range *const r[3])
{
    for (int i = 0; i < 3; i++) {
        char path[64];
        snprintf(path, sizeof path, "%s/%d", name, i);
        atmos_status st = atmos__scene_check_range(ctx, source, path, v[i], r[i], NULL);
        if (st) return st;
    }
    return ATMOS_OK;
}

static int is_zero3(const double v[3]) { return v[0] == 0 && v[1] == 0 && v[2] == 0; }

void atmos__scene_camera_effective(const atmos_camera_desc *cam, double fwd[3], double up[3])
{
    /* camera.h: zero look_at and up mean "default", resolved as atmos_camera_init
     * resolves them (the CLI relies on this when it switches the camera type). */
    int fisheye = cam->type == ATMOS_CAMERA_FISHEYE;
    if (is_zero3(cam->look_at)) {
        fwd[0] = 0.0;
        fwd[1] = fisheye ? 1.0 : 0.0;
        fwd[2] = fisheye ? 0.0 : -1.0;
    } else {
        for (int i = 0; i < 3; i++) fwd[i] = cam->look_at[i] - cam->position[i];
    }
    if (!is_zero3(cam->up)) {
        for (int i = 0; i < 3; i++) up[i] = cam->up[i];
    } else {
        double n = atmos__scene_norm3(fwd);
        int vertical = n > 0 && fabs(fwd[1]) > 0.99 * n;
        up[0] = 0.0;
        up[1] = fisheye && vertical ? 0.0 : 1.0;
        up[2] = fisheye && vertical ? -1.0 : 0.0;
    }
}

atmos_status atmos__scene_validate_camera(atmos_context *ctx, const char *source,
                                          const atmos_camera_desc *cam)
{
    static const atmos__range any = {-HUGE_VAL, HUGE_VAL, 0, 0};
    const atmos__range *pos_r[3] = {&atmos__r_pos, &atmos__r_altitude, &atmos__r_pos};
    const atmos__range *look_r[3] = {&atmos__r_look, &atmos__r_look, &atmos__r_look};
    const atmos__range *any_r[3] = {&any, &any, &any};
    atmos_status st = ATMOS_OK;

    /* fov_deg 0 means the type's default (camera.h); the parser refuses a 0
     * written in a file, where it can only be a mistake. */
    switch (cam->type) {
    case ATMOS_CAMERA_PINHOLE:
        if (cam->fov_deg != 0)
            st = atmos__scene_check_range(ctx, source, "/camera/fov_deg", cam->fov_deg,
                                          &atmos__r_fov_pinhole, " for a pinhole camera");
        break;
    case ATMOS_CAMERA_FISHEYE:
        if (cam->fov_deg != 0)
            st = atmos__scene_check_range(ctx, source, "/camera/fov_deg", cam->fov_deg,
                                          &atmos__r_fov_fisheye, " for a fisheye camera");
        break;
    case ATMOS_CAMERA_EQUIRECT:
        /* Ignored by this camera, but a NaN must not hide in a valid scene. */
        st = atmos__scene_check_range(ctx, source, "/camera/fov_deg", cam->fov_deg, &any, NULL);
        break;
    default:
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/camera/type",
                                 "must be one of pinhole, fisheye, equirect, got %d", (int)cam->type);
    }
    if (st) return st;
    if ((st = check_vec(ctx, source, "/camera/position_m", cam->position, pos_r))) return st;
    if ((st = check_vec(ctx, source, "/camera/look_at_m", cam->look_at, look_r))) return st;
    if ((st = check_vec(ctx, source, "/camera/up", cam->up, any_r))) return st;

    /* Equirect cameras ignore look_at and up, but a scene must stay valid if the
     * type is switched later (CLI override), so the same rules apply to all. */
    double fwd[3], up[3];
    atmos__scene_camera_effective(cam, fwd, up);
    if (!(atmos__scene_norm3(fwd) > 0))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/camera/look_at_m",
                                 "must differ from position_m");
    if (atmos__scene_sin_angle(fwd, up) < PARALLEL_SIN)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/camera/up",
                                 "must not be parallel to the view direction");
    return ATMOS_OK;
}

static int days_in_month(int year, int month)
{
    static const int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    int leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    return month == 2 && leap ? 29 : days[month - 1];
}

int atmos__scene_valid_time(const atmos_utc_time *t)
{
    /* A leap second may give 60.x seconds. */
    return !(t->year < 1 || t->year > 9999 || t->month < 1 || t->month > 12 || t->day < 1 ||
             t->day > days_in_month(t->year, t->month) || t->hour < 0 || t->hour > 23 ||
             t->minute < 0 || t->minute > 59 || !(t->second >= 0 && t->second < 61));
}

/* A sun time's year outside the solar position algorithm's (atmos_sun_position_compute refuses it,
 * the render would fail naming neither the scene nor the key). */
static atmos_status sun_year(atmos_context *ctx, const char *source, const char *key, const atmos_utc_time *t)
{
    if (t->year >= ATMOS_SUN_YEAR_MIN && t->year <= ATMOS_SUN_YEAR_MAX) return ATMOS_OK;
    return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, key,
                             "year %d out of range [%d, %d] of the solar position algorithm (NOAA/Meeus)", t->year,
                             ATMOS_SUN_YEAR_MIN, ATMOS_SUN_YEAR_MAX);
}

atmos_status atmos__scene_validate_sun(atmos_context *ctx, const char *source,
                                       const atmos_scene_sun *sun)
{
    atmos_status st;
    if (!sun->from_time) {
        if ((st = atmos__scene_check_range(ctx, source, "/sun/elevation_deg", sun->elevation_deg,
                                           &atmos__r_elevation, NULL)))
            return st;
        return atmos__scene_check_range(ctx, source, "/sun/azimuth_deg", sun->azimuth_deg,
                                        &atmos__r_azimuth, NULL);
    }
    const atmos_utc_time *t = &sun->time;
    if (!atmos__scene_valid_time(t))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/sun/time",
                                 "not a valid UTC date-time (%04d-%02d-%02dT%02d:%02d:%06.3f)",
                                 t->year, t->month, t->day, t->hour, t->minute,
                                 isfinite(t->second) ? t->second : -1.0);
    if ((st = sun_year(ctx, source, "/sun/time", t))) return st;
    if ((st = atmos__scene_check_range(ctx, source, "/sun/latitude_deg", sun->latitude_deg,
                                       &atmos__r_latitude, NULL)))
        return st;
    return atmos__scene_check_range(ctx, source, "/sun/longitude_deg", sun->longitude_deg,
                                    &atmos__r_longitude, NULL);
}

atmos_status atmos__scene_validate_output(atmos_context *ctx, const char *source,
                                          const atmos_scene *scene)
{
    const atmos_tonemap_desc *tm = &scene->tonemap;
    atmos_status st;
    /* exposure_ev means a manual EV100 or a compensation; name the JSON key the
     * value came from. */
    if (tm->manual_exposure == 1)
        st = atmos__scene_check_range(ctx, source, "/output/exposure", tm->exposure_ev,
                                      &atmos__r_manual_ev, NULL);
    else if (tm->manual_exposure == 0)
        st = atmos__scene_check_range(ctx, source, "/output/exposure_compensation_ev",
                                      tm->exposure_ev, &atmos__r_compensation, NULL);
    else
        st = atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/output/exposure",
                               "manual_exposure must be 0 (auto) or 1 (manual), got %d",
                               tm->manual_exposure);
    if (st) return st;
    if (tm->curve != ATMOS_TONE_FILMIC && tm->curve != ATMOS_TONE_REINHARD && tm->curve != ATMOS_TONE_CLAMP)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/output/tone_curve",
                                 "must be one of filmic, reinhard, clamp, got %d", (int)tm->curve);
    if (scene->png_bits != 8 && scene->png_bits != 16)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/output/png_bits",
                                 "must be 8 or 16, got %d", scene->png_bits);
    return ATMOS_OK;
}

static atmos_status validate_image(atmos_context *ctx, const char *source, const atmos_scene *s)
{
    atmos_status st;
    if ((st = atmos__scene_check_range(ctx, source, "/image/width", s->width, &atmos__r_dim, NULL))) return st;
    if ((st = atmos__scene_check_range(ctx, source, "/image/height", s->height, &atmos__r_dim, NULL))) return st;
    return atmos__scene_check_range(ctx, source, "/image/samples_per_pixel", s->samples_per_pixel,
                                    &atmos__r_spp, NULL);
}

static atmos_status validate_atmosphere(atmos_context *ctx, const char *source,
                                        const atmos_atmosphere_desc *a)
{
    static const struct {
        const char *path;
        size_t offset;
        const atmos__range *range;
    } fields[] = {
        {"/atmosphere/beta_sl_550_per_m", offsetof(atmos_atmosphere_desc, beta_sl_550), &atmos__r_beta},
        {"/atmosphere/scale_height_m", offsetof(atmos_atmosphere_desc, scale_height_m), &atmos__r_scale_height},
        {"/atmosphere/ground_albedo", offsetof(atmos_atmosphere_desc, ground_albedo), &atmos__r_albedo},
        {"/atmosphere/sun_diameter_deg", offsetof(atmos_atmosphere_desc, sun_diameter_deg), &atmos__r_sun_diameter},
        {"/atmosphere/sun_scale", offsetof(atmos_atmosphere_desc, sun_scale), &atmos__r_sun_scale},
        {"/atmosphere/thickness_m", offsetof(atmos_atmosphere_desc, thickness_m), &atmos__r_thickness},
        {"/background/radiance", offsetof(atmos_atmosphere_desc, background_radiance), &atmos__r_radiance},
        {"/atmosphere/planet_radius_m", offsetof(atmos_atmosphere_desc, planet_radius_m), &atmos__r_planet_radius},
        {"/atmosphere/top_m", offsetof(atmos_atmosphere_desc, top_m), &atmos__r_top},
        {"/atmosphere/rayleigh_scale_height_m", offsetof(atmos_atmosphere_desc, rayleigh_scale_height_m),
         &atmos__r_scale_height},
        {"/atmosphere/aerosol_scale_height_m", offsetof(atmos_atmosphere_desc, aerosol_scale_height_m),
         &atmos__r_scale_height},
        {"/atmosphere/visibility_km", offsetof(atmos_atmosphere_desc, visibility_km), &atmos__r_visibility},
        {"/atmosphere/ozone_du", offsetof(atmos_atmosphere_desc, ozone_du), &atmos__r_ozone},
        {"/atmosphere/dobashi_ambient", offsetof(atmos_atmosphere_desc, dobashi_ambient), &atmos__r_dobashi_ambient},
    };
    if (a->kind != ATMOS_ATMOSPHERE_RILEY && a->kind != ATMOS_ATMOSPHERE_VACUUM && a->kind != ATMOS_ATMOSPHERE_HOMOGENEOUS &&
        a->kind != ATMOS_ATMOSPHERE_DOBASHI && a->kind != ATMOS_ATMOSPHERE_SPHERICAL)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/atmosphere/model",
                                 "must be riley, dobashi, spherical, homogeneous or (through \"background\") a vacuum, "
                                 "got %d",
                                 (int)a->kind);
    if (a->turbidity != 0) {
        atmos_status st = atmos__scene_check_range(ctx, source, "/atmosphere/turbidity", a->turbidity,
                                                   &atmos__r_turbidity, NULL);
        if (st) return st;
    }
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++) {
        double v;
        memcpy(&v, (const char *)a + fields[i].offset, sizeof v);
        atmos_status st = atmos__scene_check_range(ctx, source, fields[i].path, v, fields[i].range, NULL);
        if (st) return st;
    }
    return ATMOS_OK;
}

/* Every row of the renderers' settings tables within its range (atmos_renderer_settings). */
atmos_status atmos__settings_check(atmos_context *ctx, const char *source, const atmos_scene *s)
{
    for (int r = ATMOS_RENDERER_SLICE; r <= ATMOS_RENDERER_LAST; r++) {
        int n;
        const atmos_setting *t = atmos_renderer_settings((atmos_renderer_kind)r, &n);
        for (int i = 0; i < n; i++) {
            char path[96];
            snprintf(path, sizeof path, "/%s/%s", atmos_renderer_name((atmos_renderer_kind)r), t[i].key);
            const double v = atmos_scene_setting_get(s, &t[i]);
            int choices = 0;
            if (t[i].type == ATMOS_SETTING_CHOICE)
                while (t[i].choices[choices]) choices++;
            const atmos__range range = t[i].type == ATMOS_SETTING_BOOL     ? (atmos__range){0, 1, 0, 0}
                                       : t[i].type == ATMOS_SETTING_CHOICE ? (atmos__range){0, choices - 1, 0, 0}
                                                                           : (atmos__range){t[i].min, t[i].max,
                                                                                            t[i].min_open, t[i].max_open};
            atmos_status st = atmos__scene_check_range(ctx, source, path, v, &range, NULL);
            if (st != ATMOS_OK) return st;
            /* the slice renderer's eye_scale: (0, 1], or 2 (four rays per pixel, averaged) */
            if (r == ATMOS_RENDERER_SLICE && !strcmp(t[i].key, "eye_scale") && v > 1 && v != 2) {
                char got[40];
                atmos__scene_fmt_num(got, sizeof got, v);
                return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path, "must be in (0, 1] or 2, got %s", got);
            }
        }
    }
    return atmos__slice_field_check(ctx, source, s);
}

/* A volume's "particle": a file's or a generated volume's (a simulation sets its fields' own
 * types), and a known type (the scene's "particles" or a preset), as the fog's. */
static atmos_status validate_volume_particle(atmos_context *ctx, const char *source, const atmos_scene *s)
{
    const atmos_scene_volume *v = &s->volume;
    if (!v->particle[0]) return ATMOS_OK;
    if (!memchr(v->particle, '\0', sizeof v->particle))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/volume/particle", "is not terminated");
    if (!strncmp(v->source, "simulate:", 9))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/volume/particle",
                                 "applies to volume files and generated volumes, not to a simulated volume (its "
                                 "fields have their own types)");
    atmos_particle_desc pd;
    if (atmos_scene_particle(NULL, s, v->particle, &pd) != ATMOS_OK)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/volume/particle",
                                 "'%s' is neither in the scene's \"particles\" nor a preset (atmos phase lists them)",
                                 v->particle);
    return ATMOS_OK;
}

atmos_status atmos__scene_validate_renderer(atmos_context *ctx, const char *source, const atmos_scene *s)
{
    static const atmos__range r_radiance = {0, 1e6, 0, 0}, r_dscale = {0, 1e30, 1, 0}, r_vscale = {0, 100, 1, 0},
                              r_voxel = {0, 1e5, 0, 0}, r_time_index = {0, 1000000, 0, 0}, r_detail = {0, 1, 0, 0};
    atmos_status st;
    if (s->volume.density_unit < ATMOS_DENSITY_AUTO || s->volume.density_unit > ATMOS_DENSITY_FRACTION)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/volume/density_unit",
                                 "must be auto, per_m3, g_m3 or fraction, got %d", (int)s->volume.density_unit);
    if (s->renderer < ATMOS_RENDERER_SKY || s->renderer > ATMOS_RENDERER_LAST)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/renderer", "must be sky, slice, path, nishita, harris or beams, got %d",
                                 (int)s->renderer);
    const atmos_scene_sun *sun = &s->sun;
    if (sun->irradiance_count != 0 && sun->irradiance_count != 1 && sun->irradiance_count != 3)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/sun/irradiance",
                                 "irradiance_count must be 0, 1 or 3, got %d", sun->irradiance_count);
    for (int i = 0; i < sun->irradiance_count; i++)
        if ((st = atmos__scene_check_range(ctx, source, "/sun/irradiance", sun->irradiance[i], &r_radiance, NULL)))
            return st;
    if (sun->irradiance_count == 3 && s->wavelengths != ATMOS_WAVELENGTHS_RGB)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/sun/irradiance",
                                 "three values are the rgb channels; in spectral mode give one number");
    int volume_renderer = s->renderer != ATMOS_RENDERER_SKY;
    if (!memchr(s->volume.source, '\0', sizeof s->volume.source))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/volume/file", "is not terminated");
    /* (The path tracer renders the atmosphere and the ground alone when there is no volume.) */
    if ((s->renderer == ATMOS_RENDERER_SLICE || s->renderer == ATMOS_RENDERER_NISHITA || s->renderer == ATMOS_RENDERER_HARRIS) &&
        !s->volume.source[0])
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/renderer",
                                 "\"%s\" renders a volume: the scene needs \"volume\" (a file or a generator)",
                                 atmos_renderer_name(s->renderer));
    if (s->renderer == ATMOS_RENDERER_BEAMS && s->volume.source[0])
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/volume",
                                 "the beams renderer draws no volume (lights, fog and objects only)");
    if (!volume_renderer && s->volume.source[0])
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/volume",
                                 "the sky renderer draws no volume (use \"renderer\": \"slice\" or \"path\")");
    if (s->renderer == ATMOS_RENDERER_SLICE && s->camera.type != ATMOS_CAMERA_PINHOLE)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/camera/type",
                                 "the slice renderer supports pinhole cameras only");
    if (!s->volume.placed && s->volume.source[0] && s->camera.type != ATMOS_CAMERA_PINHOLE)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/volume/position_m",
                                 "is needed with %s camera (a volume is placed in front of pinhole cameras only)",
                                 s->camera.type == ATMOS_CAMERA_FISHEYE ? "a fisheye" : "an equirect");
    const struct {
        const char *path;
        double v;
        const atmos__range *r;
    } checks[] = {
        {"/volume/density_scale", s->volume.density_scale, &r_dscale},
        {"/volume/scale", s->volume.scale, &r_vscale},
        {"/volume/voxel_size_m", s->volume.voxel_size_m, &r_voxel},
        {"/volume/time_index", s->volume.time_index, &r_time_index},
        {"/volume/subgrid_detail", s->volume.subgrid_detail, &r_detail},
        {"/volume/position_m/0", s->volume.position_m[0], &atmos__r_pos},
        {"/volume/position_m/1", s->volume.position_m[1], &atmos__r_pos},
        {"/volume/position_m/2", s->volume.position_m[2], &atmos__r_pos},
    };
    for (size_t i = 0; i < sizeof checks / sizeof checks[0]; i++)
        if ((st = atmos__scene_check_range(ctx, source, checks[i].path, checks[i].v, checks[i].r, NULL))) return st;
    if ((st = validate_volume_particle(ctx, source, s))) return st;
    if ((st = atmos__scene_validate_lights(ctx, source, s))) return st;
    return atmos__settings_check(ctx, source, s);
}

atmos_status atmos__scene_validate_animation(atmos_context *ctx, const char *source, const atmos_scene *scene)
{
    static const atmos__range r_frames = {0, ATMOS_SCENE_MAX_FRAMES, 0, 0};
    const atmos_scene_animation *a = &scene->animation;
    atmos_status st;
    if ((st = atmos__scene_check_range(ctx, source, "/animation/frames", a->frames, &r_frames, NULL))) return st;
    int angle_end = a->elevation_end_set || a->azimuth_end_set;
    if (a->time_end_set) {
        if (!scene->sun.from_time)
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/animation/time_end",
                                     "needs a sun given by time (\"sun\": {\"time\", \"latitude_deg\", "
                                     "\"longitude_deg\"}); a sun given by angles moves with elevation_end_deg/azimuth_end_deg");
        if (!atmos__scene_valid_time(&a->time_end))
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/animation/time_end", "not a valid UTC date-time");
        if ((st = sun_year(ctx, source, "/animation/time_end", &a->time_end))) return st;
    }
    if (angle_end && scene->sun.from_time)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source,
                                 a->elevation_end_set ? "/animation/elevation_end_deg" : "/animation/azimuth_end_deg",
                                 "needs a sun given by angles; a sun given by time moves with time_end");
    if (a->elevation_end_set &&
        (st = atmos__scene_check_range(ctx, source, "/animation/elevation_end_deg", a->elevation_end_deg,
                                       &atmos__r_elevation, NULL)))
        return st;
    if (a->azimuth_end_set &&
        (st = atmos__scene_check_range(ctx, source, "/animation/azimuth_end_deg", a->azimuth_end_deg,
                                       &atmos__r_azimuth, NULL)))
        return st;
    if (a->minutes_end_set && strncmp(scene->volume.source, "simulate:", 9) != 0)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/animation/minutes_end",
                                 "needs a simulated volume (\"volume\": {\"simulate\": {...}}): a time-lapse of its growth");
    if (a->minutes_end_set && !(a->minutes_end > 0 && a->minutes_end <= ATMOS_SIM_MAX_MINUTES))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/animation/minutes_end", "must be in (0, %g], got %g",
                                 ATMOS_SIM_MAX_MINUTES, a->minutes_end);
    if (a->minutes_end_set && a->frames > 1) {
        /* the first frame's minutes, as atmos_scene_animation_frame takes them */
        const double m0 = atmos__scene_first_sim_minutes(scene);
        if (!(a->minutes_end > m0))
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/animation/minutes_end",
                                     "must exceed the first frame's %g minutes (/volume/simulate/minutes): a "
                                     "time-lapse runs forward, got %g",
                                     m0, a->minutes_end);
    }
    if (a->frames > 1 && !a->time_end_set && !angle_end && !a->minutes_end_set)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/animation",
                                 "%d frames need an end: time_end (a sun given by time), elevation_end_deg/"
                                 "azimuth_end_deg (a sun given by angles) or minutes_end (a simulated volume)", a->frames);
    return ATMOS_OK;
}

atmos_status atmos_scene_validate(atmos_context *ctx, const atmos_scene *scene, const char *source)
{
    if (!scene) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_scene_validate: scene is NULL");
    atmos_status st;
    /* The name is copied around as a C string: it must be terminated inside the array. */
    if (!memchr(scene->name, '\0', sizeof scene->name))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/name",
                                 "must be at most %d bytes", (int)sizeof scene->name - 1);
    if ((st = validate_image(ctx, source, scene))) return st;
    if ((st = atmos__scene_validate_camera(ctx, source, &scene->camera))) return st;
    if ((st = atmos__scene_validate_sun(ctx, source, &scene->sun))) return st;
    if ((st = validate_atmosphere(ctx, source, &scene->atmosphere))) return st;
    if (scene->wavelengths != ATMOS_WAVELENGTHS_RGB && scene->wavelengths != ATMOS_WAVELENGTHS_SPECTRAL)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/wavelengths/mode",
                                 "must be rgb or spectral, got %d", (int)scene->wavelengths);
    /* Checked in rgb mode too, so switching the mode later cannot expose a bad count. */
    if ((st = atmos__scene_check_range(ctx, source, "/wavelengths/samples", scene->spectral_samples,
                                       &atmos__r_samples, NULL)))
        return st;
    if ((st = atmos__scene_validate_renderer(ctx, source, scene))) return st;
    if ((st = atmos__scene_validate_animation(ctx, source, scene))) return st;
    return atmos__scene_validate_output(ctx, source, scene);
}

double atmos__scene_first_sim_minutes(const atmos_scene *scene)
{
    return scene->volume.sim_minutes > 0 ? scene->volume.sim_minutes : atmos_sim_preset_minutes(scene->volume.source + 9);
}
