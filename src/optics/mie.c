/* Lorenz-Mie scattering by a homogeneous sphere.
 *
 * The series and its coefficients follow Bohren & Huffman (1983, "Absorption and
 * Scattering of Light by Small Particles", §4.4 and App. A) with the numerical choices of
 * Wiscombe (1980, "Improved Mie scattering algorithms", Appl. Opt. 19, 1505):
 *
 *  - the series is cut after N_stop terms (Wiscombe 1980 Eq. 4 / MIEV0):
 *      x <= 8:        N = x + 4 x^(1/3) + 1
 *      8 < x < 4200:  N = x + 4.05 x^(1/3) + 2
 *      x >= 4200:     N = x + 4 x^(1/3) + 2
 *  - the logarithmic derivative D_n(mx) = psi_n'(mx)/psi_n(mx) by downward recurrence
 *    (BH Eq. 4.89) started at n = max(N, |mx|) + 16 with D = 0; downward recurrence is
 *    stable for every complex m, including strongly absorbing spheres (Wiscombe §IV);
 *  - the Riccati-Bessel functions psi_n(x), chi_n(x) of the real argument x by upward
 *    recurrence (stable for psi up to N_stop, Wiscombe §IV);
 *  - a_n, b_n from D_n (BH Eq. 4.88), which avoids Bessel functions of the complex
 *    argument altogether;
 *  - the angular functions pi_n, tau_n by upward recurrence (BH Eq. 4.47).
 *
 * Sign conventions: the public API uses MIEV0's (m = n - i k, k >= 0 absorbs; S has the
 * opposite imaginary part of Bohren & Huffman's). Internally we evaluate Bohren &
 * Huffman's formulas with m_BH = conj(m) and return conj(S_BH); efficiencies are real
 * and the same in both conventions.
 *
 * The perfectly conducting sphere (m = 0) is the m -> infinity limit of BH Eq. 4.88:
 * a_n = psi_n'(x)/xi_n'(x), b_n = psi_n(x)/xi_n(x) (BH §4.8 / Wiscombe's PERFCT option).
 *
 * The angle loop dominates the cost for many angles (N_stop x angles terms). It runs
 * over angle blocks in structure-of-arrays form so that the compiler vectorises the
 * inner loop (omp simd), and it evaluates theta and 180° - theta in one pass using
 * pi_n(-mu) = (-1)^(n+1) pi_n(mu), tau_n(-mu) = (-1)^n tau_n(mu): the terms are
 * accumulated into a part even in mu and a part odd in mu, and S(+-mu) = E +- O.
 */
#include "core/internal.h"
#include "optics/optics_internal.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Wiscombe (1980) Eq. 4 as used in MIEV0; at least 3 terms so that the x^5 terms
 * (b_1 beyond the dipole, a_2) are never dropped for tiny spheres. */
static int mie_nstop(double x)
{
    double c = cbrt(x), n;
    if (x <= 8.0) n = x + 4.0 * c + 1.0;
    else if (x < 4200.0) n = x + 4.05 * c + 2.0;
    else n = x + 4.0 * c + 2.0;
    int k = (int)n;
    return k < 3 ? 3 : k;
}

/* D_n(z) = psi_n'(z)/psi_n(z) by Lentz's (1976, Appl. Opt. 15, 668) method for the
 * continued fraction of the Bessel-function ratio J_{nu-1}(z)/J_nu(z), nu = n + 1/2:
 *   D_n = -n/z + [a_1, a_2, ...],  a_k = (-1)^(k+1) 2 (nu + k - 1) / z,
 * evaluated with the modified Lentz algorithm (Thompson & Barnett 1986); used by Wiscombe
 * (1980) to start the downward recurrence exactly. Converges after about |z| - n + O(|z|^1/3)
 * terms. */
static double complex mie_logderiv_cf(int n, double complex z)
{
    const double tiny = 1e-300;
    double complex zinv = 1.0 / z;
    double nu = n + 0.5;
    double complex f = 2.0 * nu * zinv; /* a_1 */
    if (cabs(f) < tiny) f = tiny;
    double complex C = f, Dl = 0.0;
    for (long k = 2; k < 100000000L; k++) {
        double sgn = (k & 1) ? 1.0 : -1.0;
        double complex a = sgn * 2.0 * (nu + k - 1.0) * zinv;
        Dl = a + Dl;
        if (cabs(Dl) < tiny) Dl = tiny;
        Dl = 1.0 / Dl;
        C = a + 1.0 / C;
        if (cabs(C) < tiny) C = tiny;
        double complex delta = C * Dl;
        f *= delta;
        if (cabs(delta - 1.0) < 1e-16) break;
    }
    return -n * zinv + f;
}

/* Angle block length: 11 arrays of BLOCK doubles stay in the L1 cache. */
#define BLOCK 128

typedef struct {
    /* c_n a_n and c_n b_n with c_n = (2n+1)/(n(n+1)), n = 1..N (index n-1) */
    const double *ar, *ai, *br, *bi;
    int nterms;
} mie_coef;

/* One series term for a block of angles: X += ca pi, Y += cb tau, Z += cb pi,
 * W += ca tau, then pi advances to n+1. The caller picks X..W (even or odd part)
 * by the parity of n. */
static inline void mie_term(int nb, int n, const double *restrict mu, double *restrict p0,
                            double *restrict p1, double car, double cai, double cbr, double cbi,
                            double *restrict xr, double *restrict xi, double *restrict yr,
                            double *restrict yi, double *restrict zr, double *restrict zi,
                            double *restrict wr, double *restrict wi)
{
    const double dn = n, dn1 = n + 1.0, a = (2.0 * n + 1.0) / n, b = (n + 1.0) / n;
#pragma omp simd
    for (int k = 0; k < nb; k++) {
        double pn = p1[k], pm = p0[k], m = mu[k];
        double tau = dn * m * pn - dn1 * pm; /* BH Eq. 4.47 */
        xr[k] += car * pn;
        xi[k] += cai * pn;
        yr[k] += cbr * tau;
        yi[k] += cbi * tau;
        zr[k] += cbr * pn;
        zi[k] += cbi * pn;
        wr[k] += car * tau;
        wi[k] += cai * tau;
        p0[k] = pn;
        p1[k] = a * m * pn - b * pm; /* pi_{n+1} */
    }
}

/* Even (E) and odd (O) parts of S1 and S2 at nb cosines mu >= 0. */
static void mie_block(const mie_coef *c, int nb, const double *mu, double *e1r, double *e1i,
                      double *o1r, double *o1i, double *e2r, double *e2i, double *o2r, double *o2i)
{
    double p0[BLOCK], p1[BLOCK];
    for (int k = 0; k < nb; k++) {
        p0[k] = 0.0; /* pi_0 */
        p1[k] = 1.0; /* pi_1 */
        e1r[k] = e1i[k] = o1r[k] = o1i[k] = e2r[k] = e2i[k] = o2r[k] = o2i[k] = 0.0;
    }
    for (int n = 1; n <= c->nterms; n++) {
        double car = c->ar[n - 1], cai = c->ai[n - 1], cbr = c->br[n - 1], cbi = c->bi[n - 1];
        if (n & 1) /* pi_n even in mu, tau_n odd */
            mie_term(nb, n, mu, p0, p1, car, cai, cbr, cbi, e1r, e1i, o1r, o1i, e2r, e2i, o2r, o2i);
        else       /* pi_n odd in mu, tau_n even */
            mie_term(nb, n, mu, p0, p1, car, cai, cbr, cbi, o1r, o1i, e1r, e1i, o2r, o2i, e2r, e2i);
    }
}

typedef struct {
    double amu; /* |mu| */
    int idx;
} mu_key;

static int mu_key_cmp(const void *pa, const void *pb)
{
    const mu_key *a = pa, *b = pb;
    if (a->amu < b->amu) return -1;
    if (a->amu > b->amu) return 1;
    return (a->idx > b->idx) - (a->idx < b->idx);
}

/* Amplitudes at every requested cosine. Cosines whose magnitudes agree to 2 ulp of 1
 * (theta and 180° - theta, computed in floating point) share one evaluation. */
static atmos_status mie_amplitudes(atmos_context *ctx, const mie_coef *c, int n_angles,
                                   const double *mu, atmos_complex *s1, atmos_complex *s2)
{
    mu_key *key = malloc((size_t)n_angles * sizeof *key);
    int *uniq = malloc((size_t)n_angles * sizeof *uniq); /* unique slot of each key */
    double *umu = malloc((size_t)n_angles * sizeof *umu);
    double *acc = malloc((size_t)n_angles * 8 * sizeof *acc);
    if (!key || !uniq || !umu || !acc) {
        free(key), free(uniq), free(umu), free(acc);
        return atmos__error(ctx, ATMOS_E_NOMEM, "mie: out of memory for %d angles", n_angles);
    }
    for (int i = 0; i < n_angles; i++) key[i] = (mu_key){fabs(mu[i]), i};
    qsort(key, (size_t)n_angles, sizeof *key, mu_key_cmp);
    int nu = 0;
    for (int i = 0; i < n_angles; i++) {
        if (nu == 0 || key[i].amu - umu[nu - 1] > 4.5e-16) umu[nu++] = key[i].amu;
        uniq[i] = nu - 1;
    }
    double *e1r = acc, *e1i = acc + nu, *o1r = acc + 2 * nu, *o1i = acc + 3 * nu;
    double *e2r = acc + 4 * nu, *e2i = acc + 5 * nu, *o2r = acc + 6 * nu, *o2i = acc + 7 * nu;
    for (int b = 0; b < nu; b += BLOCK) {
        int nb = nu - b < BLOCK ? nu - b : BLOCK;
        mie_block(c, nb, umu + b, e1r + b, e1i + b, o1r + b, o1i + b, e2r + b, e2i + b, o2r + b, o2i + b);
    }
    for (int i = 0; i < n_angles; i++) {
        int j = key[i].idx, u = uniq[i];
        double sg = mu[j] < 0 ? -1.0 : 1.0;
        /* conj: Bohren-Huffman -> MIEV0 convention */
        if (s1) s1[j] = (atmos_complex){e1r[u] + sg * o1r[u], -(e1i[u] + sg * o1i[u])};
        if (s2) s2[j] = (atmos_complex){e2r[u] + sg * o2r[u], -(e2i[u] + sg * o2i[u])};
    }
    free(key), free(uniq), free(umu), free(acc);
    return ATMOS_OK;
}

atmos_status atmos_mie(atmos_context *ctx, atmos_complex m, double x, int n_angles, const double *mu,
                       atmos_complex *s1, atmos_complex *s2, atmos_mie_result *out)
{
    /* Below x ~ 1e-6 the series' first terms lose all their digits to cancellation in
     * double precision (the Rayleigh limit is then exact to ~1e-12 anyway). */
    if (!(x >= 1e-6 && x <= 1e5))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mie: size parameter x must be in [1e-6, 1e5], got %g", x);
    if (!isfinite(m.re) || !isfinite(m.im))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mie: refractive index must be finite, got %g%+gi", m.re, m.im);
    int perfect = m.re == 0.0 && m.im == 0.0;
    if (!perfect && !(m.re > 0.0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "mie: Re m must be > 0 (or m = 0 for a perfect conductor), got %g%+gi", m.re, m.im);
    if (m.im > 0.0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "mie: Im m must be <= 0 (MIEV0 convention: m = n - ik absorbs), got %g%+gi", m.re,
                            m.im);
    if (n_angles < 0 || (n_angles > 0 && !mu) || n_angles > 10000000)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mie: n_angles must be in [0, 1e7] with a cosine array, got %d",
                            n_angles);
    for (int i = 0; i < n_angles; i++)
        if (!(mu[i] >= -1.0 && mu[i] <= 1.0))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mie: mu[%d] must be a cosine in [-1, 1], got %g", i, mu[i]);
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mie: result pointer is NULL");

    const int N = mie_nstop(x);
    const double complex mc = CMPLX(m.re, -m.im); /* Bohren-Huffman: Im m >= 0 absorbs */
    const double complex z = mc * x;
    double *coef = malloc((size_t)N * 4 * sizeof *coef);
    double complex *D = perfect ? NULL : malloc((size_t)(N + 1) * sizeof *D);
    if (!coef || (!perfect && !D)) {
        free(coef), free(D);
        return atmos__error(ctx, ATMOS_E_NOMEM, "mie: out of memory for %d terms", N);
    }

    if (!perfect) {
        /* D_N exactly from Lentz's continued fraction, then D_n downward (BH Eq. 4.89):
         * D_{n-1} = n/z - 1/(D_n + n/z). Starting the recurrence from an arbitrary value a
         * little above |z| (BH's bhmie: max(N, |z|) + 15) is not enough for weakly
         * absorbing large spheres: the start error is damped only once n < |z| - O(|z|^1/3),
         * which costs 1e-5 .. 1e-2 relative error at m = 1.33, x = 1e2 .. 1e4. */
        D[N] = mie_logderiv_cf(N, z);
        double complex zinv = 1.0 / z;
        for (int n = N; n >= 1; n--) D[n - 1] = n * zinv - 1.0 / (D[n] + n * zinv);
    }

    /* Riccati-Bessel psi_n(x) = x j_n(x), chi_n(x) = -x y_n(x), xi_n = psi_n - i chi_n
     * (BH App. A), upward: f_n = (2n-1)/x f_{n-1} - f_{n-2}. */
    double psi_m1 = cos(x), psi_0 = sin(x), chi_m1 = -sin(x), chi_0 = cos(x);
    double psi_prev = psi_0, chi_prev = chi_0;
    double psi_pp = psi_m1, chi_pp = chi_m1;
    double complex a_prev = 0.0, b_prev = 0.0;
    double qext = 0.0, qsca = 0.0, gsum = 0.0;
    double complex sback = 0.0;
    double *car = coef, *cai = coef + N, *cbr = coef + 2 * N, *cbi = coef + 3 * N;
    for (int n = 1; n <= N; n++) {
        double fn = (2.0 * n - 1.0) / x;
        double psi = fn * psi_prev - psi_pp;
        double chi = fn * chi_prev - chi_pp;
        double complex xi = CMPLX(psi, -chi), xi_prev = CMPLX(psi_prev, -chi_prev);
        double complex an, bn;
        if (perfect) {
            /* psi_n' = psi_{n-1} - n psi_n / x, likewise xi_n' */
            an = (psi_prev - n * psi / x) / (xi_prev - n * xi / x);
            bn = psi / xi;
        } else {
            double complex da = D[n] / mc + n / x, db = mc * D[n] + n / x;
            an = (da * psi - psi_prev) / (da * xi - xi_prev); /* BH Eq. 4.88 */
            bn = (db * psi - psi_prev) / (db * xi - xi_prev);
        }
        double w = 2.0 * n + 1.0;
        qext += w * creal(an + bn);
        qsca += w * (creal(an) * creal(an) + cimag(an) * cimag(an) + creal(bn) * creal(bn) +
                     cimag(bn) * cimag(bn));
        /* BH Eq. 4.82 for g Q_sca: the n-1 cross terms, then the n-th a b* term */
        if (n > 1) {
            double k = n - 1.0;
            gsum += k * (k + 2.0) / (k + 1.0) * creal(a_prev * conj(an) + b_prev * conj(bn));
        }
        gsum += w / (n * (n + 1.0)) * creal(an * conj(bn));
        sback += w * ((n & 1) ? -1.0 : 1.0) * (an - bn);
        double cn = w / (n * (n + 1.0));
        car[n - 1] = cn * creal(an);
        cai[n - 1] = cn * cimag(an);
        cbr[n - 1] = cn * creal(bn);
        cbi[n - 1] = cn * cimag(bn);
        a_prev = an, b_prev = bn;
        psi_pp = psi_prev, psi_prev = psi;
        chi_pp = chi_prev, chi_prev = chi;
    }
    free(D);

    const double x2 = x * x;
    out->qext = 2.0 / x2 * qext;
    out->qsca = 2.0 / x2 * qsca;
    out->qback = (creal(sback) * creal(sback) + cimag(sback) * cimag(sback)) / x2;
    out->g = out->qsca > 0.0 ? 4.0 / x2 * gsum / out->qsca : 0.0;
    out->terms = N;

    atmos_status st = ATMOS_OK;
    if (n_angles > 0 && (s1 || s2)) {
        mie_coef c = {car, cai, cbr, cbi, N};
        st = mie_amplitudes(ctx, &c, n_angles, mu, s1, s2);
    }
    free(coef);
    return st;
}
