/* Scenes: everything a render needs, parsed from a JSON scene file with strict
 * validation (docs/scene-format.md). A scene is a plain value; copy it freely.
 */
#ifndef ATMOS_SCENE_H
#define ATMOS_SCENE_H

#include "atmos/base.h"
#include "atmos/spectrum.h"
#include "atmos/camera.h"
#include "atmos/sun.h"
#include "atmos/atmosphere.h"
#include "atmos/image.h"
#include "atmos/optics.h"
#include "atmos/volume.h"
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_SCENE_MAX_DIM 16384
#define ATMOS_SCENE_MAX_PARTICLES 8
#define ATMOS_SCENE_MAX_FRAMES 100000
/* An animation's automatic exposure is at most that of this EV100 by default: a camera's
 * longest metered exposure, 30 s at f/2.8 and ISO 100 (log2(2.8^2 / 30) = -1.94). */
#define ATMOS_SCENE_EXPOSURE_LIMIT_EV (-2.0)

typedef struct atmos_scene_sun {
    int from_time;             /* 0: use elevation/azimuth; 1: compute from time/latitude/longitude */
    double elevation_deg;      /* [-90, 90] */
    double azimuth_deg;        /* [0, 360), clockwise from north */
    atmos_utc_time time;
    double latitude_deg, longitude_deg;
    int refraction;            /* with from_time: include refraction (default 1) */
    int irradiance_count;      /* 0: the solar spectrum (times atmosphere sun_scale); 1: a flat
                                  irradiance[0] W m^-2 nm^-1 at every wavelength; 3: per rgb
                                  channel (680, 550, 440 nm; rgb mode only). Outside the air. */
    double irradiance[3];
} atmos_scene_sun;

/* Which renderer draws the scene ("renderer" in the file). */
typedef enum {
    ATMOS_RENDERER_SKY = 0,   /* the analytic sky (Riley §4.1, §4.2.4) */
    ATMOS_RENDERER_SLICE = 1, /* half-angle slicing over the volume (Riley §4.2-§5, slice.h) */
    ATMOS_RENDERER_PATH = 2,  /* Monte Carlo volumetric path tracing over the volume (path.h) */
    ATMOS_RENDERER_NISHITA = 3, /* Nishita et al. 1996: ray marching with a light field of orders 2-3 and sky light */
    ATMOS_RENDERER_HARRIS = 4,  /* Harris 2002: the volume as particles, multiple forward scattering, splats */
    ATMOS_RENDERER_BEAMS = 5   /* Dobashi et al. 2002 §4: light beams of point lights and spotlights in fog, with
                                  the shadows of meshes, by sampling planes and a pre-integrated table */
} atmos_renderer_kind;
/* The last renderer kind (loops over the kinds end here). */
#define ATMOS_RENDERER_LAST ATMOS_RENDERER_BEAMS

#define ATMOS_SCENE_PATH_MAX 1024

/* The volume of a scene ("volume" in the file). source "" = no volume. */
typedef struct atmos_scene_volume {
    char source[ATMOS_SCENE_PATH_MAX]; /* a file (.vdb .nvdb .nc .json; relative paths are resolved
                                          against the scene file's folder by atmos_scene_load) or
                                          "generate:PRESET" or "simulate:PRESET" (the cloud
                                          simulation, atmos/sim.h) */
    char grids[256];          /* VDB grid / NetCDF variable names, comma-separated ("" = reader default) */
    char particle[64];        /* particle type of a single-grid file: a preset or a "particles"
                                 entry ("" = "cloud") */
    double density_scale;     /* multiplies the densities (after the reader's unit conversion); 1 */
    atmos_density_unit density_unit; /* files: what the values are (ATMOS_DENSITY_AUTO: the format's own) */
    int time_index;           /* NetCDF time step; 0 */
    double voxel_size_m;      /* NetCDF resampling / generator voxel size / other files: the voxel
                                 edge replacing the file's; 0 = the source's */
    uint64_t seed;            /* generators; 1 */
    double scale;             /* generators: extent factor; VDB/NanoVDB/raw files: multiplies their
                                 lengths (0.01 for centimetres); 1 */
    double subgrid_detail;    /* NetCDF: artists' sub-grid detail amplitude, 0 = off (atmos_volume_load_desc) */
    int placed;               /* 1: position_m given; 0: atmos_scene_volume_offset's default */
    double position_m[3];     /* world position of the centre of the bottom face of the volume's box */
    double sim_minutes;       /* "simulate": simulated minutes (0 = the preset's default) */
    int sim_grid;             /* "simulate": horizontal cells (0 = 64); the seed is `seed` */
    int sim_refine, sim_ice;  /* "simulate": "refine" (0 = 1), "ice" (atmos_sim_desc) */
    double sim_detail;        /* "simulate": "detail" */
} atmos_scene_volume;

/* Settings of the slice renderer ("slice" in the file). Their ranges, defaults and meaning
 * are in the table atmos_renderer_settings(ATMOS_RENDERER_SLICE) (docs/scene-format.md). */
typedef struct atmos_scene_slice {
    int slices;               /* sampling planes; 0 (default) = chosen from the volume's shape:
                                 256, more (up to 2048) for wide, flat volumes (docs/slice.md) */
    int light_size;           /* light buffer texels per side; 256 */
    double xi;                /* Riley's back-scatter term xi (Eq. 26), sr^-1; 0.1/(4 pi); 0 = none */
    int eq24;                 /* "update": 0 = "eq25" (default), 1 = "eq24" */
    int low_albedo;           /* 0 */
    int grid_max_dim;         /* 256 */
    double eye_scale;         /* eye buffer resolution relative to the image, per axis, (0, 1] or 2; 1 */
    double edge_aa;           /* 0.05; with eye_scale 1: four eye rays in the pixels where the volume's
                                 transmittance differs from a neighbour's by more than this; 0 = off */
    int max_order;            /* Ams orders tabulated; 64 */
    int diffuse;              /* 0: the same as field ATMOS_SLICE_FIELD_NONE (the key kept); 1 (default) */
    int do_field;             /* "do", 1: the same as field ATMOS_SLICE_FIELD_DO (the key kept); 0 */
    int air_shadows;          /* 1 (default): the volume shadows the air's single scattering
                                 (light shafts, crepuscular rays); 0: the air is lit unshadowed */
    int field;                /* "field": the light scattered more than once, atmos_slice_field;
                                 ATMOS_SLICE_FIELD_AUTO (default), see atmos_scene_slice_field */
} atmos_scene_slice;

/* The slice renderer's field of the light scattered more than once ("field"). */
typedef enum atmos_slice_field {
    ATMOS_SLICE_FIELD_AUTO = 0, /* "auto": do, unless a setting of Riley's path asks for that path:
                                   p1 when xi is set away from its default or update is eq24,
                                   none when diffuse is false or low_albedo is set */
    ATMOS_SLICE_FIELD_DO = 1,   /* "do": the first order in the delta-M scaled medium plus the orders
                                   >= 2 by discrete ordinates (docs/lightfield.md) */
    ATMOS_SLICE_FIELD_P1 = 2,   /* "p1": Riley's Eq. 24/25, Ams and xi plus the diffusion (P1) field of
                                   the light they drop */
    ATMOS_SLICE_FIELD_NONE = 3  /* "none": Riley's Eq. 24/25, Ams and xi alone */
} atmos_slice_field;

/* Settings of the path tracer ("path" in the file); the table is
 * atmos_renderer_settings(ATMOS_RENDERER_PATH). */
typedef struct atmos_scene_path {
    int spp;                  /* samples per pixel; 64 */
    double time_budget_s;     /* > 0: stop when this much time has passed (after whole passes); 0 = none */
    uint64_t seed;            /* 1 */
    int max_depth;            /* scattering events per path; 0 = unlimited (Russian roulette) */
    double truncate_deg;      /* forward-peak truncation angle, degrees, [0, 20]; 0 = none (exact) */
    int sky_nee;              /* next-event estimation toward the sky; 1 */
    int forced;               /* forced single scattering on camera rays; 1 */
    int aureole;              /* the aureole estimate in droplet clouds; 1 */
    int roulette;             /* lights and fog: Russian roulette by the lights' nearness from order 4; 1 */
} atmos_scene_path;

/* Settings of the Nishita renderer ("nishita" in the file); the table is
 * atmos_renderer_settings(ATMOS_RENDERER_NISHITA) (docs/lightfield.md, "Nishita 1996"). */
typedef struct atmos_scene_nishita {
    int orders;               /* highest scattering order of the sunlight: 1, 2 or 3; 3 */
    double ratio;             /* the share r of the sample space's contribution the patterns keep; 0.95 */
    int paths;                /* n1: order-3 paths computed per cell; 256 */
    int cells;                /* the light field's grid: at most this many cells per axis; 32 */
    int sky;                  /* the sky's and the ground's light through sky elements; 1 */
    int step_scale_pct;       /* eye-ray step, per cent of a render voxel; 50 */
    int diffuse;              /* 1: the slice renderer's diffuse light field (all orders) and Riley's
                                 scattered beam where the medium is thick, the orders 2-3 and the sky
                                 elements where it is thin (docs/lightfield.md); 0 */
    int mc_kphotons;          /* > 0: a diagnostic, the orders >= 2 from a Monte Carlo field of this many
                                 thousand photons per wavelength toward the eye's central direction, the
                                 medium cut at 3 degrees (docs/lightfield.md, "A Monte Carlo field"); 0 */
    int mc_cell;              /* that field's cell edge, render voxels; 4 */
    int mc_lmax;              /* -1: the field toward the view's centre alone; 0-3: its spherical harmonics of
                                 degree <= this, turned toward the eye per cell; -1 */
    int mc_delta_m;           /* 1 (with mc_lmax >= 0): the photons traced in the delta-M scaled medium of
                                 that degree (Wiscombe 1977), the field's part of the eye rays too; 0 */
    int do_field;             /* 1: that field of the orders >= 2 (degree mc_lmax, 3 if -1) solved by
                                 discrete ordinates on its cells instead of photons (docs/lightfield.md); 0 */
    int mc_dm_clip;           /* 1 (with mc_delta_m): the photons sample the scaled phase exactly, the cut
                                 phase with its peak clipped until delta-M's fraction is gone, instead of
                                 Henyey-Greenstein of its g*; 0 */
    double edge_aa;           /* four eye rays, averaged, in the pixels whose transmittance through the volume
                                 differs from a neighbour's by more than this (its silhouette; the slice
                                 renderer's edge_aa); 0 = one ray a pixel; 0.05 */
} atmos_scene_nishita;

/* Settings of Harris's particle renderer ("harris" in the file); the table is
 * atmos_renderer_settings(ATMOS_RENDERER_HARRIS) (docs/particles.md). */
typedef struct atmos_scene_harris {
    double spacing_m;         /* particles one per cell of this edge; 0 = the volume's voxel, coarser
                                 until at most max_particles */
    int max_particles;        /* 50000 */
    int sky_lights;           /* sky lights besides the sun (Harris §2.3.1); 6 */
    int light_size;           /* light buffer texels per side; 0 = from the particles' size (<= 1024) */
    int impostors;            /* 1: clouds drawn from dynamically generated impostors (Harris §3) */
    double impostor_tolerance_deg; /* the translation error that makes an impostor again; 0.15 */
    int impostor_max_res;     /* an impostor's texels per side at most; 512 */
    int diffuse;              /* 1: each particle also scatters the slice renderer's diffuse light field
                                 toward the eye (docs/particles.md); 1 */
} atmos_scene_harris;

/* Settings of the beam renderer ("beams" in the file); the table is
 * atmos_renderer_settings(ATMOS_RENDERER_BEAMS) (docs/beams.md). */
typedef struct atmos_scene_beams {
    double plane_spacing_m;   /* distance between the main sampling planes along the view; 0 = 1/40 of the lights'
                                 depth range in view */
    double epsilon;           /* sub-planes: each may add at most this share of the pixel's unshadowed airlight
                                 (Dobashi's threshold); 0.01 */
    int max_subplanes;        /* sub-planes between two main planes at most; 64 */
    int shadow_size;          /* shadow map texels per side (per cube face for point lights); 512 */
    int sun;                  /* 1: the scene's sun lights the fog and the objects too (a directional light with a
                                 shadow map, docs/beams.md); 0 */
    int interleave;           /* Keller and Heidrich 2001's interleaved sampling: each pixel of an N x N block samples
                                 between the planes at its own offset, and the airlight is averaged over N x N pixels
                                 of similar depth; 1 = off (the default) */
    int screen_step;          /* the airlight evaluated every screen_step pixels and interpolated where the lattice's
                                 cells agree, evaluated per pixel elsewhere, and the sky behind read from the sky
                                 renderer's grid of every screen_step pixels (docs/beams.md); 1 = every pixel */
    int exact_shadows;        /* 1: the surfaces' shadows of the lights by an exact ray per pixel and light; 0 (the
                                 default): from the lights' shadow maps where they settle it, rays elsewhere */
} atmos_scene_beams;

/* Lights besides the sun ("lights" in the file; the beam renderer's). */
#define ATMOS_SCENE_MAX_LIGHTS 32
typedef enum { ATMOS_LIGHT_POINT = 0, ATMOS_LIGHT_SPOT = 1 } atmos_light_type;
typedef struct atmos_scene_light {
    atmos_light_type type;
    double position_m[3];
    double direction[3];      /* spot: the axis (normalised by the parser); point: unused */
    double cone_deg;          /* spot: full intensity within this angle of the axis, [0, 89] */
    double edge_deg;          /* spot: falling smoothly to zero over this much more, [0, 90]; cone + edge <= 90 */
    double intensity_w_sr;    /* radiant intensity on the axis, W sr^-1, (0, 1e9] */
    double colour_temperature_k; /* > 0: the spectrum of a black body at this temperature, [1000, 40000];
                                    0: colour */
    double colour[3];         /* rgb weights in [0, 1e3] (rgb wavelengths only), with no temperature; 1, 1, 1 */
    double range_m;           /* the light's reach: the beam renderer samples the air within it, a hard cut;
                                 [0, 1e6]; 0 (the default): where the airlight falls to 1e-3 of its value
                                 1 m from the light (docs/beams.md, "A light's reach") */
    char image[ATMOS_SCENE_PATH_MAX]; /* spot, rgb wavelengths: a PNG projected through the cone (stained glass):
                                         the light toward a direction is tinted by the image's texel there
                                         (docs/scene-format.md); relative paths against the scene's folder; "" none */
} atmos_scene_light;

/* A uniform participating medium ("fog" in the file): Dobashi's constant density, as
 * coefficients per metre, the same at every wavelength, with a Henyey-Greenstein phase function;
 * or a fog of a particle type (Mie droplets: its phase function and albedo from the type's
 * table, the renderers' coefficients the means over the wavelengths; docs/scene-format.md). */
typedef struct atmos_scene_fog {
    int enabled;
    double extinction_per_m;  /* (0, 10]; with particle: the extinction at 550 nm */
    double scattering_per_m;  /* [0, extinction]; with particle: unused (the type's albedo) */
    double g;                 /* Henyey-Greenstein asymmetry, (-1, 1); 0; with particle: unused */
    char particle[32];        /* a particle type (a preset or the scene's "particles"), or "" */
    double visibility_m;      /* > 0: given as visibility (extinction_per_m = 3.912 / visibility at 550 nm) */
    double height_m;          /* > 0: the coefficients fall off as exp(-(y - base_m) / height_m) (the beam renderer's
                                 sun only); 0: uniform */
    double base_m;            /* the height where the coefficients are as given; 0 */
} atmos_scene_fog;

/* Opaque Lambertian objects ("objects" in the file). */
#define ATMOS_SCENE_MAX_OBJECTS 16
typedef struct atmos_scene_object {
    char mesh[ATMOS_SCENE_PATH_MAX]; /* "builtin:NAME" or an OBJ file (relative paths: against the scene's folder);
                                        empty for a terrain */
    char terrain[ATMOS_SCENE_PATH_MAX]; /* a height map (raster file, relative paths as mesh) or
                                           "generate:ridges" (atmos_terrain_desc); empty for a mesh */
    double size_m;            /* terrain: width along x, (0, 1e7]; 1000 */
    double height_m;          /* terrain: > 0 normalises the heights to [0, height_m]; 0 */
    double height_scale;      /* terrain: with height_m 0, metres per raster unit; 0 = 1 */
    int stride, samples, max_triangles; /* terrain: atmos_terrain_desc's; 0 */
    uint64_t seed;            /* terrain: the generator's; 0 */
    double position_m[3];
    double scale[3];          /* per axis, nonzero, |s| <= 1e6; 1, 1, 1 */
    double rotation_deg[3];   /* about x, then y, then z; 0 */
    double albedo[3];         /* Lambertian reflectance per rgb channel (one value for spectral), [0, 1]; 0.5 */
} atmos_scene_object;

/* A sequence of images with the sun moving ("animation" in the file): frame i of N
 * (0-based) takes the sun at fraction i / (N - 1) of the way from the scene's sun to the
 * end given here (atmos_scene_animation_frame). With a sun given by time, the time is
 * interpolated linearly (and the solar position computed for each frame); with a sun
 * given by angles, the elevation linearly and the azimuth along the shorter arc. */
typedef struct atmos_scene_animation {
    int frames;                /* images in the sequence; 0 = a single image (no animation) */
    int time_end_set;          /* 1: time_end given (a sun given by time) */
    atmos_utc_time time_end;   /* the last frame's time */
    int elevation_end_set;     /* 1: elevation_end_deg given (a sun given by angles) */
    double elevation_end_deg;  /* the last frame's sun elevation, [-90, 90] */
    int azimuth_end_set;       /* 1: azimuth_end_deg given (a sun given by angles) */
    double azimuth_end_deg;    /* the last frame's sun azimuth, [0, 360) */
    int minutes_end_set;       /* 1: minutes_end given (a simulated volume: a time-lapse) */
    double minutes_end;        /* the last frame's simulated minutes; frame i's volume.sim_minutes goes
                                  linearly from the volume's (its preset's default when 0) to this */
    int exposure_per_frame;    /* 1: "exposure": "per_frame", an automatic exposure chosen for each
                                  frame; 0: "locked" (default), the one of the frame with the
                                  highest sun for all */
    double exposure_limit_ev;  /* "exposure_limit_ev": an automatic exposure of the animation's
                                  frames is at most that of this EV100 (a camera's limit, so
                                  night stays dark), [-20, 40]; atmos_scene_defaults and a
                                  scene file's "animation" without the key:
                                  ATMOS_SCENE_EXPOSURE_LIMIT_EV */
} atmos_scene_animation;

/* The Earth's maps and clouds of a spherical atmosphere ("atmosphere" keys "ground_map",
 * "night_lights", "map_reduce", "clouds": {"image", "world_file", ...}); relative paths are
 * resolved against the scene file's folder by atmos_scene_load, which also checks that the
 * files can be read. The images are read when the atmosphere is made
 * (atmos_scene_atmosphere_create); the other settings are in atmos_atmosphere_desc. */
typedef struct atmos_scene_earth {
    char ground_map[ATMOS_SCENE_PATH_MAX];   /* JPEG or PNG; "" none */
    char night_lights[ATMOS_SCENE_PATH_MAX]; /* JPEG or PNG; "" none */
    char cloud_image[ATMOS_SCENE_PATH_MAX];  /* JPEG or PNG; "" no clouds */
    char cloud_world_file[ATMOS_SCENE_PATH_MAX]; /* ESRI world file placing cloud_image
                                                    (longitude, latitude of pixel centres); "" */
    int map_reduce;                          /* JPEG maps decoded at 1/map_reduce: 1, 2, 4, 8 */
} atmos_scene_earth;

typedef struct atmos_scene {
    char name[128];
    int width, height;                    /* pixels, 1..ATMOS_SCENE_MAX_DIM */
    int samples_per_pixel;                /* stratified samples per pixel, 1..256 */
    atmos_camera_desc camera;
    atmos_scene_sun sun;
    atmos_atmosphere_desc atmosphere;     /* "atmosphere" in the file; "background": "black" or
                                             {"type": "uniform", "radiance": L} make it a vacuum
                                             (ATMOS_ATMOSPHERE_VACUUM: no air, no ground, L from
                                             every direction), "sky" the scene's atmosphere */
    atmos_wavelength_mode wavelengths;
    int spectral_samples;                 /* with spectral mode, 1..ATMOS_MAX_WAVELENGTHS */
    atmos_tonemap_desc tonemap;
    int png_bits;                         /* 8 or 16 */
    int exr_half;                         /* nonzero: EXR as half floats */
    int particle_count;                   /* user-defined particle types ("particles" in the file) */
    atmos_particle_desc particles[ATMOS_SCENE_MAX_PARTICLES]; /* each named by .name */
    atmos_renderer_kind renderer;
    atmos_scene_volume volume;
    atmos_scene_slice slice;
    atmos_scene_path path;
    atmos_scene_nishita nishita;
    atmos_scene_harris harris;
    atmos_scene_animation animation;
    int camera_given;                     /* the scene file has a "camera" (a volume scene without
                                             one is framed by atmos_scene_frame_volume) */
    atmos_scene_earth earth;              /* the spherical atmosphere's maps and clouds */
    atmos_scene_beams beams;
    int light_count;
    atmos_scene_light lights[ATMOS_SCENE_MAX_LIGHTS];
    atmos_scene_fog fog;
    int object_count;
    atmos_scene_object objects[ATMOS_SCENE_MAX_OBJECTS];
    char file[ATMOS_SCENE_PATH_MAX];      /* the scene file atmos_scene_load read, whose folder its
                                             relative paths were taken from (messages name it);
                                             "" for a scene from text, standard input or code */
    char origin[ATMOS_SCENE_PATH_MAX];    /* who set its file keys, for messages when file is "":
                                             "standard input", else "" */
    char volume_by[ATMOS_SCENE_PATH_MAX]; /* the override that set /volume/file ("-D volume.file=X
                                             (on SOURCE)"), blamed for its load's errors; else "" */
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
/* The scene's atmosphere for a wavelength set: atmos_atmosphere_create with the maps and
 * the cloud image of scene->earth read (JPEG or PNG, by the file's first bytes) and placed
 * (a world file sets the cloud image's extent). */
ATMOS_API atmos_status atmos_scene_atmosphere_create(atmos_context *ctx, const atmos_scene *scene,
                                                     const atmos_wavelengths *wl, atmos_atmosphere **out);
/* The clouds of the scene's spherical atmosphere as a volume (field "cloud", particle "cloud"):
 * a box of the world frame 2 half_width_m wide in x and z around (centre_xz[0], centre_xz[1]),
 * from the cloud layer's base (where the curved layer is lowest in the box) to its top, of
 * voxel_size_m voxels whose densities give the layer's extinction (docs/sky.md). The ground
 * truth for the cloud spheres with the slice renderer and the path tracer. */
/* The most voxels atmos_scene_cloud_volume puts across its box (2 half_width_m / voxel_size_m,
 * rounded up): more is ATMOS_E_INVALID_ARG. */
#define ATMOS_CLOUD_VOLUME_MAX_ACROSS 8192
/* The voxels across that box, 2 half_width_m / voxel_size_m rounded up; 0 unless both are > 0.
 * The box is allowed when it is 1..ATMOS_CLOUD_VOLUME_MAX_ACROSS. */
ATMOS_API double atmos_scene_cloud_volume_across(double half_width_m, double voxel_size_m);
ATMOS_API atmos_status atmos_scene_cloud_volume(atmos_context *ctx, const atmos_scene *scene, const double centre_xz[2],
                                                double half_width_m, double voxel_size_m, atmos_volume **out);

/* The same with keys set from outside the text (atmos render -D, as Mitsuba's): each of the
 * count overrides is "PATH=VALUE", PATH a JSON pointer ("/camera/fov_deg") or a dotted path
 * ("camera.fov_deg", "camera.position_m.1"), VALUE JSON text ("35", "[0, 900, 0]",
 * "\"path\"") or a bare word that is not JSON, taken as a string (renderer=path).
 * Objects on the path are made as needed; array items are replaced (or appended at the
 * array's size). Each value is then read with the rules and messages of the file's; a
 * mistake at a key an override set is blamed on it ("-D camera.fovv_deg=30 (on SOURCE):
 * /camera/fovv_deg: unknown key ..."). The load's path "-" reads standard input (relative
 * volume paths: from the current folder). */
ATMOS_API atmos_status atmos_scene_parse_with(atmos_context *ctx, const char *json, size_t length, const char *source,
                                              const char *const *overrides, int count, atmos_scene *out);
ATMOS_API atmos_status atmos_scene_load_with(atmos_context *ctx, const char *path, const char *const *overrides,
                                             int count, atmos_scene *out);
/* atmos_scene_load_with on a scene file's text already read (json, length bytes): its
 * relative paths (volume, Earth maps, meshes) are taken from path's folder; path "-" names
 * standard input (messages say so; relative paths from the current folder). */
ATMOS_API atmos_status atmos_scene_parse_file(atmos_context *ctx, const char *json, size_t length, const char *path,
                                              const char *const *overrides, int count, atmos_scene *out);

/* Checks a scene built or modified in code (CLI overrides) with the same rules
 * and messages as the parser, using source as the message prefix. */
ATMOS_API atmos_status atmos_scene_validate(atmos_context *ctx, const atmos_scene *scene, const char *source);

/* The particle type called name: a user-defined one of the scene's "particles"
 * section if there is one by that name, else the optics preset (atmos_particle_preset).
 * ATMOS_E_INVALID_ARG listing both kinds of names if neither exists. */
ATMOS_API atmos_status atmos_scene_particle(atmos_context *ctx, const atmos_scene *scene, const char *name,
                                            atmos_particle_desc *out);

/* The optics of a scene's volume: for field i, phase[i] (sigma_ext, albedo and P(theta) per
 * wavelength of the scene's set) and, when built with them, ms[i] (the multiple-scattering
 * phase functions Ams_n and forward fractions F_n, Riley et al. 2004 Eq. 20-23). */
typedef struct atmos_volume_optics {
    int count;
    const atmos_phase_table *phase[ATMOS_VOLUME_MAX_FIELDS];
    const atmos_msphase *ms[ATMOS_VOLUME_MAX_FIELDS]; /* NULL when built without them */
    int owned; /* set by atmos_volume_optics_build: atmos_volume_optics_free destroys the tables */
} atmos_volume_optics;

/* Builds (or loads from the disk cache) the phase table of every field of the volume, and
 * with with_msphase its Ams_n tables (64 orders), for the particle type named by
 * atmos_volume_field_particle() looked up with atmos_scene_particle() (a scene-defined type
 * or a preset), for the scene's wavelength set. Reports progress through ctx. Free with
 * atmos_volume_optics_free(). */
ATMOS_API atmos_status atmos_volume_optics_build(atmos_context *ctx, const atmos_scene *scene,
                                                 const atmos_volume *volume, int with_msphase,
                                                 atmos_volume_optics *out);
/* Destroys the tables if owned; zeroes *o. NULL does nothing. */
ATMOS_API void atmos_volume_optics_free(atmos_volume_optics *o);

/* Every generator a scene's "volume": {"generate": NAME} may name (NULL-terminated): the
 * volume generators (atmos_volume_generator_names) and the particle clouds' ("harris_cumulus",
 * "harris_field": Harris 2002's ellipsoid clusters, docs/particles.md), and the volume of one:
 * a particle cloud's is its particles summed on a grid (so every renderer draws the same cloud;
 * Harris's renderer takes the particles themselves). */
ATMOS_API const char *const *atmos_scene_generator_names(void);
/* Whether name is one of them (0 for NULL); the names, ", "-separated, into list[0..n) when
 * list is not NULL (for a message). */
ATMOS_API int atmos_scene_generator_known(const char *name, char *list, size_t n);
ATMOS_API atmos_status atmos_scene_generate_volume(atmos_context *ctx, const char *preset,
                                                   const atmos_volume_generate_desc *desc, atmos_volume **out);
/* Loads or generates the volume a scene names (scene->volume: file, grids, particle, time
 * index, voxel size, density unit, length scale, sub-grid detail; generator, seed, scale)
 * and computes offset_m, the shift that places
 * it in the world (atmos_scene_volume_offset). The scene's density_scale is not applied
 * here (the renderers apply it). */
ATMOS_API atmos_status atmos_scene_load_volume(atmos_context *ctx, const atmos_scene *scene, atmos_volume **out,
                                               double offset_m[3]);
/* The shift that places a volume in a scene's world: position_m puts the centre of the
 * box's bottom face there; without it the box's centre is moved horizontally to three of
 * its widths (at least 4 km) in front of the scene's camera, at its own altitude -- except
 * for an OpenVDB/NanoVDB file (an artist's volume in its own local frame), whose box's base
 * goes to ATMOS_SCENE_CLOUD_BASE_M above the ground. */
ATMOS_API void atmos_scene_volume_offset(const atmos_scene *scene, const atmos_volume *volume, double offset_m[3]);
#define ATMOS_SCENE_CLOUD_BASE_M 1500.0

/* Points the scene's pinhole camera at a volume placed by offset_m so that its whole box is
 * in view: looking at the box's centre along the camera's heading at view_elevation_deg
 * (the view direction's elevation; negative: looking down), from the nearest distance that keeps the box's eight
 * corners inside the field of view (with a 10 % margin), the camera at least 2 m above the
 * ground. Other camera types and fields (up, fov) are kept. */
ATMOS_API void atmos_scene_frame_volume(atmos_scene *scene, const atmos_volume *volume, const double offset_m[3],
                                        double view_elevation_deg);

/* The rule `atmos render` follows for a scene that names a volume file (not a generator)
 * and gives no camera, with a pinhole camera and a renderer other than the sky: the volume
 * is loaded into *out and placed (scene->volume.position_m made explicit, placed = 1), and
 * the camera frames it (atmos_scene_frame_volume) from view_elevation_deg, NAN for the
 * default: from 30 degrees above for a model domain (NetCDF), level for a cloud; the scene
 * then counts as having a camera. Render with the volume (atmos_render_scene,
 * atmos_plan_create) to draw it where it was framed. *out is NULL (and the scene unchanged)
 * when there is nothing to frame; the caller destroys it. */
ATMOS_API atmos_status atmos_scene_frame_volume_file(atmos_context *ctx, atmos_scene *scene, double view_elevation_deg,
                                                     atmos_volume **out);

/* Frame index (0-based, < the frame count) of the scene's animation: *out is the scene
 * with the sun moved as atmos_scene_animation describes and no animation left in it.
 * A scene without an animation has one frame, itself. ATMOS_E_INVALID_ARG for an index
 * out of range or an animation that does not match the sun (checked as the parser does). */
ATMOS_API atmos_status atmos_scene_animation_frame(atmos_context *ctx, const atmos_scene *scene, int index,
                                                   atmos_scene *out);

/* The wavelength set a scene asks for. */
ATMOS_API atmos_status atmos_scene_wavelengths(atmos_context *ctx, const atmos_scene *scene,
                                               atmos_wavelengths *out);

/* The sun's direction (unit vector towards the sun), elevation and azimuth for
 * a scene, computing the solar position when the scene gives a time. */
ATMOS_API atmos_status atmos_scene_sun_direction(atmos_context *ctx, const atmos_scene *scene,
                                                 double dir[3], double *elevation_deg,
                                                 double *azimuth_deg);

/* ---------------------------------------------------------------- renderer settings */

/* One setting of a renderer's section of a scene file ("slice", "path"): the table that the
 * scene parser, the validator, atmos render's options and its --help all read. */
typedef enum {
    ATMOS_SETTING_INT = 0,
    ATMOS_SETTING_REAL = 1,
    ATMOS_SETTING_BOOL = 2,
    ATMOS_SETTING_CHOICE = 3,  /* an int holding the index of one of choices[] */
    ATMOS_SETTING_SEED = 4     /* a uint64_t (JSON numbers up to 2^53) */
} atmos_setting_type;

typedef struct atmos_setting {
    const char *key;            /* the key in the scene file's section */
    const char *flag;           /* atmos render's option without "--" (NULL: none) */
    atmos_setting_type type;
    const char *unit;           /* "" when it has none */
    double min, max;            /* the allowed range (CHOICE and BOOL: unused) */
    int min_open, max_open;     /* nonzero: the end is excluded */
    double def;                 /* the default (BOOL 0/1; CHOICE the index) */
    const char *const *choices; /* CHOICE: the names, NULL-terminated */
    int flag_sets;              /* BOOL and CHOICE flags take no argument: the value they set */
    const char *doc;            /* one line */
    size_t offset;              /* of the value in atmos_scene */
} atmos_setting;

/* The settings of a renderer's section (count through *count; NULL and 0 for the sky). */
ATMOS_API const atmos_setting *atmos_renderer_settings(atmos_renderer_kind renderer, int *count);
/* A setting's value in a scene (as a double: exact for every type), and setting it (the value
 * is not checked: atmos_scene_validate does that). */
ATMOS_API double atmos_scene_setting_get(const atmos_scene *scene, const atmos_setting *setting);
ATMOS_API void atmos_scene_setting_set(atmos_scene *scene, const atmos_setting *setting, double value);
/* The field the slice renderer draws for these settings: "field" when set, else the old keys
 * ("do": true, "diffuse": false) and the settings of Riley's path (ATMOS_SLICE_FIELD_AUTO);
 * never ATMOS_SLICE_FIELD_AUTO. With low_albedo the field is not drawn whatever this says. */
ATMOS_API atmos_slice_field atmos_scene_slice_field(const atmos_scene_slice *slice);
/* "auto", "do", "p1", "none" (the "field" key's names, the settings table's); NULL for another value. */
ATMOS_API const char *atmos_slice_field_name(atmos_slice_field field);
/* "sky", "slice", "path", "nishita", "harris", "beams"; NULL for an unknown kind. */
ATMOS_API const char *atmos_renderer_name(atmos_renderer_kind renderer);

#ifdef __cplusplus
}
#endif
#endif
