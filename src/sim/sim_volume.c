/* The simulation's state as an atmos volume: "cloud", "rain" (and "ice") number densities
 * eta = q rho / m (rho the base-state air density of the level, m the particle type's mean
 * mass, atmos_particle_mean_mass: the WRF reader's conversion), y up. Optionally refined (the
 * mixing ratios interpolated in their logarithm), textured (sampled at places moved by a
 * fractal noise) and with the condensate split into water and ice by temperature
 * (atmos_sim_desc). */
#include "sim/sim_internal.h"
#include "volume/generator.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SIM_Q_CUT 1e-7f    /* mixing ratios below this are written as 0 (kg/kg) */
#define SIM_Q_FLOOR 1e-10f /* what an empty cell counts as in the logarithm's interpolation */

/* The written fields' mixing ratios per cell (kg/kg; cut below SIM_Q_CUT), nf of them:
 * cloud water, rain and, with ice, cloud ice. */
static void cell_fields(const atmos_sim *s, float *q[3], int nf)
{
    for (int k = 0; k < s->nz; k++)
        for (int j = 0; j < s->ny; j++)
            for (int i = 0; i < s->nx; i++) {
                const size_t n = sim_idx(s, i, j, k);
                const float c = s->qc[n] > SIM_Q_CUT ? s->qc[n] : 0.0f, r = s->qr[n] > SIM_Q_CUT ? s->qr[n] : 0.0f;
                const float f = nf > 2 && c > 0 ? (float)atmos__sim_ice_fraction(s->th[n] * s->pi0[k]) : 0.0f;
                q[0][n] = c - c * f, q[1][n] = r;
                if (nf > 2) q[2][n] = c * f;
            }
}

/* Trilinear interpolation of a per-cell array at (x, y, z) in cell-index space (x, y wrapped,
 * z clamped). */
static float cell_trilinear(const atmos_sim *s, const float *a, double x, double y, double z)
{
    const double fx = floor(x), fy = floor(y);
    double zc = z < 0 ? 0 : z > s->nz - 1 ? s->nz - 1 : z;
    int k0 = (int)floor(zc);
    if (k0 > s->nz - 2) k0 = s->nz - 2;
    const double tx = x - fx, ty = y - fy, tz = zc - k0;
    int i0 = (int)fx % s->nx, j0 = (int)fy % s->ny;
    if (i0 < 0) i0 += s->nx;
    if (j0 < 0) j0 += s->ny;
    const int i1 = i0 + 1 == s->nx ? 0 : i0 + 1, j1 = j0 + 1 == s->ny ? 0 : j0 + 1;
    double v = 0;
    for (int c = 0; c < 8; c++) {
        const int i = c & 1 ? i1 : i0, j = c & 2 ? j1 : j0, k = k0 + (c >> 2);
        const double w = (c & 1 ? tx : 1 - tx) * (c & 2 ? ty : 1 - ty) * (c & 4 ? tz : 1 - tz);
        v += w * a[sim_idx(s, i, j, k)];
    }
    return (float)v;
}

/* One refined field: voxel (I, J, K) (x, up, y of the model) at the cell-index point
 * ((I + 0.5) / r - 0.5, ...), moved by the detail noise, its mixing ratio exp of the
 * interpolated logarithm, cut below SIM_Q_CUT, times rho0 / m (rho0 interpolated between levels). */
static void refine_field(const atmos_sim *s, const float *lq, double mass, float *out, int threads)
{
    const int r = s->out_refine > 0 ? s->out_refine : 1, NX = r * s->nx, NZ = r * s->nz, NY = r * s->ny;
    const double a = 2.0 * s->out_detail;
    int octaves = 1;
    while (octaves < 6 && (1 << (octaves - 1)) < r) octaves++;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int K = 0; K < NY; K++)
        for (int J = 0; J < NZ; J++) {
            float *row = out + ((size_t)K * NZ + J) * NX;
            const double y = (K + 0.5) / r - 0.5, z = (J + 0.5) / r - 0.5;
            const double zc = z < 0 ? 0 : z > s->nz - 1 ? s->nz - 1 : z;
            const int k0 = (int)zc < s->nz - 1 ? (int)zc : s->nz - 2;
            const double rho = s->rho0[k0] + (zc - k0) * (s->rho0[k0 + 1] - s->rho0[k0]);
            for (int I = 0; I < NX; I++) {
                double px = (I + 0.5) / r - 0.5, py = y, pz = z;
                if (a > 0) { /* the warp: three noises, features from a cell down to a voxel */
                    px += a * (atmos__gen_fbm3(0xA11CE, px, py, pz, octaves, 0.5) - 0.5);
                    py += a * (atmos__gen_fbm3(0xB0B, px, py, pz, octaves, 0.5) - 0.5);
                    pz += a * (atmos__gen_fbm3(0xCAFE, px, py, pz, octaves, 0.5) - 0.5);
                }
                const float q = expf(cell_trilinear(s, lq, px, py, pz));
                row[I] = q > SIM_Q_CUT ? (float)(q * rho / mass) : 0.0f;
            }
        }
}

/* Keeps the refined field's water: the geometric mean between cells is below the cells' own
 * (arithmetic) mean, most at a cloud's edge, where a cell next to an empty one would lose
 * most of its water. Each cell's ratio of its number density to its voxels' mean (1 where it or
 * they are empty), interpolated trilinearly at every voxel, multiplies the voxel: smooth, so
 * no cell's block shows. eta: the cells' number densities; ratio: n floats of scratch. */
static void conserve(const atmos_sim *s, const float *eta, float *ratio, float *buf, int threads)
{
    const int r = s->out_refine > 0 ? s->out_refine : 1, NX = r * s->nx, NZ = r * s->nz;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int j = 0; j < s->ny; j++)
        for (int k = 0; k < s->nz; k++)
            for (int i = 0; i < s->nx; i++) {
                double sum = 0;
                for (int c = 0; c < r * r * r; c++) {
                    const int I = i * r + c % r, J = k * r + (c / r) % r, K = j * r + c / (r * r);
                    sum += buf[((size_t)K * NZ + J) * NX + I];
                }
                const size_t n = sim_idx(s, i, j, k);
                ratio[n] = eta[n] > 0 && sum > 0 ? (float)(eta[n] * r * r * r / sum) : 1.0f;
            }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int K = 0; K < r * s->ny; K++)
        for (int J = 0; J < NZ; J++) {
            float *row = buf + ((size_t)K * NZ + J) * NX;
            for (int I = 0; I < NX; I++)
                if (row[I] > 0)
                    row[I] *= cell_trilinear(s, ratio, (I + 0.5) / r - 0.5, (K + 0.5) / r - 0.5, (J + 0.5) / r - 0.5);
        }
}

/* A field's voxels into buf: the cells as they are (refine 1, no detail), else refined with
 * its water kept; q (the cells' mixing ratios) and scratch (n floats) are overwritten. */
static void field_voxels(const atmos_sim *s, float *q, float *scratch, double mass, float *buf, int threads)
{
    if ((s->out_refine <= 1) && !(s->out_detail > 0)) {
        for (int j = 0; j < s->ny; j++) /* volume voxel (i, k, j): x fastest, then up, then y */
            for (int k = 0; k < s->nz; k++) {
                const float c = (float)(s->rho0[k] / mass);
                float *row = buf + ((size_t)j * s->nz + k) * s->nx;
                const float *src = q + sim_idx(s, 0, j, k);
                for (int i = 0; i < s->nx; i++) row[i] = src[i] > 0 ? src[i] * c : 0.0f;
            }
        return;
    }
    for (size_t n = 0; n < s->n; n++) {
        scratch[n] = (float)(q[n] * s->rho0[n / ((size_t)s->nx * s->ny)] / mass); /* the cells' number densities */
        q[n] = logf(q[n] > SIM_Q_FLOOR ? q[n] : SIM_Q_FLOOR);
    }
    refine_field(s, q, mass, buf, threads);
    conserve(s, scratch, q, buf, threads);
}

static atmos_status fill_fields(atmos_context *ctx, const atmos_sim *s, atmos_volume *v, const int dims[3])
{
    static const char *const names[3] = {"cloud", "rain", "ice"};
    const int nf = s->out_ice ? 3 : 2;
    const size_t nv = (size_t)dims[0] * dims[1] * dims[2];
    float *q[3] = {NULL, NULL, NULL}, *buf = malloc(nv * sizeof *buf), *scratch = malloc(s->n * sizeof(float));
    int ok = buf != NULL && scratch != NULL;
    for (int f = 0; f < nf; f++) ok &= (q[f] = malloc(s->n * sizeof(float))) != NULL;
    atmos_status st = ok ? ATMOS_OK : atmos__error(ctx, ATMOS_E_NOMEM, "simulate: out of memory for the volume");
    if (ok) cell_fields(s, q, nf);
    for (int f = 0; f < nf && st == ATMOS_OK; f++) {
        int index = 0;
        st = atmos_volume_add_field(ctx, v, names[f], names[f], &index);
        if (st != ATMOS_OK) break;
        field_voxels(s, q[f], scratch, atmos_particle_mean_mass(names[f]), buf, atmos__threads(ctx));
        const int off[3] = {0, 0, 0};
        st = atmos_volume_set_dense(ctx, v, index, off, dims, buf, 1.0f);
    }
    for (int f = 0; f < nf; f++) free(q[f]);
    free(scratch);
    free(buf);
    return st;
}

atmos_status atmos_sim_to_volume(atmos_context *ctx, const atmos_sim *s, atmos_volume **out)
{
    if (!s || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: missing argument");
    *out = NULL;
    const int r = s->out_refine > 0 ? s->out_refine : 1;
    const int dims[3] = {r * s->nx, r * s->nz, r * s->ny};
    if ((long)dims[0] * dims[1] * dims[2] > SIM_MAX_VOXELS)
        return atmos__error(ctx, ATMOS_E_LIMIT,
                            "simulate: refine %d makes %d x %d x %d voxels, more than %ld M: a smaller refine or grid", r,
                            dims[0], dims[1], dims[2], SIM_MAX_VOXELS >> 20);
    atmos_volume_desc d;
    memset(&d, 0, sizeof d);
    d.dims[0] = dims[0], d.dims[1] = dims[1], d.dims[2] = dims[2];
    d.voxel_size_m = s->dx / r;
    d.origin_m[0] = -0.5 * s->nx * s->dx;
    d.origin_m[2] = -0.5 * s->ny * s->dx;
    d.periodic = 1; /* the model's sides are periodic (sim_pressure.c) */
    atmos_volume *v = NULL;
    atmos_status st = atmos_volume_create(ctx, &d, &v);
    if (st == ATMOS_OK) st = fill_fields(ctx, s, v, dims);
    if (st == ATMOS_OK) st = atmos_volume_finalize(ctx, v);
    if (st != ATMOS_OK) {
        atmos_volume_destroy(v);
        return st;
    }
    *out = v;
    return ATMOS_OK;
}

atmos_status atmos_simulate(atmos_context *ctx, const atmos_sim_desc *desc, atmos_volume **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: missing output");
    *out = NULL;
    atmos_sim *s = NULL;
    atmos_status st = atmos_sim_create(ctx, desc, &s);
    if (st != ATMOS_OK) return st;
    const double minutes = desc->minutes > 0 ? desc->minutes : atmos_sim_preset_minutes(desc->preset);
    st = atmos_sim_run(ctx, s, minutes * 60.0);
    if (st == ATMOS_OK) {
        atmos_sim_stats ss;
        atmos_sim_get_stats(s, &ss);
        if (ss.max_qc < 1e-5 && ss.max_qr < 1e-5) /* nothing a renderer would see */
            atmos__log(ctx, ATMOS_LOG_WARN,
                       "simulate: %s after %g minutes has no cloud or rain yet: the volume is empty (the first cloud "
                       "forms after about %g minutes at grid 64)",
                       desc->preset, minutes, atmos_sim_preset_first_cloud_minutes(desc->preset));
        st = atmos_sim_to_volume(ctx, s, out);
    }
    atmos_sim_destroy(s);
    return st;
}
