/* The pressure projection: makes the staggered velocity satisfy the anelastic continuity
 * equation div(rho0 u) = 0 exactly (to rounding; Ogura & Phillips 1962, J. Atmos. Sci. 19,
 * 173) for periodic sides and a rigid ground and lid, rho0(z) the base state's density (its
 * ratio to the ground's: a at the cell centres, b on the w faces, sim_sounding). The discrete
 * equation div(rho0 grad phi) = dx div(rho0 u) (without 1/dx^2) is diagonal in the horizontal
 * Fourier modes (eigenvalue -lambda a_k, lambda = 4 - 2 cos(2 pi a / nx) - 2 cos(2 pi b / ny)),
 * leaving one tridiagonal system per mode along z, b_(k+1) (phi_(k+1) - phi_k) -
 * b_k (phi_k - phi_(k-1)) - lambda a_k phi_k = r_k, with b = 0 at the ground and the lid
 * (zero gradient); then u -= phi[i] - phi[i-1] on every face. The 2-D transforms are FFTW's (one plan of one
 * level, run for every level in parallel: each level's arithmetic is the same whichever thread
 * runs it, so the result does not depend on the thread count). */
#include "sim/sim_internal.h"

#include <complex.h>
#include <fftw3.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#define PROJ_CLONES ATMOS_CLONES

atmos_status atmos__sim_fft_init(atmos_context *ctx, atmos_sim *s)
{
    const int nh = s->nx / 2 + 1;
    /* on 2 MB pages where the system gives them: the column solves stride through the levels */
    s->spec = atmos__sim_alloc(sizeof(fftwf_complex) * (size_t)nh * s->ny * s->nz);
    s->colbuf = malloc(sizeof(double) * SIM_COLUMN_SCRATCH(s->nz) * (size_t)(s->threads > 1 ? s->threads : 1));
    if (!s->spec || !s->colbuf) return atmos__error(ctx, ATMOS_E_NOMEM, "simulate: out of memory for the pressure solver");
    /* planned on scratch arrays (ESTIMATE leaves them alone, and chooses the same plan every
     * time): one pair for the levels aligned as the (64-byte aligned) arrays' starts, whose
     * SIMD codelets need that, and one pair (UNALIGNED) for any level */
    fftwf_complex *c = s->spec;
    const unsigned flags = FFTW_ESTIMATE;
#pragma omp critical(atmos_fftw_planner)
    {
        s->fft_fwd = fftwf_plan_dft_r2c_2d(s->ny, s->nx, s->s[0], c, flags);
        s->fft_inv = fftwf_plan_dft_c2r_2d(s->ny, s->nx, c, s->s[0], flags);
        s->fft_fwd_u = fftwf_plan_dft_r2c_2d(s->ny, s->nx, s->s[0], c, flags | FFTW_UNALIGNED);
        s->fft_inv_u = fftwf_plan_dft_c2r_2d(s->ny, s->nx, c, s->s[0], flags | FFTW_UNALIGNED);
    }
    if (!s->fft_fwd || !s->fft_inv || !s->fft_fwd_u || !s->fft_inv_u)
        return atmos__error(ctx, ATMOS_E_NOMEM, "simulate: FFTW could not plan");
    return ATMOS_OK;
}

void atmos__sim_fft_free(atmos_sim *s)
{
#pragma omp critical(atmos_fftw_planner)
    {
        if (s->fft_fwd) fftwf_destroy_plan(s->fft_fwd);
        if (s->fft_inv) fftwf_destroy_plan(s->fft_inv);
        if (s->fft_fwd_u) fftwf_destroy_plan(s->fft_fwd_u);
        if (s->fft_inv_u) fftwf_destroy_plan(s->fft_inv_u);
    }
    free(s->spec);
    free(s->colbuf);
    s->colbuf = NULL;
    s->fft_fwd = s->fft_inv = s->fft_fwd_u = s->fft_inv_u = s->spec = NULL;
}

/* dx times the divergence of rho0 u (relative to the ground's density) of the cells of level k
 * into d (the row's last cell wraps). */
PROJ_CLONES static void divergence(const atmos_sim *s, int k, float *restrict d)
{
    const int nx = s->nx, ny = s->ny;
    const size_t lev = (size_t)nx * ny;
    const float *restrict u = s->u, *restrict v = s->v, *restrict w = s->w;
    const float a = (float)s->rho_c[k], b0 = (float)s->rho_f[k], b1 = (float)s->rho_f[k + 1];
    for (int j = 0; j < ny; j++) {
        const size_t r = sim_idx(s, 0, j, k), rp = sim_idx(s, 0, j + 1 == ny ? 0 : j + 1, k);
        for (size_t n = r; n + 1 < r + nx; n++)
            d[n] = a * ((u[n + 1] - u[n]) + (v[rp + n - r] - v[n])) + (b1 * w[n + lev] - b0 * w[n]);
        const size_t n = r + nx - 1;
        d[n] = a * ((u[r] - u[n]) + (v[rp + nx - 1] - v[n])) + (b1 * w[n + lev] - b0 * w[n]);
    }
}

double atmos__sim_max_divergence(const atmos_sim *s)
{
    for (int k = 0; k < s->nz; k++) divergence(s, k, s->s[7]);
    double m = 0;
    for (size_t n = 0; n < s->n; n++) m = fmax(m, fabs(s->s[7][n]));
    return m;
}

/* Solves b[k+1] (phi[k+1] - phi[k]) - b[k] (phi[k] - phi[k-1]) = r[k] along one column of
 * modes (stride between levels), b[0] = b[nz] = 0, in place, times `norm` (the inverse
 * transform's 1 / (nx ny)): the mean mode (lam = 0), defined up to a constant, with phi[0] = 0
 * and then row by row through the fluxes F[k+1] = b[k+1] (phi[k+1] - phi[k]) = F[k] + r[k]. */
static void mean_column(fftwf_complex *r, size_t stride, int nz, const double *b, double norm)
{
    double pr = 0, pi = 0, fr = 0, fi = 0;
    for (int k = 0; k < nz; k++) {
        const double dr = crealf(r[(size_t)k * stride]), di = cimagf(r[(size_t)k * stride]);
        r[(size_t)k * stride] = (float)(pr * norm) + I * (float)(pi * norm);
        if (k + 1 == nz) break;
        fr += dr, fi += di;
        pr += fr / b[k + 1], pi += fi / b[k + 1];
    }
}

/* The system with lam (Thomas algorithm) for SIM_CW columns of modes side by side,
 * r[0..SIM_CW) at each level, lam > 0 each, a and b the densities (the file's header); tmp
 * holds 3 nz SIM_CW doubles. Every column's arithmetic is the one-column algorithm's, the
 * columns are independent lanes (vectorised). */
PROJ_CLONES static void columns(fftwf_complex *r, size_t stride, int nz, const double *lam, const double *a,
                                const double *b, double norm, double *tmp)
{
    double(*cp)[SIM_CW] = (double(*)[SIM_CW])tmp, (*dre)[SIM_CW] = (double(*)[SIM_CW])(tmp + (size_t)nz * SIM_CW),
        (*dim)[SIM_CW] = (double(*)[SIM_CW])(tmp + 2 * (size_t)nz * SIM_CW);
    for (int k = 0; k < nz; k++) {
        const float *q = (const float *)(r + (size_t)k * stride);
        for (int l = 0; l < SIM_CW; l++) dre[k][l] = q[2 * l], dim[k][l] = q[2 * l + 1];
    }
    for (int k = 0; k < nz; k++) {
        const double lo = b[k], up = b[k + 1], d = -(lo + up);
        for (int l = 0; l < SIM_CW; l++) {
            const double diag = d - lam[l] * a[k];
            const double m = k ? diag - lo * cp[k - 1][l] : diag;
            cp[k][l] = up / m;
            dre[k][l] = (dre[k][l] - (k ? lo * dre[k - 1][l] : 0)) / m;
            dim[k][l] = (dim[k][l] - (k ? lo * dim[k - 1][l] : 0)) / m;
        }
    }
    for (int k = nz - 2; k >= 0; k--)
        for (int l = 0; l < SIM_CW; l++) {
            dre[k][l] -= cp[k][l] * dre[k + 1][l];
            dim[k][l] -= cp[k][l] * dim[k + 1][l];
        }
    for (int k = 0; k < nz; k++) {
        float *q = (float *)(r + (size_t)k * stride);
        for (int l = 0; l < SIM_CW; l++) q[2 * l] = (float)(dre[k][l] * norm), q[2 * l + 1] = (float)(dim[k][l] * norm);
    }
}

/* The modes (a, b), a = 0 .. nh - 1, of row b of the spectrum, SIM_CW columns at a time; a group
 * with the mean mode (0, 0), and the last group if short, go through a copy whose spare lanes
 * repeat a mode of the group (solved and discarded). tmp holds SIM_COLUMN_SCRATCH(nz) doubles. */
static void mode_row(const atmos_sim *s, fftwf_complex *c, size_t clev, int b, double norm, double *tmp)
{
    const int nx = s->nx, ny = s->ny, nz = s->nz;
    const int nh = nx / 2 + 1;
    fftwf_complex *pad = (fftwf_complex *)(tmp + 3 * (size_t)nz * SIM_CW);
    for (int a0 = 0; a0 < nh; a0 += SIM_CW) {
        const int n = nh - a0 < SIM_CW ? nh - a0 : SIM_CW, mean = a0 == 0 && b == 0;
        int src[SIM_CW];
        double lam[SIM_CW];
        for (int l = 0; l < SIM_CW; l++) {
            src[l] = l >= n ? n - 1 : (mean && l == 0 ? 1 : l); /* nh >= 3: lane 1 exists */
            const int a = a0 + src[l];
            lam[l] = 4.0 - 2.0 * cos(2.0 * ATMOS_PI * a / nx) - 2.0 * cos(2.0 * ATMOS_PI * b / ny);
        }
        fftwf_complex *r = c + (size_t)b * nh + a0;
        if (mean) mean_column(r, clev, nz, s->rho_f, norm);
        if (n == SIM_CW && !mean) {
            columns(r, clev, nz, lam, s->rho_c, s->rho_f, norm, tmp);
            continue;
        }
        for (int k = 0; k < nz; k++)
            for (int l = 0; l < SIM_CW; l++) pad[(size_t)k * SIM_CW + l] = r[(size_t)k * clev + src[l]];
        columns(pad, SIM_CW, nz, lam, s->rho_c, s->rho_f, norm, tmp);
        for (int k = 0; k < nz; k++)
            for (int l = mean; l < n; l++) r[(size_t)k * clev + l] = pad[(size_t)k * SIM_CW + l];
    }
}

/* u -= grad phi on the faces of level k (w stays 0 at the ground and the lid); returns the
 * level's largest |u|, |v|, |w| afterwards (the next step's time step; a NaN is passed over,
 * as fmaxf would). */
static inline float amax(float m, float a)
{
    a = fabsf(a);
    return a > m ? a : m;
}

PROJ_CLONES static float gradient(atmos_sim *s, int k, const float *restrict d)
{
    const int nx = s->nx, ny = s->ny;
    const size_t lev = (size_t)nx * ny;
    float *restrict u = s->u, *restrict v = s->v, *restrict w = s->w;
    float m = 0;
    for (int j = 0; j < ny; j++) {
        const size_t r = sim_idx(s, 0, j, k), rm = sim_idx(s, 0, j ? j - 1 : ny - 1, k);
        u[r] -= d[r] - d[r + nx - 1];
        for (size_t n = r + 1; n < r + nx; n++) u[n] -= d[n] - d[n - 1];
        for (size_t i = 0; i < (size_t)nx; i++) v[r + i] -= d[r + i] - d[rm + i];
        if (k > 0)
            for (size_t n = r; n < r + nx; n++) w[n] -= d[n] - d[n - lev];
        for (size_t n = r; n < r + nx; n++) m = amax(amax(amax(m, u[n]), v[n]), w[n]);
    }
    return m;
}

/* Whether a level's arrays are aligned as the plans' were (their starts, 64-byte aligned:
 * atmos__sim_alloc), so that the aligned plans may run on it: a matter of the grid's size
 * only, never of where the arrays are or of the thread that runs the level. */
static int aligned(float *r, fftwf_complex *c)
{
    return fftwf_alignment_of(r) == 0 && fftwf_alignment_of((float *)c) == 0;
}

void atmos__sim_project(atmos_sim *s)
{
    const int nx = s->nx, ny = s->ny, nz = s->nz, nh = nx / 2 + 1;
    const size_t lev = (size_t)nx * ny, clev = (size_t)nh * ny;
    float *d = s->s[7];
    fftwf_complex *c = s->spec;
    SIM_FOR
    for (int k = 0; k < nz; k++) {
        float *dk = d + k * lev;
        fftwf_complex *ck = c + k * clev;
        divergence(s, k, d);
        fftwf_execute_dft_r2c(aligned(dk, ck) ? s->fft_fwd : s->fft_fwd_u, dk, ck);
    }
    atmos__sim_sync(s);
    const double norm = 1.0 / ((double)nx * ny);
    SIM_FOR
    for (int b = 0; b < ny; b++) {
        mode_row(s, c, clev, b, norm, s->colbuf + (size_t)omp_get_thread_num() * SIM_COLUMN_SCRATCH(nz));
    }
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k < nz; k++) {
        float *dk = d + k * lev;
        fftwf_complex *ck = c + k * clev;
        fftwf_execute_dft_c2r(aligned(dk, ck) ? s->fft_inv : s->fft_inv_u, ck, dk);
    }
    atmos__sim_sync(s);
    double *lm = s->part;
    SIM_FOR
    for (int k = 0; k < nz; k++) lm[k] = gradient(s, k, d);
    atmos__sim_sync(s);
#pragma omp master
    {
        float m = 0; /* the lid's w is 0 */
        for (int k = 0; k < nz; k++) m = fmaxf(m, (float)lm[k]);
        s->vmax = m; /* read after the parallel region */
    }
}
