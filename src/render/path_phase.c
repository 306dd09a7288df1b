/* Tabulated phase functions for the path tracer: evaluation that matches the inverse-CDF
 * sampler of phase_table.c exactly.
 *
 * atmos_phase_table_sample draws theta with density 2 pi f(theta) / F, where f is the
 * piecewise-linear interpolant of f_i = P(theta_i) sin(theta_i) on the grid and F its
 * trapezoid integral. As a density over solid angle that is f(theta) / (F sin theta).
 * Evaluating this function (rather than P interpolated linearly) for next-event
 * estimation and for the spectral weights makes the phase function that is sampled and
 * the one that is evaluated the same, so a phase-sampled direction has weight exactly 1.
 * The two differ from each other by the interpolation error only (far below 1e-4 on the
 * grid of atmos_phase_grid).
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
 * single-precision values the evaluation reads, so sampler and evaluator stay matched. */
#include "render/path_internal.h"

#include <stdlib.h>
#include <string.h>

#define PHASE_LUT 3600 /* bins of 0.05° */

void atmos__path_phase_free(path_phase *p)
{
    if (!p) return;
    for (int f = 0; f < PATH_F; f++) free(p->fv[f]), free(p->cdf[f]);
    free(p->th_rad);
    free(p->lut);
    memset(p, 0, sizeof *p);
}

atmos_status atmos__path_phase_build(atmos_context *ctx, const atmos_volume_optics *o, int nwl, double truncate_deg,
                                     path_phase *p)
{
    memset(p, 0, sizeof *p);
    p->nf = o->count;
    p->nwl = nwl;
    p->ng = atmos_phase_grid(&p->theta);
    const int ng = p->ng;
    if (truncate_deg > 0) {
        /* the grid angle nearest theta_c (at least the first one after 0) */
        int ic = 1;
        for (int i = 1; i < ng - 1; i++)
            if (fabs(p->theta[i] - truncate_deg) < fabs(p->theta[ic] - truncate_deg)) ic = i;
        p->ic = ic;
        p->cut_deg = p->theta[ic];
    }
    p->th_rad = malloc(sizeof(double) * (size_t)ng);
    p->lut = malloc(sizeof(unsigned short) * (PHASE_LUT + 2));
    if (!p->th_rad || !p->lut) goto nomem;
    for (int i = 0; i < ng; i++) p->th_rad[i] = p->theta[i] * ATMOS_DEG2RAD;
    for (int j = 0, i = 0; j <= PHASE_LUT + 1; j++) {
        double x = j * 0.05;
        while (i + 2 < ng && p->theta[i + 1] <= x) i++;
        p->lut[j] = (unsigned short)i;
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
        if (!p->fv[f]) goto nomem;
        p->gray[f] = 1;
        const double *v0 = atmos_phase_table_values(t, 0);
        for (int k = 0; k < nwl; k++) {
            const double *v = atmos_phase_table_values(t, k);
            if (k > 0 && memcmp(v, v0, sizeof(double) * (size_t)ng) != 0) p->gray[f] = 0;
            double total = 0;
            for (int i = 0; i + 1 < ng; i++)
                total += ATMOS_PI * (v[i] * sin(p->th_rad[i]) + v[i + 1] * sin(p->th_rad[i + 1])) *
                         (p->th_rad[i + 1] - p->th_rad[i]);
            if (!(total > 0) || !isfinite(total)) total = 1;
            float *fv = p->fv[f] + (size_t)k * ng;
            if (!p->ic) {
                for (int i = 0; i < ng; i++) fv[i] = (float)(v[i] * sin(p->th_rad[i]) / total);
                fv[0] = 0.0f; /* sin 0 */
                continue;
            }
            /* truncated: P clipped at P(theta_c) inside the cone */
            const double pc = v[p->ic];
            double kept = 0;
            for (int i = 0; i + 1 < ng; i++) {
                double a = i < p->ic && v[i] > pc ? pc : v[i], b = i + 1 < p->ic && v[i + 1] > pc ? pc : v[i + 1];
                kept += ATMOS_PI * (a * sin(p->th_rad[i]) + b * sin(p->th_rad[i + 1])) * (p->th_rad[i + 1] - p->th_rad[i]);
            }
            double frac = 1.0 - kept / total;
            if (!(kept > 0) || !isfinite(kept)) kept = total, frac = 0;
            if (frac < 0) frac = 0; /* rounding only: clipping never adds */
            p->trunc[f][k] = (float)frac;
            for (int i = 0; i < ng; i++) {
                double a = i < p->ic && v[i] > pc ? pc : v[i];
                fv[i] = (float)(a * sin(p->th_rad[i]) / kept);
            }
            fv[0] = 0.0f;
        }
        if (p->ic) {
            /* CDF of 2 pi f(theta) (trapezoids of the float values), normalised to end at 1 */
            p->cdf[f] = malloc(sizeof(double) * (size_t)nwl * ng);
            if (!p->cdf[f]) goto nomem;
            for (int k = 0; k < nwl; k++) {
                const float *fv = p->fv[f] + (size_t)k * ng;
                double *c = p->cdf[f] + (size_t)k * ng;
                c[0] = 0;
                for (int i = 0; i + 1 < ng; i++)
                    c[i + 1] = c[i] + 0.5 * ((double)fv[i] + fv[i + 1]) * (p->th_rad[i + 1] - p->th_rad[i]);
                const double last = c[ng - 1];
                for (int i = 1; i < ng; i++) c[i] = last > 0 ? c[i] / last : (double)i / (ng - 1);
                c[ng - 1] = 1.0;
            }
        }
    }
    return ATMOS_OK;
nomem:
    atmos__path_phase_free(p);
    return atmos__error(ctx, ATMOS_E_NOMEM, "render path: out of memory for the phase tables");
}

void atmos__path_angle(const path_phase *p, double mu, path_angle *a)
{
    if (!(mu > -1)) mu = -1;
    if (mu > 1) mu = 1;
    const double th = acos(mu), thd = th * ATMOS_RAD2DEG;
    int j = (int)(thd * 20.0);
    if (j < 0) j = 0;
    if (j > PHASE_LUT - 1) j = PHASE_LUT - 1;
    int lo = p->lut[j], hi = p->lut[j + 1] + 1;
    if (hi > p->ng - 1) hi = p->ng - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) >> 1;
        if (p->theta[mid] <= thd) lo = mid;
        else hi = mid;
    }
    const int i = lo;
    const double h = p->th_rad[i + 1] - p->th_rad[i];
    double s = (th - p->th_rad[i]) / h;
    if (s < 0) s = 0;
    if (s > 1) s = 1;
    a->i = i;
    a->s = s;
    if (i == 0) {
        /* f_0 = 0: p = (theta / h) f_1 / sin(theta), finite as theta -> 0 */
        a->w0 = 0;
        a->w1 = (th > 1e-12 ? th / sin(th) : 1.0) / h;
    } else if (i == p->ng - 2) {
        /* f_{n-1} = P sin(pi) ~ 0: p = ((pi - theta) / h) f_{n-2} / sin(theta) */
        const double e = ATMOS_PI - th;
        a->w0 = (e > 1e-12 ? e / sin(th) : 1.0) / h;
        a->w1 = 0;
    } else {
        const double is = 1.0 / sin(th);
        a->w0 = (1 - s) * is;
        a->w1 = s * is;
    }
}

double atmos__path_phase_sample(const path_phase *p, int f, int k, double u)
{
    if (!p->ic) return atmos_phase_table_sample(p->t[f], k, u);
    const double *c = p->cdf[f] + (size_t)k * p->ng;
    const float *fv = p->fv[f] + (size_t)k * p->ng;
    if (!(u >= 0)) u = 0;
    if (u >= 1) u = 0x1.fffffffffffffp-1;
    /* the interval [i, i+1] with c[i] <= u < c[i+1] (never one of zero mass) */
    int lo = 0, hi = p->ng - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) >> 1;
        if (c[mid] <= u) lo = mid;
        else hi = mid;
    }
    const int i = lo;
    const double h = p->th_rad[i + 1] - p->th_rad[i], mass = c[i + 1] - c[i];
    double x = 0;
    if (mass > 0 && h > 0) {
        /* density linear from f0 to f1 over [0, h]: its integral to x, f0 x + (f1 - f0) x^2 / (2h),
         * equals the fraction (u - c_i) / mass of the interval's (f0 + f1) h / 2; the root
         * written as 2r / (f0 + sqrt(f0^2 + 2 (f1 - f0) r / h)) has no cancellation. */
        const double f0 = fv[i], f1 = fv[i + 1];
        const double r = (u - c[i]) / mass * 0.5 * (f0 + f1) * h;
        double disc = f0 * f0 + 2.0 * (f1 - f0) * r / h;
        if (disc < 0) disc = 0;
        const double den = f0 + sqrt(disc);
        x = den > 0 ? 2.0 * r / den : 0.0;
        if (x > h) x = h;
        if (x < 0) x = 0;
    }
    const double mu = cos(p->th_rad[i] + x);
    return mu < -1 ? -1 : (mu > 1 ? 1 : mu);
}
