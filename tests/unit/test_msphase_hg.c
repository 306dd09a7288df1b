/* Multiple-scattering phase functions against an analytic case: the Henyey-Greenstein
 * function has Legendre coefficients chi_l = g^l, so convolving it n times with itself
 * gives Henyey-Greenstein with g^n, and its forward fraction has a closed form. */
#define _POSIX_C_SOURCE 200809L /* setrlimit, sysconf */
#include "atmos/atmos.h"
#include "optics/optics_internal.h"
#include "test.h"

#include <stdint.h>
#include <sys/resource.h>
#include <unistd.h>

#define PI 3.14159265358979323846

#if defined(__SANITIZE_ADDRESS__)
/* check_mix_failure: under the sanitizer an allocation above 16 MB fails (returns NULL)
 * instead of being refused through an address-space limit, which the sanitizer's own
 * mappings make unusable. Nothing else in this test allocates that much. */
const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "allocator_may_return_null=1:max_allocation_size_mb=16"; }
#endif

static double hg(double mu, double g) { return (1 - g * g) / (4 * PI * pow(1 + g * g - 2 * g * mu, 1.5)); }

/* int over the forward hemisphere of HG(g) */
static double hg_forward(double g)
{
    if (fabs(g) < 1e-12) return 0.5;
    return (1 + g) / (2 * g) - (1 - g * g) / (2 * g * sqrt(1 + g * g));
}

static void check_hg(double g)
{
    const double *theta;
    int n = atmos_phase_grid(&theta);
    double *P = malloc(sizeof(double) * n);
    for (int i = 0; i < n; i++) P[i] = hg(cos(theta[i] * PI / 180), g);
    const double *Ps[1] = {P};
    atmos_msphase *m = NULL;
    atmos_msphase_desc d = {0};
    CHECK_OK(atmos__msphase_build_arrays(NULL, 1, n, theta, Ps, &d, &m));
    if (!m) {
        free(P);
        return;
    }
    /* Legendre coefficients */
    double max_chi = 0;
    for (int l = 0; l < 200 && l < atmos_msphase_legendre_count(m, 0); l++)
        max_chi = fmax(max_chi, fabs(atmos_msphase_legendre(m, 0, l) - pow(g, l)));
    printf("g = %.3f: %d coefficients, max |chi_l - g^l| (l < 200) = %.2e, max order %d\n", g,
           atmos_msphase_legendre_count(m, 0), max_chi, atmos_msphase_max_order(m));
    CHECK(max_chi < 1e-5); /* the table is linear between grid points: its coefficients differ from g^l by ~1e-7..1e-6 */
    /* Ams_n = HG(g^n), n = 1, 2, 5, 10 */
    const double *grid;
    int ng = atmos_msphase_grid(m, &grid);
    const int orders[] = {1, 2, 5, 10};
    for (int o = 0; o < 4; o++) {
        int k = orders[o];
        /* orders past the isotropic one are not stored: evaluate through the API */
        double *v = malloc(sizeof(double) * ng);
        for (int j = 0; j < ng; j++) v[j] = atmos_msphase_eval(m, 0, k, cos(grid[j] * PI / 180));
        if (k <= atmos_msphase_max_order(m)) CHECK_REL(atmos_msphase_values(m, 0, k)[7], v[7], 1e-9);
        double gn = pow(g, k), max_rel = 0;
        for (int j = 0; j < ng; j++) {
            double ref = hg(cos(grid[j] * PI / 180), gn);
            max_rel = fmax(max_rel, fabs(v[j] - ref) / ref);
        }
        CHECK_MSG(max_rel < 1e-4, "g %.3f order %d: max rel err %.3g vs HG(g^n)", g, k, max_rel);
        /* normalisation by the trapezoid rule on the output grid */
        double s = 0;
        for (int j = 0; j + 1 < ng; j++) {
            double a = grid[j] * PI / 180, b = grid[j + 1] * PI / 180;
            s += 0.5 * (v[j] * sin(a) + v[j + 1] * sin(b)) * (b - a);
        }
        CHECK_NEAR(2 * PI * s, 1.0, 1e-4);
        CHECK_NEAR(atmos_msphase_forward(m, 0, k), hg_forward(gn), 1e-6);
        free(v);
    }
    /* Isotropic at the last order to the requested tolerance; F_n -> 1/2 */
    int N = atmos_msphase_max_order(m);
    const double *v = atmos_msphase_values(m, 0, N);
    double dev = 0;
    for (int j = 0; j < ng; j++) dev = fmax(dev, fabs(4 * PI * v[j] - 1));
    CHECK_MSG(dev < 1e-6, "order %d not isotropic: %.3g", N, dev);
    CHECK_NEAR(atmos_msphase_forward(m, 0, N), 0.5, 1e-6);
    CHECK(atmos_msphase_forward(m, 0, 0) == 1.0);
    /* fractional orders interpolate; log-sum gives the product of Eq. 24 */
    double mu = cos(3 * PI / 180);
    double a2 = atmos_msphase_eval(m, 0, 2, mu), a3 = atmos_msphase_eval(m, 0, 3, mu);
    CHECK_NEAR(atmos_msphase_eval(m, 0, 2.25, mu), 0.75 * a2 + 0.25 * a3, 1e-12 * a2);
    double prod = 1;
    for (int i = 3; i <= 7; i++) prod *= hg_forward(pow(g, i));
    CHECK_REL(exp(atmos_msphase_log_forward_sum(m, 0, 7) - atmos_msphase_log_forward_sum(m, 0, 2)), prod, 1e-5);
    atmos_msphase_destroy(m);
    free(P);
}

/* Eq. 6 mixtures: atmos_msphase_mix (Legendre coefficients mixed) against Ams_n built
 * directly from the mixed, tabulated phase function; and the size of the error made by
 * mixing the components' Ams_n linearly instead. */
static void check_mixture(void)
{
    const double *theta;
    int n = atmos_phase_grid(&theta);
    const double g1 = 0.9, g2 = 0.2, w1 = 0.3, w2 = 0.7;
    double *a = malloc(sizeof(double) * n), *b = malloc(sizeof(double) * n), *mix = malloc(sizeof(double) * n);
    for (int i = 0; i < n; i++) {
        double mu = cos(theta[i] * PI / 180);
        a[i] = hg(mu, g1), b[i] = hg(mu, g2), mix[i] = w1 * a[i] + w2 * b[i];
    }
    atmos_msphase *ma = NULL, *mb = NULL, *mm = NULL, *mx = NULL;
    const double *pa[1] = {a}, *pb[1] = {b}, *pm[1] = {mix};
    CHECK_OK(atmos__msphase_build_arrays(NULL, 1, n, theta, pa, NULL, &ma));
    CHECK_OK(atmos__msphase_build_arrays(NULL, 1, n, theta, pb, NULL, &mb));
    CHECK_OK(atmos__msphase_build_arrays(NULL, 1, n, theta, pm, NULL, &mm));
    const atmos_msphase *parts[2] = {ma, mb};
    const double w[2] = {w1 * 10, w2 * 10}; /* unnormalised on purpose */
    CHECK_OK(atmos_msphase_mix(NULL, parts, w, 2, NULL, &mx));
    if (ma && mb && mm && mx) {
        const double *grid;
        int ng = atmos_msphase_grid(mx, &grid);
        const int orders[] = {1, 2, 5, 10};
        for (int o = 0; o < 4; o++) {
            int k = orders[o];
            double max_rel = 0, lin_err = 0;
            for (int j = 0; j < ng; j++) {
                double mu = cos(grid[j] * PI / 180);
                double exact = atmos_msphase_eval(mm, 0, k, mu), got = atmos_msphase_eval(mx, 0, k, mu);
                /* closed form too: the mixture's chi_l = w1 g1^l + w2 g2^l */
                max_rel = fmax(max_rel, fabs(got - exact) / exact);
                double lin = w1 * atmos_msphase_eval(ma, 0, k, mu) + w2 * atmos_msphase_eval(mb, 0, k, mu);
                lin_err = fmax(lin_err, fabs(lin - exact) / exact);
            }
            CHECK_MSG(max_rel < 1e-4, "mixture order %d: %.3g from the directly built table", k, max_rel);
            CHECK_NEAR(atmos_msphase_forward(mx, 0, k), atmos_msphase_forward(mm, 0, k), 1e-6);
            printf("mixture 0.3 HG(0.9) + 0.7 HG(0.2), order %d: exact vs direct %.2e; linear mixing of Ams_n errs by %.1f %%\n",
                   k, max_rel, 100 * lin_err);
            if (k == 1) CHECK(lin_err < 1e-5);
            else CHECK(lin_err > 0.01); /* the approximation is not exact beyond n = 1 */
        }
    }
    double bad[2] = {1, -1};
    atmos_msphase *none = NULL;
    CHECK(atmos_msphase_mix(NULL, parts, bad, 2, NULL, &none) == ATMOS_E_INVALID_ARG && none == NULL);
    atmos_msphase_destroy(ma), atmos_msphase_destroy(mb), atmos_msphase_destroy(mm), atmos_msphase_destroy(mx);
    free(a), free(b), free(mix);
}

static uint64_t rng_state = 99;
static double uniform(void)
{
    return test_uniform_from(&rng_state);
}

static atmos_msphase *hg_msphase(double g, int max_order)
{
    const double *theta;
    int n = atmos_phase_grid(&theta);
    double *P = malloc(sizeof(double) * n);
    if (!P) return NULL;
    for (int i = 0; i < n; i++) P[i] = hg(cos(theta[i] * PI / 180), g);
    const double *Ps[1] = {P};
    atmos_msphase *m = NULL;
    atmos_msphase_desc d = {0};
    d.max_order = max_order;
    CHECK_OK(atmos__msphase_build_arrays(NULL, 1, n, theta, Ps, &d, &m));
    free(P);
    return m;
}

/* atmos_msphase_eval as it read its grid before the angle-table reader: a bisection of the
 * whole grid, linear in degrees, then linear between orders. The reference for check_eval. */
static double old_eval(const atmos_msphase *m, double n, double mu)
{
    const double *grid;
    const int ng = atmos_msphase_grid(m, &grid), N = atmos_msphase_max_order(m);
    if (!(n >= 1)) n = 1;
    if (mu > 1) mu = 1;
    if (mu < -1) mu = -1;
    double t = acos(mu) * (180.0 / PI), f;
    int lo = 0, hi = ng - 1;
    if (!(t > 0)) t = 0;
    if (t >= 180.0) {
        f = 1.0;
        lo = ng - 2;
    } else {
        while (hi - lo > 1) {
            int mid = (lo + hi) / 2;
            if (grid[mid] <= t) lo = mid;
            else hi = mid;
        }
        f = (t - grid[lo]) / (grid[lo + 1] - grid[lo]);
    }
    if (n >= N + 1) return 1.0 / (4.0 * PI);
    const int n0 = (int)floor(n);
    const double w = n - n0;
    const double *v0 = atmos_msphase_values(m, 0, n0), *v1 = n0 + 1 <= N ? atmos_msphase_values(m, 0, n0 + 1) : NULL;
    const double a = v0[lo] * (1 - f) + v0[lo + 1] * f;
    const double b = v1 ? v1[lo] * (1 - f) + v1[lo + 1] * f : 1.0 / (4.0 * PI);
    return w > 0 ? a * (1 - w) + b * w : a;
}

/* Ams lookups through the angle-table reader give the former lookups' numbers bit for bit:
 * at every grid angle, one ulp beside it, between grid angles, at random and at the ends. */
static void check_eval(void)
{
    atmos_msphase *m = hg_msphase(0.7, 6);
    if (!m) return;
    const double *grid;
    const int ng = atmos_msphase_grid(m, &grid);
    const double orders[] = {1, 2.5, 6, 6.75, 9, 0.2};
    long bad = 0, count = 0;
    for (int q = 0; q < 4 * ng + 100000; q++) {
        double th;
        if (q < 4 * ng) {
            th = grid[q / 4] * PI / 180;
            if (q % 4 == 1) th = nextafter(th, 0);
            if (q % 4 == 2) th = nextafter(th, 4);
            if (q % 4 == 3 && q / 4 + 1 < ng) th = 0.5 * (grid[q / 4] + grid[q / 4 + 1]) * PI / 180;
        } else {
            th = q % 2 ? PI * uniform() : 0.05 * uniform();
        }
        for (int o = 0; o < 6; o++) {
            const double a = atmos_msphase_eval(m, 0, orders[o], cos(th)), b = old_eval(m, orders[o], cos(th));
            bad += memcmp(&a, &b, sizeof a) != 0;
            count++;
        }
    }
    const double ends[] = {1, -1, 1.5, -3, NAN};
    for (int e = 0; e < 5; e++) {
        const double a = atmos_msphase_eval(m, 0, 2, ends[e]), b = old_eval(m, 2, ends[e]);
        bad += memcmp(&a, &b, sizeof a) != 0;
    }
    CHECK_MSG(bad == 0, "atmos_msphase_eval: %ld of %ld lookups differ from the former reader", bad, count);
    atmos_msphase_destroy(m);
}

/* Every wavelength's Ams at once (atmos__msphase_eval_all, one angle lookup for all) gives
 * atmos_msphase_eval's numbers bit for bit, wavelength by wavelength; a wavelength beyond the
 * object's gives 0, as atmos_msphase_eval does. */
static void check_eval_all(void)
{
    const double *theta;
    const int n = atmos_phase_grid(&theta);
    double *P = malloc(sizeof(double) * 3 * (size_t)n);
    if (!P) return;
    const double g[3] = {0.7, 0.5, 0.85};
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < n; i++) P[k * n + i] = hg(cos(theta[i] * PI / 180), g[k]);
    const double *Ps[3] = {P, P + n, P + 2 * n};
    atmos_msphase *m = NULL;
    atmos_msphase_desc d = {0};
    d.max_order = 6;
    CHECK_OK(atmos__msphase_build_arrays(NULL, 3, n, theta, Ps, &d, &m));
    free(P);
    if (!m) return;
    const double orders[] = {1, 2.5, 6, 6.75, 9, 0.2, NAN};
    const double ends[] = {1, -1, 1.5, -3, NAN};
    long bad = 0, count = 0;
    for (int q = 0; q < 20000 + 5; q++) {
        const double mu = q < 20000 ? cos(PI * uniform()) : ends[q - 20000];
        for (int o = 0; o < 7; o++) {
            double all[4];
            atmos__msphase_eval_all(m, 4, orders[o], mu, all);
            for (int k = 0; k < 4; k++) {
                const double one = atmos_msphase_eval(m, k, orders[o], mu);
                bad += memcmp(&one, &all[k], sizeof one) != 0;
                count++;
            }
        }
    }
    CHECK_MSG(bad == 0, "atmos__msphase_eval_all: %ld of %ld values differ from atmos_msphase_eval", bad, count);
    atmos_msphase_destroy(m);
}

/* The accessors on a NULL object: 0 or NULL, no crash (issue: they dereferenced it). */
static void check_null(void)
{
    const double *g = (const double *)&g;
    CHECK(atmos_msphase_max_order(NULL) == 0 && atmos_msphase_wavelength_count(NULL) == 0);
    CHECK(atmos_msphase_grid(NULL, &g) == 0 && g == NULL && atmos_msphase_grid(NULL, NULL) == 0);
    CHECK(atmos_msphase_from_cache(NULL) == 0 && atmos_msphase_legendre_count(NULL, 0) == 0);
    CHECK(atmos_msphase_legendre(NULL, 0, 0) == 0 && atmos_msphase_values(NULL, 0, 1) == NULL);
    CHECK(atmos_msphase_eval(NULL, 0, 1, 0.5) == 0 && atmos_msphase_forward(NULL, 0, 1) == 0);
    CHECK(atmos_msphase_log_forward_sum(NULL, 0, 1) == 0);
    atmos_msphase_destroy(NULL);
    atmos_msphase *out = (atmos_msphase *)&g;
    CHECK(atmos_msphase_build(NULL, NULL, NULL, &out) == ATMOS_E_INVALID_ARG && out == NULL);
}

/* A mix whose tables cannot be allocated fails with ATMOS_E_NOMEM and *out = NULL, with or
 * without a context (issue: without one it returned ATMOS_OK and no object). Order 1000 on
 * the Ams grid is 22 MB of values; the address space is limited to 8 MB more than in use
 * (the sanitizer build instead fails allocations above 16 MB, see the top of this file). */
static void check_mix_failure(void)
{
    atmos_msphase *a = hg_msphase(0.5, 0), *b = hg_msphase(-0.2, 0);
    if (!a || !b) {
        atmos_msphase_destroy(a), atmos_msphase_destroy(b);
        return;
    }
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    const atmos_msphase *parts[2] = {a, b};
    const double w[2] = {1, 1};
    atmos_msphase_desc d = {0};
    d.max_order = 1000;
    atmos_msphase *out1 = a, *out2 = a;
    atmos_status s1, s2;
#if !defined(__SANITIZE_ADDRESS__)
    struct rlimit old, lim;
    long pages = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%ld", &pages) != 1) pages = 0;
        fclose(f);
    }
    if (pages <= 0 || getrlimit(RLIMIT_AS, &old) != 0) {
        printf("mix failure: no /proc/self/statm or RLIMIT_AS here; skipped\n");
        atmos_context_destroy(ctx), atmos_msphase_destroy(a), atmos_msphase_destroy(b);
        return;
    }
    lim = old;
    lim.rlim_cur = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + ((rlim_t)8 << 20);
    if (old.rlim_cur != RLIM_INFINITY && old.rlim_cur < lim.rlim_cur) lim.rlim_cur = old.rlim_cur;
    setrlimit(RLIMIT_AS, &lim);
#endif
    s1 = atmos_msphase_mix(NULL, parts, w, 2, &d, &out1);
    s2 = atmos_msphase_mix(ctx, parts, w, 2, &d, &out2);
#if !defined(__SANITIZE_ADDRESS__)
    setrlimit(RLIMIT_AS, &old);
#endif
    CHECK_MSG(s1 == ATMOS_E_NOMEM && out1 == NULL, "mix without a context: %s, out %p", atmos_status_string(s1), (void *)out1);
    CHECK_MSG(s2 == ATMOS_E_NOMEM && out2 == NULL, "mix with a context: %s, out %p", atmos_status_string(s2), (void *)out2);
    CHECK_MSG(strstr(atmos_context_error(ctx), "out of memory") != NULL, "message: %s", atmos_context_error(ctx));
    atmos_msphase_destroy(out1 == a ? NULL : out1), atmos_msphase_destroy(out2 == a ? NULL : out2);
    /* and with the memory there, the same mix works */
    d.max_order = 8;
    CHECK_OK(atmos_msphase_mix(NULL, parts, w, 2, &d, &out1));
    CHECK(out1 && atmos_msphase_max_order(out1) == 8);
    atmos_msphase_destroy(out1);
    atmos_context_destroy(ctx), atmos_msphase_destroy(a), atmos_msphase_destroy(b);
}

int main(void)
{
    check_null();
    check_eval();
    check_eval_all();
    check_mix_failure();
    check_mixture();
    check_hg(0.0);
    check_hg(0.5);
    check_hg(0.85);
    check_hg(0.95);
    check_hg(-0.3);
    return test_summary("test_msphase_hg");
}
