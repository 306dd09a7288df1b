/* The stratocumulus preset (src/sim/sim_presets.c, sim_diffuse.c; docs/clouds.md): after its
 * default 20 minutes the deck is a layer of cells, as stratocumulus seen from above — not
 * streaks along the wind nor cell-sized noise. The column liquid water's autocorrelation
 * falls to 1/e at about the same lag along x and y (ratio under 1.6: a sheared run gave
 * streaks 5-10 times longer than wide) and not within 1.5 cells (a run without sub-grid mixing
 * gave noise one cell across); most columns are cloudy. The horizontal mixing keeps the total
 * water budget closed and the result the same for 1 and 2 threads. */
#include "atmos/atmos.h"
#include "sim/sim_internal.h"
#include "test.h"
#include "test_sim_state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GRID 48

static atmos_sim *run(atmos_context *c, double minutes)
{
    atmos_sim_desc d = {.preset = "stratocumulus", .minutes = 0, .grid = GRID, .seed = 1};
    atmos_sim *s = NULL;
    CHECK_OK(atmos_sim_create(c, &d, &s));
    if (s) CHECK_OK(atmos_sim_run(c, s, minutes * 60.0));
    return s;
}

/* Column sums of q_c (kg/kg x cells) into lwp[j nx + i]. */
static void columns(const atmos_sim *s, double *lwp)
{
    for (int j = 0; j < s->ny; j++)
        for (int i = 0; i < s->nx; i++) {
            double t = 0;
            for (int k = 0; k < s->nz; k++) t += s->qc[sim_idx(s, i, j, k)];
            lwp[j * s->nx + i] = t;
        }
}

/* The lag (cells, linearly interpolated) at which the periodic autocorrelation of the
 * anomalies a along x (dir 0) or y (dir 1) falls below 1/e. */
static double corr_length(const double *a, int nx, int ny, int dir)
{
    double var = 0;
    for (int n = 0; n < nx * ny; n++) var += a[n] * a[n];
    double prev = 1.0;
    for (int lag = 1; lag < (dir ? ny : nx) / 2; lag++) {
        double c = 0;
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const int i2 = dir ? i : (i + lag) % nx, j2 = dir ? (j + lag) % ny : j;
                c += a[j * nx + i] * a[j2 * nx + i2];
            }
        c /= var;
        if (c < exp(-1.0)) return lag - 1 + (prev - exp(-1.0)) / (prev - c);
        prev = c;
    }
    return (dir ? ny : nx) / 2;
}

static void test_cells(void)
{
    atmos_context *c = test_context(2, NULL);
    atmos_sim *s = run(c, 20.0);
    if (s) {
        double *lwp = malloc(sizeof(double) * s->nx * s->ny);
        columns(s, lwp);
        double mean = 0;
        int cloudy = 0;
        for (int n = 0; n < s->nx * s->ny; n++) mean += lwp[n] / (s->nx * s->ny);
        for (int n = 0; n < s->nx * s->ny; n++) cloudy += lwp[n] > 1e-5, lwp[n] -= mean;
        const double lx = corr_length(lwp, s->nx, s->ny, 0), ly = corr_length(lwp, s->nx, s->ny, 1);
        const double frac = (double)cloudy / (s->nx * s->ny);
        printf("  stratocumulus %d^2 x %d, 20 min: cloudy columns %.2f, correlation lengths x %.2f y %.2f cells\n",
               s->nx, s->nz, frac, lx, ly);
        CHECK_MSG(lx / ly < 1.6 && ly / lx < 1.6, "streaks: lengths %.2f and %.2f", lx, ly);
        CHECK_MSG(lx > 1.5 && ly > 1.5, "cell-sized noise: lengths %.2f and %.2f", lx, ly);
        CHECK_MSG(frac > 0.6, "cloudy columns %.2f", frac);
        free(lwp);
    }
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
}

/* The budget: water in the domain + rain out - surface in, unchanged within 1 %; 1 and 2
 * threads the same bytes. */
static void test_budget_threads(void)
{
    atmos_context *c1 = test_context(1, NULL), *c2 = test_context(2, NULL);
    atmos_sim_desc d = {.preset = "stratocumulus", .minutes = 0, .grid = 24, .seed = 1};
    atmos_sim *a = NULL, *b = NULL;
    CHECK_OK(atmos_sim_create(c1, &d, &a));
    CHECK_OK(atmos_sim_create(c2, &d, &b));
    if (a && b) {
        atmos_sim_stats s0, s1;
        atmos_sim_get_stats(a, &s0);
        CHECK_OK(atmos_sim_run(c1, a, 300.0));
        CHECK_OK(atmos_sim_run(c2, b, 300.0));
        atmos_sim_get_stats(a, &s1);
        const double w0 = s0.water, w1 = s1.water + s1.rain_out - s1.surface_in;
        printf("  budget: %.6f -> %.6f kg/m^2 over %ld steps\n", w0, w1, s1.steps);
        CHECK_REL(w1, w0, 0.01);
        CHECK_MSG(test_sim_same_state(a, b), "1 and 2 threads differ");
    }
    atmos_sim_destroy(a);
    atmos_sim_destroy(b);
    atmos_context_destroy(c1);
    atmos_context_destroy(c2);
}

int main(void)
{
    test_cells();
    test_budget_threads();
    return test_summary("test_sim_deck");
}
