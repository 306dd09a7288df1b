/* Shared between the scene parser (scene_json.c) and the struct validator
 * (scene_validate.c): the value ranges and the message format, so a value
 * rejected in a JSON file and the same value set by a CLI override produce the
 * same message ("SOURCE: /camera/fov_deg: must be in (0, 180) ..., got 270").
 */
#ifndef ATMOS_SCENE_INTERNAL_H
#define ATMOS_SCENE_INTERNAL_H

#include "core/internal.h"

/* Inputs above this are refused before any parsing (ATMOS_E_LIMIT): a real scene
 * is a few hundred bytes, so this only stops accidents and hostile input. */
#define ATMOS__SCENE_MAX_BYTES ((size_t)16 << 20)
/* The scene format needs three levels ({"camera": {"view": {...}}}); "_" keys may
 * hold annotations of any shape, so allow some room but stop absurd nesting
 * before cJSON recurses into it. */
#define ATMOS__SCENE_MAX_DEPTH 64
/* Camera coordinates are bounded so that differences and norms of positions stay
 * far from overflow; 1e8 m is well beyond anything an atmosphere renderer needs.
 * look_at gets ten times more room so that position + 1000 m * direction (the
 * look_at the parser derives from a view) always stays in range. */
#define ATMOS__SCENE_MAX_POS 1e8
#define ATMOS__SCENE_MAX_LOOK 1e9

/* A volume whose peak extinction times its box's diagonal (a bound on the optical depth of
 * any ray across it) is below this is reported as nearly invisible. */
#define ATMOS__SCENE_THIN_TAU 0.01
/* The warnings about a scene's volume once its optics are known (a plan's): a VDB file read
 * as a 0..1 fraction and scaled by >= 1e3 (values meant as particles per m^3), a volume
 * too thin to see (ATMOS__SCENE_THIN_TAU), naming the density unit and scale options, and a
 * volume whose box placed at offset_m (the world's metres) lies wholly below the ground. */
void atmos__scene_volume_warnings(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *vol,
                                  const atmos_volume_optics *optics, const double offset_m[3]);

/* A closed, open or half-open interval. */
typedef struct atmos__range {
    double lo, hi;
    int lo_open, hi_open;
} atmos__range;

extern const atmos__range atmos__r_dim, atmos__r_spp, atmos__r_altitude, atmos__r_pos, atmos__r_look,
    atmos__r_fov_pinhole, atmos__r_fov_fisheye, atmos__r_elevation, atmos__r_azimuth,
    atmos__r_latitude, atmos__r_longitude, atmos__r_beta, atmos__r_scale_height, atmos__r_albedo,
    atmos__r_sun_diameter, atmos__r_sun_scale, atmos__r_thickness, atmos__r_radiance, atmos__r_samples, atmos__r_manual_ev,
    atmos__r_compensation, atmos__r_planet_radius, atmos__r_top, atmos__r_visibility, atmos__r_turbidity,
    atmos__r_ozone, atmos__r_dobashi_ambient;

/* Reports "SOURCE: PATH: <fmt>" through ctx and returns status. */
/* A simulated volume's minutes at the animation's first frame: the scene's, or its preset's
 * (source "simulate:PRESET"). */
double atmos__scene_first_sim_minutes(const atmos_scene *scene);
atmos_status atmos__scene_fail(atmos_context *ctx, atmos_status status, const char *source,
                               const char *path, const char *fmt, ...) ATMOS_PRINTF(5, 6);

/* Formats a double compactly and exactly enough to round-trip ("270", "0.01"). */
void atmos__scene_fmt_num(char *buf, size_t cap, double v);

/* Checks v against r; on failure reports "PATH: must be in [lo, hi]<extra>, got v".
 * extra (may be NULL) qualifies the range (" for a pinhole camera"). Non-finite
 * values get their own message. */
atmos_status atmos__scene_check_range(atmos_context *ctx, const char *source, const char *path,
                                      double v, const atmos__range *r, const char *extra);

/* Per-section validators, also run by the parser at the end of each section so
 * that cross-field rules (look_at vs position, fov by camera type) exist once. */
atmos_status atmos__scene_validate_camera(atmos_context *ctx, const char *source,
                                          const atmos_camera_desc *cam);
atmos_status atmos__scene_validate_sun(atmos_context *ctx, const char *source,
                                       const atmos_scene_sun *sun);
/* The renderer, background, sun irradiance, volume, slice and path settings, and
 * the rules between them (a volume renderer needs a volume, ...). */
atmos_status atmos__scene_validate_renderer(atmos_context *ctx, const char *source, const atmos_scene *scene);
atmos_status atmos__scene_validate_output(atmos_context *ctx, const char *source,
                                          const atmos_scene *scene);
/* The animation section and its match with the sun (time_end with a sun given by time,
 * elevation/azimuth ends with a sun given by angles). */
atmos_status atmos__scene_validate_animation(atmos_context *ctx, const char *source, const atmos_scene *scene);
/* 1 if t is a real UTC date-time (years 1..9999, a leap second allowed). */
int atmos__scene_valid_time(const atmos_utc_time *t);

/* Fills scene from a parsed JSON document (root), which must be an object. scene
 * holds the starting values (the defaults); absent keys keep them. */
struct cJSON;
atmos_status atmos__scene_from_json(atmos_context *ctx, const char *source, const struct cJSON *root,
                                    atmos_scene *scene);

/* Sets each "PATH=VALUE" of overrides in root (scene_override.c; atmos_scene_parse_with). */
atmos_status atmos__scene_apply_overrides(atmos_context *ctx, const char *source, struct cJSON *root,
                                          const char *const *overrides, int count);
/* After a failed parse of a tree with overrides: when the message's key (SOURCE: /a/b: ...) is
 * one an override set (or lies inside it), the message says so (-D PATH=VALUE on SOURCE),
 * rather than blaming the file, which may not have the key at all. Returns st. */
atmos_status atmos__scene_blame_override(atmos_context *ctx, atmos_status st, const char *source,
                                         const char *const *overrides, int count);
/* Writes into buf who set key (a JSON pointer): "-D PATH=VALUE (on SOURCE)" for the last
 * override that sets it or an object holding it ("-D PATH=VALUE" when source is "-D"), else "". */
void atmos__scene_override_blame(char *buf, size_t cap, const char *key, const char *source,
                                 const char *const *overrides, int count);

/* The view direction and up vector atmos_camera_init will use for cam, with
 * camera.h's zero-means-default rules for look_at and up applied. */
void atmos__scene_camera_effective(const atmos_camera_desc *cam, double fwd[3], double up[3]);

/* The defaults of every row of the renderers' settings tables (scene_settings.c), and the
 * range check of every row (scene_validate.c). */
void atmos__settings_defaults(atmos_scene *s);
atmos_status atmos__settings_check(atmos_context *ctx, const char *source, const atmos_scene *s);
/* The slice renderer's "field" against "do", "diffuse" and the settings the do field leaves
 * without a use (scene_slice_field.c). */
atmos_status atmos__slice_field_check(atmos_context *ctx, const char *source, const atmos_scene *s);

/* Robust vector helpers (scaled so huge components never overflow). */
double atmos__scene_norm3(const double v[3]);
/* Sine of the angle between a and b (0 when parallel); -1 if either is zero. */
double atmos__scene_sin_angle(const double a[3], const double b[3]);

/* scene_lights.c: a light's and an object's defaults (a point light of 100 W/sr, white, reaching
 * 100 m; the spot's axis straight down, cone 30 and edge 5 degrees; an object at the origin,
 * unscaled, albedo 0.5), and the checks of the lights, the fog and the objects. */
void atmos__scene_light_defaults(atmos_scene_light *l);
void atmos__scene_object_defaults(atmos_scene_object *o);
atmos_status atmos__scene_validate_lights(atmos_context *ctx, const char *source, const atmos_scene *scene);

/* scene_earth.c: the Earth's map and cloud files of a scene loaded from `path`, made
 * relative to its folder (the first dir bytes of path; 0: the current folder) and checked
 * to be readable. */
atmos_status atmos__scene_earth_paths(atmos_context *ctx, const char *path, size_t dir, atmos_scene_earth *e);

/* scene_paths.c: the path p (cap bytes) of a scene loaded from `scene` made usable from
 * anywhere: relative to the scene's folder (its first dir bytes; 0: standard input, the
 * current folder), "data:REST" in the data folder (atmos__scene_data_dir(), which must hold
 * it); absolute paths and generated sources unchanged. key names the field in messages. */
atmos_status atmos__scene_join_path(atmos_context *ctx, const char *scene, size_t dir, char *p, size_t cap,
                                    const char *key);
/* $ATMOS_DATA, else the folder the build was configured with (ATMOS_DATA_DIR). */
const char *atmos__scene_data_dir(void);
/* A file the scene names (path, after atmos_scene_load joined it) could not be read: the
 * reader's message (the context's error, status st) with "FILE: " (a scene from a file) and
 * key (e.g. "/volume/file") in front and, when where is set and the path is relative, where
 * it was looked for: " (resolved against the scene's folder DIR; the scene wrote REST)" or
 * " (a relative path: from the current folder)". Returns st. */
atmos_status atmos__scene_file_error(atmos_context *ctx, atmos_status st, const atmos_scene *s, const char *path,
                                    const char *key, int where);

#endif
