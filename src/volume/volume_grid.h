/* The sparse multi-field grid behind atmos_volume (volume.c builds it,
 * volume_sample.c reads it, raw_json.c and the generators fill it).
 *
 * Storage: the index box is cut into bricks of VOL_BRICK^3 voxels. Each field has
 * its own brick table (one uint32 per brick position: 0 = empty, else 1 + slot in
 * the field's array of brick pointers) so a rain field does not pay for the cloud
 * field's bricks. A brick is VOL_BRICK^3 floats, x fastest. Memory therefore is
 * 4 bytes per brick position per field (the table) + 4 bytes per brick position per
 * field (the majorant grid, after finalize) + 2 KiB per occupied brick.
 *
 * Majorant grid: one cell per brick position per field holding the largest density
 * that the trilinear interpolant can take anywhere inside that brick's region of
 * space (the region's voxels plus the one-voxel ring its interpolation reaches).
 * At query time the cell's extinction bound is sum_i sigma_ext[i] * maj_i (Riley
 * Eq. 3), so a cell whose bound is 0 is exactly empty and may be skipped.
 */
#ifndef ATMOS_VOLUME_GRID_H
#define ATMOS_VOLUME_GRID_H

#include "atmos/atmos.h"
#include "core/internal.h"

#include <stdint.h>

#define VOL_BRICK_LOG2 3
#define VOL_BRICK (1 << VOL_BRICK_LOG2)
#define VOL_BRICK_VOXELS (VOL_BRICK * VOL_BRICK * VOL_BRICK)
#define VOL_NAME_MAX 64

typedef struct vol_field {
    char name[VOL_NAME_MAX];
    char particle[VOL_NAME_MAX];
    uint32_t *table;      /* nbricks entries: 0 empty, else 1 + index into bricks */
    float **bricks;       /* occupied bricks, VOL_BRICK_VOXELS floats each */
    uint32_t count, cap;  /* occupied bricks, capacity of bricks[] */
    float *majorant;      /* nbricks entries after finalize */
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
    int identity;             /* rotation is the identity (fast path) */
    uint64_t memory;          /* bytes held */
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

/* Density of voxel (i, j, k) of field f; 0 for empty bricks. Indices must be in range. */
static inline float vol_voxel(const atmos_volume *v, const vol_field *f, int i, int j, int k)
{
    uint32_t s = f->table[vol_brick_index(v, i, j, k)];
    return s ? f->bricks[s - 1][vol_in_brick(i, j, k)] : 0.0f;
}

/* World -> continuous index coordinates (voxel (i,j,k) covers [i, i+1) etc.). */
void atmos__volume_world_to_index(const atmos_volume *v, const double p[3], double q[3]);
/* Direction world -> index space (no translation). */
void atmos__volume_dir_to_index(const atmos_volume *v, const double d[3], double q[3]);
/* Optical depth with empty-space skipping on (skip != 0) or off, for tests. */
double atmos__volume_optical_depth_ex(const atmos_volume *vol, const double *sigma_ext, const double o[3],
                                      const double d[3], double t0, double t1, int skip);
/* Bytes the volume may still allocate. */
int atmos__volume_can_alloc(const atmos_volume *v, uint64_t bytes);

#endif
