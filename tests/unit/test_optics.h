/* Analytic Henyey-Greenstein optics for the unit tests: one particle, quick to build and
 * exactly known, in RGB. Header-only (static inline), included after test.h. */
#ifndef ATMOS_TEST_OPTICS_H
#define ATMOS_TEST_OPTICS_H
#include "atmos/atmos.h"

#include <stdio.h>
#include <string.h>

typedef struct {
    atmos_phase_table *t;
    atmos_msphase *m; /* NULL unless built */
    atmos_volume_optics o;
} test_optics;

/* One HG lobe of asymmetry g, extinction cross-section 1e-9 m^2, single-scattering albedo. */
static inline void test_hg_particle(atmos_particle_desc *p, const char *name, double g, double albedo)
{
    memset(p, 0, sizeof *p);
    snprintf(p->name, sizeof p->name, "%s", name);
    p->kind = ATMOS_PARTICLE_ANALYTIC;
    p->analytic.count = 1;
    p->analytic.kind[0] = ATMOS_PHASE_HG;
    p->analytic.g[0] = g;
    p->analytic.weight[0] = 1;
    p->sigma_ext_m2 = 1e-9;
    p->albedo = albedo;
}

/* Its phase table at the RGB wavelengths and, with ms, its Ams table (64 orders' grid). */
static inline void test_hg_optics(atmos_context *ctx, const char *name, double g, double albedo, int ms,
                                  test_optics *op)
{
    atmos_particle_desc p;
    test_hg_particle(&p, name, g, albedo);
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_phase_table_desc td = {1};
    memset(op, 0, sizeof *op);
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &op->t));
    if (ms) {
        atmos_msphase_desc md = {64, 0, 1};
        CHECK_OK(atmos_msphase_build(ctx, op->t, &md, &op->m));
    }
    op->o.count = 1;
    op->o.phase[0] = op->t;
    op->o.ms[0] = op->m;
}

static inline void test_optics_free(test_optics *op)
{
    atmos_msphase_destroy(op->m);
    atmos_phase_table_destroy(op->t);
}
#endif
