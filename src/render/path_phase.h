/* The tabulated phase functions for the path tracer (path_phase.c): single-precision copies
 * of the tables' sampled densities for evaluation, forward-peak truncation. Not part of the
 * API. */
#ifndef ATMOS_RENDER_PATH_PHASE_H
#define ATMOS_RENDER_PATH_PHASE_H

#include "optics/angle_table.h"
#include "render/path_common.h"

/* For every field and wavelength the density atmos_phase_table_sample draws from
 * (atmos_phase_table_eval, angle_table.h), as f_i in single precision so that evaluating
 * all fields and wavelengths of a scattering event reads few cache lines; evaluation (next-
 * event estimation, spectral weights) and sampling use the same function, so phase sampling
 * has weight 1. */
typedef struct {
    int nf, nwl;
    int ng;                        /* grid angles */
    const atmos__angle_grid *grid; /* atmos__phase_angle_grid() */
    float *fv[PATH_F];             /* nwl * n: f_i = P_i sin(theta_i) / F, or truncated */
    int gray[PATH_F];              /* same table at every wavelength */
    const atmos_phase_table *t[PATH_F];
    /* Forward-peak truncation (docs/path.md, "Forward-peak truncation"); ic = 0: none, the
     * tables above are the exact phase functions and the sampler is the table's own. */
    int ic;                        /* grid index of the cut angle theta_c */
    double cut_deg;                /* theta_c (a grid angle) */
    double *cdf[PATH_F];           /* nwl * n: CDF over theta of 2 pi f (truncated tables only) */
    float trunc[PATH_F][ATMOS_MAX_WAVELENGTHS]; /* fraction of the scattering removed (f) */
} path_phase;

/* truncate_deg > 0: the tables are the truncated phase functions P' (P'(theta) =
 * min(P(theta), P(theta_c)) inside the cone theta < theta_c, P outside, renormalised),
 * trunc[][] the fractions f removed, and atmos__path_phase_sample draws from them. */
atmos_status atmos__path_phase_build(atmos_context *ctx, const atmos_volume_optics *optics, int nwl,
                                     double truncate_deg, path_phase *p);
/* cos(theta) drawn from field f's (truncated) table at wavelength k, matched with
 * atmos__path_phase_eval; for ic = 0 it is atmos_phase_table_sample. */
double atmos__path_phase_sample(const path_phase *p, int f, int k, double u);
void atmos__path_phase_free(path_phase *p);

/* The tables of src (truncated or not) with their forward peak clipped further, per field and
 * wavelength at the level P_c that removes the fraction frac[f][k] of them: P*(theta) =
 * min(P(theta), P_c) / (1 - frac) in the forward hemisphere, P / (1 - frac) elsewhere (the cut
 * of atmos__path_phase_build at the angle theta_c where P falls to P_c, found by bisection on
 * P_c rather than snapped to a grid angle), dst->trunc[][] the fractions removed, sampled by
 * atmos__path_phase_sample from their own inverse CDF and evaluated by atmos__path_phase_eval. */
atmos_status atmos__path_phase_clip(atmos_context *ctx, const path_phase *src,
                                    const float frac[PATH_F][ATMOS_MAX_WAVELENGTHS], path_phase *dst);
/* The Legendre moments pl[l] = 2 pi int p(mu) P_l(mu) dmu, l <= lmax (at most
 * ATMOS__PATH_PHASE_LMAX), of the phase function atmos__path_phase_eval evaluates (midpoint
 * rule on 36000 angles); returns pl[0] (1 up to the tables' rounding). */
#define ATMOS__PATH_PHASE_LMAX 8
double atmos__path_phase_moments(const path_phase *p, int f, int k, int lmax, double *pl);

/* The interval of theta (from mu = cos theta) and the weights of f_i, f_{i+1} there: one
 * lookup serves every field and wavelength of a scattering event. */
typedef atmos__angle_weights path_angle;
static inline void atmos__path_angle(const path_phase *p, double mu, path_angle *a)
{
    atmos__angle_density_weights(p->grid, mu, a);
}
static inline double atmos__path_phase_eval(const path_phase *p, int f, int k, const path_angle *a)
{
    const float *v = p->fv[f] + (size_t)k * p->ng;
    return a->w0 * v[a->i] + a->w1 * v[a->i + 1];
}

#endif
