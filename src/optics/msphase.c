/* Multiple-scattering phase functions Ams_n and forward fractions F_n
 * (Riley et al. 2004 §4.2.1-4.2.2, Eq. 20 and 23).
 *
 * Method. For azimuthally symmetric functions on the sphere, spherical convolution is a
 * product of Legendre coefficients (Funk-Hecke): with
 *     P(mu) = sum_l (2l+1)/(4 pi) chi_l P_l(mu),   chi_l = 2 pi int P(mu) P_l(mu) dmu,
 * the distribution after n scatterings of a collimated beam (Eq. 20) is
 *     Ams_n(mu) = sum_l (2l+1)/(4 pi) chi_l^n P_l(mu),
 * and its forward-hemisphere fraction (Eq. 23) is, with int_0^1 P_l = (P_{l-1}(0) - P_{l+1}(0))/(2l+1),
 *     F_n = 1/2 + 1/2 sum_{l odd} chi_l^n (P_{l-1}(0) - P_{l+1}(0)).
 *
 * chi_l is computed by Gauss-Legendre quadrature in theta over every interval of the
 * phase table's grid, with the table linearly interpolated in theta (atmos_phase_table_eval
 * interpolates P sin(theta) instead, to match its sampler; the two readings differ by
 * O(h^2), far below the series' tolerance) and enough nodes per interval for the highest
 * l needed; the series is cut where |chi_l| stays below 2e-6 for 256 consecutive l
 * (forward diffraction peaks of drops of size parameter x have coefficients up to l ~ 2x;
 * beyond, the piecewise-linear table has a floor of ~1e-7 coefficients, which matter only
 * for Ams_1, taken from the table: squared, they are below 1e-12). Everything is summed in
 * a fixed order, so results do not depend on the thread count.
 *
 * Tables are read through angle_table.h: the phase table on its grid (Ams_1), Ams_n on the
 * output grid of phase_grid.c (atmos_msphase_eval, and the slice renderer per pixel).
 */
#include "core/internal.h"
#include "optics/angle_table.h"
#include "optics/optics_internal.h"
#include "core/cache.h"

#include <stdio.h>
#include <stdint.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MS_L_CAP 200000
#define MS_MAX_ORDER 1000
#define MS_CHI_TOL 2e-6
#define MS_CHUNKS 32
#define MS_L_SMOOTH 8192  /* series length used away from the forward cone */
#define MS_THETA_C 1.0    /* degrees: the forward cone where diffraction peaks live */
/* Bump when the numbers this file produces change: old cache entries are then ignored. */
#define MS_ALGORITHM_VERSION 6

struct atmos_msphase {
    int nwl, max_order, ngrid;
    const atmos__angle_grid *ag; /* the output grid, atmos__msphase_angle_grid() */
    const double *grid;  /* its angles, degrees */
    double *values;      /* [k][n-1][j], n = 1..max_order */
    double *forward;     /* [k][n], n = 0..max_order */
    double *logsum;      /* [k][n], n = 0..max_order: sum_{i=1}^{n} ln F_i */
    int *nchi;           /* [k] */
    int *truncated;      /* [k]: the series was cut before its coefficients decayed */
    double **chi;        /* [k][l] */
    int from_cache;
};

/* The output grid (phase_grid.c; why it is not the phase tables' grid is said there). */
static void use_out_grid(atmos_msphase *m)
{
    m->ag = atmos__msphase_angle_grid();
    m->grid = m->ag->deg;
    m->ngrid = m->ag->n;
}

/* Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_m; m <= 64). */
static void gauss_legendre(int m, double *x, double *w)
{
    for (int i = 0; i < (m + 1) / 2; i++) {
        double z = cos(ATMOS_PI * (i + 0.75) / (m + 0.5)), pp = 0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1, p1 = z;
            for (int k = 2; k <= m; k++) {
                double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                p0 = p1, p1 = p2;
            }
            if (m == 1) p1 = z, p0 = 1;
            pp = m * (z * p1 - p0) / (z * z - 1);
            double dz = p1 / pp;
            z -= dz;
            if (fabs(dz) < 1e-15) break;
        }
        x[i] = -z, x[m - 1 - i] = z;
        w[i] = w[m - 1 - i] = 2 / ((1 - z * z) * pp * pp);
    }
}

/* Angle (radians) below which P stays above 1 % of P(0): sets the series length. */
static double forward_width(int n, const double *theta_deg, const double *P)
{
    for (int i = 1; i < n; i++)
        if (P[i] < 0.01 * P[0]) return theta_deg[i] * ATMOS_DEG2RAD;
    return ATMOS_PI;
}

/* Gauss nodes of 2 pi P(theta) sin(theta) dtheta over the grid intervals [i0, i1), with
 * P linear in theta inside an interval and enough nodes per interval for P_L's oscillation
 * (period 2 pi / L). Appends to mu/f; returns the count (or, with mu == NULL, only counts). */
static int make_nodes(int i0, int i1, const double *theta_deg, const double *P, int L, double *mu, double *f)
{
    double gx[64], gw[64];
    int last_m = 0, j = 0;
    for (int i = i0; i < i1; i++) {
        double a = theta_deg[i] * ATMOS_DEG2RAD, b = theta_deg[i + 1] * ATMOS_DEG2RAD;
        int m = 2 + (int)ceil((b - a) * L / ATMOS_PI);
        if (m > 64) m = 64;
        if (!mu) {
            j += m;
            continue;
        }
        if (m != last_m) gauss_legendre(m, gx, gw), last_m = m;
        for (int q = 0; q < m; q++, j++) {
            double t = 0.5 * (a + b) + 0.5 * (b - a) * gx[q];
            double s = (t - a) / (b - a);
            mu[j] = cos(t);
            f[j] = 2.0 * ATMOS_PI * (P[i] * (1 - s) + P[i + 1] * s) * sin(t) * 0.5 * (b - a) * gw[q];
        }
    }
    return j;
}

/* part[c][l - lb] = sum over chunk c of nodes of f P_l(mu) for l in [lb, le], advancing
 * the chunks' recurrences (p0 = P_{l-1}, p1 = P_l on entry for l = lb > 0). */
static void node_sums(int nodes, const double *mu, const double *f, double *p0, double *p1, int lb, int le,
                      double *part, int stride, int threads)
{
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int c = 0; c < MS_CHUNKS; c++) {
        int k0 = (int)((long long)nodes * c / MS_CHUNKS), k1 = (int)((long long)nodes * (c + 1) / MS_CHUNKS);
        double *pc = part + (size_t)c * stride;
        for (int l = lb; l <= le; l++) {
            double s = 0;
            if (l == 0) {
                for (int k = k0; k < k1; k++) s += f[k];
            } else {
                for (int k = k0; k < k1; k++) s += f[k] * p1[k];
                double c1 = (2.0 * l + 1) / (l + 1), c2 = (double)l / (l + 1);
                for (int k = k0; k < k1; k++) {
                    double nx = c1 * mu[k] * p1[k] - c2 * p0[k];
                    p0[k] = p1[k];
                    p1[k] = nx;
                }
            }
            pc[l - lb] = s;
        }
    }
}

/* Legendre coefficients chi_l of a tabulated phase function; returns the count.
 *
 * Narrow features (diffraction peaks, coronae, glories' fine rings aside) live in the
 * forward cone theta < MS_THETA_C; beyond it the tables are smooth on the scale of
 * 1/MS_L_SMOOTH (0.014°), so the far region contributes only to l <= MS_L_SMOOTH.
 * Its higher coefficients are the piecewise-linear table's own ripple, which would
 * matter only for Ams_1, and Ams_1 is taken from the table. */
static int legendre_coefficients(int n, const double *theta_deg, const double *P, int threads, double **chi_out,
                                 int *truncated)
{
    *chi_out = NULL;
    double w = forward_width(n, theta_deg, P);
    /* Diffraction by a sphere of size parameter x: P falls to 1 % near theta ~ 3/x and its
     * coefficients vanish beyond l ~ 2x; a size distribution reaches larger x than its 1 %
     * width suggests (rain: ~20/theta_1%), so the series may run to 30/theta_1% (it stops
     * where the coefficients have decayed to the table's own floor); at least
     * MS_L_SMOOTH for smooth but strongly peaked functions (HG with g = 0.99 needs ~2800). */
    int L = (int)fmin(MS_L_CAP, fmax(MS_L_SMOOTH, 30.0 / w));
    int ic = 0; /* first grid interval of the far region */
    while (ic + 1 < n && theta_deg[ic] < MS_THETA_C) ic++;
    int nn = make_nodes(0, ic, theta_deg, P, L, NULL, NULL), nf = make_nodes(ic, n - 1, theta_deg, P, MS_L_SMOOTH, NULL, NULL);
    double *mu = malloc(sizeof(double) * (nn + nf)), *f = malloc(sizeof(double) * (nn + nf));
    double *p0 = malloc(sizeof(double) * (nn + nf)), *p1 = malloc(sizeof(double) * (nn + nf));
    double *chi = malloc(sizeof(double) * (L + 1));
    const int block = 512; /* l per round: chunks meet after each block so the stop test can run */
    double *part = malloc(sizeof(double) * MS_CHUNKS * block);
    if (!mu || !f || !p0 || !p1 || !chi || !part) {
        free(mu), free(f), free(p0), free(p1), free(chi), free(part);
        return -1;
    }
    make_nodes(0, ic, theta_deg, P, L, mu, f);
    make_nodes(ic, n - 1, theta_deg, P, MS_L_SMOOTH, mu + nn, f + nn);
    for (int k = 0; k < nn + nf; k++) p0[k] = 1.0, p1[k] = mu[k];
    /* Chunks are fixed (not per thread) and summed in order: the result does not depend
     * on the thread count. The series stops once |chi_l| stays below MS_CHI_TOL. */
    int count = L + 1, quiet = 0;
    for (int lb = 0; lb <= L && count == L + 1; lb += block) {
        int le = lb + block - 1 > L ? L : lb + block - 1;
        for (int l = lb; l <= le; l++) chi[l] = 0;
        for (int region = 0; region < 2; region++) {
            int nodes = region ? nf : nn, off = region ? nn : 0;
            int hi = region ? (le < MS_L_SMOOTH ? le : MS_L_SMOOTH) : le;
            if (nodes == 0 || hi < lb) continue;
            node_sums(nodes, mu + off, f + off, p0 + off, p1 + off, lb, hi, part, block, threads);
            for (int l = lb; l <= hi; l++)
                for (int c = 0; c < MS_CHUNKS; c++) chi[l] += part[(size_t)c * block + (l - lb)];
        }
        for (int l = lb; l <= le; l++) {
            quiet = fabs(chi[l]) < MS_CHI_TOL * fabs(chi[0]) ? quiet + 1 : 0;
            if (quiet >= 256) {
                count = l - 255;
                break;
            }
        }
    }
    free(mu), free(f), free(p0), free(p1), free(part);
    *truncated = count == L + 1;
    /* chi_0 is the table's integral (1 for a normalised table); scale so that Ams_n
     * integrates to exactly 1 in the series. */
    double c0 = chi[0];
    for (int l = 0; l < count; l++) chi[l] /= c0;
    *chi_out = chi;
    return count;
}

/* Smallest n with sum_{l>=1} (2l+1) |chi_l|^n < tol: beyond it Ams_n is isotropic. */
static int isotropic_order(const double *chi, int count, double tol, int cap)
{
    for (int n = 1; n <= cap; n++) {
        double s = 0;
        for (int l = 1; l < count; l++) {
            double c = pow(fabs(chi[l]), n) * (2 * l + 1);
            s += c;
            if (c < 1e-300 && l > 8) break;
        }
        if (s < tol) return n;
    }
    return cap;
}

/* Ams_n = sum_l (2l+1)/(4 pi) chi_l^n P_l(mu) at the output angles for n = 2..max_order,
 * in fixed chunks of angles (each with its own recurrence) processed in parallel. */
static int reconstruct(const double *chi, int count, int truncated, int max_order, int ngrid, const double *grid,
                       int threads, double *values)
{
    int failed = 0;
    memset(values, 0, sizeof(double) * (size_t)ngrid * max_order);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int c = 0; c < MS_CHUNKS; c++) {
        /* Half the chunks cover the forward cone, half the rest, so that no chunk mixes
         * near angles (full series) with far ones (tapered series). */
        int jc = 0;
        while (jc < ngrid && grid[jc] < MS_THETA_C) jc++;
        const int half = MS_CHUNKS / 2, cc = c < half ? c : c - half;
        const int lo = c < half ? 0 : jc, span = c < half ? jc : ngrid - jc;
        int j0 = lo + (int)((long long)span * cc / half), j1 = lo + (int)((long long)span * (cc + 1) / half), nj = j1 - j0;
        if (nj <= 0) continue;
        double *mu = malloc(sizeof(double) * nj), *p0 = malloc(sizeof(double) * nj), *p1 = malloc(sizeof(double) * nj);
        if (mu && p0 && p1) {
            for (int j = 0; j < nj; j++) mu[j] = cos(grid[j0 + j] * ATMOS_DEG2RAD), p0[j] = 1.0, p1[j] = mu[j];
            /* Far from the forward direction (theta >= MS_THETA_C) the series is summed with
             * a Gaussian window exp(-(l/L_g)^2), L_g = MS_L_SMOOTH/4.3 (1e-8 at the cut) when the
             * series is longer than MS_L_SMOOTH (converged shorter series need no window): the
             * full series would alias the products of the forward peak's large coefficients
             * with the table's small high-l floor into noise, a sharp cut would ring, and a
             * window with a slowly decaying kernel leaks the enormous forward peak into the
             * degree beyond 1°. The Gaussian kernel blurs by ~2/L_g rad (0.06°) and leaks
             * nothing measurable. A series cut before its coefficients have decayed
             * (truncated, not converged) gets the same window near the forward direction,
             * scaled to its length. */
            int far = grid[j0] >= MS_THETA_C;
            int lend = far && count > MS_L_SMOOTH ? MS_L_SMOOTH : count;
            double lg = far && count > MS_L_SMOOTH ? MS_L_SMOOTH / 4.3 : (truncated ? count / 4.3 : 0.0);
            for (int l = 0; l < lend; l++) {
                const double *pl = l == 0 ? p0 : p1;
                double taper = lg > 0 ? exp(-(l / lg) * (l / lg)) : 1.0;
                double norm = (2.0 * l + 1) / (4.0 * ATMOS_PI) * taper, cn = chi[l];
                for (int n = 2; n <= max_order; n++) {
                    cn *= chi[l];
                    double a = norm * cn;
                    if (fabs(a) < 1e-16 * norm || a == 0) break; /* higher orders are smaller still */
                    double *row = values + (size_t)(n - 1) * ngrid + j0;
                    for (int j = 0; j < nj; j++) row[j] += a * pl[j];
                }
                if (l > 0) {
                    double c1 = (2.0 * l + 1) / (l + 1), c2 = (double)l / (l + 1);
                    for (int j = 0; j < nj; j++) {
                        double nx = c1 * mu[j] * p1[j] - c2 * p0[j];
                        p0[j] = p1[j];
                        p1[j] = nx;
                    }
                }
            }
        }
        else {
#pragma omp atomic write
            failed = 1;
        }
        free(mu), free(p0), free(p1);
    }
    return failed ? -1 : 0;
}

/* Ams_1 is the phase function itself: interpolate the table (linear in theta, as the
 * Legendre coefficients read it) onto the output grid, renormalised on that grid. */
static void first_order(const atmos__angle_grid *pg, const double *P, int ngrid, const double *grid, double *out)
{
    for (int j = 0; j < ngrid; j++) {
        double s;
        const int i = atmos__angle_lerp(pg, grid[j], &s);
        out[j] = P[i] * (1 - s) + P[i + 1] * s;
    }
    double integral = 0;
    for (int j = 0; j + 1 < ngrid; j++) {
        double a = grid[j] * ATMOS_DEG2RAD, b = grid[j + 1] * ATMOS_DEG2RAD;
        integral += 0.5 * (out[j] * sin(a) + out[j + 1] * sin(b)) * (b - a);
    }
    integral *= 2.0 * ATMOS_PI;
    if (integral > 0)
        for (int j = 0; j < ngrid; j++) out[j] /= integral;
}

static void forward_fractions(const double *chi, int count, int max_order, double *F)
{
    F[0] = 1.0;
    for (int n = 1; n <= max_order; n++) F[n] = 0.5;
    /* P_{l-1}(0) - P_{l+1}(0) for odd l, from P_{2m}(0) = (-1)^m (2m-1)!!/(2m)!!. */
    double pe = 1.0; /* P_{l-1}(0), l = 1 */
    for (int l = 1; l < count; l += 2) {
        double pn = -pe * (double)l / (l + 1); /* P_{l+1}(0) */
        double d = pe - pn;
        double c = 1.0;
        for (int n = 1; n <= max_order; n++) {
            c *= chi[l];
            if (fabs(c) < 1e-18) break;
            F[n] += 0.5 * c * d;
        }
        pe = pn;
    }
}

/* Ams_1 by the series (when no table is given): like reconstruct's higher orders,
 * tapered far from the forward direction. */
static void series_first_order(const double *chi, int count, int ngrid, const double *grid, double *out)
{
    for (int j = 0; j < ngrid; j++) {
        double mu = cos(grid[j] * ATMOS_DEG2RAD), p0 = 1.0, p1 = mu, s = 0;
        int far = grid[j] >= MS_THETA_C;
        int lend = far && count > MS_L_SMOOTH ? MS_L_SMOOTH : count;
        double lg = far && count > MS_L_SMOOTH ? MS_L_SMOOTH / 4.3 : 0.0; /* the window of reconstruct() */
        for (int l = 0; l < lend; l++) {
            double pl = l == 0 ? p0 : p1, taper = lg > 0 ? exp(-(l / lg) * (l / lg)) : 1.0;
            s += (2.0 * l + 1) / (4.0 * ATMOS_PI) * taper * chi[l] * pl;
            if (l > 0) {
                double nx = ((2.0 * l + 1) * mu * p1 - l * p0) / (l + 1);
                p0 = p1;
                p1 = nx;
            }
        }
        out[j] = s;
    }
}

/* From the Legendre coefficients in m: the highest order, Ams_n for n >= 2 by the
 * series, Ams_1 from the tables P on the grid pg (or, when P is NULL, by the series too),
 * F_n and their log-sums. Frees m on failure and returns the error (with its message). */
static atmos_status finish_orders(atmos_context *ctx, atmos_msphase *m, const atmos_msphase_desc *dp,
                                  const atmos__angle_grid *pg, const double *const *P, int threads)
{
    const atmos_msphase_desc d = *dp;
    const int nwl = m->nwl;
    int fail = 0;
    int order = d.max_order;
    if (order == 0) {
        for (int k = 0; k < nwl; k++) {
            int o = isotropic_order(m->chi[k], m->nchi[k], d.isotropy_tol, MS_MAX_ORDER);
            if (o > order) order = o;
        }
    }
    if (order < 1) order = 1;
    m->max_order = order;
    size_t nv = (size_t)nwl * order * m->ngrid;
    if (nv > ((size_t)1 << 31))
        fail = 2;
    else {
        m->values = malloc(sizeof(double) * nv);
        m->forward = malloc(sizeof(double) * (size_t)nwl * (order + 1));
        m->logsum = malloc(sizeof(double) * (size_t)nwl * (order + 1));
        if (!m->values || !m->forward || !m->logsum) fail = 1;
    }
    if (fail) {
        int ngrid = m->ngrid;
        atmos_msphase_destroy(m);
        return atmos__error(ctx, fail == 2 ? ATMOS_E_LIMIT : ATMOS_E_NOMEM, "msphase: %d orders x %d angles x %d wavelengths: %s",
                            order, ngrid, nwl, fail == 2 ? "table too large" : "out of memory");
    }
    for (int k = 0; k < nwl; k++) {
        double *vk = m->values + (size_t)k * order * m->ngrid;
        if (reconstruct(m->chi[k], m->nchi[k], m->truncated[k], order, m->ngrid, m->grid, threads, vk) != 0) {
            atmos_msphase_destroy(m);
            return atmos__error(ctx, ATMOS_E_NOMEM, "msphase: out of memory summing the series");
        }
        if (P) first_order(pg, P[k], m->ngrid, m->grid, vk);
        else series_first_order(m->chi[k], m->nchi[k], m->ngrid, m->grid, vk);
        atmos__progress(ctx, "multiple-scattering phase", 0.5 + 0.5 * (k + 1) / nwl);
        double *F = m->forward + (size_t)k * (order + 1), *S = m->logsum + (size_t)k * (order + 1);
        forward_fractions(m->chi[k], m->nchi[k], order, F);
        S[0] = 0;
        for (int i = 1; i <= order; i++) S[i] = S[i - 1] + log(fmax(F[i], 1e-300));
    }
    return ATMOS_OK;
}

void atmos_msphase_destroy(atmos_msphase *m)
{
    if (!m) return;
    if (m->chi)
        for (int k = 0; k < m->nwl; k++) free(m->chi[k]);
    free(m->chi), free(m->nchi), free(m->truncated), free(m->values), free(m->forward), free(m->logsum);
    free(m);
}

atmos_status atmos__msphase_build_arrays(atmos_context *ctx, int nwl, int n, const double *theta_deg,
                                         const double *const *P, const atmos_msphase_desc *desc, atmos_msphase **out)
{
    *out = NULL;
    const atmos__angle_grid *pg = atmos__phase_angle_grid();
    if (theta_deg != pg->deg || n != pg->n)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase: the phase functions must be on atmos_phase_grid()");
    atmos_msphase_desc d = {0};
    if (desc) d = *desc;
    if (d.isotropy_tol == 0) d.isotropy_tol = 1e-6;
    if (d.max_order < 0 || d.max_order > MS_MAX_ORDER)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase: max_order must be in [0, %d], got %d", MS_MAX_ORDER, d.max_order);
    if (!(d.isotropy_tol > 0 && d.isotropy_tol < 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase: isotropy_tol must be in (0, 1), got %g", d.isotropy_tol);
    atmos_msphase *m = calloc(1, sizeof *m);
    if (!m) return atmos__error(ctx, ATMOS_E_NOMEM, "msphase: out of memory");
    m->nwl = nwl;
    m->chi = calloc(nwl, sizeof(double *));
    m->nchi = calloc(nwl, sizeof(int));
    m->truncated = calloc(nwl, sizeof(int));
    use_out_grid(m);
    if (!m->chi || !m->nchi || !m->truncated) {
        atmos_msphase_destroy(m);
        return atmos__error(ctx, ATMOS_E_NOMEM, "msphase: out of memory");
    }
    int fail = 0;
    int threads = atmos__threads(ctx);
    int cancelled = 0;
    for (int k = 0; k < nwl && !fail && !cancelled; k++) {
        m->nchi[k] = legendre_coefficients(n, theta_deg, P[k], threads, &m->chi[k], &m->truncated[k]);
        if (m->nchi[k] < 0) fail = 1;
        cancelled = atmos__progress(ctx, "multiple-scattering phase", 0.5 * (k + 1) / nwl);
    }
    if (fail) {
        atmos_msphase_destroy(m);
        return atmos__error(ctx, ATMOS_E_NOMEM, "msphase: out of memory for Legendre coefficients");
    }
    if (cancelled) {
        atmos_msphase_destroy(m);
        return atmos__error(ctx, ATMOS_E_CANCELLED, "msphase: cancelled");
    }
    atmos_status st = finish_orders(ctx, m, &d, pg, P, threads);
    if (st != ATMOS_OK) return st;
    *out = m;
    return ATMOS_OK;
}

/* ---- disk cache: payload = ints (nwl, max_order, ngrid, nchi[k]), doubles (grid,
 * forward, logsum, chi[k]), then the values as floats (7 significant digits are plenty
 * for a distribution, and half the bytes keep a cached load within a few ms). */

static size_t payload_size(const atmos_msphase *m)
{
    size_t nd = (size_t)m->ngrid + 2 * (size_t)m->nwl * (m->max_order + 1);
    for (int k = 0; k < m->nwl; k++) nd += (size_t)m->nchi[k];
    return sizeof(int32_t) * (3 + (size_t)m->nwl) + sizeof(double) * nd +
           sizeof(float) * (size_t)m->nwl * m->max_order * m->ngrid;
}

static void *serialise(const atmos_msphase *m, size_t *size)
{
    *size = payload_size(m);
    unsigned char *buf = malloc(*size), *p = buf;
    if (!buf) return NULL;
    int32_t hdr[3] = {m->nwl, m->max_order, m->ngrid};
    memcpy(p, hdr, sizeof hdr), p += sizeof hdr;
    for (int k = 0; k < m->nwl; k++) {
        int32_t c = m->nchi[k];
        memcpy(p, &c, sizeof c), p += sizeof c;
    }
#define PUT(ptr, count) (memcpy(p, (ptr), sizeof(double) * (size_t)(count)), p += sizeof(double) * (size_t)(count))
    PUT(m->grid, m->ngrid);
    PUT(m->forward, (size_t)m->nwl * (m->max_order + 1));
    PUT(m->logsum, (size_t)m->nwl * (m->max_order + 1));
    for (int k = 0; k < m->nwl; k++) PUT(m->chi[k], m->nchi[k]);
#undef PUT
    size_t nv = (size_t)m->nwl * m->max_order * m->ngrid;
    for (size_t i = 0; i < nv; i++, p += sizeof(float)) {
        float v = (float)m->values[i];
        memcpy(p, &v, sizeof v);
    }
    return buf;
}

/* Rebuilds an object from a cache payload; NULL if it does not fit the expected shape. */
static atmos_msphase *deserialise(const unsigned char *p, size_t size, int nwl)
{
    const unsigned char *end = p + size;
    int32_t hdr[3];
    if (size < sizeof hdr) return NULL;
    memcpy(hdr, p, sizeof hdr), p += sizeof hdr;
    if (hdr[0] != nwl || hdr[1] < 1 || hdr[1] > MS_MAX_ORDER || hdr[2] < 2 || hdr[2] > 100000) return NULL;
    /* The entry must use today's output grid (mixtures index parts by it; checked below). */
    if (hdr[2] != atmos__msphase_angle_grid()->n) return NULL;
    if ((size_t)(end - p) < sizeof(int32_t) * (size_t)nwl) return NULL;
    atmos_msphase *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    m->nwl = nwl, m->max_order = hdr[1];
    use_out_grid(m);
    m->nchi = calloc(nwl, sizeof(int));
    m->chi = calloc(nwl, sizeof(double *));
    if (!m->nchi || !m->chi) goto bad;
    for (int k = 0; k < nwl; k++) {
        int32_t c;
        memcpy(&c, p, sizeof c), p += sizeof c;
        if (c < 1 || c > MS_L_CAP + 1) goto bad;
        m->nchi[k] = c;
    }
    if (payload_size(m) != size) goto bad;
    size_t nv = (size_t)nwl * m->max_order * m->ngrid, nf = (size_t)nwl * (m->max_order + 1);
    m->values = malloc(sizeof(double) * nv);
    m->forward = malloc(sizeof(double) * nf);
    m->logsum = malloc(sizeof(double) * nf);
    if (!m->values || !m->forward || !m->logsum) goto bad;
    if (memcmp(p, m->grid, sizeof(double) * (size_t)m->ngrid) != 0) goto bad;
    p += sizeof(double) * (size_t)m->ngrid;
#define GET(ptr, count) (memcpy((ptr), p, sizeof(double) * (size_t)(count)), p += sizeof(double) * (size_t)(count))
    GET(m->forward, nf);
    GET(m->logsum, nf);
    for (int k = 0; k < nwl; k++) {
        m->chi[k] = malloc(sizeof(double) * m->nchi[k]);
        if (!m->chi[k]) goto bad;
        GET(m->chi[k], m->nchi[k]);
    }
#undef GET
    {
        const float *fv = (const float *)(const void *)p; /* payload buffers come from malloc: aligned */
        for (size_t i = 0; i < nv; i++) m->values[i] = fv[i];
    }
    m->from_cache = 1;
    return m;
bad:
    atmos_msphase_destroy(m);
    return NULL;
}

/* Value checks of an entry read from the cache: the checksum only proves that the bytes
 * are those written, not that they are a multiple-scattering table (an entry written by a
 * broken build, or forged with a recomputed checksum, passes it). NULL when the entry is
 * plausible, else what is wrong. The forward fractions and their log-sums are recomputed
 * from the Legendre coefficients (they must agree to rounding); each Ams_n must be finite,
 * at most slightly negative (the series' ringing), integrate to 1 over the sphere and to
 * F_n over the forward hemisphere. Correct tables (water drops, ice crystals, HG) are
 * within 3e-5 of both and never below -1e-9 of their maximum; the tolerances are wide
 * so that only numbers that are not such a table fail. */
#define MS_CHECK_CHI0 1e-3   /* |chi_0 - 1|: the phase function's normalisation */
#define MS_CHECK_NORM 0.02   /* |2 pi int Ams_n - 1| on the output grid */
#define MS_CHECK_FWD 0.02    /* |2 pi int_fwd Ams_n - F_n| */
#define MS_CHECK_NEG 0.01    /* lowest value over the largest */
static const char *implausible(const atmos_msphase *m)
{
    const int no = m->max_order, ng = m->ngrid;
    /* Trapezoid weights of 2 pi int f sin(theta) dtheta on the grid, over the sphere (wt)
     * and over the intervals of the forward hemisphere (wf), computed once. */
    double *F = malloc(sizeof(double) * ((size_t)(no + 1) + 2 * (size_t)ng)), *wt = F + no + 1, *wf = wt + ng;
    if (!F) return NULL; /* cannot check: trust the checksum, as before */
    for (int j = 0; j < ng; j++) wt[j] = wf[j] = 0;
    for (int j = 0; j + 1 < ng; j++) {
        double a = m->grid[j] * ATMOS_DEG2RAD, b = m->grid[j + 1] * ATMOS_DEG2RAD;
        double wa = ATMOS_PI * sin(a) * (b - a), wb = ATMOS_PI * sin(b) * (b - a);
        wt[j] += wa, wt[j + 1] += wb;
        if (m->grid[j + 1] <= 90) wf[j] += wa, wf[j + 1] += wb;
    }
    const char *why = NULL;
    for (int k = 0; k < m->nwl && !why; k++) {
        const double *chi = m->chi[k], *Fk = m->forward + (size_t)k * (no + 1), *Sk = m->logsum + (size_t)k * (no + 1);
        if (!(fabs(chi[0] - 1) <= MS_CHECK_CHI0)) why = "chi_0 is not 1 (the phase function is not normalised)";
        for (int l = 1; l < m->nchi[k] && !why; l++)
            if (!(fabs(chi[l]) <= 1 + 1e-9)) why = "a Legendre coefficient lies outside [-1, 1]";
        if (why) break;
        forward_fractions(chi, m->nchi[k], no, F);
        double sum = 0;
        for (int n = 0; n <= no && !why; n++) {
            if (n) sum += log(fmax(F[n], 1e-300));
            if (!(fabs(Fk[n] - F[n]) <= 1e-12) || !(fabs(Sk[n] - sum) <= 1e-9 * (1 + fabs(sum))))
                why = "the forward fractions disagree with the Legendre coefficients";
        }
        for (int n = 1; n <= no && !why; n++) {
            const double *v = m->values + ((size_t)k * no + (size_t)(n - 1)) * ng;
            double lo = 0, hi = 0, total = 0, fwd = 0;
            for (int j = 0; j < ng; j++) {
                if (!isfinite(v[j])) {
                    why = "a value is not finite";
                    break;
                }
                if (v[j] < lo) lo = v[j];
                if (v[j] > hi) hi = v[j];
                total += v[j] * wt[j], fwd += v[j] * wf[j];
            }
            if (!why && !(hi > 0 && lo >= -MS_CHECK_NEG * hi)) why = "a distribution is negative";
            else if (!why && !(fabs(total - 1) <= MS_CHECK_NORM)) why = "a distribution does not integrate to 1";
            else if (!why && !(fabs(fwd - F[n]) <= MS_CHECK_FWD)) why = "a distribution's forward part is not F_n";
        }
    }
    free(F);
    return why;
}

atmos_status atmos_msphase_build(atmos_context *ctx, const atmos_phase_table *table, const atmos_msphase_desc *desc,
                                 atmos_msphase **out)
{
    if (out) *out = NULL;
    if (!table || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase: missing table or output");
    int nwl = atmos_phase_table_wavelength_count(table);
    const double *theta;
    int n = atmos_phase_grid(&theta);
    const double *P[ATMOS_MAX_WAVELENGTHS];
    if (nwl < 1 || nwl > ATMOS_MAX_WAVELENGTHS)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase: table has %d wavelengths", nwl);
    uint64_t sum = atmos__cache_checksum(theta, sizeof(double) * (size_t)n);
    for (int k = 0; k < nwl; k++) {
        P[k] = atmos_phase_table_values(table, k);
        double nm = atmos_phase_table_wavelength_nm(table, k);
        sum = sum * 1099511628211ull ^ atmos__cache_checksum(P[k], sizeof(double) * (size_t)n);
        sum = sum * 1099511628211ull ^ atmos__cache_checksum(&nm, sizeof nm);
    }
    atmos_msphase_desc d = {0};
    if (desc) d = *desc;
    /* The key names the source table by a checksum of its values, wavelengths and grid. */
    char key[256];
    snprintf(key, sizeof key, "msphase alg=%d nwl=%d ngrid=%d table=%016llx max_order=%d tol=%.17g", MS_ALGORITHM_VERSION,
             nwl, n, (unsigned long long)sum, d.max_order, d.isotropy_tol);
    if (!d.no_cache) {
        void *data = NULL;
        size_t size = 0;
        if (atmos__cache_load(ctx, key, &data, &size)) {
            atmos_msphase *m = deserialise(data, size, nwl);
            free(data);
            const int shaped = m != NULL;
            const char *why = shaped ? implausible(m) : "an unexpected shape";
            if (!why) {
                *out = m;
                return ATMOS_OK;
            }
            atmos_msphase_destroy(m);
            char path[4096];
            if (!atmos__cache_entry_path(ctx, key, path, sizeof path)) snprintf(path, sizeof path, "(entry)");
            atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: multiple-scattering entry has %s%s; ignoring it and rebuilding",
                       path, shaped ? "values out of range: " : "", why);
            remove(path);
        }
    }
    atmos_status st = atmos__msphase_build_arrays(ctx, nwl, n, theta, P, &d, out);
    if (st == ATMOS_OK) {
        /* the values as the cache keeps them (floats), so that a table built here and one
         * loaded from the cache answer with the same bits */
        const size_t nv = (size_t)(*out)->nwl * (*out)->max_order * (*out)->ngrid;
        for (size_t i = 0; i < nv; i++) (*out)->values[i] = (double)(float)(*out)->values[i];
    }
    if (st == ATMOS_OK && !d.no_cache) {
        size_t size = 0;
        void *data = serialise(*out, &size);
        if (data) atmos__cache_store(ctx, key, data, size);
        free(data);
    }
    return st;
}

/* Accessors: a NULL object or an index out of range gives 0 (or NULL), never a crash. */
static int wl_ok(const atmos_msphase *m, int k) { return m && k >= 0 && k < m->nwl; }

int atmos_msphase_max_order(const atmos_msphase *m) { return m ? m->max_order : 0; }
int atmos_msphase_wavelength_count(const atmos_msphase *m) { return m ? m->nwl : 0; }
int atmos_msphase_grid(const atmos_msphase *m, const double **theta_deg)
{
    if (theta_deg) *theta_deg = m ? m->grid : NULL;
    return m ? m->ngrid : 0;
}
int atmos_msphase_from_cache(const atmos_msphase *m) { return m ? m->from_cache : 0; }
int atmos_msphase_legendre_count(const atmos_msphase *m, int k) { return wl_ok(m, k) ? m->nchi[k] : 0; }
double atmos_msphase_legendre(const atmos_msphase *m, int k, int l)
{
    if (!wl_ok(m, k) || l < 0 || l >= m->nchi[k]) return 0.0;
    return m->chi[k][l];
}

const double *atmos_msphase_values(const atmos_msphase *m, int k, int n)
{
    if (!wl_ok(m, k) || n < 1 || n > m->max_order) return NULL;
    return m->values + ((size_t)k * m->max_order + (n - 1)) * m->ngrid;
}

static double eval_order(const atmos_msphase *m, int k, int n, int i, double f)
{
    if (n > m->max_order) return 1.0 / (4.0 * ATMOS_PI);
    const double *v = atmos_msphase_values(m, k, n);
    return v[i] * (1 - f) + v[i + 1] * f;
}

double atmos_msphase_eval(const atmos_msphase *m, int k, double n, double cos_theta)
{
    if (!wl_ok(m, k)) return 0.0;
    if (!(n >= 1)) n = 1;
    if (cos_theta > 1) cos_theta = 1;
    if (cos_theta < -1) cos_theta = -1;
    double f;
    const int i = atmos__angle_lerp(m->ag, acos(cos_theta) * ATMOS_RAD2DEG, &f);
    if (n >= m->max_order + 1) return 1.0 / (4.0 * ATMOS_PI);
    int n0 = (int)floor(n);
    double w = n - n0;
    double a = eval_order(m, k, n0, i, f);
    return w > 0 ? a * (1 - w) + eval_order(m, k, n0 + 1, i, f) * w : a;
}

void atmos__msphase_eval_all(const atmos_msphase *m, int nw, double n, double cos_theta, double *out)
{
    if (!(n >= 1)) n = 1;
    if (cos_theta > 1) cos_theta = 1;
    if (cos_theta < -1) cos_theta = -1;
    double f = 0;
    const int i = m ? atmos__angle_lerp(m->ag, acos(cos_theta) * ATMOS_RAD2DEG, &f) : 0;
    const int high = !m || n >= m->max_order + 1, n0 = high ? 0 : (int)floor(n);
    const double w = n - n0;
    for (int k = 0; k < nw; k++) {
        if (!wl_ok(m, k)) out[k] = 0.0;
        else if (high) out[k] = 1.0 / (4.0 * ATMOS_PI);
        else {
            const double a = eval_order(m, k, n0, i, f);
            out[k] = w > 0 ? a * (1 - w) + eval_order(m, k, n0 + 1, i, f) * w : a;
        }
    }
}

double atmos_msphase_forward(const atmos_msphase *m, int k, double n)
{
    if (!wl_ok(m, k)) return 0.0;
    if (!(n > 0)) return 1.0;
    if (n >= m->max_order) return n >= m->max_order + 1 ? 0.5 : m->forward[(size_t)k * (m->max_order + 1) + m->max_order] * (m->max_order + 1 - n) + 0.5 * (n - m->max_order);
    const double *F = m->forward + (size_t)k * (m->max_order + 1);
    int n0 = (int)floor(n);
    double w = n - n0;
    return F[n0] * (1 - w) + F[n0 + 1] * w;
}

double atmos_msphase_log_forward_sum(const atmos_msphase *m, int k, double n)
{
    if (!wl_ok(m, k) || !(n > 0)) return 0.0;
    const double *S = m->logsum + (size_t)k * (m->max_order + 1);
    if (n >= m->max_order) return S[m->max_order] + (n - m->max_order) * log(0.5);
    int n0 = (int)floor(n);
    double w = n - n0;
    return S[n0] * (1 - w) + S[n0 + 1] * w;
}

atmos_status atmos_msphase_mix(atmos_context *ctx, const atmos_msphase *const *parts, const double *weights, int count,
                               const atmos_msphase_desc *desc, atmos_msphase **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase mix: missing output");
    *out = NULL;
    if (!parts || !weights || count < 1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase mix: need at least one part, got %d", count);
    double wsum = 0;
    for (int i = 0; i < count; i++) {
        if (!parts[i]) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase mix: part %d is missing", i);
        if (parts[i]->ngrid != parts[0]->ngrid)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase mix: part %d has a different angle grid", i);
        if (!(weights[i] >= 0) || !isfinite(weights[i]))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase mix: weight %d must be finite and >= 0, got %g", i, weights[i]);
        if (parts[i]->nwl != parts[0]->nwl)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase mix: part %d has %d wavelengths, part 0 has %d", i,
                                parts[i]->nwl, parts[0]->nwl);
        wsum += weights[i];
    }
    if (!(wsum > 0)) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase mix: the weights are all zero");
    atmos_msphase_desc d = {0};
    if (desc) d = *desc;
    if (d.isotropy_tol == 0) d.isotropy_tol = 1e-6;
    if (d.max_order < 0 || d.max_order > MS_MAX_ORDER || !(d.isotropy_tol > 0 && d.isotropy_tol < 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "msphase mix: max_order must be in [0, %d] and isotropy_tol in (0, 1)",
                            MS_MAX_ORDER);
    int nwl = parts[0]->nwl;
    atmos_msphase *m = calloc(1, sizeof *m);
    if (!m) return atmos__error(ctx, ATMOS_E_NOMEM, "msphase mix: out of memory");
    m->nwl = nwl;
    m->chi = calloc(nwl, sizeof(double *));
    m->nchi = calloc(nwl, sizeof(int));
    m->truncated = calloc(nwl, sizeof(int));
    use_out_grid(m);
    int fail = !m->chi || !m->nchi || !m->truncated;
    for (int k = 0; k < nwl && !fail; k++) {
        int len = 0;
        for (int i = 0; i < count; i++) {
            if (parts[i]->nchi[k] > len) len = parts[i]->nchi[k];
            m->truncated[k] |= parts[i]->truncated ? parts[i]->truncated[k] : 0;
        }
        m->chi[k] = calloc(len, sizeof(double));
        if (!m->chi[k]) {
            fail = 1;
            break;
        }
        m->nchi[k] = len;
        /* Eq. 6 in Legendre space: chi_mix = sum_i w_i chi_i / sum_i w_i. */
        for (int i = 0; i < count; i++)
            for (int l = 0; l < parts[i]->nchi[k]; l++) m->chi[k][l] += weights[i] / wsum * parts[i]->chi[k][l];
    }
    if (fail) {
        atmos_msphase_destroy(m);
        return atmos__error(ctx, ATMOS_E_NOMEM, "msphase mix: out of memory");
    }
    /* finish_orders has freed m and reported the error; return its status, not the
     * context's (there may be no context to hold it). */
    atmos_status st = finish_orders(ctx, m, &d, NULL, NULL, atmos__threads(ctx));
    if (st != ATMOS_OK) return st;
    /* Order 1 mixes linearly (Eq. 6 itself): use the parts' tabulated Ams_1 rather than
     * the series, exactly as a table built from the mixed phase function would. */
    for (int k = 0; k < nwl; k++) {
        double *row = m->values + (size_t)k * m->max_order * m->ngrid;
        for (int j = 0; j < m->ngrid; j++) row[j] = 0;
        for (int i = 0; i < count; i++) {
            const double *src = parts[i]->values + (size_t)k * parts[i]->max_order * parts[i]->ngrid;
            for (int j = 0; j < m->ngrid; j++) row[j] += weights[i] / wsum * src[j];
        }
    }
    *out = m;
    return ATMOS_OK;
}
