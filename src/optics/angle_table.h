/* Tables over the scattering angle: the grids they are tabulated on, the one reader that
 * finds an angle's interval on a grid, and the density over the sphere that a tabulated
 * phase function is sampled from (so that its pdf and its evaluation are one function).
 *
 * The reader is the uniform-bin lookup of Cycles' lookup tables (Blender, intern/cycles,
 * lookup_table_read): a table of 0.05° bins gives, in O(1), the few grid intervals an
 * angle can fall in, and a bisection over those (one or two steps where the grid is 0.05°
 * or coarser, at most seven in the 0.0005° steps near the forward direction) picks the
 * interval. Every reader of an angle table in the library goes through it: phase table
 * evaluation and sampling (phase_table.c), Ams_n lookups (msphase.c), the path tracer's
 * phase functions (render/path_phase.c) and the slice renderer's per-pixel angle
 * (render/slice_tables.c). Not part of the API.
 */
#ifndef ATMOS_OPTICS_ANGLE_TABLE_H
#define ATMOS_OPTICS_ANGLE_TABLE_H

#include "atmos/atmos.h"

#include <stdint.h>

#define ATMOS__ANGLE_MAX 6000          /* angles a grid may hold */
#define ATMOS__ANGLE_BINS_PER_DEG 20.0 /* lookup bins of 0.05° */
#define ATMOS__ANGLE_LUT (180 * 20 + 2)

/* A grid of scattering angles from 0° to 180°, strictly increasing, with its radians, sines
 * and lookup table. Built once (atmos__angle_grid_init), then read-only: any number of
 * threads may read it. */
typedef struct atmos__angle_grid {
    int n;                              /* angles */
    double deg[ATMOS__ANGLE_MAX];       /* theta_i, degrees; deg[0] = 0, deg[n-1] = 180 */
    double rad[ATMOS__ANGLE_MAX];       /* deg[i] * ATMOS_DEG2RAD */
    double sin[ATMOS__ANGLE_MAX];       /* sin(rad[i]) */
    uint16_t lut[ATMOS__ANGLE_LUT];     /* lut[j]: the last i whose bin is below j (0 if none) */
} atmos__angle_grid;

/* A piecewise-uniform stretch of a grid: angles from, from + step, ... up to (not
 * including) to, in degrees. */
typedef struct atmos__angle_segment {
    double from, to, step;
} atmos__angle_segment;

/* Writes the angles of the segments, then 180, to out (at most cap); returns their count,
 * 0 if cap is too small. Each angle is from + i * step, so two grids made of the same
 * segments hold the same numbers. */
int atmos__angle_segments(const atmos__angle_segment *seg, int count, double *out, int cap);

/* Fills g from n angles (copied): 0 if they are not a grid (2 <= n <= ATMOS__ANGLE_MAX,
 * finite, strictly increasing, from exactly 0 to exactly 180), else 1. */
int atmos__angle_grid_init(atmos__angle_grid *g, const double *deg, int n);

/* The two grids of the library (phase_grid.c), built on first use; see there why they
 * differ. atmos__angle_grid_known returns the one whose angles deg points to (NULL if
 * neither): the slice renderer is handed the angles alone. */
const atmos__angle_grid *atmos__phase_angle_grid(void);
const atmos__angle_grid *atmos__msphase_angle_grid(void);
const atmos__angle_grid *atmos__angle_grid_known(const double *deg, int n);

/* ---------------------------------------------------------------- the reader */

static inline int atmos__angle_bin(double theta_deg) { return (int)(theta_deg * ATMOS__ANGLE_BINS_PER_DEG); }

/* The i in [lo, hi) with a[i] <= x < a[i + 1], for a nondecreasing a with a[lo] <= x < a[hi]. */
static inline int atmos__angle_search(const double *a, int lo, int hi, double x)
{
    while (hi - lo > 1) {
        const int mid = (lo + hi) >> 1;
        if (a[mid] <= x) lo = mid;
        else hi = mid;
    }
    return lo;
}

/* The interval of theta: the i with deg[i] <= theta < deg[i + 1]; 0 at or below 0° (and
 * for NaN), n - 2 at or above 180°.
 *
 * Why the bounds hold: bin() is nondecreasing in theta (a product with a positive constant
 * and a truncation, both monotone in IEEE arithmetic), so every grid angle of a lower bin
 * than theta's lies below theta, and every one of a higher bin above it, whatever the
 * rounding of bin() at the bin edges. lut[j] is the last angle of a bin below j, and
 * lut[j + 1] + 1 the first of a bin above j. */
static inline int atmos__angle_find(const atmos__angle_grid *g, double theta_deg)
{
    if (!(theta_deg > g->deg[0])) return 0;
    if (theta_deg >= g->deg[g->n - 1]) return g->n - 2;
    const int j = atmos__angle_bin(theta_deg);
    int hi = g->lut[j + 1] + 1;
    if (hi > g->n - 1) hi = g->n - 1;
    return atmos__angle_search(g->deg, g->lut[j], hi, theta_deg);
}

/* The interval of theta and the fraction of the way through it, linear in degrees:
 * (0, 0) at or below 0° and for NaN, (n - 2, 1) at or above 180°. */
static inline int atmos__angle_lerp(const atmos__angle_grid *g, double theta_deg, double *frac)
{
    if (!(theta_deg > 0)) theta_deg = 0;
    if (theta_deg >= g->deg[g->n - 1]) {
        *frac = 1.0;
        return g->n - 2;
    }
    const int i = atmos__angle_find(g, theta_deg);
    *frac = (theta_deg - g->deg[i]) / (g->deg[i + 1] - g->deg[i]);
    return i;
}

/* ---------------------------------------------------------------- the sampled density
 *
 * A tabulated phase function is sampled (atmos__angle_cdf_find, atmos__angle_invert) with
 * the density over theta 2 pi f(theta), where f is the piecewise-linear interpolant in theta
 * of f_i = P_i sin(theta_i) / F, F = 2 pi int P sin(theta) dtheta by the trapezoid rule (the
 * rule that normalises the table), so that 2 pi int f dtheta = 1. Over solid angle that
 * density is f(theta) / sin(theta): evaluating it (rather than P interpolated linearly)
 * makes the evaluated and the sampled phase function the same, so pdf = eval and a
 * phase-sampled direction has weight exactly 1. The two differ by the interpolation error
 * only (relative O(h^2), far below 1e-4 on the grids here). */

/* Where cos(theta) falls and how f_i, f_{i+1} make the density there:
 * p = w0 f_i + w1 f_{i+1} (sr^-1 for f normalised as above). */
typedef struct atmos__angle_weights {
    int i;         /* interval */
    double s;      /* fraction of the way through it, linear in theta */
    double w0, w1; /* see atmos__angle_density_weights */
} atmos__angle_weights;

/* The weights at mu = cos(theta) (clamped to [-1, 1]; NaN counts as -1). Inside the grid
 * w0 = (1 - s) / sin(theta), w1 = s / sin(theta). In the first interval f_0 = 0 (sin 0) and
 * p = (theta / h) f_1 / sin(theta), finite as theta -> 0; in the last, f_{n-1} = P sin(pi)
 * is zero up to rounding and p = ((pi - theta) / h) f_{n-2} / sin(theta). */
void atmos__angle_density_weights(const atmos__angle_grid *g, double mu, atmos__angle_weights *a);

/* The interval of a CDF over the grid (c[0] = 0, nondecreasing, c[n-1] = 1) that holds u,
 * c[i] <= u < c[i + 1], never one of zero mass. *u is first clamped into [0, 1). */
static inline int atmos__angle_cdf_find(const double *c, int n, double *u)
{
    if (!(*u >= 0)) *u = 0;
    if (*u >= 1) *u = 0x1.fffffffffffffp-1;
    return atmos__angle_search(c, 0, n - 1, *u);
}

/* cos(theta) for u inside interval i of the CDF c, whose density over theta is linear
 * there from f0 to f1 (any common scale): the exact inverse of its quadratic integral. */
double atmos__angle_invert(const atmos__angle_grid *g, const double *c, int i, double u, double f0, double f1);

/* ---------------------------------------------------------------- phase tables */

/* F of a phase table's wavelength k (0 for a bad k): its sampled density has
 * f_i = P_i sin(theta_i) / F on atmos__phase_angle_grid(), P_i = atmos_phase_table_values.
 * F is the trapezoid integral 2 pi int P sin(theta) dtheta summed in radians interval by
 * interval, sum_i pi (P_i sin_i + P_i+1 sin_i+1) (rad_i+1 - rad_i), 1 to rounding. */
double atmos__phase_table_total(const atmos_phase_table *t, int k);

#endif
