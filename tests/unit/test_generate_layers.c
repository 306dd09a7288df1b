/* The layer-cloud generators (docs/clouds.md "Generated clouds"): the cirrus is fibrous and
 * sheared (its column optical depth correlated >= 4x farther along the wind, +x, than across;
 * thin, tau mostly 0.1-2; fall streaks whose ice moves downwind with depth below the
 * generating heads), the stratocumulus a deck of cells (cloud fraction 0.6-0.95, a flat base,
 * a flat top under the inversion, cells 1-3 km apart). Both deterministic for a seed and the
 * same for any thread count. Coarse voxels keep it fast (well under a second). */
#include "atmos/atmos.h"
#include "test.h"
#include "volume/volume_grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SIGMA_ICE 1.82e-6    /* m^2, the 'ice' preset (Riley Table 2) */
#define SIGMA_CLOUD 6.28e-10 /* m^2, the 'cloud' preset */

static double at(const atmos_volume *v, int i, int j, int k) { return vol_voxel(v, &v->field[0], i, j, k); }

/* Column optical depth tau[k * nx + i] of field 0. */
static double *columns(const atmos_volume *v, double sigma)
{
    const int *n = v->desc.dims;
    double *tau = calloc((size_t)n[0] * n[2], sizeof *tau), dy = v->desc.voxel_size_m;
    for (int k = 0; k < n[2]; k++)
        for (int i = 0; i < n[0]; i++)
            for (int j = 0; j < n[1]; j++) tau[(size_t)k * n[0] + i] += at(v, i, j, k) * sigma * dy;
    return tau;
}

/* Autocorrelation length (voxels) of a field f[k * nx + i] along i (axis 0) or k (axis 2):
 * the lag where the normalised autocorrelation first falls below 1/e, linear between lags. */
static double corr_length(const double *f, int nx, int nz, int axis)
{
    double m = 0;
    for (long p = 0; p < (long)nx * nz; p++) m += f[p];
    m /= (double)nx * nz;
    double prev = 1;
    int lmax = (axis == 0 ? nx : nz) / 2;
    for (int l = 1; l < lmax; l++) {
        double c = 0, c0 = 0;
        for (int k = 0; k < nz - (axis == 2 ? l : 0); k++)
            for (int i = 0; i < nx - (axis == 0 ? l : 0); i++) {
                double a = f[(size_t)k * nx + i] - m;
                double b = f[(size_t)(k + (axis == 2 ? l : 0)) * nx + i + (axis == 0 ? l : 0)] - m;
                c += a * b, c0 += a * a;
            }
        c /= c0;
        if (c < exp(-1)) return l - 1 + (prev - exp(-1)) / (prev - c);
        prev = c;
    }
    return lmax;
}

/* The x lag (voxels, in [-lmax, lmax]) that best matches layer j2 to layer j1:
 * argmax over l of sum rho(i, j1, k) rho(i + l, j2, k). */
static int best_lag(const atmos_volume *v, int j1, int j2, int lmax)
{
    const int *n = v->desc.dims;
    double best = -1;
    int arg = 0;
    for (int l = -lmax; l <= lmax; l++) {
        double s = 0;
        for (int k = 0; k < n[2]; k++)
            for (int i = 0; i < n[0]; i++)
                if (i + l >= 0 && i + l < n[0]) s += at(v, i, j1, k) * at(v, i + l, j2, k);
        if (s > best) best = s, arg = l;
    }
    return arg;
}

static long count_diff(const atmos_volume *a, const atmos_volume *b)
{
    const int *n = a->desc.dims;
    if (memcmp(n, b->desc.dims, sizeof a->desc.dims)) return -1;
    long d = 0;
    for (int k = 0; k < n[2]; k++)
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++) d += at(a, i, j, k) != at(b, i, j, k);
    return d;
}

static void test_determinism(const char *preset, double voxel)
{
    atmos_context *c1 = test_context(1, NULL), *c3 = test_context(3, NULL);
    atmos_volume *a = test_generate(c1, preset, 5, voxel), *b = test_generate(c3, preset, 5, voxel), *c = test_generate(c1, preset, 6, voxel);
    if (a && b && c) {
        CHECK_MSG(count_diff(a, b) == 0, "%s: 1 vs 3 threads differ in %ld voxels", preset, count_diff(a, b));
        CHECK_MSG(count_diff(a, c) > 0, "%s: seeds 5 and 6 give the same volume", preset);
    }
    atmos_volume_destroy(a);
    atmos_volume_destroy(b);
    atmos_volume_destroy(c);
    atmos_context_destroy(c1);
    atmos_context_destroy(c3);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void test_cirrus(atmos_context *ctx, uint64_t seed)
{
    const double vox = 100;
    atmos_volume *v = test_generate(ctx, "cirrus", seed, vox);
    if (!v) return;
    CHECK(!strcmp(atmos_volume_field_name(v, 0), "ice"));
    const int *n = v->desc.dims;
    double *tau = columns(v, SIGMA_ICE);
    /* Fibrous along the wind. */
    double lx = corr_length(tau, n[0], n[2], 0), lz = corr_length(tau, n[0], n[2], 2);
    printf("cirrus seed %llu: correlation length along the wind %.0f m, across %.0f m (ratio %.1f)\n",
           (unsigned long long)seed, lx * vox, lz * vox, lx / lz);
    CHECK_MSG(lx >= 4 * lz, "seed %llu: along %.2f, across %.2f voxels", (unsigned long long)seed, lx, lz);
    /* Thin: of the columns with tau >= 0.05, the median >= 0.1 and the 95th percentile <= 2.5;
     * and a sky neither empty nor overcast. */
    long nc = 0, all = (long)n[0] * n[2];
    double *t = malloc(sizeof *t * (size_t)all);
    for (long p = 0; p < all; p++)
        if (tau[p] >= 0.05) t[nc++] = tau[p];
    qsort(t, (size_t)nc, sizeof *t, cmp_double);
    double med = nc ? t[nc / 2] : 0, p95 = nc ? t[(long)(0.95 * (nc - 1))] : 0, frac = (double)nc / all;
    printf("cirrus seed %llu: %.0f %% of the columns with tau >= 0.05; median %.2f, 95th percentile %.2f, max %.2f\n",
           (unsigned long long)seed, 100 * frac, med, p95, nc ? t[nc - 1] : 0);
    CHECK_MSG(frac >= 0.15 && frac <= 0.85, "cover %.2f", frac);
    CHECK_MSG(med >= 0.1 && p95 <= 2.5, "median %.2f p95 %.2f", med, p95);
    free(t);
    /* Fall streaks: the generating heads' level is the highest layer holding >= 30 % of the
     * busiest layer's ice; the ice below it matches the heads at a lag that grows downwind
     * (+x) with depth. */
    double *ls = calloc((size_t)n[1], sizeof *ls), lmaxs = 0;
    for (int j = 0; j < n[1]; j++) {
        for (int k = 0; k < n[2]; k++)
            for (int i = 0; i < n[0]; i++) ls[j] += at(v, i, j, k);
        if (ls[j] > lmaxs) lmaxs = ls[j];
    }
    int jh = n[1] - 1;
    while (jh > 0 && ls[jh] < 0.3 * lmaxs) jh--;
    int lag[4], lagmax = n[0] / 4;
    for (int d = 1; d <= 3; d++) lag[d] = jh - 3 * d >= 0 ? best_lag(v, jh, jh - 3 * d, lagmax) : -999;
    printf("cirrus seed %llu: heads at layer %d; lag of the ice %0.f, %.0f, %.0f m below: %d, %d, %d voxels\n",
           (unsigned long long)seed, jh, 3 * vox, 6 * vox, 9 * vox, lag[1], lag[2], lag[3]);
    CHECK_MSG(lag[1] >= 0 && lag[2] > lag[1] && lag[3] > lag[2] && lag[3] >= 5, "lags %d %d %d", lag[1], lag[2],
              lag[3]);
    free(ls);
    free(tau);
    atmos_volume_destroy(v);
}

/* Cells: the columns at least 0.9 x the deck's 90th-percentile optical depth, 4-connected, of
 * at least 0.1 km^2 (cores of a cell); the mean spacing sqrt(area / cells). */
static int count_cells(const double *tau, int nx, int nz, double thr, int min_pixels, int *lab)
{
    int cells = 0, *stack = malloc(sizeof(int) * (size_t)nx * nz);
    for (long p = 0; p < (long)nx * nz; p++) lab[p] = -1;
    for (long p = 0; p < (long)nx * nz; p++) {
        if (tau[p] < thr || lab[p] >= 0) continue;
        int sp = 0, size = 0;
        stack[sp++] = (int)p, lab[p] = cells;
        while (sp) {
            int q = stack[--sp], i = q % nx, k = q / nx;
            size++;
            int nb[4] = {i > 0 ? q - 1 : -1, i < nx - 1 ? q + 1 : -1, k > 0 ? q - nx : -1, k < nz - 1 ? q + nx : -1};
            for (int e = 0; e < 4; e++)
                if (nb[e] >= 0 && lab[nb[e]] < 0 && tau[nb[e]] >= thr) lab[nb[e]] = cells, stack[sp++] = nb[e];
        }
        cells += size >= min_pixels; /* fragments of a core do not count */
    }
    free(stack);
    return cells;
}

static void test_stratocumulus(atmos_context *ctx, uint64_t seed)
{
    const double vox = 50;
    atmos_volume *v = test_generate(ctx, "stratocumulus", seed, vox);
    if (!v) return;
    CHECK(!strcmp(atmos_volume_field_name(v, 0), "cloud"));
    const int *n = v->desc.dims;
    long all = (long)n[0] * n[2], cloudy = 0;
    double *tau = columns(v, SIGMA_CLOUD);
    int *base = malloc(sizeof(int) * (size_t)all), *top = malloc(sizeof(int) * (size_t)all);
    int jb_min = n[1], jt_max = -1;
    for (int k = 0; k < n[2]; k++)
        for (int i = 0; i < n[0]; i++) {
            long p = (long)k * n[0] + i;
            base[p] = top[p] = -1;
            for (int j = 0; j < n[1]; j++)
                if (at(v, i, j, k) > 0) {
                    if (base[p] < 0) base[p] = j;
                    top[p] = j;
                }
            if (tau[p] >= 1) {
                cloudy++;
                if (base[p] < jb_min) jb_min = base[p];
                if (top[p] > jt_max) jt_max = top[p];
            }
        }
    /* Flat base and flat top: of the cloudy columns, >= 95 % with their lowest cloudy voxel
     * within 1 voxel of the lowest, >= 30 % with their top within 1 voxel of the highest. */
    long flat_base = 0, flat_top = 0;
    for (long p = 0; p < all; p++)
        if (tau[p] >= 1) flat_base += base[p] <= jb_min + 1, flat_top += top[p] >= jt_max - 1;
    double frac = (double)cloudy / all;
    printf("stratocumulus seed %llu: cloud fraction %.2f (tau >= 1); base layer %d (%.0f %% within a voxel), top layer "
           "%d (%.0f %% within a voxel), %.0f m thick\n",
           (unsigned long long)seed, frac, jb_min, 100.0 * flat_base / cloudy, jt_max, 100.0 * flat_top / cloudy,
           (jt_max - jb_min + 1) * vox);
    CHECK_MSG(frac >= 0.6 && frac <= 0.95, "cloud fraction %.2f", frac);
    CHECK_MSG(flat_base >= 0.95 * cloudy, "base not flat: %ld of %ld", flat_base, cloudy);
    CHECK_MSG(flat_top >= 0.3 * cloudy, "top not flat: %ld of %ld", flat_top, cloudy);
    double thick = (jt_max - jb_min + 1) * vox, ybase = v->desc.origin_m[1] + jb_min * vox;
    CHECK_MSG(thick >= 300 && thick <= 600, "deck %.0f m thick", thick);
    CHECK_MSG(ybase >= 1000 && ybase <= 2000, "base at %.0f m", ybase);
    /* Cells 1-3 km apart. */
    double *t = malloc(sizeof *t * (size_t)all);
    memcpy(t, tau, sizeof *t * (size_t)all);
    qsort(t, (size_t)all, sizeof *t, cmp_double);
    int *lab = malloc(sizeof(int) * (size_t)all);
    int cells = count_cells(tau, n[0], n[2], 0.9 * t[(long)(0.9 * (all - 1))], (int)(0.1e6 / (vox * vox)), lab);
    double spacing = sqrt((double)all * vox * vox / (cells ? cells : 1));
    printf("stratocumulus seed %llu: %d cells, spacing %.0f m\n", (unsigned long long)seed, cells, spacing);
    CHECK_MSG(spacing >= 1000 && spacing <= 3000, "cell spacing %.0f m", spacing);
    free(lab);
    free(t);
    free(base);
    free(top);
    free(tau);
    atmos_volume_destroy(v);
}

int main(void)
{
    atmos_context *ctx = test_context(0, NULL);
    for (uint64_t seed = 1; seed <= 2; seed++) test_cirrus(ctx, seed);
    for (uint64_t seed = 1; seed <= 2; seed++) test_stratocumulus(ctx, seed);
    test_determinism("cirrus", 200);
    test_determinism("stratocumulus", 100);
    atmos_context_destroy(ctx);
    return test_summary("test_generate_layers");
}
