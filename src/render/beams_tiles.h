/* The min/max pyramid of a beam renderer's depth map (the spotlights' faces, beams_shadow.c,
 * and the sun's orthographic map, beams_sun.c): per tile of 2^shift x 2^shift texels, the
 * least and the greatest depth over the tile and a ring of one texel around it (what a 2x2
 * filtered look-up in the tile may read), then the same over 2x2, 4x4, ... tiles up to the
 * whole map. A point nearer than the least depth of its tile is lit, one at or beyond the
 * greatest in shadow, without reading the map; a segment whose depths lie all below (or all
 * beyond) the bounds of every tile it crosses is lit (or dark) all along. Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_TILES_H
#define ATMOS_RENDER_BEAMS_TILES_H

#include "core/clones.h"

#include <math.h>
#include <stddef.h>

/* The tiles' sizes: 2 x 2 texels for the lights' faces (docs/beams.md, *Twentieth round*:
 * a point light's samples read four texels less than half as often as with 8 x 8), 8 x 8 for
 * the sun's. */
#define ATMOS__BEAMS_LIGHT_TILE_SHIFT 1
#define ATMOS__BEAMS_SUN_TILE_SHIFT 3

typedef struct atmos__beams_tiles {
    int shift;               /* a tile is 2^shift texels a side */
    int tiles, levels;       /* tiles a side at level 0; levels down to one cell */
    int level_n[24];         /* level k: level_n[k] cells a side at offset level_at[k] */
    size_t level_at[24];
    float *min, *max;        /* every level's cells, one allocation (min) */
} atmos__beams_tiles;

/* The pyramid of the n x n map depth, tiles of 2^shift texels a side, its rows of tiles on
 * up to threads threads (each cell on its own: the same bits with any number); 0, or -1 out
 * of memory (t then empty). */
int atmos__beams_tiles_build(atmos__beams_tiles *t, const float *depth, int n, int shift, int threads);
void atmos__beams_tiles_free(atmos__beams_tiles *t);
/* The tile of the texel x, y (a look-up's floor; -1 is clamped to 0) at level 0; shift the
 * pyramid's own (t->shift), given by the caller as a constant for a shift rather than a load. */
static inline int atmos__beams_tiles_at(const atmos__beams_tiles *t, int x, int y, int shift)
{
    return (y < 0 ? 0 : y >> shift) * t->tiles + (x < 0 ? 0 : x >> shift);
}
/* The least and greatest depth over the tiles of the texels [x0, x1] x [y0, y1] (floors of
 * look-up coordinates, each >= -1 and < n), read at the finest level where they span at most
 * 2 x 2 cells. */
void atmos__beams_tiles_range(const atmos__beams_tiles *t, int x0, int x1, int y0, int y1, float *lo, float *hi);
/* The same, always inlined into a cloned caller (beams_lookup.h's runs' tests: no call through
 * the clones' resolver a run). */
ATMOS_CLONE_HELPER void atmos__beams_tiles_range_in(const atmos__beams_tiles *t, int x0, int x1, int y0, int y1,
                                                    float *lo, float *hi)
{
    const int sh = t->shift, tx0 = x0 < 0 ? 0 : x0 >> sh, tx1 = x1 < 0 ? 0 : x1 >> sh, ty0 = y0 < 0 ? 0 : y0 >> sh,
              ty1 = y1 < 0 ? 0 : y1 >> sh;
    /* the finest level where the tiles' box spans at most 2 x 2 cells: none below the one where
     * the larger side d (2^(B-1) <= d < 2^B) is halved to 1, since at level k the box spans at
     * least floor(d / 2^k) + 1 cells */
    const unsigned d = (unsigned)(tx1 - tx0 > ty1 - ty0 ? tx1 - tx0 : ty1 - ty0);
    int k = d > 1 ? 31 - __builtin_clz(d) : 0;
    if (k > t->levels - 1) k = t->levels - 1;
    while (k + 1 < t->levels && ((tx1 >> k) - (tx0 >> k) > 1 || (ty1 >> k) - (ty0 >> k) > 1)) k++;
    /* at most 2 x 2 cells there: the four corners' read (a corner twice where the box is one
     * cell wide; the least and the greatest are the same whatever the order: no NaN depths) */
    const int xa = tx0 >> k, xb = tx1 >> k, ya = ty0 >> k, yb = ty1 >> k;
    if (xb < xa || yb < ya) { /* an empty box (the texels' ends out of order) */
        *lo = INFINITY, *hi = -INFINITY;
        return;
    }
    const size_t m = (size_t)t->level_n[k], ra = t->level_at[k] + ya * m, rb = t->level_at[k] + yb * m;
    const float *cmin = t->min, *cmax = t->max;
    float a = cmin[ra + xa], b = cmax[ra + xa], u, v;
    u = cmin[ra + xb], v = cmax[ra + xb], a = u < a ? u : a, b = v > b ? v : b;
    u = cmin[rb + xa], v = cmax[rb + xa], a = u < a ? u : a, b = v > b ? v : b;
    u = cmin[rb + xb], v = cmax[rb + xb], a = u < a ? u : a, b = v > b ? v : b;
    *lo = a, *hi = b;
}

/* The 2x2 filtered look-up that the tiles bound: H at depth z and texel coordinates (fx, fy) of
 * an n x n depth map, (x0, y0) = (floor(fx), floor(fy)) with fx, fy in (-1, n): the four nearest
 * comparisons, blended (the texels beyond the edge are the edge's). */
ATMOS_CLONE_HELPER double atmos__beams_depth_blend(const float *depth, int n, double fx, double fy, int x0, int y0,
                                                   double z)
{
    const double ax = fx - x0, ay = fy - y0;
    const int xa = x0 < 0 ? 0 : x0, xb = x0 + 1 > n - 1 ? n - 1 : x0 + 1;
    const int ya = y0 < 0 ? 0 : y0, yb = y0 + 1 > n - 1 ? n - 1 : y0 + 1;
    const float *ra = depth + (size_t)ya * n, *rb = depth + (size_t)yb * n;
    const double top = (1 - ax) * (z < ra[xa]) + ax * (z < ra[xb]), bottom = (1 - ax) * (z < rb[xa]) + ax * (z < rb[xb]);
    return (1 - ay) * top + ay * bottom;
}

#endif
