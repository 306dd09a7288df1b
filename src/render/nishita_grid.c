/* The Nishita renderer's trilinear look-up on its render grid (nishita_internal.h,
 * atmos__nishita_grid_at): m values a grid point, read at grid coordinates (u, v, w) clamped to
 * the grid; used by the eye rays (nishita_render.c) and the air's shadow (nishita_air.c). */
#include "render/nishita_internal.h"

#include <stddef.h>

void atmos__nishita_grid_at(const sgrid *g, const float *arr, int m, double u, double v, double w, float *out)
{
    const double x[3] = {u, v, w};
    int i[3];
    double f[3];
    for (int a = 0; a < 3; a++) {
        double y = x[a] < 0 ? 0 : (x[a] > g->c[a] - 1 ? g->c[a] - 1 : x[a]);
        i[a] = (int)y;
        if (i[a] > g->c[a] - 2) i[a] = g->c[a] - 2;
        f[a] = y - i[a];
    }
    const size_t sx = (size_t)m, sy = (size_t)g->c[0] * m, sz = (size_t)g->c[0] * g->c[1] * m;
    const float *p = arr + (((size_t)i[2] * g->c[1] + i[1]) * g->c[0] + i[0]) * m;
    for (int q = 0; q < m; q++) {
        const double a00 = p[q] + f[0] * (p[sx + q] - p[q]), a10 = p[sy + q] + f[0] * (p[sx + sy + q] - p[sy + q]),
                     a01 = p[sz + q] + f[0] * (p[sx + sz + q] - p[sz + q]),
                     a11 = p[sy + sz + q] + f[0] * (p[sx + sy + sz + q] - p[sy + sz + q]);
        const double b0 = a00 + f[1] * (a10 - a00), b1 = a01 + f[1] * (a11 - a01);
        out[q] = (float)(b0 + f[2] * (b1 - b0));
    }
}
