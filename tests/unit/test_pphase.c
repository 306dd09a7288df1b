/* The particles' phase functions on the scattering angle's cosine (src/particles/pphase.h)
 * against the exact Ams_n (atmos_msphase_eval: acos and the msphase grid's search) of the cloud
 * droplets in rgb, as the viewer's field uses them: at random angles (uniform in theta and in
 * cos theta) and random orders, the relative error by angle range; exactly the msphase's value
 * at the nodes of integer orders; the isotropic order past the last. */
#include "atmos/atmos.h"
#include "particles/pphase.h"
#include "test.h"

#include <stdint.h>

#define PI 3.14159265358979323846

static uint64_t rng_state = 1234;
static double uniform(void)
{
    return test_uniform_from(&rng_state);
}

/* Worst and mean relative error of t against m over draws with theta in [lo, hi) degrees, at
 * orders from 1 to the last (first: Ams_1 alone, the sharpest). */
static void errors(const atmos__pphase *t, const atmos_msphase *m, double lo, double hi, int by_cos, int first,
                   double *worst, double *mean)
{
    const int draws = 20000, nw = t->nw, top = atmos_msphase_max_order(m);
    double sum = 0;
    *worst = 0;
    for (int d = 0; d < draws; d++) {
        const double c = by_cos ? cos(hi * PI / 180) + uniform() * (cos(lo * PI / 180) - cos(hi * PI / 180))
                                : cos((lo + uniform() * (hi - lo)) * PI / 180),
                     n = first ? 1.0 : 1.0 + uniform() * top;
        double got[ATMOS_MAX_WAVELENGTHS];
        atmos__pphase_eval(t, n, c, got);
        for (int k = 0; k < nw; k++) {
            const double want = atmos_msphase_eval(m, k, n, c), e = fabs(got[k] - want) / want;
            *worst = e > *worst ? e : *worst;
            sum += e;
        }
    }
    *mean = sum / ((double)draws * nw);
}

int main(void)
{
    atmos_context *ctx = test_context(2, NULL);
    atmos_particle_desc p;
    CHECK_OK(atmos_particle_preset(ctx, "cloud", &p));
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_phase_table *pt = NULL;
    atmos_phase_table_desc td = {1};
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &pt));
    atmos_msphase *m = NULL;
    CHECK_OK(atmos_msphase_build(ctx, pt, NULL, &m));
    const int top = m ? atmos_msphase_max_order(m) : 0;
    /* the size cap: the table's floats, orders x both halves' nodes x wavelengths; one byte
     * under it, no table */
    const size_t bytes = sizeof(float) * (size_t)(top + 1) * 2 * (ATMOS__PPHASE_NODES + 1) * (size_t)wl.count;
    CHECK(atmos__pphase_bytes(m, wl.count) == bytes);
    CHECK(m && atmos__pphase_make(m, wl.count, bytes - 1) == NULL);
    atmos__pphase *t = m ? atmos__pphase_make(m, wl.count, bytes) : NULL;
    CHECK(t != NULL);
    if (!t) return test_summary("test_pphase");
    CHECK(t->orders == top + 1);

    /* the nodes of integer orders: the msphase's own values (in floats) */
    double worst_node = 0;
    for (int n = 1; n <= top + 1; n += 7)
        for (int i = 0; i <= ATMOS__PPHASE_NODES; i += 37)
            for (int h = 0; h < 2; h++) {
                const double s = (double)i / ATMOS__PPHASE_NODES, c = h ? s * s - 1 : 1 - s * s;
                double got[ATMOS_MAX_WAVELENGTHS];
                atmos__pphase_eval(t, n, c, got);
                for (int k = 0; k < wl.count; k++) {
                    const double want = atmos_msphase_eval(m, k, n, c), e = fabs(got[k] - want) / want;
                    worst_node = e > worst_node ? e : worst_node;
                }
            }
    CHECK_MSG(worst_node < 1e-6, "at the nodes %.3g", worst_node);
    /* past the last order: isotropic */
    double iso[ATMOS_MAX_WAVELENGTHS];
    atmos__pphase_eval(t, top + 5.5, 0.3, iso);
    for (int k = 0; k < wl.count; k++) CHECK_NEAR(iso[k], 1.0 / (4 * PI), 1e-8);

    /* between the nodes: by angle range (the forward peak within 2 degrees, where the msphase
     * grid is finer than the table) */
    static const double ranges[][2] = {{0, 0.5}, {0.5, 2}, {2, 20}, {20, 160}, {160, 180}, {0, 180}};
    for (int first = 0; first < 2; first++)
        for (int r = 0; r < 6; r++)
            for (int by_cos = 0; by_cos < 2; by_cos++) {
                double worst, mean;
                errors(t, m, ranges[r][0], ranges[r][1], by_cos, first, &worst, &mean);
                printf("%s, theta %g-%g deg, uniform in %s: worst %.3g mean %.3g\n", first ? "Ams_1" : "orders 1-last",
                       ranges[r][0], ranges[r][1], by_cos ? "cos" : "theta", worst, mean);
                CHECK_MSG(worst <= 5e-3 && mean <= 3e-4, "%g-%g: %.3g %.3g", ranges[r][0], ranges[r][1], worst, mean);
            }
    atmos__pphase_free(t);
    atmos_msphase_destroy(m);
    atmos_phase_table_destroy(pt);
    atmos_context_destroy(ctx);
    return test_summary("test_pphase");
}
