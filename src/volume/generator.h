/* Internals of the cloud generators (generate*.c, metaballs.c, marching_cubes.c,
 * noise.c). All randomness comes from one explicitly seeded generator and all
 * parallel loops write disjoint voxels in a fixed order, so a preset gives the same
 * voxels for a seed whatever the thread count. */
#ifndef ATMOS_GENERATOR_H
#define ATMOS_GENERATOR_H

#include "atmos/atmos.h"
#include "core/rng.h"

#include <stdint.h>

/* splitmix64 (Steele, Lea & Flood 2014): a tiny generator with good statistics,
 * enough for placing balls. */
typedef struct {
    uint64_t s;
} gen_rng;

/* Uniform in [0, 1). */
static inline double gen_u01(gen_rng *r) { return atmos__u01(atmos__splitmix64(&r->s)); }
static inline double gen_range(gen_rng *r, double lo, double hi) { return lo + (hi - lo) * gen_u01(r); }

/* A dense scalar work grid in world space: value at voxel centre
 * origin + (i+0.5, j+0.5, k+0.5) * voxel, x fastest. */
typedef struct {
    int n[3];
    double voxel, origin[3];
    float *v;
} gen_grid;

/* One metaball (Nishita et al. 1996 §4): centre, radius R, weight w (the density
 * at the centre), and a vertical squash (1 = sphere, > 1 = oblate: the vertical
 * distance counts squash times). */
typedef struct {
    double c[3], r, w, squash;
} gen_ball;

typedef struct {
    gen_ball *b;
    int n, cap;
} gen_balls;

int atmos__gen_balls_add(gen_balls *bl, double x, double y, double z, double r, double w, double squash);
void atmos__gen_balls_free(gen_balls *bl);

/* The degree-6 falloff of Wyvill's soft objects used by Nishita et al. for their
 * metaballs: f(s) = 1 - 4/9 s^6 + 17/9 s^4 - 22/9 s^2 for s = r/R <= 1, else 0.
 * f(0) = 1, f(1) = 0, f'(0) = f'(1) = 0 (smooth joins). */
static inline double atmos__wyvill(double s2)
{
    if (s2 >= 1) return 0;
    double s4 = s2 * s2;
    return 1 - (4.0 / 9.0) * s4 * s2 + (17.0 / 9.0) * s4 - (22.0 / 9.0) * s2;
}

/* Adds balls[first..n) to the grid: v += w f(|x - c| / R). Parallel over z planes. */
void atmos__gen_accumulate(gen_grid *g, const gen_balls *bl, int first, int threads);

/* Isosurface triangles: 3 vertices and the outward unit normal (-grad F). */
typedef struct {
    float p[3][3];
    float n[3];
    float area;
} gen_tri;

typedef struct {
    gen_tri *t;
    size_t n, cap;
} gen_mesh;

/* Marching cubes on the grid sampled every `stride` voxels at level iso; voxels
 * with j < floor_j count as 0 (a cut at the cloud base). Stops at max_tris.
 * Returns 0 on allocation failure. */
int atmos__gen_marching_cubes(const gen_grid *g, int stride, float iso, int floor_j, size_t max_tris, gen_mesh *out);

/* Fractal refinement (Nishita et al. 1996 §4): levels rounds of "extract the
 * isosurface, place smaller balls on its triangles", radius r0 * ratio^level.
 * Downward-facing triangles (normal y < -0.25) get no new balls, sideways ones
 * (-0.25..0.15) a third of them, so bases stay flat and tops grow bumpy. */
typedef struct {
    int levels;
    double r0, ratio;   /* first new radius (m) and the factor per level */
    double coverage;    /* new balls per level ~ coverage * area / (pi r^2) */
    float iso;
    int floor_j;
    int max_balls;      /* per level */
    int fringe;         /* shrink radii away from the centre (one cloud) */
    const atmos_context *ctx; /* progress "volume generate" from 0.1 to 0.9 over the levels */
} gen_refine;
int atmos__gen_refine(gen_grid *g, gen_balls *bl, const gen_refine *p, gen_rng *rng, int threads);

/* Value noise with quintic interpolation on a hashed integer lattice, and its
 * fractal sum over octaves (each octave: frequency x2, amplitude x gain). In [0, 1]. */
double atmos__gen_noise3(uint64_t seed, double x, double y, double z);
double atmos__gen_fbm3(uint64_t seed, double x, double y, double z, int octaves, double gain);

/* A fractal outline (generate_footprint.c): phi = e + rough SIGMA (N - 1/2) - T at (u, v), the
 * point in units of the cloud's width, e its smooth envelope there (1 at the centre, 0 at the
 * nominal rim), N fractional Brownian noise of Hurst exponent 0.15 over `octaves` octaves from
 * one width down (atmos__gen_fractal_octaves: to half of `finest`). The cloud is where phi >= 0;
 * with rough = 1 the cumulus field's outlines have a perimeter-area dimension of 1.34, near the
 * observed 1.35 (docs/clouds.md); less roughness leaves more of the smooth envelope. */
double atmos__gen_fractal_phi(uint64_t seed, double u, double v, double e, int octaves, double rough);
int atmos__gen_fractal_octaves(double width, double finest);

/* Cellular noise in the plane (noise_cells.c): one feature point per unit cell, jittered by
 * `jitter` (0..1) of the cell; f1, f2 the distances to the nearest two, id a hash of the
 * nearest one's cell (for per-cell random values). */
typedef struct {
    double f1, f2;
    uint64_t id;
} gen_cell;
void atmos__gen_cells2(uint64_t seed, double x, double z, double jitter, gen_cell *out);

#endif
