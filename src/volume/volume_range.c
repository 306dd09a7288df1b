/* The per-brick bounds of the interpolant, built once at finalize (volume_grid.h,
 * volume_access.h: atmos__vol_range).
 *
 * Inside brick c (voxels 8c .. 8c+7 per axis) the trilinear interpolant is a convex
 * combination of voxels whose index lies in [8c - 1, 8c + 8] (the one-voxel ring: a point
 * within half a voxel of the brick's face reads the neighbour's face voxel), clamped to
 * the grid like the sampler's indices. The minimum and maximum of those voxels therefore
 * bound it everywhere in the brick. The maximum is the majorant of delta and ratio
 * tracking and of empty-space skipping (Riley et al. 2004 §3.2); the minimum is the
 * control of residual ratio tracking (Novák et al. 2014). Only positions within one brick
 * of an occupied brick can have a nonzero range, so only those are scanned and stored.
 */
#include "volume/volume_access.h"

#include <stdlib.h>
#include <string.h>

/* Minimum and maximum of field fl's voxels over the region of brick c. Empty bricks of the
 * region count as zeros. */
static void region_range(const atmos_volume *v, const vol_field *fl, const int c[3], float *mn_out, float *mx_out)
{
    int lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = c[a] * VOL_BRICK - 1;
        hi[a] = c[a] * VOL_BRICK + VOL_BRICK;
        if (lo[a] < 0) lo[a] = 0;
        if (hi[a] > v->desc.dims[a] - 1) hi[a] = v->desc.dims[a] - 1;
    }
    float mn = INFINITY, mx = 0;
    for (int bz = lo[2] >> VOL_BRICK_LOG2; bz <= hi[2] >> VOL_BRICK_LOG2; bz++)
        for (int by = lo[1] >> VOL_BRICK_LOG2; by <= hi[1] >> VOL_BRICK_LOG2; by++)
            for (int bx = lo[0] >> VOL_BRICK_LOG2; bx <= hi[0] >> VOL_BRICK_LOG2; bx++) {
                const int b[3] = {bx, by, bz};
                int s0[3], s1[3]; /* the part of the region inside this brick */
                for (int a = 0; a < 3; a++) {
                    s0[a] = b[a] * VOL_BRICK > lo[a] ? b[a] * VOL_BRICK : lo[a];
                    s1[a] = b[a] * VOL_BRICK + VOL_BRICK - 1 < hi[a] ? b[a] * VOL_BRICK + VOL_BRICK - 1 : hi[a];
                }
                const uint32_t s = fl->table[vol_brick_index(v, s0[0], s0[1], s0[2])];
                if (!s) {
                    mn = 0;
                    continue;
                }
                const float *p = vol_brick_data(v, s);
                for (int k = s0[2]; k <= s1[2]; k++)
                    for (int j = s0[1]; j <= s1[1]; j++)
                        for (int i = s0[0]; i <= s1[0]; i++) {
                            const float val = p[vol_in_brick(i, j, k)];
                            if (val > mx) mx = val;
                            if (val < mn) mn = val;
                        }
            }
    *mx_out = mx;
    *mn_out = mn > 0 ? mn : 0.0f;
}

static void grow_box(int lo[3], int hi[3], const int c[3])
{
    for (int a = 0; a < 3; a++) {
        if (c[a] < lo[a]) lo[a] = c[a];
        if (c[a] > hi[a]) hi[a] = c[a];
    }
}

static void empty_box(int lo[3], int hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = INT32_MAX;
        hi[a] = -1;
    }
}

static void brick_coords(const atmos_volume *v, uint64_t b, int c[3])
{
    c[0] = (int)(b % (uint64_t)v->nb[0]);
    c[1] = (int)((b / (uint64_t)v->nb[0]) % (uint64_t)v->nb[1]);
    c[2] = (int)(b / ((uint64_t)v->nb[0] * (uint64_t)v->nb[1]));
}

/* Marks (cell = 1) the positions within one brick of an occupied brick of any field and
 * records the occupied box; returns how many are marked. */
static uint64_t mark_reached(atmos_volume *v)
{
    uint64_t marked = 0;
    empty_box(v->occ_lo, v->occ_hi);
    for (uint64_t b = 0; b < v->nbricks; b++) {
        int occ = 0;
        for (int f = 0; f < v->nfields && !occ; f++) occ = v->field[f].table[b] != 0;
        if (!occ) continue;
        int c[3];
        brick_coords(v, b, c);
        grow_box(v->occ_lo, v->occ_hi, c);
        for (int z = c[2] > 0 ? c[2] - 1 : 0; z <= c[2] + 1 && z < v->nb[2]; z++)
            for (int y = c[1] > 0 ? c[1] - 1 : 0; y <= c[1] + 1 && y < v->nb[1]; y++)
                for (int x = c[0] > 0 ? c[0] - 1 : 0; x <= c[0] + 1 && x < v->nb[0]; x++) {
                    uint32_t *m = &v->cell[((uint64_t)z * v->nb[1] + y) * v->nb[0] + x];
                    if (!*m) marked++;
                    *m = 1;
                }
    }
    return marked;
}

atmos_status atmos__volume_build_ranges(atmos_context *ctx, atmos_volume *v)
{
    const size_t nf = (size_t)v->nfields, pair = 2 * nf * sizeof(float);
    free(v->cell); /* a finalize that failed earlier */
    free(v->range);
    v->cell = NULL, v->range = NULL;
    uint64_t bytes = v->nbricks * sizeof(uint32_t);
    if (!atmos__volume_can_alloc(v, bytes)) return atmos__volume_limit_error(ctx, v, "the index of per-brick bounds", bytes);
    v->cell = calloc((size_t)v->nbricks, sizeof(uint32_t));
    if (!v->cell) return atmos__error(ctx, ATMOS_E_NOMEM, "volume: out of memory for the per-brick bounds");
    v->memory += bytes;
    const uint64_t marked = mark_reached(v);
    if (marked >= UINT32_MAX) return atmos__error(ctx, ATMOS_E_LIMIT, "volume: too many bricks for 32-bit bounds");
    uint64_t rbytes = (marked + 1) * pair;
    if (!atmos__volume_can_alloc(v, rbytes)) return atmos__volume_limit_error(ctx, v, "the table of per-brick bounds", rbytes);
    v->range = calloc((size_t)(marked + 1), pair ? pair : 1);
    if (!v->range) return atmos__error(ctx, ATMOS_E_NOMEM, "volume: out of memory for the per-brick bounds");
    v->memory += rbytes;
    /* Range 0 stays all zero; positions whose every maximum is 0 point at it. */
    uint32_t r = 1;
    empty_box(v->rng_lo, v->rng_hi);
    for (uint64_t b = 0; b < v->nbricks; b++) {
        if (!v->cell[b]) continue;
        int c[3], any = 0;
        brick_coords(v, b, c);
        float *dst = v->range + (size_t)r * 2 * nf;
        for (size_t f = 0; f < nf; f++) {
            region_range(v, &v->field[f], c, &dst[2 * f], &dst[2 * f + 1]);
            any |= dst[2 * f + 1] > 0;
        }
        v->cell[b] = any ? r : 0;
        if (!any) continue;
        grow_box(v->rng_lo, v->rng_hi, c);
        r++;
    }
    /* Give back what the all-zero positions did not use. */
    if (r < marked + 1 && pair) {
        float *shrunk = realloc(v->range, (size_t)r * pair);
        if (shrunk) {
            v->range = shrunk;
            v->memory -= (marked + 1 - r) * pair;
        }
    }
    v->nrange = r;
    return ATMOS_OK;
}
