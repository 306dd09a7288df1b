/* Nishita, Dobashi & Nakamae 1996, "Display of clouds taking into account multiple
 * anisotropic scattering and sky light" (§3.4, §3.5): the light field of orders 2 and 3 by
 * reference patterns, and the sky's and the ground's light through sky elements, per cell of
 * a light field's grid, toward one eye direction (docs/lightfield.md, "Nishita 1996").
 *
 *   nishita_pattern.c  the reference patterns: phase-weighted form factors over a sample space
 *                      of uniform mean density, the paths kept by their contribution ratio
 *   nishita_field.c    the patterns moved over the grid (the real medium's attenuation between
 *                      the cells), the stochastic selection of order-3 paths, the solve
 *   nishita_sky.c      the sky elements: the axis and diagonal attenuation per cell, the
 *                      element of a direction
 *
 * Directions are in the field's frame (lfield.h); lengths of the patterns in cells. Not part
 * of the API. */
#ifndef ATMOS_LIGHT_NISHITA_H
#define ATMOS_LIGHT_NISHITA_H

#include "light/lfield.h"

#include <math.h>
#include <stdint.h>

#define ATMOS__NISHITA_PHASE_N 1801 /* the patterns' phase table: theta = 0, 0.1, ..., 180 degrees */
#define ATMOS__NISHITA_DIRS 14      /* sky elements around the 6 axes and the 8 diagonals */
#define ATMOS__NISHITA_ELEMENTS 15  /* and the circumsolar cone (attenuated toward the sun) */
#define ATMOS__NISHITA_AUREOLE_DEG 8.0

typedef struct {
    const atmos__lmedium *m; /* sig_t, sig_s per cell and wavelength, the cell edge h */
    double lt[3];            /* the sunlight's direction of travel (unit) */
    double ev[3];            /* the scattered light's direction of travel toward the eye (unit) */
    const double *sun;       /* the sunlight's irradiance entering the grid, per wavelength */
    const float *E;          /* [cell * n + w] or NULL: the sunlight reaching each cell (a finer grid's
                                mean over the cell weighted by the scattering); NULL: at the cell's centre,
                                marched on the field's grid */
    const float *phase;      /* ATMOS__NISHITA_PHASE_N values of the patterns' phase function, sr^-1 */
    const double *sky;       /* [element * n + w]: I_l of Eq. 7 (the element's radiance integrated with the
                                phase toward ev, W m^-2 sr^-1 nm^-1); NULL: no sky light */
    int orders;              /* the highest order kept: 1, 2 or 3 */
    double ratio;            /* r: the share of the sample space's contribution the patterns keep */
    int paths3;              /* n1: order-3 paths computed per cell */
    int radius2, radius3;    /* half-size of the sample space, cells (order 2; order 3, per leg) */
    uint64_t seed;           /* the order-3 path selection's */
    int threads;
} atmos__nishita_in;

typedef struct {
    int n2, n3;              /* paths kept in the patterns (order 3: n2 of the paper) */
    long long n3_space;      /* order-3 paths of the sample space */
    double kept2, kept3;     /* the share of the sample space's contribution they carry */
    int box2, box3;          /* the patterns' half-size (largest offset kept), cells */
    double theta_b_deg;      /* the beam spread */
    double pattern_s, sky_s, apply_s;
} atmos__nishita_stats;

/* A reference pattern (nishita_pattern.c). Order 2: entry e of o2 is a cell offset o (from the
 * cell P receiving, o = the first scattering's cell) with w2 = the phase-weighted form factor
 * int p(theta1) p(theta2) / r^2 dV / h over the cell (integrated over directions, exactly along
 * each) and r2 its weighted mean distance (cells). Order 3: offsets j (second scattering) and k
 * (first), w3 = p p p / (r1^2 r2^2) times the cells' volumes / h^2 (the phases averaged over the
 * cone a cell subtends; a leg inside one cell over its sub-voxels), r3 the two legs' lengths.
 * Sorted by contribution, largest first. */
#define ATMOS__NISHITA_SELF_N 49 /* optical depths of a cell's edge 10^(-3 + i / 8) */
typedef struct {
    int n2, n3;
    /* P's own cell, for order 2: int p p exp(-sig_t r) dV / r^2 / h over the cell at the cell
     * optical depths tau = sig_t h of ATMOS__NISHITA_SELF_N (exact along each direction: in a
     * dense cell the light scattered once reaches P from within a mean free path) */
    float self2[ATMOS__NISHITA_SELF_N];
    int16_t *o2; /* 3 per entry */
    float *w2, *r2;
    int16_t *o3; /* 6 per entry: j, k */
    float *w3, *r3; /* r3: 2 per entry */
    double kept2, kept3;
    long long space3;
    int box2, box3;
    double theta_b_deg;
} atmos__nishita_pattern;

/* The pattern for directions lt, ev in a medium of uniform extinction sig_t and scattering
 * sig_s (m^-1, cell edge h). Returns 0 when out of memory. */
int atmos__nishita_pattern_build(const atmos__nishita_in *in, double sig_t, double sig_s, atmos__nishita_pattern *p);
void atmos__nishita_pattern_free(atmos__nishita_pattern *p);

/* Order 2's weight of P's own cell at cell optical depth tau (log-linear in tau). */
static inline double atmos__nishita_self2(const atmos__nishita_pattern *p, double tau)
{
    double x = (log10(tau > 1e-3 ? tau : 1e-3) + 3.0) * 8.0;
    if (x > ATMOS__NISHITA_SELF_N - 1.001) x = ATMOS__NISHITA_SELF_N - 1.001;
    const int i = (int)x;
    return p->self2[i] + (x - i) * (p->self2[i + 1] - p->self2[i]);
}

/* The patterns' phase function at cos(theta) (linear in theta). */
static inline double atmos__nishita_phase(const float *ph, double mu)
{
    mu = mu > 1.0 ? 1.0 : (mu < -1.0 ? -1.0 : mu);
    const double x = acos(mu) * (1800.0 / 3.14159265358979323846);
    int i = (int)x;
    if (i > ATMOS__NISHITA_PHASE_N - 2) i = ATMOS__NISHITA_PHASE_N - 2;
    const double f = x - i;
    return ph[i] + f * (ph[i + 1] - ph[i]);
}

/* The sky element of a direction d looking out of the volume (unit): the axis or diagonal
 * nearest to it, or the circumsolar cone (ATMOS__NISHITA_DIRS) within
 * ATMOS__NISHITA_AUREOLE_DEG of the sun's direction sun (unit, toward the sun). */
int atmos__nishita_sky_element(const double d[3], const double sun[3]);
/* The element's direction (l < ATMOS__NISHITA_DIRS), unit. */
void atmos__nishita_sky_dir(int l, double d[3]);
/* Per cell and element the transmittance of the medium from the cell's centre to the grid's
 * edge toward element l's direction (the sun's for the cone): t[(cell * ELEMENTS + l) * n + w]. */
int atmos__nishita_sky_attenuation(const atmos__lmedium *m, const double sun[3], float *t, int threads);

/* Fills f (allocated here for m's grid, s host voxels per cell): f->part and f->L. Returns 0
 * when out of memory. */
int atmos__nishita_solve(const atmos__nishita_in *in, int s, atmos__lfield *f, atmos__nishita_stats *st);

#endif
