"""The C side of the Python package, through cffi's API mode.

``ffibuilder`` declares the part of atmos's C API the package uses (cffi checks each
declaration against the real headers when the module is compiled, so the layouts cannot
drift) and a few loops kept in C (a sky query over many directions, a volume read back
voxel by voxel). Run as a script it writes the module's C source:

    python3 _build_ffi.py OUT.c

atmos's CMake build compiles that source against the library in the build tree;
``setup.py`` (``pip install ./python``) compiles it against an installed atmos found by
pkg-config.
"""
import sys

import cffi

CDEF = r"""
typedef enum { ATMOS_OK = 0, ATMOS_E_INVALID_ARG, ATMOS_E_NOMEM, ATMOS_E_IO, ATMOS_E_FORMAT,
               ATMOS_E_UNSUPPORTED, ATMOS_E_LIMIT, ATMOS_E_CANCELLED } atmos_status;
typedef struct atmos_context atmos_context;
typedef struct atmos_volume atmos_volume;
typedef int (*atmos_progress_fn)(void *user, const char *stage, double fraction);
typedef struct atmos_context_desc { int threads; const char *cache_dir; ...; } atmos_context_desc;
extern "Python" int atmos_py_progress(void *user, const char *stage, double fraction);
atmos_status atmos_py_context_create(atmos_context **out);
int atmos_py_progress_swap(int on);
const char *atmos_version(void);
const char *atmos_status_string(atmos_status status);
void atmos_context_defaults(atmos_context_desc *desc);
atmos_status atmos_context_create(const atmos_context_desc *desc, atmos_context **out);
void atmos_context_destroy(atmos_context *ctx);
const char *atmos_context_error(const atmos_context *ctx);

#define ATMOS_MAX_WAVELENGTHS ...
typedef struct atmos_wavelengths { int count; double nm[...]; ...; } atmos_wavelengths;
void atmos_wavelengths_rgb(atmos_wavelengths *out);
atmos_status atmos_wavelengths_spectral(int n, atmos_wavelengths *out);

typedef struct atmos_image_meta { char *key; char *value; } atmos_image_meta;
typedef struct atmos_image { int width, height, channels; float *pixels; int meta_count; atmos_image_meta *meta; ...; }
    atmos_image;
atmos_status atmos_read_exr_named(atmos_context *ctx, const char *path, atmos_image **out, char ***names);
void free(void *ptr);
void atmos_image_destroy(atmos_image *img);
const char *atmos_image_get_meta(const atmos_image *img, const char *key);
atmos_status atmos_image_to_srgb(atmos_context *ctx, const atmos_image *spectral, const atmos_wavelengths *wl,
                                 atmos_image **out);
atmos_status atmos_write_exr(atmos_context *ctx, const atmos_image *img, const char *path, const void *desc);
atmos_status atmos_write_pfm(atmos_context *ctx, const atmos_image *img, const char *path);
atmos_status atmos_read_pfm(atmos_context *ctx, const char *path, atmos_image **out);
const char *atmos_image_kind(const void *bytes, size_t n);
const char *atmos_image_file_kind(const char *path);

typedef struct atmos_utc_time { int year, month, day; int hour, minute; double second; } atmos_utc_time;
typedef struct atmos_sun_position { double elevation_deg; double azimuth_deg; ...; } atmos_sun_position;
atmos_status atmos_parse_utc_time(atmos_context *ctx, const char *text, atmos_utc_time *out);
atmos_status atmos_sun_position_compute(atmos_context *ctx, const atmos_utc_time *t, double latitude_deg,
                                        double longitude_deg, int refraction, atmos_sun_position *out);

typedef struct atmos_camera_desc { double position[3]; double look_at[3]; double up[3]; double fov_deg; ...; }
    atmos_camera_desc;
void atmos_direction_from_angles(double elevation_deg, double azimuth_deg, double dir[3]);
typedef struct atmos_scene_volume { char source[...]; ...; } atmos_scene_volume;
typedef enum { ATMOS_RENDERER_SKY = 0, ... } atmos_renderer_kind;
typedef struct atmos_scene_sun { int from_time; atmos_utc_time time; double latitude_deg, longitude_deg; ...; }
    atmos_scene_sun;
typedef enum { ATMOS_ATMOSPHERE_RILEY = 0, ATMOS_ATMOSPHERE_VACUUM, ATMOS_ATMOSPHERE_HOMOGENEOUS,
               ATMOS_ATMOSPHERE_DOBASHI, ATMOS_ATMOSPHERE_SPHERICAL } atmos_atmosphere_kind;
typedef struct atmos_atmosphere_desc { atmos_atmosphere_kind kind; double latitude_deg, longitude_deg; ...; }
    atmos_atmosphere_desc;
typedef struct atmos_scene_animation { int frames; int elevation_end_set; int azimuth_end_set; int minutes_end_set;
                                       ...; } atmos_scene_animation;
typedef struct atmos_scene { char name[128]; int width, height; atmos_camera_desc camera; atmos_renderer_kind renderer;
                             atmos_scene_sun sun; atmos_atmosphere_desc atmosphere; atmos_scene_volume volume;
                             atmos_scene_animation animation; ...; } atmos_scene;
atmos_status atmos_scene_animation_frame(atmos_context *ctx, const atmos_scene *scene, int index, atmos_scene *out);
atmos_status atmos_scene_parse_with(atmos_context *ctx, const char *json, size_t length, const char *source,
                                    const char *const *overrides, int count, atmos_scene *out);
atmos_status atmos_scene_load_with(atmos_context *ctx, const char *path, const char *const *overrides, int count,
                                   atmos_scene *out);
atmos_status atmos_scene_frame_volume_file(atmos_context *ctx, atmos_scene *scene, double view_elevation_deg,
                                           atmos_volume **out);
atmos_status atmos_scene_wavelengths(atmos_context *ctx, const atmos_scene *scene, atmos_wavelengths *out);
atmos_status atmos_scene_sun_direction(atmos_context *ctx, const atmos_scene *scene, double dir[3],
                                       double *elevation_deg, double *azimuth_deg);

typedef struct atmos_volume_desc { int dims[3]; double voxel_size_m; double origin_m[3]; ...; } atmos_volume_desc;
atmos_status atmos_volume_create(atmos_context *ctx, const atmos_volume_desc *desc, atmos_volume **out);
void atmos_volume_destroy(atmos_volume *vol);
atmos_status atmos_volume_add_field(atmos_context *ctx, atmos_volume *vol, const char *name, const char *particle,
                                    int *index);
atmos_status atmos_volume_set_dense(atmos_context *ctx, atmos_volume *vol, int field, const int offset[3],
                                    const int size[3], const float *values, float scale);
atmos_status atmos_volume_finalize(atmos_context *ctx, atmos_volume *vol);
const atmos_volume_desc *atmos_volume_get_desc(const atmos_volume *vol);
int atmos_volume_field_count(const atmos_volume *vol);
const char *atmos_volume_field_name(const atmos_volume *vol, int field);
const char *atmos_volume_field_particle(const atmos_volume *vol, int field);
typedef struct atmos_volume_load_desc { ...; } atmos_volume_load_desc;
atmos_status atmos_volume_load(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                               atmos_volume **out);

typedef struct atmos_render_info { double seconds; double sun_elevation_deg, sun_azimuth_deg; ...; }
    atmos_render_info;
atmos_status atmos_render_scene(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                atmos_image **out, atmos_render_info *info);
typedef struct atmos_plan atmos_plan;
typedef struct atmos_frame { atmos_camera_desc camera; int width, height; double sun_dir[3]; int spp; ...; }
    atmos_frame;
typedef struct atmos_plan_desc { int offset_given; double offset_m[3]; ...; } atmos_plan_desc;
atmos_status atmos_plan_create(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                               const atmos_plan_desc *desc, atmos_plan **out);
void atmos_plan_destroy(atmos_plan *plan);
const atmos_wavelengths *atmos_plan_wavelengths(const atmos_plan *plan);
atmos_status atmos_frame_from_scene(atmos_context *ctx, const atmos_scene *scene, atmos_frame *out);
atmos_status atmos_plan_image_create(const atmos_plan *plan, const atmos_frame *frame, atmos_image **out);
atmos_status atmos_plan_render(atmos_plan *plan, const atmos_frame *frame, const void *region, atmos_image *img,
                               atmos_render_info *info);

typedef struct atmos_complex { double re, im; } atmos_complex;
typedef struct atmos_mie_result { double qext, qsca, qback, g; int terms; } atmos_mie_result;
atmos_status atmos_mie(atmos_context *ctx, atmos_complex m, double x, int n_angles, const double *mu,
                       atmos_complex *s1, atmos_complex *s2, atmos_mie_result *out);
atmos_complex atmos_refractive_index_water(double nm);
atmos_complex atmos_refractive_index_ice(double nm);
typedef struct atmos_particle_desc { ...; } atmos_particle_desc;
atmos_status atmos_particle_preset(atmos_context *ctx, const char *name, atmos_particle_desc *out);
typedef struct atmos_phase_table atmos_phase_table;
int atmos_phase_grid(const double **theta_deg);
atmos_status atmos_phase_table_build(atmos_context *ctx, const atmos_particle_desc *particle,
                                     const atmos_wavelengths *wl, const void *desc, atmos_phase_table **out);
void atmos_phase_table_destroy(atmos_phase_table *t);
int atmos_phase_table_wavelength_count(const atmos_phase_table *t);
double atmos_phase_table_wavelength_nm(const atmos_phase_table *t, int k);
const double *atmos_phase_table_values(const atmos_phase_table *t, int k);
double atmos_phase_table_g(const atmos_phase_table *t, int k);
double atmos_phase_table_sigma_ext(const atmos_phase_table *t, int k);
double atmos_phase_table_albedo(const atmos_phase_table *t, int k);

atmos_status atmos_py_particle_fast(atmos_context *ctx, const char *name, int fast, atmos_particle_desc *out);
atmos_status atmos_py_sky_radiance(atmos_context *ctx, const atmos_scene *scene, const double position[3],
                                   const double *dirs, long n, double *out, int *count);
void atmos_py_volume_dense(const atmos_volume *vol, int field, float *out);
"""

# Loops the package keeps in C: per-direction and per-voxel calls from Python would cost
# more than the work they do.
SOURCE = r"""
#include <atmos/atmos.h>
#include <stdlib.h>

/* Progress: every context's sink passes reports on to Python (atmos_py_progress) only while
 * the calling thread's current call has a callback (atmos_py_progress_swap), so that a call
 * without one never waits for the GIL. The library reports from the calling thread only. */
static int atmos_py_progress(void *user, const char *stage, double fraction); /* cffi defines it */
static _Thread_local int atmos_py_progress_on;

static int atmos_py_progress_sink(void *user, const char *stage, double fraction)
{
    return atmos_py_progress_on ? atmos_py_progress(user, stage, fraction) : 0;
}

/* Sets whether this thread's calls report to Python; returns what it was. */
static int atmos_py_progress_swap(int on)
{
    const int was = atmos_py_progress_on;
    atmos_py_progress_on = on;
    return was;
}

/* A context as atmos_context_create(NULL, out) makes it, with the progress sink. */
static atmos_status atmos_py_context_create(atmos_context **out)
{
    atmos_context_desc desc = {0};
    desc.progress = atmos_py_progress_sink;
    return atmos_context_create(&desc, out);
}

/* A particle preset, with its fast (coarser) optics if asked. */
static atmos_status atmos_py_particle_fast(atmos_context *ctx, const char *name, int fast, atmos_particle_desc *out)
{
    atmos_status st = atmos_particle_preset(ctx, name, out);
    if (st == ATMOS_OK) out->fast = fast;
    return st;
}

/* What the scene's atmosphere shows along each of n unit directions (dirs: n x 3) seen from
 * position, under the scene's sun: out is n x count radiances (W m^-2 sr^-1 nm^-1) at the
 * scene's wavelengths. */
static atmos_status atmos_py_sky_radiance(atmos_context *ctx, const atmos_scene *scene, const double position[3],
                                          const double *dirs, long n, double *out, int *count)
{
    atmos_wavelengths wl;
    atmos_atmosphere *atm = NULL;
    double sun[3];
    atmos_status st = atmos_scene_wavelengths(ctx, scene, &wl);
    if (st == ATMOS_OK) st = atmos_scene_sun_direction(ctx, scene, sun, NULL, NULL);
    if (st == ATMOS_OK) st = atmos_scene_atmosphere_create(ctx, scene, &wl, &atm);
    if (st != ATMOS_OK) return st;
    *count = wl.count;
    for (long i = 0; i < n && st == ATMOS_OK; i++) /* an observer under the ground, a bad direction */
        st = atmos_atmosphere_check_ray(ctx, atm, position, dirs + 3 * i, sun);
    for (long i = 0; i < n && st == ATMOS_OK; i++)
        atmos_atmosphere_radiance(atm, position, dirs + 3 * i, sun, out + (size_t)i * wl.count, NULL);
    atmos_atmosphere_destroy(atm);
    return st;
}

/* A field's densities at the voxel centres (world = origin + R (index + 1/2) voxel size), x fastest:
 * dims[0] * dims[1] * dims[2] floats. */
static void atmos_py_volume_dense(const atmos_volume *vol, int field, float *out)
{
    const atmos_volume_desc *d = atmos_volume_get_desc(vol);
    double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (int a = 0; a < 9; a++)
        if (d->rotation[a] != 0.0) {
            for (int b = 0; b < 9; b++) r[b] = d->rotation[b];
            break;
        }
    size_t q = 0;
    for (int k = 0; k < d->dims[2]; k++)
        for (int j = 0; j < d->dims[1]; j++)
            for (int i = 0; i < d->dims[0]; i++) {
                double g[3] = {(i + 0.5) * d->voxel_size_m, (j + 0.5) * d->voxel_size_m, (k + 0.5) * d->voxel_size_m}, p[3];
                for (int a = 0; a < 3; a++) p[a] = d->origin_m[a] + r[3 * a] * g[0] + r[3 * a + 1] * g[1] + r[3 * a + 2] * g[2];
                out[q++] = (float)atmos_volume_sample(vol, field, p);
            }
}
"""

def _installed_atmos():
    """Where an installed atmos is, from its pkg-config file (pip install); {} when there is
    none (the CMake build passes its own paths)."""
    import shutil
    import subprocess

    if not shutil.which("pkg-config"):
        return {}
    run = lambda *a: subprocess.run(["pkg-config", *a, "atmos"], capture_output=True, text=True)  # noqa: E731
    if run("--exists").returncode != 0:
        return {}
    inc = [f[2:] for f in run("--cflags-only-I").stdout.split()]
    lib = [f[2:] for f in run("--libs-only-L").stdout.split()]
    return {"include_dirs": inc, "library_dirs": lib, "runtime_library_dirs": lib}


ffibuilder = cffi.FFI()
ffibuilder.cdef(CDEF)
ffibuilder.set_source("atmos._native", SOURCE, libraries=["atmos"],
                      **({} if __name__ == "__main__" else _installed_atmos()))

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: _build_ffi.py OUT.c")
    ffibuilder.emit_c_code(sys.argv[1])
