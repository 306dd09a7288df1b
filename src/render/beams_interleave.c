/* Interleaved sampling for the beam renderer (beams_interleave.h). The pattern: pixel (x, y)
 * takes offset index (x mod N) + N (y mod N), so any N x N window holds every offset once.
 * The filter is Keller and Heidrich's discontinuity buffer, a box of N x N centred on the pixel: a neighbour counts when it sees
 * the same object (or none) at a depth within 5 % of the pixel's; a pixel always counts
 * itself. The window's pixels outside the frame's own rectangle are held too (the rectangle
 * is widened by N - 1), so a frame split into tiles gives the image of one piece. */
#include "render/beams_interleave.h"
#include "atmos/spectrum.h"

#include <math.h>
#include <stdlib.h>

/* Depths within this share of each other are one surface (or the same open sky). */
#define SAME_DEPTH 0.05

int atmos__beams_il_init(atmos__beams_il *il, int n, int nw, const atmos__rect *r, int width, int height)
{
    il->n = n, il->nw = nw;
    il->e.x0 = r->x0 - (n - 1) < 0 ? 0 : r->x0 - (n - 1);
    il->e.y0 = r->y0 - (n - 1) < 0 ? 0 : r->y0 - (n - 1);
    il->e.x1 = r->x1 + (n - 1) > width ? width : r->x1 + (n - 1);
    il->e.y1 = r->y1 + (n - 1) > height ? height : r->y1 + (n - 1);
    const size_t count = (size_t)(il->e.x1 - il->e.x0) * (size_t)(il->e.y1 - il->e.y0);
    il->air = malloc(sizeof(float) * count * (size_t)nw);
    il->depth = malloc(sizeof(float) * count);
    il->object = malloc(sizeof(int) * count);
    if (il->air && il->depth && il->object) return 0;
    atmos__beams_il_free(il);
    return 1;
}

void atmos__beams_il_free(atmos__beams_il *il)
{
    free(il->air);
    free(il->depth);
    free(il->object);
    il->air = NULL, il->depth = NULL, il->object = NULL;
}

double atmos__beams_il_offset(int n, int x, int y)
{
    const int k = x % n + n * (y % n);
    return (k + 0.5) / ((double)n * n);
}

long atmos__beams_il_index(const atmos__beams_il *il, int x, int y)
{
    if (x < il->e.x0 || x >= il->e.x1 || y < il->e.y0 || y >= il->e.y1) return -1;
    return (long)(y - il->e.y0) * (il->e.x1 - il->e.x0) + (x - il->e.x0);
}

static inline int same_surface(const atmos__beams_il *il, long a, long b)
{
    if (il->object[a] != il->object[b]) return 0;
    const float da = il->depth[a], db = il->depth[b], big = da > db ? da : db;
    if (big == INFINITY) return da == db;
    return (da > db ? da - db : db - da) <= SAME_DEPTH * big;
}

/* The window's weight at offset i from its centre: 1 across, and for an even N a window of
 * N + 1 with halves at its ends, so it is centred and still weighs every offset index once. */
static double weight(int n, int i)
{
    return n % 2 == 0 && abs(i) == n / 2 ? 0.5 : 1.0;
}

void atmos__beams_il_add(const atmos__beams_il *il, int x, int y, float *px)
{
    const long c = atmos__beams_il_index(il, x, y), w = il->e.x1 - il->e.x0;
    const int n = il->n, r = n / 2, nw = il->nw;
    const int j0 = y - r < il->e.y0 ? il->e.y0 - y : -r, j1 = y + r >= il->e.y1 ? il->e.y1 - 1 - y : r;
    const int i0 = x - r < il->e.x0 ? il->e.x0 - x : -r, i1 = x + r >= il->e.x1 ? il->e.x1 - 1 - x : r;
    double sum[ATMOS_MAX_WAVELENGTHS], total = 0;
    for (int k = 0; k < nw; k++) sum[k] = 0;
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++) {
            const long q = c + j * w + i;
            if (!same_surface(il, c, q)) continue;
            const double wt = weight(n, i) * weight(n, j);
            const float *a = il->air + (size_t)q * nw;
            for (int k = 0; k < nw; k++) sum[k] += wt * a[k];
            total += wt;
        }
    for (int k = 0; k < nw; k++) px[k] += (float)(sum[k] / total);
}
