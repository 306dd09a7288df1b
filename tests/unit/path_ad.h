/* An independent adding-doubling solver for the test of the path tracer: a homogeneous
 * plane-parallel slab with Henyey-Greenstein scattering, azimuth-averaged (the m = 0
 * Fourier term, which is the whole field for a collimated beam at normal incidence).
 *
 * Method (van de Hulst 1980; Wiscombe 1976 for the diamond initialisation):
 *  - directions: N-point Gauss-Legendre cosines on (0, 1) per hemisphere, plus the
 *    incident direction mu0 with a vanishing quadrature weight eps, so that the response
 *    to a collimated beam is one column of the operators (column / eps is exact because
 *    every scattered term of that column is proportional to eps);
 *  - redistribution: h(mu, mu') = sum_l (2l+1)/(4 pi) chi_l P_l(mu) P_l(mu') with
 *    delta-M scaling (Wiscombe 1977) keeping chi_0..chi_{2N-1}, so the discrete phase
 *    matrix is normalised exactly by the quadrature;
 *  - thin layer of depth tau / 2^n by the diamond-difference equations, then n doublings
 *    R' = R + T (I - R R)^-1 R T, T' = T (I - R R)^-1 T (a homogeneous layer reflects
 *    the same from both sides).
 * Operators act on vectors of radiances at the quadrature cosines, the weights built in.
 */
#ifndef ATMOS_TEST_PATH_AD_H
#define ATMOS_TEST_PATH_AD_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define AD_MAXN 65 /* quadrature points + the incident direction */

typedef struct {
    int D;                 /* directions: 0 = incident (weight eps), 1..N Gauss */
    double mu[AD_MAXN], w[AD_MAXN];
    double R[AD_MAXN * AD_MAXN], T[AD_MAXN * AD_MAXN];
    double refl, trans;    /* diffuse reflectance and transmittance (fluxes / incident flux) */
    double radiance_up[AD_MAXN];   /* reflected radiance per unit incident irradiance at mu[i] */
    double radiance_down[AD_MAXN]; /* diffusely transmitted radiance, same units */
} ad_result;

/* Gauss-Legendre nodes and weights on (0, 1). */
static void ad_gauss01(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(3.14159265358979323846 * (i + 0.75) / (n + 0.5)), pp = 1;
        for (int it = 0; it < 100; it++) {
            double p0 = 1, p1 = z;
            for (int l = 2; l <= n; l++) {
                double p2 = ((2 * l - 1) * z * p1 - (l - 1) * p0) / l;
                p0 = p1, p1 = p2;
            }
            pp = n * (z * p1 - p0) / (z * z - 1);
            double dz = p1 / pp;
            z -= dz;
            if (fabs(dz) < 1e-15) break;
        }
        x[i] = 0.5 * (1 - z);
        w[i] = 1.0 / ((1 - z * z) * pp * pp);
    }
}

/* out = a b (D x D). */
static void ad_mul(int D, const double *a, const double *b, double *out)
{
    for (int i = 0; i < D; i++)
        for (int j = 0; j < D; j++) {
            double s = 0;
            for (int k = 0; k < D; k++) s += a[i * D + k] * b[k * D + j];
            out[i * D + j] = s;
        }
}

/* Solves A X = B in place (A: n x n, B: n x m) by Gaussian elimination with partial
 * pivoting; A is destroyed. Returns 0 if singular. */
static int ad_solve(int n, int m, double *A, double *B)
{
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(A[r * n + c]) > fabs(A[p * n + c])) p = r;
        if (A[p * n + c] == 0) return 0;
        if (p != c) {
            for (int k = 0; k < n; k++) {
                double t = A[c * n + k];
                A[c * n + k] = A[p * n + k], A[p * n + k] = t;
            }
            for (int k = 0; k < m; k++) {
                double t = B[c * m + k];
                B[c * m + k] = B[p * m + k], B[p * m + k] = t;
            }
        }
        for (int r = 0; r < n; r++) {
            if (r == c) continue;
            double f = A[r * n + c] / A[c * n + c];
            if (f == 0) continue;
            for (int k = c; k < n; k++) A[r * n + k] -= f * A[c * n + k];
            for (int k = 0; k < m; k++) B[r * m + k] -= f * B[c * m + k];
        }
    }
    for (int r = 0; r < n; r++)
        for (int k = 0; k < m; k++) B[r * m + k] /= A[r * n + r];
    return 1;
}

/* Slab of optical thickness tau, single-scattering albedo a, phase function the sum of two
 * HG lobes w1 HG(g1) + (1 - w1) HG(g2) (Legendre moments w1 g1^l + (1 - w1) g2^l), collimated
 * beam at cosine mu0 (0 < mu0 <= 1) on top; N Gauss points per hemisphere (<= 64); lt >= 0:
 * delta-M of degree lt instead (f = chi_{lt+1}, the scaled moments above lt 0: a field that
 * keeps the phase's degrees <= lt alone, solved exactly in angle and depth), else of 2N - 1. */
static int ad_slab_lt(double tau, double a, double w1, double g1, double g2, double mu0, int N, int lt,
                      ad_result *res)
{
    const double PI = 3.14159265358979323846, eps = 1e-12;
    const int D = N + 1, L = 2 * N; /* Legendre terms kept: 0..L-1 */
    memset(res, 0, sizeof *res);
    res->D = D;
    res->mu[0] = mu0, res->w[0] = eps;
    ad_gauss01(N, res->mu + 1, res->w + 1);
    /* delta-M */
    const int lf = lt >= 0 && lt + 1 < L ? lt + 1 : L;
    const double f = w1 * pow(g1, lf) + (1 - w1) * pow(g2, lf);
    const double ts = (1 - a * f) * tau, as = a * (1 - f) / (1 - a * f);
    double chi[2 * AD_MAXN];
    for (int l = 0; l < L; l++) chi[l] = l < lf ? (w1 * pow(g1, l) + (1 - w1) * pow(g2, l) - f) / (1 - f) : 0;
    /* Legendre polynomials at the directions */
    static double P[AD_MAXN][2 * AD_MAXN];
    for (int i = 0; i < D; i++) {
        double x = res->mu[i];
        P[i][0] = 1, P[i][1] = x;
        for (int l = 2; l < L; l++) P[i][l] = ((2 * l - 1) * x * P[i][l - 1] - (l - 1) * P[i][l - 2]) / l;
    }
    /* 2 pi h(mu_i, +-mu_j) times the weight w_j */
    const size_t DD = (size_t)D * D;
    double *Pt = calloc(DD, sizeof(double)), *Pr = calloc(DD, sizeof(double));
    double *A = calloc(4 * DD, sizeof(double)), *B = calloc(2 * DD, sizeof(double));
    double *tmp = calloc(DD, sizeof(double)), *tmp2 = calloc(DD, sizeof(double)), *E = calloc(DD, sizeof(double));
    if (!Pt || !Pr || !A || !B || !tmp || !tmp2 || !E) return 0;
    for (int i = 0; i < D; i++)
        for (int j = 0; j < D; j++) {
            double st = 0, sr = 0;
            for (int l = 0; l < L; l++) {
                double t = (2 * l + 1) * chi[l] * P[i][l] * P[j][l];
                st += t;
                sr += (l & 1) ? -t : t;
            }
            Pt[i * D + j] = 0.5 * st * res->w[j];
            Pr[i * D + j] = 0.5 * sr * res->w[j];
        }
    /* Thin layer by the diamond-difference equations:
     *   (I + Aa) r - Bb t = Bb a_in,   -Bb r + (I + Aa) t = (I - Aa) a_in
     * with Aa = d/2 M^-1 (I - as Pt W), Bb = d/2 M^-1 as Pr W. */
    int n = 0;
    double d = ts;
    while (d > 1e-5 || n < 4) d *= 0.5, n++;
    const int D2 = 2 * D;
    for (int i = 0; i < D; i++)
        for (int j = 0; j < D; j++) {
            double aa = 0.5 * d / res->mu[i] * ((i == j) - as * Pt[i * D + j]);
            double bb = 0.5 * d / res->mu[i] * as * Pr[i * D + j];
            A[i * D2 + j] = (i == j) + aa;
            A[(i + D) * D2 + (j + D)] = (i == j) + aa;
            A[i * D2 + (j + D)] = -bb;
            A[(i + D) * D2 + j] = -bb;
            B[i * D + j] = bb;                   /* rows 0..D-1: right-hand side for r */
            B[(i + D) * D + j] = (i == j) - aa;  /* rows D..2D-1: for t */
        }
    if (!ad_solve(D2, D, A, B)) return 0;
    memcpy(res->R, B, DD * sizeof(double));
    memcpy(res->T, B + DD, DD * sizeof(double));
    /* doubling */
    for (int k = 0; k < n; k++) {
        /* E = (I - R R)^-1 (as a solve against I) */
        ad_mul(D, res->R, res->R, tmp);
        for (size_t q = 0; q < DD; q++) tmp[q] = -tmp[q];
        for (int i = 0; i < D; i++) tmp[i * D + i] += 1;
        memset(E, 0, DD * sizeof(double));
        for (int i = 0; i < D; i++) E[i * D + i] = 1;
        if (!ad_solve(D, D, tmp, E)) return 0;
        ad_mul(D, res->T, E, tmp);   /* T E */
        ad_mul(D, tmp, res->R, tmp2); /* T E R */
        double *RT = calloc(DD, sizeof(double));
        if (!RT) return 0;
        ad_mul(D, tmp2, res->T, RT); /* T E R T */
        ad_mul(D, tmp, res->T, tmp2); /* T E T */
        for (size_t q = 0; q < DD; q++) res->R[q] += RT[q];
        memcpy(res->T, tmp2, DD * sizeof(double));
        free(RT);
    }
    /* the collimated beam: incident radiance I0 = 1 / (2 pi eps) for unit irradiance on a
     * surface normal to it (the operators carry the quadrature weights, not the cosines:
     * checked by the single-scattering limit and by R + T + exp(-tau / mu0) = 1 at mu0 < 1) */
    const double I0 = 1.0 / (2 * PI * eps);
    double R = 0, Tt = 0;
    for (int i = 0; i < D; i++) {
        res->radiance_up[i] = res->R[i * D] * I0;
        res->radiance_down[i] = res->T[i * D] * I0;
        if (i == 0) continue; /* weight eps: no flux */
        R += 2 * PI * res->mu[i] * res->w[i] * res->radiance_up[i];
        Tt += 2 * PI * res->mu[i] * res->w[i] * res->radiance_down[i];
    }
    /* fluxes per unit incident flux mu0 * E */
    res->refl = R / mu0;
    /* T(0,0) holds the direct beam exp(-ts/mu0) (which in delta-M carries the truncated
     * forward peak too); the remaining transmitted flux of the quadrature directions is
     * diffuse, the forward peak's share is added back as diffuse: */
    res->trans = Tt / mu0 + (exp(-ts / mu0) - exp(-tau / mu0));
    res->radiance_down[0] = 0; /* the direct beam is not a diffuse radiance */
    res->radiance_up[0] = res->R[0] * I0;
    free(Pt), free(Pr), free(A), free(B), free(tmp), free(tmp2), free(E);
    return 1;
}

static int ad_slab2(double tau, double a, double w1, double g1, double g2, double mu0, int N, ad_result *res)
{
    return ad_slab_lt(tau, a, w1, g1, g2, mu0, N, -1, res);
}

/* One HG lobe of asymmetry g. */
static int ad_slab(double tau, double a, double g, double mu0, int N, ad_result *res)
{
    return ad_slab2(tau, a, 1.0, g, 0.0, mu0, N, res);
}

#endif
