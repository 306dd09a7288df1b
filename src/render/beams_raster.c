/* The depth maps' triangle rasteriser (beams_raster.h): barycentric coverage of texel
 * centres over the triangle's bounding box. */
#include "render/beams_raster.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

void atmos__beams_raster(float *depth, int n, const double x[3], const double y[3], const double z[3], int perspective)
{
    atmos__beams_raster_rows(depth, n, x, y, z, perspective, 0, n - 1);
}

void atmos__beams_raster_rows(float *depth, int n, const double x[3], const double y[3], const double z[3],
                              int perspective, int row0, int row1)
{
    const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if (area == 0 || !isfinite(area)) return;
    /* the bounding box within the map, clamped before the conversion to int (a vertex near a
     * light's plane projects far out); a box beside the map costs nothing, not a pass over
     * its rows (most of a city's triangles lie outside a narrow spot's map) */
    const double bx0 = fmax(0, floor(fmin(x[0], fmin(x[1], x[2])))), bx1 = fmin(n - 1, ceil(fmax(x[0], fmax(x[1], x[2]))));
    const double by0 = fmax(row0, floor(fmin(y[0], fmin(y[1], y[2])))), by1 = fmin(row1, ceil(fmax(y[0], fmax(y[1], y[2]))));
    if (!(bx0 <= bx1 && by0 <= by1)) return;
    const int x0 = (int)bx0, x1 = (int)bx1, y0 = (int)by0, y1 = (int)by1;
    for (int py = y0; py <= y1; py++)
        for (int px = x0; px <= x1; px++) {
            const double cx = px + 0.5, cy = py + 0.5;
            double b[3];
            for (int k = 0; k < 3; k++) {
                const int i = (k + 1) % 3, j = (k + 2) % 3;
                b[k] = ((x[j] - x[i]) * (cy - y[i]) - (y[j] - y[i]) * (cx - x[i])) / area;
            }
            if (b[0] < 0 || b[1] < 0 || b[2] < 0) continue;
            const double w = b[0] * z[0] + b[1] * z[1] + b[2] * z[2];
            const float d = (float)(perspective ? 1.0 / w : w);
            float *t = depth + (size_t)py * n + px;
            if (d < *t) *t = d;
        }
}

int atmos__beams_clip_near(const double in[3][3], double near, double poly[4][3])
{
    int m = 0;
    for (int k = 0; k < 3; k++) {
        const double *a = in[k], *b = in[(k + 1) % 3];
        const int ia = a[2] >= near, ib = b[2] >= near;
        if (ia) memcpy(poly[m++], a, sizeof poly[0]);
        if (ia != ib) {
            const double s = (near - a[2]) / (b[2] - a[2]);
            for (int c = 0; c < 3; c++) poly[m][c] = a[c] + s * (b[c] - a[c]);
            poly[m++][2] = near;
        }
    }
    return m;
}
