/* Tabulated phase functions for the path tracer: the tables' own matched density and
 * sampler (atmos_phase_table_eval / _sample / _pdf, angle_table.h), kept in single precision
 * for evaluation, and forward-peak truncation.
 *
 * atmos_phase_table_sample draws theta with density 2 pi f(theta), f the piecewise-linear
 * interpolant of the table's f_i = P(theta_i) sin(theta_i) / F; over solid angle that is
 * f(theta) / sin(theta), which is what atmos_phase_table_eval returns and what
 * atmos__path_phase_eval computes from fv = (float)f_i (F = atmos__phase_table_total) with
 * the same interval and weights (atmos__angle_density_weights). Evaluating this function
 * (rather than P interpolated linearly) for next-event estimation and for the spectral
 * weights makes the phase function that is sampled and the one that is evaluated the same,
 * so a phase-sampled direction has weight exactly 1.
 *
 * Forward-peak truncation (the delta-M idea of Wiscombe 1977, J. Atmos. Sci. 34, 1408, in
 * the form of Potter 1970, J. Atmos. Sci. 27, 617: the peak is cut off at an angle rather
 * than fitted by Legendre moments): with the cut theta_c (snapped to a grid angle), the
 * phase function inside the cone theta < theta_c is replaced by min(P(theta), P(theta_c)),
 * so P' is continuous at theta_c and flat where the peak stood above it. The removed
 * fraction f = 1 - integral of the clipped function (with the same trapezoid rule on
 * P sin theta as the normalisation) counts as not scattered: the medium's scattering
 * becomes sigma_s (1 - f) (path_medium.c), the phase function P' = P_clipped / (1 - f).
 * The truncated tables are sampled here by their own inverse CDF, built from the same
 * single-precision values the evaluation reads, and inverted by the tables' own
 * atmos__angle_invert, so sampler and evaluator stay matched. */
#include "render/path_internal.h"

#include <stdlib.h>
#include <string.h>

void atmos__path_phase_free(path_phase *p)
{
    if (!p) return;
    for (int f = 0; f < PATH_F; f++) free(p->fv[f]), free(p->cdf[f]);
    memset(p, 0, sizeof *p);
}

/* The grid angle nearest theta_c (at least the first one after 0). */
static int cut_index(const atmos__angle_grid *g, double truncate_deg)
{
    int ic = 1;
    for (int i = 1; i < g->n - 1; i++)
        if (fabs(g->deg[i] - truncate_deg) < fabs(g->deg[ic] - truncate_deg)) ic = i;
    return ic;
}

/* fv = P' sin(theta) / (its integral) for the table v clipped at v[ic] inside the cone;
 * returns the fraction of the scattering removed. total is the table's own integral
 * (atmos__phase_table_total), summed the same way as kept here. */
static float truncate_table(const atmos__angle_grid *g, int ic, const double *v, double total, float *fv)
{
    const int ng = g->n;
    const double pc = v[ic];
    double kept = 0;
    for (int i = 0; i + 1 < ng; i++) {
        double a = i < ic && v[i] > pc ? pc : v[i], b = i + 1 < ic && v[i + 1] > pc ? pc : v[i + 1];
        kept += ATMOS_PI * (a * g->sin[i] + b * g->sin[i + 1]) * (g->rad[i + 1] - g->rad[i]);
    }
    double frac = 1.0 - kept / total;
    if (!(kept > 0) || !isfinite(kept)) kept = total, frac = 0;
    if (frac < 0) frac = 0; /* rounding only: clipping never adds */
    for (int i = 0; i < ng; i++) {
        double a = i < ic && v[i] > pc ? pc : v[i];
        fv[i] = (float)(a * g->sin[i] / kept);
    }
    fv[0] = 0.0f;
    return (float)frac;
}

/* CDF of 2 pi f(theta) (trapezoids of the float values), normalised to end at 1. */
static void truncated_cdf(const atmos__angle_grid *g, const float *fv, double *c)
{
    const int ng = g->n;
    c[0] = 0;
    for (int i = 0; i + 1 < ng; i++) c[i + 1] = c[i] + 0.5 * ((double)fv[i] + fv[i + 1]) * (g->rad[i + 1] - g->rad[i]);
    const double last = c[ng - 1];
    for (int i = 1; i < ng; i++) c[i] = last > 0 ? c[i] / last : (double)i / (ng - 1);
    c[ng - 1] = 1.0;
}

atmos_status atmos__path_phase_build(atmos_context *ctx, const atmos_volume_optics *o, int nwl, double truncate_deg,
                                     path_phase *p)
{
    memset(p, 0, sizeof *p);
    p->nf = o->count;
    p->nwl = nwl;
    p->grid = atmos__phase_angle_grid();
    p->ng = p->grid->n;
    const int ng = p->ng;
    if (truncate_deg > 0) {
        p->ic = cut_index(p->grid, truncate_deg);
        p->cut_deg = p->grid->deg[p->ic];
    }
    for (int f = 0; f < o->count; f++) {
        const atmos_phase_table *t = o->phase[f];
        if (!t || atmos_phase_table_wavelength_count(t) != nwl) {
            atmos__path_phase_free(p);
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render path: phase table of field %d has %d wavelengths, the scene %d",
                                f, t ? atmos_phase_table_wavelength_count(t) : 0, nwl);
        }
        p->t[f] = t;
        p->fv[f] = malloc(sizeof(float) * (size_t)nwl * ng);
        if (p->ic) p->cdf[f] = malloc(sizeof(double) * (size_t)nwl * ng);
        if (!p->fv[f] || (p->ic && !p->cdf[f])) {
            atmos__path_phase_free(p);
            return atmos__error(ctx, ATMOS_E_NOMEM, "render path: out of memory for the phase tables");
        }
        p->gray[f] = 1;
        const double *v0 = atmos_phase_table_values(t, 0);
        for (int k = 0; k < nwl; k++) {
            const double *v = atmos_phase_table_values(t, k);
            if (k > 0 && memcmp(v, v0, sizeof(double) * (size_t)ng) != 0) p->gray[f] = 0;
            const double total = atmos__phase_table_total(t, k);
            float *fv = p->fv[f] + (size_t)k * ng;
            if (!p->ic) {
                for (int i = 0; i < ng; i++) fv[i] = (float)(v[i] * p->grid->sin[i] / total);
                continue;
            }
            p->trunc[f][k] = truncate_table(p->grid, p->ic, v, total, fv);
            truncated_cdf(p->grid, fv, p->cdf[f] + (size_t)k * ng);
        }
    }
    return ATMOS_OK;
}

double atmos__path_phase_sample(const path_phase *p, int f, int k, double u)
{
    if (!p->ic) return atmos_phase_table_sample(p->t[f], k, u);
    const double *c = p->cdf[f] + (size_t)k * p->ng;
    const float *fv = p->fv[f] + (size_t)k * p->ng;
    const int i = atmos__angle_cdf_find(c, p->ng, &u);
    return atmos__angle_invert(p->grid, c, i, u, fv[i], fv[i + 1]);
}

/* The removed fraction of the density fv (a truncated table, fv[0] = 0) when P = fv / sin is
 * clipped at level c in the forward hemisphere (into g if not NULL), by the trapezoids the
 * tables are normalised with; T is fv's own trapezoid sum. */
static double clip_removed(const atmos__angle_grid *g, const float *fv, double c, double T, double *out)
{
    double kept = 0, prev = 0;
    for (int i = 0; i < g->n; i++) {
        const double v = fv[i], lim = g->deg[i] < 90 ? c * g->sin[i] : INFINITY, x = v > lim ? lim : v;
        if (out) out[i] = x;
        if (i > 0) kept += 0.5 * (prev + x) * (g->rad[i] - g->rad[i - 1]);
        prev = x;
    }
    return 1.0 - kept / T;
}

atmos_status atmos__path_phase_clip(atmos_context *ctx, const path_phase *src,
                                    const float frac[PATH_F][ATMOS_MAX_WAVELENGTHS], path_phase *dst)
{
    memset(dst, 0, sizeof *dst);
    dst->nf = src->nf, dst->nwl = src->nwl, dst->grid = src->grid, dst->ng = src->ng;
    dst->ic = src->ic ? src->ic : 1, dst->cut_deg = src->cut_deg;
    const atmos__angle_grid *g = src->grid;
    const int ng = src->ng;
    double *x = malloc(sizeof(double) * (size_t)ng);
    for (int f = 0; f < src->nf; f++) {
        dst->t[f] = src->t[f];
        dst->fv[f] = malloc(sizeof(float) * (size_t)src->nwl * ng);
        dst->cdf[f] = malloc(sizeof(double) * (size_t)src->nwl * ng);
        if (!x || !dst->fv[f] || !dst->cdf[f]) {
            free(x), atmos__path_phase_free(dst);
            return atmos__error(ctx, ATMOS_E_NOMEM, "render path: out of memory for the phase tables");
        }
        for (int k = 0; k < src->nwl; k++) {
            const float *fv = src->fv[f] + (size_t)k * ng;
            double T = 0, hi = 0, lo = 0;
            for (int i = 1; i < ng; i++) {
                T += 0.5 * ((double)fv[i - 1] + fv[i]) * (g->rad[i] - g->rad[i - 1]);
                if (g->sin[i] > 0 && fv[i] / g->sin[i] > hi) hi = fv[i] / g->sin[i];
            }
            const double want = frac[f][k] > 0 && frac[f][k] < 1 ? frac[f][k] : 0;
            for (int it = 0; it < 200 && want > 0 && hi > lo; it++) { /* removed(c) falls as c grows */
                const double c = 0.5 * (lo + hi);
                if (clip_removed(g, fv, c, T, NULL) > want) lo = c;
                else hi = c;
            }
            const double r = T > 0 ? clip_removed(g, fv, want > 0 ? hi : INFINITY, T, x) : 0;
            float *out = dst->fv[f] + (size_t)k * ng;
            for (int i = 0; i < ng; i++) out[i] = (float)(T > 0 ? x[i] / (2 * ATMOS_PI * T * (1 - r)) : fv[i]);
            dst->trunc[f][k] = (float)r;
            truncated_cdf(g, out, dst->cdf[f] + (size_t)k * ng);
        }
    }
    free(x);
    return ATMOS_OK;
}

double atmos__path_phase_moments(const path_phase *p, int f, int k, int lmax, double *pl)
{
    enum { STEPS = 36000 };
    double acc[ATMOS__PATH_PHASE_LMAX + 1] = {0};
    if (lmax > ATMOS__PATH_PHASE_LMAX) lmax = ATMOS__PATH_PHASE_LMAX;
    for (int i = 0; i < STEPS; i++) {
        const double th = (i + 0.5) * ATMOS_PI / STEPS, mu = cos(th);
        path_angle a;
        atmos__path_angle(p, mu, &a);
        const double w = atmos__path_phase_eval(p, f, k, &a) * 2 * ATMOS_PI * sin(th) * ATMOS_PI / STEPS;
        double P0 = 1, P1 = mu;
        acc[0] += w;
        if (lmax >= 1) acc[1] += w * mu;
        for (int l = 1; l < lmax; l++) {
            const double P2 = ((2 * l + 1) * mu * P1 - l * P0) / (l + 1);
            acc[l + 1] += w * P2;
            P0 = P1, P1 = P2;
        }
    }
    for (int l = 0; l <= lmax; l++) pl[l] = acc[l];
    return acc[0];
}
