/* The min/max pyramid of a beam renderer's depth map (the spotlights' faces, beams_shadow.c,
 * and the sun's orthographic map, beams_sun.c): per tile of ATMOS__BEAMS_TILE x
 * ATMOS__BEAMS_TILE texels, the least and the greatest depth over the tile and a ring of one
 * texel around it (what a 2x2 filtered look-up in the tile may read), then the same over 2x2,
 * 4x4, ... tiles up to the whole map. A point nearer than the least depth of its tile is lit,
 * one at or beyond the greatest in shadow, without reading the map; a segment whose depths
 * lie all below (or all beyond) the bounds of every tile it crosses is lit (or dark) all
 * along. Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_TILES_H
#define ATMOS_RENDER_BEAMS_TILES_H

#include <stddef.h>

#define ATMOS__BEAMS_TILE 8

typedef struct atmos__beams_tiles {
    int tiles, levels;       /* tiles a side at level 0; levels down to one cell */
    int level_n[24];         /* level k: level_n[k] cells a side at offset level_at[k] */
    size_t level_at[24];
    float *min, *max;        /* every level's cells, one allocation (min) */
} atmos__beams_tiles;

/* The pyramid of the n x n map depth; 0, or -1 out of memory (t then empty). */
int atmos__beams_tiles_build(atmos__beams_tiles *t, const float *depth, int n);
void atmos__beams_tiles_free(atmos__beams_tiles *t);
/* The tile of the texel x, y (a look-up's floor; -1 is clamped to 0) at level 0. */
static inline int atmos__beams_tiles_at(const atmos__beams_tiles *t, int x, int y)
{
    return (y < 0 ? 0 : y / ATMOS__BEAMS_TILE) * t->tiles + (x < 0 ? 0 : x / ATMOS__BEAMS_TILE);
}
/* The least and greatest depth over the tiles of the texels [x0, x1] x [y0, y1] (floors of
 * look-up coordinates, each >= -1 and < n), read at the finest level where they span at most
 * 2 x 2 cells. */
void atmos__beams_tiles_range(const atmos__beams_tiles *t, int x0, int x1, int y0, int y1, float *lo, float *hi);

#endif
