/* The cumulonimbus preset reaches the tropopause and spreads an anvil (issue 19; docs/clouds.md,
 * *The anvil*): its top reaches the tropopause and stays within 2 km over it, and at maturity
 * the cloud 1 km under the tropopause reaches along the wind over more than twice the tower's
 * extent at mid levels; 1 and 2 threads give the same bytes. With a grid and minutes as
 * arguments the program prints the sounding and the cloud's extent level by level instead
 * (the diagnosis in docs/clouds.md). */
#include "atmos/atmos.h"
#include "sim/sim_internal.h"
#include "test.h"
#include "test_sim_state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define Q_MIN 1e-5 /* condensate, kg/kg: opaque over a cell (docs/clouds.md) */

/* Columns of level k holding condensate (cloud, and ice where the model has it) above q_min. */
static int level_area(const atmos_sim *s, int k, double q_min)
{
    int n = 0;
    for (int j = 0; j < s->ny; j++)
        for (int i = 0; i < s->nx; i++) n += s->qc[sim_idx(s, i, j, k)] > q_min;
    return n;
}

/* Extent along x (cells) of level k's condensate: columns of x with any. */
static int level_xspan(const atmos_sim *s, int k, double q_min)
{
    int n = 0;
    for (int i = 0; i < s->nx; i++) {
        int any = 0;
        for (int j = 0; j < s->ny; j++) any |= s->qc[sim_idx(s, i, j, k)] > q_min;
        n += any;
    }
    return n;
}

/* Mean over levels k0..k1 of f. */
static double mean_levels(const atmos_sim *s, int k0, int k1, int (*f)(const atmos_sim *, int, double))
{
    double t = 0;
    for (int k = k0; k <= k1; k++) t += f(s, k, Q_MIN);
    return t / (k1 - k0 + 1);
}

/* The cumulonimbus at grid G, every 5 minutes from 20 to 45: its top must reach the
 * tropopause (the centre of the highest cloudy cell within half a kilometre under it) and
 * never rise more than 2 km over it (the stratosphere stops it); its maturity is the time the
 * cloud 1 km under the tropopause (the anvil's level) covers the most columns, and there
 * that level's cloud must reach along the wind (x) over more than twice the tower's extent at
 * mid levels (3-6 km) and cover more than 4 times its area. */
static void test_anvil(int grid)
{
    atmos_context *c = test_context(2, NULL);
    atmos_sim_desc d = {.preset = "cumulonimbus", .minutes = 0, .grid = grid, .seed = 1};
    atmos_sim *s = NULL;
    CHECK_OK(atmos_sim_create(c, &d, &s));
    if (!s) return;
    const double ztp = s->env.z_tp;
    const int k6 = (int)(6000 / s->dx), k3 = (int)(3000 / s->dx), ka = (int)((ztp - 1000) / s->dx);
    int best_area = -1, best_min = 0, top_k = -1;
    double best_x = 0, best_a = 0;
    CHECK_OK(atmos_sim_run(c, s, 15 * 60.0));
    for (int m = 20; m <= 45; m += 5) {
        CHECK_OK(atmos_sim_run(c, s, 300.0));
        for (int k = 0; k < s->nz; k++)
            if (level_area(s, k, Q_MIN) > 0 && k > top_k) top_k = k;
        const int area = level_area(s, ka, Q_MIN);
        const double xr = level_xspan(s, ka, Q_MIN) / fmax(mean_levels(s, k3, k6 - 1, level_xspan), 1.0);
        const double ar = area / fmax(mean_levels(s, k3, k6 - 1, level_area), 1.0);
        printf("  %2d min: at %.1f km %d columns, x extent %d cells: %.1f x the mid levels' extent, %.1f x their "
               "area; top %.1f km\n",
               m, (ka + 0.5) * s->dx * 1e-3, area, level_xspan(s, ka, Q_MIN), xr, ar, (top_k + 0.5) * s->dx * 1e-3);
        if (area > best_area) best_area = area, best_min = m, best_x = xr, best_a = ar;
    }
    const double ztop = (top_k + 0.5) * s->dx;
    printf("  grid %d: maturity at %d min: the anvil's x extent %.1f x, area %.1f x the mid levels'; highest "
           "cloud %.1f km (tropopause %.1f km)\n",
           grid, best_min, best_x, best_a, ztop * 1e-3, ztp * 1e-3);
    CHECK_MSG(ztop >= ztp - 500, "the top stays at %.0f m", ztop);
    CHECK_MSG(ztop <= ztp + 2000, "cloud at %.0f m", ztop);
    CHECK_MSG(best_x >= 2.0, "the anvil's extent only %.2f x the tower's", best_x);
    CHECK_MSG(best_a >= 4.0, "the anvil's area only %.2f x the tower's", best_a);
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
}

/* The ice and the anelastic projection keep the result independent of the thread count: the
 * preset at grid 32 to 22 minutes (its top in the ice, its anvil spreading), 1 and 2 threads,
 * every field the same bytes. */
static void test_threads(void)
{
    atmos_context *c1 = test_context(1, NULL), *c2 = test_context(2, NULL);
    atmos_sim_desc d = {.preset = "cumulonimbus", .minutes = 0, .grid = 32, .seed = 1};
    atmos_sim *a = NULL, *b = NULL;
    CHECK_OK(atmos_sim_create(c1, &d, &a));
    CHECK_OK(atmos_sim_create(c2, &d, &b));
    if (a && b) {
        CHECK_OK(atmos_sim_run(c1, a, 22 * 60.0));
        CHECK_OK(atmos_sim_run(c2, b, 22 * 60.0));
        atmos_sim_stats st;
        atmos_sim_get_stats(a, &st);
        printf("  threads: grid 32, 22 min, top %.0f m, max w %.1f m/s\n", st.cloud_top_m, st.max_w);
        CHECK_MSG(st.cloud_top_m > 0.75 * a->env.z_tp, "no deep cloud to compare (top %.0f m)", st.cloud_top_m);
        CHECK_MSG(test_sim_same_state(a, b), "1 and 2 threads differ");
    }
    atmos_sim_destroy(a);
    atmos_sim_destroy(b);
    atmos_context_destroy(c1);
    atmos_context_destroy(c2);
}

static void diagnose(int grid, int minutes)
{
    atmos_context *c = test_context(2, NULL);
    atmos_sim_desc d = {.preset = "cumulonimbus", .minutes = 0, .grid = grid, .seed = 1};
    atmos_sim *s = NULL;
    CHECK_OK(atmos_sim_create(c, &d, &s));
    if (!s) return;
    printf("dx %.0f nz %d top %.0f m\n", s->dx, s->nz, s->nz * s->dx);
    for (int k = 0; k < s->nz; k += 1) {
        const double n2 = k + 1 < s->nz ? SIM_G / s->th0[k] * (s->th0[k + 1] - s->th0[k]) / s->dx : 0;
        printf(" z %6.0f th0 %6.1f T %6.1f N2 %.2e ue %5.1f qv0 %.2e\n", (k + 0.5) * s->dx, s->th0[k],
               s->th0[k] * s->pi0[k], n2, s->ue[k], s->qv0[k]);
    }
    for (int m = 5; m <= minutes; m += 5) {
        CHECK_OK(atmos_sim_run(c, s, 300.0));
        atmos_sim_stats st;
        atmos_sim_get_stats(s, &st);
        printf("min %d top %.0f max_w %.1f\n  area(cells)/xspan per level:", m, st.cloud_top_m, st.max_w);
        for (int k = 0; k < s->nz; k++) printf(" %d/%d", level_area(s, k, 1e-5), level_xspan(s, k, 1e-5));
        printf("\n");
    }
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
}

int main(int argc, char **argv)
{
    if (argc > 2) diagnose(atoi(argv[1]), atoi(argv[2])); /* the profiles minute by minute (docs/clouds.md) */
    else {
        test_anvil(argc > 1 ? atoi(argv[1]) : 48);
        test_threads();
    }
    return test_summary("test_sim_anvil");
}
