/* The min/max pyramid of a depth map (beams_tiles.h). */
#include "render/beams_tiles.h"
#include "core/clones.h"

#include <math.h>
#include <stdlib.h>

void atmos__beams_tiles_free(atmos__beams_tiles *t)
{
    free(t->min);
    t->min = t->max = NULL, t->tiles = t->levels = t->shift = 0;
}

/* The levels' sizes and offsets; the cells of all levels. */
static size_t plan_levels(atmos__beams_tiles *t)
{
    size_t at = 0;
    int m = t->tiles, k = 0;
    for (;;) {
        t->level_n[k] = m, t->level_at[k] = at;
        at += (size_t)m * m, k++;
        if (m == 1) break;
        m = (m + 1) / 2;
    }
    t->levels = k;
    return at;
}

/* Level 0: each tile over its texels and a ring of one around. */
static void finest(atmos__beams_tiles *t, const float *depth, int n, int threads)
{
    const int T = t->tiles, TILE = 1 << t->shift;
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
    for (int ty = 0; ty < T; ty++)
        for (int tx = 0; tx < T; tx++) {
            float lo = INFINITY, hi = -INFINITY;
            for (int y = ty * TILE - 1; y <= (ty + 1) * TILE; y++) {
                const float *row = depth + (size_t)(y < 0 ? 0 : y >= n ? n - 1 : y) * n;
                for (int x = tx * TILE - 1; x <= (tx + 1) * TILE; x++) {
                    const float z = row[x < 0 ? 0 : x >= n ? n - 1 : x];
                    lo = z < lo ? z : lo, hi = z > hi ? z : hi;
                }
            }
            t->min[ty * T + tx] = lo, t->max[ty * T + tx] = hi;
        }
}

int atmos__beams_tiles_build(atmos__beams_tiles *t, const float *depth, int n, int shift, int threads)
{
    t->shift = shift;
    t->tiles = (n + (1 << shift) - 1) >> shift;
    const size_t cells = plan_levels(t);
    if (!(t->min = malloc(sizeof(float) * 2 * cells))) {
        t->max = NULL, t->tiles = t->levels = 0;
        return -1;
    }
    t->max = t->min + cells;
    finest(t, depth, n, threads);
    for (int k = 1; k < t->levels; k++) {
        const int m = t->level_n[k], c = t->level_n[k - 1];
        const float *cmin = t->min + t->level_at[k - 1], *cmax = t->max + t->level_at[k - 1];
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1 && m >= 64)
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++) {
                float lo = INFINITY, hi = -INFINITY;
                for (int y = 2 * j; y < 2 * j + 2 && y < c; y++)
                    for (int x = 2 * i; x < 2 * i + 2 && x < c; x++) {
                        const float a = cmin[y * c + x], b = cmax[y * c + x];
                        lo = a < lo ? a : lo, hi = b > hi ? b : hi;
                    }
                t->min[t->level_at[k] + (size_t)j * m + i] = lo, t->max[t->level_at[k] + (size_t)j * m + i] = hi;
            }
    }
    return 0;
}

/* An AVX2 clone where the processor has it (the same comparisons: the same bounds). */
ATMOS_CLONES void atmos__beams_tiles_range(const atmos__beams_tiles *t, int x0, int x1, int y0, int y1, float *lo,
                                           float *hi)
{
    atmos__beams_tiles_range_in(t, x0, x1, y0, y1, lo, hi);
}
