/* The storage behind atmos_volume: volume.c builds it, volume_range.c adds the
 * per-brick interpolant bounds at finalize, and everything that reads a volume goes
 * through volume_access.h (transform, trilinear sampler, brick DDA, brick iterator).
 *
 * Bricks: the index box is cut into bricks of VOL_BRICK^3 voxels (x fastest). All
 * bricks of all fields live in ONE pooled allocation (pool) addressed by 32-bit brick
 * indices, in the way PNanoVDB addresses a whole grid by 32-bit offsets into one
 * buffer: brick n is pool[n * VOL_BRICK_VOXELS ...]. Brick 0 is a brick of zeros
 * that every empty position points at, so "0 = empty" in a brick table is also a valid
 * address and reading a voxel needs no branch. Indexing by brick rather than by byte
 * lets 32 bits reach 2^32 bricks (8 TiB) instead of 4 GiB. The pool grows (doubling,
 * never past max_memory) while the volume is built and is trimmed to its size and
 * fixed at finalize.
 *
 * Each field has its own brick table (one uint32 per brick position), so a rain field
 * does not pay for the cloud field's bricks.
 *
 * Bounds (after finalize): for every brick position whose region holds a nonzero
 * voxel of some field, cell[] holds an index r > 0 into range[], where
 * range[(r * nfields + f) * 2 + {0, 1}] are the minimum and maximum of field f's
 * voxels over the brick's region (its voxels plus the one-voxel ring the trilinear
 * interpolation reads, clamped to the grid). Range 0 is all zeros: positions that
 * nothing reaches. Memory: 4 B per brick position per field (table) + 4 B per brick
 * position (cell) + 2 KiB per occupied brick + 8 B per field per non-empty region.
 */
#ifndef ATMOS_VOLUME_GRID_H
#define ATMOS_VOLUME_GRID_H

#include "atmos/atmos.h"
#include "core/internal.h"

#include <stdint.h>

#define VOL_BRICK_LOG2 3
#define VOL_BRICK (1 << VOL_BRICK_LOG2)
#define VOL_BRICK_VOXELS_LOG2 (3 * VOL_BRICK_LOG2)
#define VOL_BRICK_VOXELS (VOL_BRICK * VOL_BRICK * VOL_BRICK)
#define VOL_BRICK_BYTES ((uint64_t)VOL_BRICK_VOXELS * sizeof(float))
#define VOL_NAME_MAX 64

/* World <-> index: world = org + R (index * vs). Operations: volume_access.h. */
typedef struct {
    double org[3];  /* world position of index point (0, 0, 0), m: origin_m plus a placement offset */
    double R[9];    /* grid axes -> world axes, row-major; orthonormal, so its inverse is R^T */
    double vs;      /* voxel edge, m */
    double inv_vs;  /* 1 / vs, m^-1 */
} atmos__vol_xform;

typedef struct vol_field {
    char name[VOL_NAME_MAX];
    char particle[VOL_NAME_MAX];
    uint32_t *table;       /* nbricks entries: 0 empty (the zero brick), else a brick index into the pool */
    uint32_t count;        /* occupied bricks */
    atmos_volume_field_stats stats;
    uint64_t file_active;  /* the reader's own active-voxel count, 0 if none */
} vol_field;

struct atmos_volume {
    atmos_volume_desc desc;   /* resolved: rotation filled in, max_memory set */
    int nb[3];                /* bricks along each axis */
    uint64_t nbricks;
    int nfields;
    vol_field field[ATMOS_VOLUME_MAX_FIELDS];
    int finalized;
    atmos__vol_xform xform;   /* from desc, not moved */
    uint64_t memory;          /* bytes held */
    float *pool;              /* pool_cap bricks; brick 0 is all zeros */
    uint32_t pool_used, pool_cap;
    uint32_t *cell;           /* after finalize: nbricks entries, index into range (0: nothing reaches) */
    float *range;             /* after finalize: nrange * nfields (min, max) pairs */
    uint32_t nrange;
    int occ_lo[3], occ_hi[3]; /* brick box of the occupied bricks of all fields (hi < lo: none) */
    int rng_lo[3], rng_hi[3]; /* brick box of the positions with a range > 0 (hi < lo: none) */
    char source_format[16];   /* atmos_volume_source_format */
};

/* Index of the brick containing voxel (i, j, k) (all in range). */
static inline uint64_t vol_brick_index(const atmos_volume *v, int i, int j, int k)
{
    return ((uint64_t)(k >> VOL_BRICK_LOG2) * (uint64_t)v->nb[1] + (uint64_t)(j >> VOL_BRICK_LOG2)) * (uint64_t)v->nb[0] +
           (uint64_t)(i >> VOL_BRICK_LOG2);
}

static inline int vol_in_brick(int i, int j, int k)
{
    const int m = VOL_BRICK - 1;
    return ((k & m) * VOL_BRICK + (j & m)) * VOL_BRICK + (i & m);
}

/* The VOL_BRICK_VOXELS floats of brick n of the pool (n = 0: zeros). */
static inline const float *vol_brick_data(const atmos_volume *v, uint32_t n)
{
    return v->pool + ((size_t)n << VOL_BRICK_VOXELS_LOG2);
}

/* Density of voxel (i, j, k) of field f; 0 for empty bricks. Indices must be in range. */
static inline float vol_voxel(const atmos_volume *v, const vol_field *f, int i, int j, int k)
{
    return vol_brick_data(v, f->table[vol_brick_index(v, i, j, k)])[vol_in_brick(i, j, k)];
}

/* Optical depth with empty-space skipping on (skip != 0) or off, for tests. */
double atmos__volume_optical_depth_ex(const atmos_volume *vol, const double *sigma_ext, const double o[3],
                                      const double d[3], double t0, double t1, int skip);
/* Bytes the volume may still allocate. */
int atmos__volume_can_alloc(const atmos_volume *v, uint64_t bytes);
/* ATMOS_E_LIMIT: "volume: WHAT needs BYTES bytes but the volume already holds ..." */
atmos_status atmos__volume_limit_error(atmos_context *ctx, const atmos_volume *v, const char *what, uint64_t bytes);
/* Builds cell[], range[] and the two brick boxes (volume_range.c); part of finalize. */
atmos_status atmos__volume_build_ranges(atmos_context *ctx, atmos_volume *v);

#endif
