/* The slice renderer's optics tables (slice_tables.h): sigma_ext and albedo per field and
 * wavelength, Ams_n in a layout the eye pass reads in two cache lines, F_n, S(n) and the
 * backward hemisphere's mean cosine. */
#include "optics/angle_table.h"
#include "render/slice_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void atmos__stables_free(stables *t)
{
    for (int f = 0; f < ATMOS_VOLUME_MAX_FIELDS; f++) free(t->ams[f]), free(t->F[f]), free(t->S[f]), free(t->B[f]);
}

/* The mean cosine of a phase function (values p on the angle grid th, degrees) over the
 * backward hemisphere, int p mu dOmega / int p dOmega over theta > 90 degrees (trapezoids in
 * theta, the interval across 90 degrees cut there). */
static double back_mean_cosine(const double *th, const double *p, int ng)
{
    double num = 0, den = 0;
    for (int a = 0; a + 1 < ng; a++) {
        if (th[a + 1] <= 90.0) continue;
        const double t0 = th[a] > 90.0 ? th[a] : 90.0, t1 = th[a + 1];
        const double p0 = p[a] + (p[a + 1] - p[a]) * (t0 - th[a]) / (th[a + 1] - th[a]), p1 = p[a + 1];
        const double s0 = sin(t0 * ATMOS_DEG2RAD), s1 = sin(t1 * ATMOS_DEG2RAD), dt = (t1 - t0) * ATMOS_DEG2RAD;
        const double c0 = cos(t0 * ATMOS_DEG2RAD), c1 = cos(t1 * ATMOS_DEG2RAD);
        den += 0.5 * dt * (p0 * s0 + p1 * s1);
        num += 0.5 * dt * (p0 * s0 * c0 + p1 * s1 * c1);
    }
    return den > 0 ? num / den : -0.5;
}

atmos_status atmos__stables_build(atmos_context *ctx, const atmos_volume_optics *o, int n, int max_order, stables *t)
{
    memset(t, 0, sizeof *t);
    t->n = n;
    t->nf = o->count;
    t->no = max_order < 2 ? 2 : max_order;
    for (int f = 0; f < o->count; f++) {
        if (!o->phase[f] || !o->ms[f]) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice: optics of field %d missing", f);
        if (atmos_phase_table_wavelength_count(o->phase[f]) != n || atmos_msphase_wavelength_count(o->ms[f]) != n)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "slice: optics of field %d have %d wavelengths, the scene %d", f,
                                atmos_phase_table_wavelength_count(o->phase[f]), n);
        const atmos_msphase *m = o->ms[f];
        int mo = atmos_msphase_max_order(m);
        t->ng[f] = atmos_msphase_grid(m, &t->grid[f]);
        const int ng = t->ng[f];
        /* + 4: the RGB eye pass reads four floats where the last row's three end */
        t->ams[f] = calloc((size_t)n * ng * t->no + 4, sizeof(float));
        t->F[f] = malloc(sizeof(float) * (size_t)n * (SLICE_F_ORDERS + 1));
        t->S[f] = malloc(sizeof(float) * (size_t)n * (SLICE_F_ORDERS + 1));
        t->B[f] = malloc(sizeof(float) * (size_t)n * (SLICE_F_ORDERS + 1));
        if (!t->ams[f] || !t->F[f] || !t->S[f] || !t->B[f]) {
            atmos__stables_free(t);
            return atmos__error(ctx, ATMOS_E_NOMEM, "slice: out of memory for Ams tables");
        }
        for (int k = 0; k < n; k++) {
            double se, ss;
            atmos_phase_table_cross_sections(o->phase[f], k, &se, &ss);
            t->sig[f][k] = (float)se;
            t->sca[f][k] = (float)ss;
            for (int ord = 1; ord <= t->no; ord++) {
                /* Orders past the table's last are isotropic (Riley §4.2.1). */
                const double *vals = ord <= mo ? atmos_msphase_values(m, k, ord) : NULL;
                for (int a = 0; a < ng; a++)
                    t->ams[f][((size_t)a * t->no + (ord - 1)) * n + k] =
                        (float)(vals ? vals[a] : 1.0 / (4.0 * ATMOS_PI));
            }
            for (int i = 0; i <= SLICE_F_ORDERS; i++) {
                t->F[f][(size_t)k * (SLICE_F_ORDERS + 1) + i] = (float)atmos_msphase_forward(m, k, i);
                t->S[f][(size_t)k * (SLICE_F_ORDERS + 1) + i] = (float)atmos_msphase_log_forward_sum(m, k, i);
                const double *v = i >= 1 && i <= mo ? atmos_msphase_values(m, k, i) : NULL;
                t->B[f][(size_t)k * (SLICE_F_ORDERS + 1) + i] = (float)(v ? back_mean_cosine(t->grid[f], v, ng) : -0.5);
            }
        }
    }
    return ATMOS_OK;
}

/* Index a and weight w (of grid point a+1) of angle theta on an increasing grid. *a
 * holds a guess on entry (the neighbouring pixel's index: angles change little from
 * pixel to pixel), tried with its neighbours before the angle-table reader. The result
 * does not depend on the guess: a is the one interval with grid[a] <= theta < grid[a+1]
 * ((0, 0) at or below the first angle, (ng - 2, 1) at or above the last, (0, NaN) for NaN). */
void atmos__angle_locate(const double *grid, int ng, double theta_deg, int *a, float *w)
{
    for (int g = *a - 1; g <= *a + 1; g++)
        if (g >= 0 && g < ng - 1 && grid[g] < theta_deg && theta_deg < grid[g + 1]) {
            *a = g;
            *w = (float)((theta_deg - grid[g]) / (grid[g + 1] - grid[g]));
            return;
        }
    if (theta_deg <= grid[0]) {
        *a = 0, *w = 0;
        return;
    }
    if (theta_deg >= grid[ng - 1]) {
        *a = ng - 2, *w = 1;
        return;
    }
    /* The grids the renderer is given are the library's (the Ams grid); any other is
     * searched whole by the same bisection. */
    const atmos__angle_grid *known = atmos__angle_grid_known(grid, ng);
    const int lo = known ? atmos__angle_find(known, theta_deg) : atmos__angle_search(grid, 0, ng - 1, theta_deg);
    *a = lo;
    *w = (float)((theta_deg - grid[lo]) / (grid[lo + 1] - grid[lo]));
}
