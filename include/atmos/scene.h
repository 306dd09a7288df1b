/* Scenes: everything a render needs, parsed from a JSON scene file with strict
 * validation (docs/scene-format.md). A scene is a plain value; copy it freely.
 */
#ifndef ATMOS_SCENE_H
#define ATMOS_SCENE_H

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_SCENE_MAX_DIM 16384
#define ATMOS_SCENE_MAX_PARTICLES 8

typedef struct atmos_scene_sun {
    int from_time;             /* 0: use elevation/azimuth; 1: compute from time/latitude/longitude */
    double elevation_deg;      /* [-90, 90] */
    double azimuth_deg;        /* [0, 360), clockwise from north */
    atmos_utc_time time;
    double latitude_deg, longitude_deg;
    int refraction;            /* with from_time: include refraction (default 1) */
} atmos_scene_sun;

typedef struct atmos_scene {
    char name[128];
    int width, height;                    /* pixels, 1..ATMOS_SCENE_MAX_DIM */
    int samples_per_pixel;                /* stratified samples per pixel, 1..256 */
    atmos_camera_desc camera;
    atmos_scene_sun sun;
    atmos_atmosphere_desc atmosphere;
    atmos_wavelength_mode wavelengths;
    int spectral_samples;                 /* with spectral mode, 1..ATMOS_MAX_WAVELENGTHS */
    atmos_tonemap_desc tonemap;
    int png_bits;                         /* 8 or 16 */
    int exr_half;                         /* nonzero: EXR as half floats */
    int particle_count;                   /* user-defined particle types ("particles" in the file) */
    atmos_particle_desc particles[ATMOS_SCENE_MAX_PARTICLES]; /* each named by .name */
} atmos_scene;

/* The built-in default scene (what `atmos render` renders with no scene file). */
ATMOS_API void atmos_scene_defaults(atmos_scene *scene);

/* Parses and validates a JSON scene. Keys absent from the JSON keep the defaults.
 * source names the text in messages ("scene.json: /camera/fov_deg: must be in
 * (0, 180), got 270"). Unknown keys, wrong types and out-of-range values are
 * ATMOS_E_INVALID_ARG; malformed JSON is ATMOS_E_FORMAT. */
ATMOS_API atmos_status atmos_scene_parse(atmos_context *ctx, const char *json, size_t length,
                                         const char *source, atmos_scene *out);
/* Reads a file (at most 16 MiB) and parses it. */
ATMOS_API atmos_status atmos_scene_load(atmos_context *ctx, const char *path, atmos_scene *out);

/* Checks a scene built or modified in code (CLI overrides) with the same rules
 * and messages as the parser, using source as the message prefix. */
ATMOS_API atmos_status atmos_scene_validate(atmos_context *ctx, const atmos_scene *scene, const char *source);

/* The particle type called name: a user-defined one of the scene's "particles"
 * section if there is one by that name, else the optics preset (atmos_particle_preset).
 * ATMOS_E_INVALID_ARG listing both kinds of names if neither exists. */
ATMOS_API atmos_status atmos_scene_particle(atmos_context *ctx, const atmos_scene *scene, const char *name,
                                            atmos_particle_desc *out);

/* The sun's direction (unit vector towards the sun), elevation and azimuth for
 * a scene, computing the solar position when the scene gives a time. */
ATMOS_API atmos_status atmos_scene_sun_direction(atmos_context *ctx, const atmos_scene *scene,
                                                 double dir[3], double *elevation_deg,
                                                 double *azimuth_deg);

#ifdef __cplusplus
}
#endif
#endif
