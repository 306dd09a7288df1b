/* The pressure projection: makes the staggered velocity divergence-free exactly (to
 * rounding) for periodic sides and a rigid ground and lid. The discrete Poisson equation
 * L phi = dx div u (L the 7-point Laplacian without 1/dx^2) is diagonal in the horizontal
 * Fourier modes (eigenvalue -lambda = -(4 - 2 cos(2 pi a / nx) - 2 cos(2 pi b / ny))), leaving one
 * tridiagonal system per mode along z with phi's zero-gradient rows at the ground and the lid;
 * then u -= phi[i] - phi[i-1] on every face. The 2-D transforms are FFTW's (one plan of one
 * level, run for every level in parallel: each level's arithmetic is the same whichever thread
 * runs it, so the result does not depend on the thread count). */
#include "sim/sim_internal.h"

#include <complex.h>
#include <fftw3.h>
#include <math.h>

atmos_status atmos__sim_fft_init(atmos_context *ctx, atmos_sim *s)
{
    const int nh = s->nx / 2 + 1;
    s->spec = fftwf_malloc(sizeof(fftwf_complex) * (size_t)nh * s->ny * s->nz);
    if (!s->spec) return atmos__error(ctx, ATMOS_E_NOMEM, "simulate: out of memory for the pressure solver");
    /* planned on scratch arrays (ESTIMATE leaves them alone); UNALIGNED so the plan runs on any level */
    fftwf_complex *c = s->spec;
    const unsigned flags = FFTW_ESTIMATE | FFTW_UNALIGNED;
#pragma omp critical(atmos_fftw_planner)
    {
        s->fft_fwd = fftwf_plan_dft_r2c_2d(s->ny, s->nx, s->s[0], c, flags);
        s->fft_inv = fftwf_plan_dft_c2r_2d(s->ny, s->nx, c, s->s[0], flags);
    }
    if (!s->fft_fwd || !s->fft_inv) return atmos__error(ctx, ATMOS_E_NOMEM, "simulate: FFTW could not plan");
    return ATMOS_OK;
}

void atmos__sim_fft_free(atmos_sim *s)
{
#pragma omp critical(atmos_fftw_planner)
    {
        if (s->fft_fwd) fftwf_destroy_plan(s->fft_fwd);
        if (s->fft_inv) fftwf_destroy_plan(s->fft_inv);
    }
    if (s->spec) fftwf_free(s->spec);
    s->fft_fwd = s->fft_inv = s->spec = NULL;
}

/* dx times the divergence of the cells of level k into d. */
static void divergence(const atmos_sim *s, int k, float *d)
{
    const int nx = s->nx, ny = s->ny;
    const size_t lev = (size_t)nx * ny;
    for (int j = 0; j < ny; j++) {
        const size_t r = sim_idx(s, 0, j, k), rp = sim_idx(s, 0, j + 1 == ny ? 0 : j + 1, k);
        for (int i = 0; i < nx; i++) {
            const size_t n = r + i, ip = r + (i + 1 == nx ? 0 : i + 1);
            d[n] = (s->u[ip] - s->u[n]) + (s->v[rp + i] - s->v[n]) + (s->w[n + lev] - s->w[n]);
        }
    }
}

double atmos__sim_max_divergence(const atmos_sim *s)
{
    for (int k = 0; k < s->nz; k++) divergence(s, k, s->s[7]);
    double m = 0;
    for (size_t n = 0; n < s->n; n++) m = fmax(m, fabs(s->s[7][n]));
    return m;
}

/* Solves (phi[k+1] - 2 phi[k] + phi[k-1]) - lam phi[k] = r[k] along one column of modes
 * (stride between levels), zero gradient at both ends, in place, times `norm` (the inverse
 * transform's 1 / (nx ny)); tmp holds 3 nz doubles. */
static void column(fftwf_complex *r, size_t stride, int nz, double lam, double norm, double *tmp)
{
    double *cp = tmp, *dre = tmp + nz, *dim = tmp + 2 * nz;
    for (int k = 0; k < nz; k++) {
        dre[k] = crealf(r[(size_t)k * stride]);
        dim[k] = cimagf(r[(size_t)k * stride]);
    }
    if (lam < 1e-9) { /* the mean mode, defined up to a constant: phi[0] = 0, then row by row */
        double pr = 0, pi = 0, qr = dre[0], qi = dim[0];
        r[0] = 0;
        for (int k = 1; k < nz; k++) {
            r[(size_t)k * stride] = (float)(qr * norm) + I * (float)(qi * norm);
            const double nr = dre[k] + 2 * qr - pr, ni = dim[k] + 2 * qi - pi;
            pr = qr, pi = qi, qr = nr, qi = ni;
        }
        return;
    }
    for (int k = 0; k < nz; k++) {
        const double b = (k == 0 || k == nz - 1 ? -1.0 : -2.0) - lam;
        const double m = k ? b - cp[k - 1] : b;
        cp[k] = 1.0 / m;
        dre[k] = (dre[k] - (k ? dre[k - 1] : 0)) / m;
        dim[k] = (dim[k] - (k ? dim[k - 1] : 0)) / m;
    }
    for (int k = nz - 2; k >= 0; k--) {
        dre[k] -= cp[k] * dre[k + 1];
        dim[k] -= cp[k] * dim[k + 1];
    }
    for (int k = 0; k < nz; k++) r[(size_t)k * stride] = (float)(dre[k] * norm) + I * (float)(dim[k] * norm);
}

/* u -= grad phi on the faces of level k (w stays 0 at the ground and the lid); returns the
 * level's largest |u|, |v|, |w| afterwards (the next step's time step). */
static float gradient(atmos_sim *s, int k, const float *d)
{
    const int nx = s->nx, ny = s->ny;
    const size_t lev = (size_t)nx * ny;
    float m = 0;
    for (int j = 0; j < ny; j++) {
        const size_t r = sim_idx(s, 0, j, k), rm = sim_idx(s, 0, j ? j - 1 : ny - 1, k);
        for (int i = 0; i < nx; i++) {
            const size_t n = r + i;
            s->u[n] -= d[n] - d[r + (i ? i - 1 : nx - 1)];
            s->v[n] -= d[n] - d[rm + i];
            if (k > 0) s->w[n] -= d[n] - d[n - lev];
            m = fmaxf(m, fmaxf(fabsf(s->u[n]), fmaxf(fabsf(s->v[n]), fabsf(s->w[n]))));
        }
    }
    return m;
}

void atmos__sim_project(atmos_sim *s)
{
    const int nx = s->nx, ny = s->ny, nz = s->nz, nh = nx / 2 + 1;
    const size_t lev = (size_t)nx * ny, clev = (size_t)nh * ny;
    float *d = s->s[7];
    fftwf_complex *c = s->spec;
    SIM_FOR
    for (int k = 0; k < nz; k++) {
        divergence(s, k, d);
        fftwf_execute_dft_r2c(s->fft_fwd, d + k * lev, c + k * clev);
    }
    atmos__sim_sync(s);
    const double norm = 1.0 / ((double)nx * ny);
    SIM_FOR
    for (int b = 0; b < ny; b++) {
        double tmp[3 * 2 * ATMOS_SIM_MAX_GRID]; /* nz <= 2 ATMOS_SIM_MAX_GRID */
        for (int a = 0; a < nh; a++) {
            const double lam = 4.0 - 2.0 * cos(2.0 * ATMOS_PI * a / nx) - 2.0 * cos(2.0 * ATMOS_PI * b / ny);
            column(c + (size_t)b * nh + a, clev, nz, lam, norm, tmp);
        }
    }
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k < nz; k++) fftwf_execute_dft_c2r(s->fft_inv, c + k * clev, d + k * lev);
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
