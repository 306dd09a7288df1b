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

/* Trilinear densities of all fields at render-voxel coordinate (u, v, w). Returns 0
 * if the point is outside the grid or in an empty occupancy block (dens untouched). */
static inline int sgrid_sample_u(const sgrid *g, float u, float v, float w, float *dens)
{
    if (!(u >= 0.0f && v >= 0.0f && w >= 0.0f)) return 0;
    int i = (int)u, j = (int)v, k = (int)w;
    if (i > g->c[0] - 2 || j > g->c[1] - 2 || k > g->c[2] - 2) return 0;
    if (!g->occ[((size_t)(k / SLICE_OCC_B) * g->ob[1] + j / SLICE_OCC_B) * g->ob[0] + i / SLICE_OCC_B]) return 0;
    float fu = u - i, fv = v - j, fw = w - k;
    const int nf = g->nf;
    const size_t sx = (size_t)nf, sy = (size_t)g->c[0] * nf, sz = (size_t)g->c[0] * g->c[1] * nf;
    const float *p = g->v + (((size_t)k * g->c[1] + j) * g->c[0] + i) * nf;
    float w000 = (1 - fu) * (1 - fv) * (1 - fw), w100 = fu * (1 - fv) * (1 - fw), w010 = (1 - fu) * fv * (1 - fw),
          w110 = fu * fv * (1 - fw), w001 = (1 - fu) * (1 - fv) * fw, w101 = fu * (1 - fv) * fw,
          w011 = (1 - fu) * fv * fw, w111 = fu * fv * fw;
    for (int f = 0; f < nf; f++)
        dens[f] = w000 * p[f] + w100 * p[sx + f] + w010 * p[sy + f] + w110 * p[sx + sy + f] + w001 * p[sz + f] +
                  w101 * p[sx + sz + f] + w011 * p[sy + sz + f] + w111 * p[sx + sy + sz + f];
    return 1;
}

#endif
