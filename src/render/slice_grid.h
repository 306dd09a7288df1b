/* The slice renderer's render grid (slice_grid.c). Not part of the API. */
#ifndef ATMOS_RENDER_SLICE_GRID_H
#define ATMOS_RENDER_SLICE_GRID_H

#include "core/internal.h"

#include <stdint.h>

#define SLICE_OCC_B 4          /* occupancy block edge, render-grid voxels */

/* The volume box-filtered onto a dense grid (integer factor f native voxels per
 * render voxel), fields interleaved per voxel, with one empty voxel of padding on
 * every side so that the trilinear interpolant falls to zero at the edges, and a
 * coarse occupancy grid (Riley §3.2's majorant idea: blocks that are exactly empty
 * are skipped without interpolating). */
typedef struct {
    int nf;
    int c[3];             /* render voxels per axis, padding included */
    float *v;             /* c0*c1*c2*nf */
    int ob[3];
    int32_t *occ;         /* ob0*ob1*ob2, 1 = occupied (32-bit: the passes gather it) */
    float sc, off[3];     /* u = g * sc + off: grid-frame metres -> render-voxel coordinate */
    double box_lo[3], box_hi[3]; /* grid-frame metres where the interpolant may be nonzero */
} sgrid;

/* Box-filters the volume (densities times scale) onto a grid of at most cap voxels per
 * axis (padding included). An empty volume leaves g->v NULL. */
atmos_status atmos__sgrid_build(atmos_context *ctx, const atmos_volume *vol, double scale, int cap, sgrid *g);
void atmos__sgrid_free(sgrid *g);

#endif
