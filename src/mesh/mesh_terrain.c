/* Terrain (atmos_mesh_terrain, include/atmos/mesh.h): a height map, read from a raster file
 * (mesh_gdal.c) or generated here as a ridged fractal, turned into a grid of triangles. */
#include "mesh/mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_MAX_TRIANGLES 1000000L
#define DEFAULT_SAMPLES 257
#define RIDGE_OCTAVES 7

/* A number in [0, 1) for a lattice point of one octave (splitmix64's finaliser). */
static double lattice(uint64_t seed, int octave, long ix, long iz)
{
    uint64_t z = seed + 0x9E3779B97F4A7C15ull * (uint64_t)(octave + 1) + 0xBF58476D1CE4E5B9ull * (uint64_t)ix +
                 0x94D049BB133111EBull * (uint64_t)iz;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) / 9007199254740992.0;
}

/* Value noise of one octave at (x, z) in lattice cells: smooth between the four corners. */
static double value_noise(uint64_t seed, int octave, double x, double z)
{
    const double fx = floor(x), fz = floor(z), ax = x - fx, az = z - fz;
    const double sx = ax * ax * (3 - 2 * ax), sz = az * az * (3 - 2 * az);
    const long ix = (long)fx, iz = (long)fz;
    const double a = lattice(seed, octave, ix, iz), b = lattice(seed, octave, ix + 1, iz);
    const double c = lattice(seed, octave, ix, iz + 1), d = lattice(seed, octave, ix + 1, iz + 1);
    return (a + (b - a) * sx) * (1 - sz) + (c + (d - c) * sx) * sz;
}

/* Ridged multifractal heights (Musgrave's construction: ridges 1 - |2n - 1| squared, each
 * octave weighted by the one before), n x n samples over 4 cells of the first octave. */
static atmos_status generate_ridges(atmos_context *ctx, int n, uint64_t seed, atmos__heights *out)
{
    out->nx = out->nz = n;
    if (!(out->h = malloc(sizeof(double) * (size_t)n * n))) return atmos__error(ctx, ATMOS_E_NOMEM, "terrain: out of memory");
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double x = 4.0 * i / (n - 1), z = 4.0 * j / (n - 1), sum = 0, weight = 1, amp = 1;
            for (int o = 0; o < RIDGE_OCTAVES; o++) {
                double r = 1 - fabs(2 * value_noise(seed, o, x, z) - 1);
                r *= r * weight;
                sum += r * amp;
                weight = fmin(1, 2 * r);
                amp *= 0.5, x *= 2.03, z *= 2.03;
            }
            out->h[(size_t)j * n + i] = sum;
        }
    return ATMOS_OK;
}

/* A block city: n x n samples in blocks of CITY_BLOCK samples, each block's inner part a
 * building of a random height in [0.15, 1] (a few in five tall), a street of CITY_STREET
 * samples at height 0 round it; walls lean over one sample. */
#define CITY_BLOCK 12
#define CITY_STREET 3
static atmos_status generate_city(atmos_context *ctx, int n, uint64_t seed, atmos__heights *out)
{
    out->nx = out->nz = n;
    if (!(out->h = malloc(sizeof(double) * (size_t)n * n))) return atmos__error(ctx, ATMOS_E_NOMEM, "terrain: out of memory");
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            const int bi = i / CITY_BLOCK, bj = j / CITY_BLOCK, li = i % CITY_BLOCK, lj = j % CITY_BLOCK;
            const int lot = (li >= CITY_STREET) + (li >= CITY_BLOCK / 2 + 1); /* two lots a block each way */
            const int lotj = (lj >= CITY_STREET) + (lj >= CITY_BLOCK / 2 + 1);
            double h = 0;
            if (li >= CITY_STREET && lj >= CITY_STREET && i < n - 1 && j < n - 1) {
                const double r = lattice(seed, 99, 4L * bi + lot, 4L * bj + lotj);
                h = r < 0.8 ? 0.15 + 0.35 * r / 0.8 : 0.5 + 2.5 * (r - 0.8);
            }
            out->h[(size_t)j * n + i] = h;
        }
    return ATMOS_OK;
}

/* The grid as triangles facing +y: cell (i, j) is (a, c, b) and (b, c, d). */
static atmos_status grid_mesh(atmos_context *ctx, const atmos__heights *g, double cell, atmos_mesh **out)
{
    const long nv = (long)g->nx * g->nz, nt = 2L * (g->nx - 1) * (g->nz - 1);
    atmos_status st = atmos__mesh_alloc(ctx, nv, nt, 0, out);
    if (st != ATMOS_OK) return st;
    atmos_mesh *m = *out;
    const double x0 = -0.5 * cell * (g->nx - 1), z0 = -0.5 * cell * (g->nz - 1);
    for (int j = 0; j < g->nz; j++)
        for (int i = 0; i < g->nx; i++) {
            float *p = m->positions + 3 * ((size_t)j * g->nx + i);
            p[0] = (float)(x0 + i * cell), p[1] = (float)g->h[(size_t)j * g->nx + i], p[2] = (float)(z0 + j * cell);
        }
    uint32_t *t = m->indices;
    for (int j = 0; j + 1 < g->nz; j++)
        for (int i = 0; i + 1 < g->nx; i++) {
            const uint32_t a = (uint32_t)(j * g->nx + i), b = a + 1, c = a + (uint32_t)g->nx, d = c + 1;
            t[0] = a, t[1] = c, t[2] = b, t[3] = b, t[4] = c, t[5] = d;
            t += 6;
        }
    return atmos_mesh_finish(ctx, m);
}

/* Heights to metres: normalised to [0, height_m], or scaled. */
static atmos_status scale_heights(atmos_context *ctx, const atmos_terrain_desc *d, atmos__heights *g)
{
    const size_t n = (size_t)g->nx * g->nz;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) lo = fmin(lo, g->h[i]), hi = fmax(hi, g->h[i]);
    if (d->height_m > 0) {
        if (!(hi > lo))
            return atmos__error(ctx, ATMOS_E_FORMAT, "terrain %s: the height map is flat (every value %g): nothing to "
                                "normalise to height_m", d->source, lo);
        for (size_t i = 0; i < n; i++) g->h[i] = (g->h[i] - lo) / (hi - lo) * d->height_m;
    } else {
        const double s = d->height_scale != 0 ? d->height_scale : 1;
        for (size_t i = 0; i < n; i++)
            if (!(fabs(g->h[i] *= s) <= 1e8)) /* a mesh's bound: said of the height map, not of a vertex */
                return atmos__error(ctx, ATMOS_E_FORMAT, "terrain %s: the height %g m at sample (%zu, %zu) of its grid "
                                    "(the value times height_scale %g) is beyond 1e8 m: set height_m, or a smaller "
                                    "height_scale", d->source, g->h[i], i % (size_t)g->nx, i / (size_t)g->nx, s);
    }
    return ATMOS_OK;
}

atmos_status atmos_mesh_terrain(atmos_context *ctx, const atmos_terrain_desc *d, atmos_mesh **out)
{
    if (!d || !out || !d->source) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "terrain: missing description or output");
    *out = NULL;
    if (!(d->size_m > 0 && d->size_m <= 1e7) || !(d->height_m >= 0 && d->height_m <= 1e5) ||
        !isfinite(d->height_scale) || fabs(d->height_scale) > 1e5 || d->stride < 0 || d->max_triangles < 0 ||
        d->samples < 0 || d->samples == 1 || d->samples > 4097)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "terrain %s: size_m must be in (0, 1e7], height_m in [0, 1e5], "
                            "|height_scale| at most 1e5, samples 0 or in [2, 4097], stride and max_triangles not negative",
                            d->source);
    const long max_t = d->max_triangles ? (d->max_triangles > ATMOS_MESH_MAX_TRIANGLES ? ATMOS_MESH_MAX_TRIANGLES
                                                                                     : d->max_triangles)
                                        : DEFAULT_MAX_TRIANGLES;
    atmos__heights g = {0, 0, NULL};
    atmos_status st;
    if (!strncmp(d->source, "generate:", 9)) {
        const int city = !strcmp(d->source + 9, "city");
        if (!city && strcmp(d->source + 9, "ridges"))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "terrain %s: unknown generator (known: generate:ridges, "
                                "generate:city)", d->source);
        if (!(d->height_m > 0))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "terrain %s: a generated terrain needs height_m > 0", d->source);
        const int n = d->samples ? d->samples : DEFAULT_SAMPLES;
        if (2L * (n - 1) * (n - 1) > max_t)
            return atmos__error(ctx, ATMOS_E_LIMIT, "terrain %s: %d x %d samples make %ld triangles, more than %ld",
                                d->source, n, n, 2L * (n - 1) * (n - 1), max_t);
        st = city ? generate_city(ctx, n, d->seed, &g) : generate_ridges(ctx, n, d->seed, &g);
    } else
        st = atmos__terrain_read(ctx, d->source, d->stride, max_t, &g);
    if (st == ATMOS_OK) st = scale_heights(ctx, d, &g);
    if (st == ATMOS_OK) st = grid_mesh(ctx, &g, d->size_m / (g.nx - 1), out);
    free(g.h);
    return st;
}
