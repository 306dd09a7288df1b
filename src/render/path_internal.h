/* Internals of the path tracer (path.c: integrator and render loop; path_medium.c: the
 * volume as a participating medium, free flights and transmittance; path_phase.c: the
 * tabulated phase functions as exactly matched sampling and evaluation pairs). */
#ifndef ATMOS_PATH_INTERNAL_H
#define ATMOS_PATH_INTERNAL_H

#include "core/internal.h"
#include "volume/volume_grid.h"

#include <math.h>
#include <stdint.h>

#define PATH_B 4 /* wavelengths carried by one path (all of them when the set has <= 4) */
#define PATH_F ATMOS_VOLUME_MAX_FIELDS

/* ------------------------------------------------------------------ random numbers */

/* SplitMix64 (Steele, Lea & Flood 2014) as a counter-based stream: each (seed, pixel,
 * sample) gets its own state, so results do not depend on which thread runs what. */
typedef struct {
    uint64_t s;
} path_rng;

static inline uint64_t path_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static inline void path_rng_seed(path_rng *r, uint64_t seed, uint64_t pixel, uint64_t sample)
{
    r->s = path_mix64(path_mix64(seed + 0x9e3779b97f4a7c15ULL) ^ (pixel * 0xd1b54a32d192ed03ULL)) ^
           path_mix64(sample + 0x632be59bd9b4e019ULL);
}

static inline uint64_t path_next(path_rng *r)
{
    r->s += 0x9e3779b97f4a7c15ULL;
    return path_mix64(r->s);
}

/* Uniform in [0, 1) with 53 bits. */
static inline double path_u(path_rng *r) { return (double)(path_next(r) >> 11) * 0x1.0p-53; }

/* ------------------------------------------------------------------ wavelength bundle */

typedef struct {
    int m;             /* wavelengths carried: min(count, PATH_B) */
    int k[PATH_B];     /* their indices in the scene's set */
} path_bundle;

/* ------------------------------------------------------------------ medium */

typedef struct {
    const atmos_volume *v;
    int nf;
    int n[3];               /* voxels per axis */
    int nb[3];              /* majorant cells (bricks) per axis */
    double org[3];          /* world position of the grid corner (origin + offset) */
    double R[9];            /* grid axes -> world (row-major) */
    double inv_vs;
    float scale;            /* density scale */
    float *mm;              /* per cell, per field: (min, max) of the scaled interpolated density */
    double box_lo[3], box_hi[3]; /* index-space box of the occupied cells (ray clipping) */
    int empty;              /* no occupied cell */
    float sig[PATH_F][ATMOS_MAX_WAVELENGTHS]; /* extinction cross-section, m^2 */
    float sca[PATH_F][ATMOS_MAX_WAVELENGTHS]; /* scattering cross-section, m^2 */
} path_medium;

atmos_status atmos__path_medium_build(atmos_context *ctx, const atmos_volume *v, double scale, const double offset[3],
                                      const atmos_slice_optics *optics, int nwl, path_medium *m);
void atmos__path_medium_free(path_medium *m);
/* Forward-peak truncation of the medium: per field and wavelength the fraction trunc of the
 * scattering counts as not scattered, sigma_s' = sigma_s (1 - trunc), sigma_t' = sigma_t -
 * trunc sigma_s (the absorption is unchanged). Majorants and transmittance follow. */
void atmos__path_medium_truncate(path_medium *m, int nwl, const float trunc[][ATMOS_MAX_WAVELENGTHS]);

/* World point / direction to index space (t stays in metres along a unit world direction). */
void atmos__path_to_index(const path_medium *m, const double p[3], const double d[3], double q[3], double qd[3]);
/* Interval [t0, t1] of a ray (index space) inside the occupied box, clipped to [0, tmax];
 * 0 if none. */
int atmos__path_clip(const path_medium *m, const double q[3], const double qd[3], double tmax, double *t0, double *t1);

/* Free flight by delta tracking with spectral tracking weights (Kutz et al. 2017,
 * "Spectral and decomposition tracking", the history-aware average probabilities) from
 * t0 to t1 (inside the box). Returns 1 at a real scattering event (*t, dens[] = the
 * scaled field densities there), 0 when the ray leaves at t1, -1 when every weight is 0.
 * w[] (per carried wavelength) is updated. *tentative counts tentative collisions. */
int atmos__path_free_flight(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                            const path_bundle *b, double *w, path_rng *r, double *t, float *dens, long long *tentative);

/* Transmittance from t0 to t1 by ratio tracking on the residual above each cell's
 * minorant (the minorant's part is exact: exp(-sigma_c * length)), with Russian roulette
 * when it gets small. Writes T[] per carried wavelength. */
void atmos__path_transmittance(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                               const path_bundle *b, path_rng *r, double *T);

/* A point of [t0, t1] for forced single scattering, by the majorant mu of the carried
 * wavelengths: with u0 < 0.5 the first tentative collision conditioned to lie in [t0, t1]
 * (density mu e^-tau_mu(t) / (1 - e^-tau_mu(t1)): good in dense media), else uniform in
 * majorant optical depth (mu / tau_mu(t1): good in thin ones); *pdf is the mixture's
 * density (per metre), u uniform in [0, 1). 0 if the majorant is 0 all along or its optical
 * depth over [t0, t1] exceeds tau_max. */
int atmos__path_majorant_point(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                               const path_bundle *b, double tau_max, double u0, double u, double *t, double *pdf);

/* Scaled densities at an index-space point (0 outside the grid). */
void atmos__path_density(const path_medium *m, double x, double y, double z, float *dens);

/* ------------------------------------------------------------------ phase functions */

/* For every field and wavelength the sampling density of atmos_phase_table_sample, which is
 * piecewise linear in 2 pi P(theta) sin(theta) between grid angles (phase_table.c), so
 * that evaluation (next-event estimation, spectral weights) and sampling use exactly the
 * same function and phase sampling has weight 1. */
typedef struct {
    int nf, nwl;
    int ng;
    const double *theta;       /* degrees, the shared grid */
    double *th_rad;            /* radians */
    unsigned short *lut;       /* PHASE_LUT + 2 entries: first interval of each 0.05° bin */
    float *fv[PATH_F];         /* nwl * ng: f_i = P_i sin(theta_i) / total */
    int gray[PATH_F];          /* same table at every wavelength */
    const atmos_phase_table *t[PATH_F];
    /* Forward-peak truncation (docs/path.md, "Forward-peak truncation"); ic = 0: none, the
     * tables above are the exact phase functions and the sampler is the table's own. */
    int ic;                    /* grid index of the cut angle theta_c */
    double cut_deg;            /* theta_c (a grid angle) */
    double *cdf[PATH_F];       /* nwl * ng: CDF over theta of 2 pi f (truncated tables only) */
    float trunc[PATH_F][ATMOS_MAX_WAVELENGTHS]; /* fraction of the scattering removed (f) */
} path_phase;

/* truncate_deg > 0: the tables are the truncated phase functions P' (P'(theta) =
 * min(P(theta), P(theta_c)) inside the cone theta < theta_c, P outside, renormalised),
 * trunc[][] the fractions f removed, and atmos__path_phase_sample draws from them. */
atmos_status atmos__path_phase_build(atmos_context *ctx, const atmos_slice_optics *optics, int nwl,
                                     double truncate_deg, path_phase *p);
/* cos(theta) drawn from field f's (truncated) table at wavelength k, matched with
 * atmos__path_phase_eval; for ic = 0 it is atmos_phase_table_sample. */
double atmos__path_phase_sample(const path_phase *p, int f, int k, double u);
void atmos__path_phase_free(path_phase *p);

/* Interval index i and fraction s of theta (from mu = cos theta), and 1/sin(theta) factor. */
typedef struct {
    int i;
    double s;
    double w0, w1; /* p = w0 * f_i + w1 * f_{i+1}, see path_phase.c */
} path_angle;
void atmos__path_angle(const path_phase *p, double mu, path_angle *a);
static inline double atmos__path_phase_eval(const path_phase *p, int f, int k, const path_angle *a)
{
    const float *v = p->fv[f] + (size_t)k * p->ng;
    return a->w0 * v[a->i] + a->w1 * v[a->i + 1];
}

/* ------------------------------------------------------------------ the sky as a light */

/* A sampling distribution of directions for next-event estimation of the sky's light: a
 * table over (cos of the angle from +y, azimuth), cells of equal solid angle, each holding
 * the luminance of the analytic sky's single scattering seen from a reference altitude,
 * mixed with a uniform distribution over the sphere (so that no direction has density 0).
 * Only the density matters: the radiance itself is always evaluated exactly. */
#define PATH_ENV_NMU 32
#define PATH_ENV_NPHI 64
typedef struct {
    double cdf[PATH_ENV_NMU * PATH_ENV_NPHI + 1]; /* cumulative over cells, cdf[0] = 0, last 1 */
    double pdf_cell[PATH_ENV_NMU * PATH_ENV_NPHI]; /* density (sr^-1) of the table part */
    double uniform;                                 /* weight of the uniform part */
} path_env;

/* Builds the table for the sky seen from altitude y_ref (weights Y[] per wavelength).
 * Returns 0 when the sky is dark (sun below the horizon): no next-event estimation. */
int atmos__path_env_build(const atmos_sky *sky, const double sun[3], double y_ref, const double *Y, path_env *e);
/* A direction drawn from the distribution; returns its density (sr^-1). */
double atmos__path_env_sample(const path_env *e, double u0, double u1, double u2, double d[3]);
/* Density (sr^-1) of unit direction d. */
double atmos__path_env_pdf(const path_env *e, const double d[3]);

#endif
