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
 * grid of atmos_phase_grid). */
#include "render/path_internal.h"

#include <stdlib.h>
#include <string.h>

#define PHASE_LUT 3600 /* bins of 0.05° */

void atmos__path_phase_free(path_phase *p)
{
    if (!p) return;
    for (int f = 0; f < PATH_F; f++) free(p->fv[f]);
    free(p->th_rad);
    free(p->lut);
    memset(p, 0, sizeof *p);
}

atmos_status atmos__path_phase_build(atmos_context *ctx, const atmos_slice_optics *o, int nwl, path_phase *p)
{
    memset(p, 0, sizeof *p);
    p->nf = o->count;
    p->nwl = nwl;
    p->ng = atmos_phase_grid(&p->theta);
    const int ng = p->ng;
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
            for (int i = 0; i < ng; i++) fv[i] = (float)(v[i] * sin(p->th_rad[i]) / total);
            fv[0] = 0.0f; /* sin 0 */
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
