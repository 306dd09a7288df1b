/* Atmospheric volumes: several particle fields (number densities, m^-3) on one
 * uniform voxel grid in world space, stored sparsely in bricks, with a coarse
 * majorant grid for empty-space skipping (Riley et al. 2004 §3.2, Eq. 2-6).
 *
 * Life cycle: create -> add fields -> write voxels (set / set_dense) -> finalize.
 * After atmos_volume_finalize() a volume is immutable: any number of threads may
 * sample it. Memory limits are checked before allocating (ATMOS_E_LIMIT).
 */
#ifndef ATMOS_VOLUME_H
#define ATMOS_VOLUME_H

#include "atmos/base.h"
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_VOLUME_MAX_FIELDS 8
#define ATMOS_VOLUME_MAX_DIM 16384          /* voxels along one axis */
#define ATMOS_VOLUME_MIN_VOXEL_M 1e-6      /* voxel edge, metres: the supported range */
#define ATMOS_VOLUME_MAX_VOXEL_M 1e5       /* (100 km) */
#define ATMOS_VOLUME_DEFAULT_MAX_MEMORY ((uint64_t)8 << 30)

/* Settings for a new volume; zero means default where stated. */
typedef struct atmos_volume_desc {
    int dims[3];              /* voxels along x, y, z: 1..ATMOS_VOLUME_MAX_DIM */
    double voxel_size_m;      /* edge of a (cubic) voxel, metres, in [ATMOS_VOLUME_MIN_VOXEL_M,
                                 ATMOS_VOLUME_MAX_VOXEL_M] */
    double origin_m[3];       /* world position of the corner of voxel (0,0,0) */
    double rotation[9];       /* row-major 3x3 rotation from grid axes to world axes;
                                 all zero = identity. world = origin + R (index * voxel_size) */
    uint64_t max_memory;      /* bytes the volume may use; 0 = ATMOS_VOLUME_DEFAULT_MAX_MEMORY */
    int periodic;             /* nonzero: the grid wraps round along its x and z axes (the
                                 periodic sides of a simulation, atmos_sim_to_volume); written
                                 to and read from a raw volume's sidecar ("periodic": true).
                                 The cloud statistics take it as their default; the renderers
                                 do not repeat the grid. Default 0 */
} atmos_volume_desc;

typedef struct atmos_volume atmos_volume;

ATMOS_API atmos_status atmos_volume_create(atmos_context *ctx, const atmos_volume_desc *desc, atmos_volume **out);
ATMOS_API void atmos_volume_destroy(atmos_volume *vol);

/* Adds a field named `name` ("cloud", "rain", "ice", "snow", "graupel", ...) whose
 * particles are of the optics preset `particle` (atmos_particle_preset(); may equal
 * name). Returns its index through *index. Before finalize only. */
ATMOS_API atmos_status atmos_volume_add_field(atmos_context *ctx, atmos_volume *vol, const char *name,
                                              const char *particle, int *index);
/* Writes one voxel's number density (m^-3, finite, >= 0). Before finalize only. */
ATMOS_API atmos_status atmos_volume_set(atmos_context *ctx, atmos_volume *vol, int field, int i, int j, int k,
                                        float density);
/* Writes a dense block of nx*ny*nz values (x fastest) times scale, at voxel offset
 * (i0, j0, k0); zeros leave bricks unallocated. Rejects NaN, Inf and negatives with
 * a message naming the first bad index. Before finalize only. */
ATMOS_API atmos_status atmos_volume_set_dense(atmos_context *ctx, atmos_volume *vol, int field, const int offset[3],
                                              const int size[3], const float *values, float scale);
/* Builds the per-brick bounds (majorants) and statistics; the volume becomes read-only. */
ATMOS_API atmos_status atmos_volume_finalize(atmos_context *ctx, atmos_volume *vol);

ATMOS_API const atmos_volume_desc *atmos_volume_get_desc(const atmos_volume *vol);
ATMOS_API int atmos_volume_field_count(const atmos_volume *vol);
ATMOS_API const char *atmos_volume_field_name(const atmos_volume *vol, int field);
ATMOS_API const char *atmos_volume_field_particle(const atmos_volume *vol, int field);

typedef struct atmos_volume_field_stats {
    uint64_t active_voxels;   /* voxels with density > 0 */
    uint64_t file_active_voxels; /* the source file's own count of active voxels, when it has one
                                    (OpenVDB/NanoVDB: active tiles count as the voxels they cover,
                                    active zeros included); 0 otherwise */
    double min, max;          /* over active voxels (0, 0 if none) */
    double bounds_m[2][3];    /* world-space AABB of the active voxels */
} atmos_volume_field_stats;
/* Statistics of a field of a finalized volume; a bad argument or a volume that is not
 * finalized gives ATMOS_E_INVALID_ARG with a message in ctx. */
ATMOS_API atmos_status atmos_volume_field_stats_get(atmos_context *ctx, const atmos_volume *vol, int field,
                                                    atmos_volume_field_stats *out);
/* Bytes held (bricks, majorant grid, bookkeeping). */
ATMOS_API uint64_t atmos_volume_memory(const atmos_volume *vol);
/* World-space AABB of the whole grid. */
ATMOS_API void atmos_volume_bounds(const atmos_volume *vol, double lo[3], double hi[3]);

/* Trilinear number density (m^-3) of a field at a world position; 0 outside. */
ATMOS_API double atmos_volume_sample(const atmos_volume *vol, int field, const double p[3]);
/* Extinction coefficient (m^-1) at p: sum_i eta_i(p) sigma_ext[i] (Riley Eq. 2-3). */
ATMOS_API double atmos_volume_extinction(const atmos_volume *vol, const double *sigma_ext, const double p[3]);
/* Optical depth along p = o + t d, t in [t0, t1] (Riley Eq. 4) with the extinction
 * above, integrated by DDA over the voxels with empty-space skipping by the majorant
 * grid; d need not be unit length (t is in units of |d|). */
ATMOS_API double atmos_volume_optical_depth(const atmos_volume *vol, const double *sigma_ext, const double o[3],
                                            const double d[3], double t0, double t1);

/* ---------------------------------------------------------------- files */

/* What a file's values are (atmos_volume_load_desc.density_unit; "density_unit" in a scene). */
typedef enum atmos_density_unit {
    ATMOS_DENSITY_AUTO = 0,     /* the format's own: OpenVDB/NanoVDB FRACTION, raw JSON PER_M3,
                                   NetCDF the model's mass mixing ratios (docs/volumes.md) */
    ATMOS_DENSITY_PER_M3 = 1,   /* number density, particles per m^3 */
    ATMOS_DENSITY_G_M3 = 2,     /* water content, g of water or ice per m^3 of air, turned into a
                                   number density by the particle type's mean mass (cloud, rain,
                                   ice, snow, graupel; ATMOS_DENSITY_G_M3_MASS lists them) */
    ATMOS_DENSITY_FRACTION = 3  /* a dimensionless 0..1 "density" (artist fog volumes): 1 is
                                   ATMOS_DENSITY_FRACTION_PER_M3 particles per m^3 */
} atmos_density_unit;

/* A fraction of 1 is 1e8 particles per m^3 (100 per cm^3, a cumulus's droplet concentration,
 * the generated cumulus's peak): with the "cloud" droplet preset an extinction of 63 km^-1 (a
 * mean free path of 16 m), so a cloud a few hundred metres across is optically thick. */
#define ATMOS_DENSITY_FRACTION_PER_M3 1e8

/* Mean mass (kg) of one particle of a hydrometeor type ("cloud", "rain", "ice", "snow",
 * "graupel"), the assumption that turns a water content into a number density; 0 for
 * other names. */
ATMOS_API double atmos_particle_mean_mass(const char *particle);

typedef struct atmos_volume_load_desc {
    const char *grids;        /* VDB/NanoVDB: comma-separated grid names to load (NULL = "density"
                                 or all float grids); NetCDF: variables (NULL = all hydrometeors) */
    const char *field;        /* field/particle name for a single-grid file (NULL = "cloud") */
    double density_scale;     /* multiplies the file's values to get m^-3; 0 = 1 for VDB/raw,
                                 mass-based conversion for WRF/CM1 (docs/volumes.md) */
    int time_index;           /* NetCDF: time step (default 0) */
    int region[6];            /* NetCDF: i0, i1, j0, j1, k0, k1 sub-region (all 0 = everything) */
    double voxel_size_m;      /* NetCDF: resampling voxel size (0 = from the model levels and
                                 grid spacing); other formats: the voxel edge in metres, replacing
                                 the file's (its origin scaled by the same factor); 0 = the file's */
    uint64_t max_memory;      /* 0 = default */
    atmos_density_unit density_unit; /* what the values are; AUTO = the format's own */
    double length_scale;      /* VDB/NanoVDB/raw: multiplies every length of the file (voxel size and
                                 origin; 0.01 for a file in centimetres), after voxel_size_m; 0 = 1.
                                 NetCDF: must be 0 or 1 (its lengths are metres) */
    double subgrid_detail;    /* NetCDF, for artists: 0 = off (the model's fields, smoothly
                                 reconstructed); (0, 1]: each voxel times 1 + a (2 n - 1), n a
                                 fractal noise in [0, 1] at scales from half the model's grid
                                 spacing down to the voxel: a texture the model does not hold
                                 (logged as such). Other formats: must be 0 */
} atmos_volume_load_desc;

/* Loads .vdb (OpenVDB, when built with it), .nvdb (NanoVDB), .nc (WRF or CM1
 * NetCDF) or .json (raw float32 + JSON sidecar, see docs/volumes.md), chosen by
 * the file's contents/extension. Malformed files: ATMOS_E_FORMAT naming the file
 * and the problem; unsupported formats in this build: ATMOS_E_UNSUPPORTED. */
ATMOS_API atmos_status atmos_volume_load(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                         atmos_volume **out);
/* The kind of file a volume was loaded from: "openvdb", "nanovdb", "netcdf", "raw", or ""
 * (generated or built in code). */
ATMOS_API const char *atmos_volume_source_format(const atmos_volume *vol);
/* Writes every field as raw little-endian float32 (x fastest, one .raw per field
 * next to the sidecar) and a JSON sidecar at json_path. Atomic per file. */
ATMOS_API atmos_status atmos_volume_write_raw(atmos_context *ctx, const atmos_volume *vol, const char *json_path);

/* ---------------------------------------------------------------- generators */

typedef struct atmos_volume_generate_desc {
    uint64_t seed;            /* same seed, same volume */
    double voxel_size_m;      /* 0 = the preset's default */
    double scale;             /* multiplies the preset's extent (1 = default); 0 = 1; else in
                                 [ATMOS_GENERATE_SCALE_MIN, ATMOS_GENERATE_SCALE_MAX] */
    uint64_t max_memory;      /* 0 = default */
} atmos_volume_generate_desc;
#define ATMOS_GENERATE_SCALE_MIN 0.05
#define ATMOS_GENERATE_SCALE_MAX 20.0

/* Presets: "cumulus", "cumulonimbus", "cumulus_field", "cirrus", "rain_shaft", "storm",
 * "stratocumulus", "virga" (docs/volumes.md). Unknown names list the known ones. */
ATMOS_API atmos_status atmos_volume_generate(atmos_context *ctx, const char *preset,
                                             const atmos_volume_generate_desc *desc, atmos_volume **out);
ATMOS_API const char *const *atmos_volume_generator_names(void);

#ifdef __cplusplus
}
#endif
#endif
