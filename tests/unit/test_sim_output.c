/* The simulation's state written as a volume (src/sim/sim_volume.c): the cells as they are,
 * the condensate split into water and ice by temperature (conserving its mass), and the
 * refined volume whose edges follow the smeared-out field between the cells (a tilted edge
 * whose logarithm falls linearly: its iso-surface is a plane, which the cells' own trilinear
 * reconstruction turns into a staircase), with and without the detail noise. */
#include "atmos/atmos.h"
#include "sim/sim_internal.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SLOPE 0.5   /* the edge's plane: z = SLOPE x + Z0 (cells) */
#define Z0 3.0
#define LAMBDA 0.5  /* e-folding length of q_c above the plane, cells */
#define QTOP 1e-3
#define QISO 1e-5   /* the iso-surface looked for: LAMBDA ln(QTOP / QISO) above the plane */

static atmos_sim *make(atmos_context *c)
{
    atmos_sim_desc d = {.preset = "towering_cumulus", .grid = 16, .seed = 1};
    atmos_sim *s = NULL;
    CHECK_OK(atmos_sim_create(c, &d, &s));
    return s;
}

/* q_c = QTOP below the plane, QTOP exp(-d / LAMBDA) at d cells above it; no rain. */
static void tilted_edge(atmos_sim *s)
{
    for (int k = 0; k < s->nz; k++)
        for (int j = 0; j < s->ny; j++)
            for (int i = 0; i < s->nx; i++) {
                const double d = k - (SLOPE * i + Z0);
                const size_t n = sim_idx(s, i, j, k);
                s->qc[n] = (float)(QTOP * exp(-fmax(d, 0.0) / LAMBDA));
                s->qr[n] = 0;
            }
}

static double voxel(const atmos_volume *v, int f, int I, int J, int K)
{
    const atmos_volume_desc *d = atmos_volume_get_desc(v);
    const double p[3] = {d->origin_m[0] + (I + 0.5) * d->voxel_size_m, d->origin_m[1] + (J + 0.5) * d->voxel_size_m,
                         d->origin_m[2] + (K + 0.5) * d->voxel_size_m};
    return atmos_volume_sample(v, f, p);
}

/* The cells as they are: each voxel q rho0 / m where q > 1e-7, else 0. */
static void check_cells(atmos_context *c, atmos_sim *s)
{
    atmos_volume *v = NULL;
    CHECK_OK(atmos_sim_to_volume(c, s, &v));
    if (!v) return;
    CHECK(atmos_volume_field_count(v) == 2);
    const double m = atmos_particle_mean_mass("cloud");
    double worst = 0;
    for (int k = 0; k < s->nz; k++)
        for (int i = 0; i < s->nx; i += 3) {
            const double q = s->qc[sim_idx(s, i, 5, k)], want = q > 1e-7 ? q * s->rho0[k] / m : 0;
            worst = fmax(worst, fabs(voxel(v, 0, i, k, 5) - want) / (want > 0 ? want : 1));
        }
    CHECK_MSG(worst < 1e-6, "cells: worst relative difference %g", worst);
    atmos_volume_destroy(v);
}

/* Ice by temperature: the published end points, and the condensate's mass conserved. */
static void check_ice(atmos_context *c, atmos_sim *s)
{
    CHECK_NEAR(atmos__sim_ice_fraction(280.0), 0.0, 0);
    CHECK_NEAR(atmos__sim_ice_fraction(273.16), 0.0, 1e-12);
    CHECK_NEAR(atmos__sim_ice_fraction(261.66), 0.75, 1e-12); /* half-way: alpha = 1/4 liquid */
    CHECK_NEAR(atmos__sim_ice_fraction(250.16), 1.0, 1e-12);
    for (int k = 0; k < s->nz; k++) /* condensate at every level: a column of 1 g/kg */
        s->qc[sim_idx(s, 4, 4, k)] = 1e-3f;
    s->out_ice = 1;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_sim_to_volume(c, s, &v));
    s->out_ice = 0;
    if (!v) return;
    CHECK(atmos_volume_field_count(v) == 3 && !strcmp(atmos_volume_field_name(v, 2), "ice"));
    const double mc = atmos_particle_mean_mass("cloud"), mi = atmos_particle_mean_mass("ice");
    int warm = 0, cold = 0;
    double worst = 0;
    for (int k = 0; k < s->nz; k++) {
        const double t = s->th[sim_idx(s, 4, 4, k)] * s->pi0[k];
        const double w = voxel(v, 0, 4, k, 4) * mc, ice = voxel(v, 2, 4, k, 4) * mi, all = 1e-3 * s->rho0[k];
        worst = fmax(worst, fabs(w + ice - all) / all);
        worst = fmax(worst, fabs(ice / all - atmos__sim_ice_fraction(t)));
        if (t > 273.16 && ice == 0) warm++;
        if (t < 250.16 && w == 0) cold++;
    }
    CHECK_MSG(worst < 1e-5, "ice: worst mass or fraction error %g", worst);
    CHECK_MSG(warm > 0 && cold > 0, "ice: %d warm levels without ice, %d cold without water", warm, cold);
    atmos_volume_destroy(v);
}

/* The base state's density at cell-index height z, interpolated as the writer does. */
static double rho_at(const atmos_sim *s, double z)
{
    const double zc = fmin(fmax(z, 0), s->nz - 1);
    const int k0 = (int)zc < s->nz - 1 ? (int)zc : s->nz - 2;
    return s->rho0[k0] + (zc - k0) * (s->rho0[k0 + 1] - s->rho0[k0]);
}

/* The largest distance (cells) between where the column (I, K) of the fine volume (refine r)
 * crosses QISO and the plane LAMBDA ln(QTOP/QISO) above the edge; with linear = 1, of the
 * cells' own trilinear reconstruction sampled at the same places instead. */
static double edge_error(const atmos_sim *s, const atmos_volume *v, int r, int linear)
{
    const double m = atmos_particle_mean_mass("cloud"), off = LAMBDA * log(QTOP / QISO);
    double worst = 0;
    for (int I = 2 * r; I < (s->nx - 6) * r; I++) {
        const double x = (I + 0.5) / r - 0.5, want = SLOPE * x + Z0 + off;
        if (want > s->nz - 3) break;
        double prev = 0, prevz = 0, found = -1;
        for (int J = 0; J < s->nz * r && found < 0; J++) {
            const double z = (J + 0.5) / r - 0.5;
            if (z < 0 || z >= s->nz - 1) continue; /* between the first and the last level */
            double q;
            if (linear) {
                const int i0 = (int)floor(x), k0 = (int)floor(z);
                const double tx = x - i0, tz = z - k0;
                const double a = s->qc[sim_idx(s, i0, 7, k0)], b = s->qc[sim_idx(s, i0 + 1, 7, k0)];
                const double cc = s->qc[sim_idx(s, i0, 7, k0 + 1)], d = s->qc[sim_idx(s, i0 + 1, 7, k0 + 1)];
                q = (1 - tz) * ((1 - tx) * a + tx * b) + tz * ((1 - tx) * cc + tx * d);
            } else {
                q = voxel(v, 0, I, J, 7 * r + r / 2) * m / rho_at(s, z);
            }
            if (J > 0 && prev >= QISO && q < QISO) /* the crossing, log-linear between the samples */
                found = prevz + (z - prevz) * log(prev / QISO) / log(prev / fmax(q, 1e-30));
            prev = q, prevz = z;
        }
        worst = fmax(worst, found < 0 ? 99 : fabs(found - want));
    }
    return worst;
}

/* The refined volume keeps the water of a small cloud (a Gaussian of 0.8 cells: its edge cells
 * are most of it), within 3 %. */
static void check_mass(atmos_context *c, atmos_sim *s)
{
    double cells = 0;
    for (int k = 0; k < s->nz; k++)
        for (int j = 0; j < s->ny; j++)
            for (int i = 0; i < s->nx; i++) {
                const double d2 = (i - 7.3) * (i - 7.3) + (j - 8.1) * (j - 8.1) + (k - 5.6) * (k - 5.6);
                const size_t n = sim_idx(s, i, j, k);
                s->qc[n] = (float)(1e-3 * exp(-d2 / (2 * 0.8 * 0.8)));
                if (s->qc[n] > 1e-7) cells += s->qc[n] * s->rho0[k];
            }
    s->out_refine = 3;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_sim_to_volume(c, s, &v));
    s->out_refine = 1;
    if (!v) return;
    const double m = atmos_particle_mean_mass("cloud");
    double fine = 0;
    for (int K = 0; K < 3 * s->ny; K++)
        for (int J = 0; J < 3 * s->nz; J++)
            for (int I = 0; I < 3 * s->nx; I++) fine += voxel(v, 0, I, J, K) * m / 27;
    printf("mass: the refined volume holds %.4f of the cells' water\n", fine / cells);
    CHECK_MSG(fabs(fine / cells - 1) < 0.03, "mass: the refined volume holds %.3f of the cells' water", fine / cells);
    atmos_volume_destroy(v);
}

static void check_refine(atmos_context *c, atmos_sim *s, int threads_other)
{
    tilted_edge(s);
    const double stairs = edge_error(s, NULL, 3, 1);
    s->out_refine = 3;
    atmos_volume *v = NULL, *w = NULL, *u = NULL;
    CHECK_OK(atmos_sim_to_volume(c, s, &v));
    if (!v) return;
    const atmos_volume_desc *d = atmos_volume_get_desc(v);
    CHECK(d->dims[0] == 3 * s->nx && d->dims[1] == 3 * s->nz && d->dims[2] == 3 * s->ny);
    CHECK_REL(d->voxel_size_m, s->dx / 3, 1e-12);
    const double refined = edge_error(s, v, 3, 0);
    printf("edge: refined %.3f cells from the plane, the cells' trilinear %.3f\n", refined, stairs);
    CHECK_MSG(refined < 0.12 && stairs > 0.2, "edge: refined %.3f cells from the plane, the cells' trilinear %.3f",
              refined, stairs);
    /* at a cell's centre the refined voxel is the cell's value */
    const double m = atmos_particle_mean_mass("cloud");
    const double at = voxel(v, 0, 3 * 5 + 1, 3 * 6 + 1, 3 * 7 + 1), want = s->qc[sim_idx(s, 5, 7, 6)] * s->rho0[6] / m;
    CHECK_REL(at, want, 0.02); /* the water-keeping correction moves it a little */
    /* the detail noise: moves the edge by less than the amplitude, the same bytes again and
     * with another thread count */
    s->out_detail = 0.5;
    CHECK_OK(atmos_sim_to_volume(c, s, &w));
    atmos_context *c2 = test_context(threads_other, NULL);
    CHECK_OK(atmos_sim_to_volume(c2, s, &u));
    atmos_context_destroy(c2);
    s->out_detail = 0, s->out_refine = 1;
    if (!w || !u) goto done;
    const double ragged = edge_error(s, w, 3, 0);
    printf("edge with detail 0.5: %.3f cells from the plane\n", ragged);
    CHECK_MSG(ragged > 0.05 && ragged < 0.5 + 0.05, "detail 0.5: the edge %.3f cells from the plane", ragged);
    int same = 1;
    for (int K = 0; K < d->dims[2] && same; K += 5)
        for (int J = 0; J < d->dims[1] && same; J++)
            for (int I = 0; I < d->dims[0]; I++) same &= voxel(w, 0, I, J, K) == voxel(u, 0, I, J, K);
    CHECK_MSG(same, "detail: the volume depends on the thread count");
done:
    atmos_volume_destroy(u);
    atmos_volume_destroy(w);
    atmos_volume_destroy(v);
}

int main(void)
{
    atmos_context *c = test_context(2, NULL);
    atmos_sim *s = make(c);
    if (s) {
        tilted_edge(s);
        check_cells(c, s);
        check_ice(c, s);
        check_refine(c, s, 1);
        check_mass(c, s);
        /* bad values are refused */
        atmos_sim *bad = NULL;
        atmos_sim_desc d = {.preset = "towering_cumulus", .grid = 16, .seed = 1, .refine = 9};
        CHECK(atmos_sim_create(c, &d, &bad) == ATMOS_E_INVALID_ARG && !bad);
        d.refine = 2, d.detail = 1.5;
        CHECK(atmos_sim_create(c, &d, &bad) == ATMOS_E_INVALID_ARG && !bad);
        /* a refined volume too large to write is refused before the run, not after it:
         * the cumulonimbus at grid 128 has 128 x 128 x 80 cells, x 4^3 = 84 M voxels > 64 M */
        atmos_sim_desc big = {.preset = "cumulonimbus", .grid = 128, .seed = 1, .refine = 4};
        CHECK(atmos_sim_create(c, &big, &bad) == ATMOS_E_LIMIT && !bad);
        atmos_sim_destroy(bad), bad = NULL;
        big.refine = 3; /* 35 M voxels: allowed */
        CHECK(atmos_sim_create(c, &big, &bad) == ATMOS_OK && bad);
        atmos_sim_destroy(bad);
    }
    atmos_sim_destroy(s);
    atmos_context_destroy(c);
    return test_summary("sim_output");
}
