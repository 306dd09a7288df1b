/* Analytic phase functions: normalisation over the sphere, mean cosines against closed
 * forms, exactness of the samplers (inverse CDFs and chi-square tests), edge cases. */
#include "atmos/atmos.h"
#include "test.h"

#include <stdint.h>

#define PI 3.14159265358979323846

typedef double (*fn_mu)(const void *user, double mu);

/* Adaptive Simpson on [a, b]: the HG lobes at g = 0.95 are ~0.003 wide in mu, which a
 * fixed rule would need ~1e5 points for. */
static double simpson_rec(fn_mu f, const void *u, double a, double b, double fa, double fm, double fb, double whole,
                          double tol, int depth)
{
    double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
    double flm = f(u, lm), frm = f(u, rm);
    double left = (m - a) / 6 * (fa + 4 * flm + fm), right = (b - m) / 6 * (fm + 4 * frm + fb);
    if (depth <= 0 || fabs(left + right - whole) <= 15 * tol) return left + right + (left + right - whole) / 15;
    return simpson_rec(f, u, a, m, fa, flm, fm, left, tol / 2, depth - 1) +
           simpson_rec(f, u, m, b, fm, frm, fb, right, tol / 2, depth - 1);
}

static double integrate(fn_mu f, const void *u, double a, double b, double tol)
{
    double fa = f(u, a), fb = f(u, b), fm = f(u, 0.5 * (a + b));
    return simpson_rec(f, u, a, b, fa, fm, fb, (b - a) / 6 * (fa + 4 * fm + fb), tol, 48);
}

/* ---- integrands: 2 pi P(mu) and 2 pi mu P(mu) over mu in [-1, 1] = integrals over the sphere */
typedef struct {
    const atmos_phase_mixture *m;
    int moment;
} mix_arg;

static double mix_integrand(const void *user, double mu)
{
    const mix_arg *a = user;
    double p = 2 * PI * atmos_phase_mixture_eval(a->m, mu);
    return a->moment ? mu * p : p;
}

static atmos_phase_mixture single(atmos_phase_kind kind, double g)
{
    atmos_phase_mixture m;
    memset(&m, 0, sizeof m);
    m.count = 1;
    m.kind[0] = kind;
    m.g[0] = g;
    m.weight[0] = 1;
    return m;
}

static double sphere_integral(const atmos_phase_mixture *m, int moment)
{
    mix_arg a = {m, moment};
    return integrate(mix_integrand, &a, -1, 1, 1e-10);
}

/* ---- RNG: SplitMix64 */
static uint64_t rng_state = 12345;
static double uniform(void)
{
    return test_uniform_from(&rng_state);
}

/* Chi-square test of the sampler against the pdf over bins uniform in theta (which
 * resolves forward peaks better than bins uniform in mu); bins whose expected count is
 * under 20 are merged with their neighbour. Returns chi2 / threshold (< 1 passes),
 * the threshold being dof + 5 sqrt(2 dof), far in the tail for a correct sampler. */
static double chi2_ratio(const atmos_phase_mixture *m, int n_samples, const char *label)
{
    enum { BINS = 90 };
    double edges_mu[BINS + 1];
    for (int i = 0; i <= BINS; i++) edges_mu[i] = cos(PI * (BINS - i) / BINS); /* increasing mu */
    edges_mu[0] = -1;
    edges_mu[BINS] = 1;
    long counts[BINS] = {0};
    for (int s = 0; s < n_samples; s++) {
        double mu = atmos_phase_mixture_sample(m, uniform(), uniform());
        if (!(mu >= -1 && mu <= 1)) {
            fprintf(stderr, "%s: sample out of range: %g\n", label, mu);
            return 1e9;
        }
        int lo = 0, hi = BINS;
        while (hi - lo > 1) {
            int mid = (lo + hi) / 2;
            if (edges_mu[mid] <= mu) lo = mid;
            else hi = mid;
        }
        counts[lo]++;
    }
    double chi2 = 0, exp_acc = 0, obs_acc = 0;
    int dof = -1;
    mix_arg a = {m, 0};
    for (int i = 0; i < BINS; i++) {
        exp_acc += n_samples * integrate(mix_integrand, &a, edges_mu[i], edges_mu[i + 1], 1e-12);
        obs_acc += counts[i];
        if (exp_acc >= 20 || i == BINS - 1) {
            chi2 += (obs_acc - exp_acc) * (obs_acc - exp_acc) / (exp_acc > 0 ? exp_acc : 1e-300);
            dof++;
            exp_acc = obs_acc = 0;
        }
    }
    double thr = dof + 5 * sqrt(2.0 * dof);
    if (chi2 > thr) fprintf(stderr, "%s: chi2 = %.1f, dof = %d, threshold %.1f\n", label, chi2, dof, thr);
    return chi2 / thr;
}

static void test_normalisation_and_moments(void)
{
    /* Rayleigh: normalised, symmetric. */
    atmos_phase_mixture r = single(ATMOS_PHASE_RAYLEIGH, 0);
    CHECK_NEAR(sphere_integral(&r, 0), 1.0, 1e-6);
    CHECK_NEAR(sphere_integral(&r, 1), 0.0, 1e-9);
    CHECK_NEAR(atmos_phase_rayleigh(1.0), 3.0 / (8 * PI), 1e-15); /* Harris Eq. 3: 3/4 * 2 / (4 pi) */
    atmos_phase_mixture iso = single(ATMOS_PHASE_ISOTROPIC, 0);
    CHECK_NEAR(sphere_integral(&iso, 0), 1.0, 1e-9);

    static const double gs[] = {-0.9, -0.5, -0.1, 0.0, 0.1, 0.3, 0.5, 0.7, 0.85, 0.9, 0.95};
    for (size_t i = 0; i < sizeof gs / sizeof *gs; i++) {
        double g = gs[i];
        /* HG: normalised, <mu> = g (Henyey & Greenstein 1941). */
        atmos_phase_mixture hg = single(ATMOS_PHASE_HG, g);
        CHECK_NEAR(sphere_integral(&hg, 0), 1.0, 1e-6);
        CHECK_NEAR(sphere_integral(&hg, 1), g, 1e-6);
        /* Cornette-Shanks: normalised; <mu> = 3g(4 + g^2) / (5(2 + g^2)), the mean cosine
         * of Draine's (2003, ApJ 598:1017) phase function (1 - g^2)(1 + alpha mu^2) /
         * (4 pi (1 + alpha(1 + 2g^2)/3)(1 + g^2 - 2g mu)^1.5), g (1 + alpha(3 + 2g^2)/5) /
         * (1 + alpha(1 + 2g^2)/3), at alpha = 1, where it is Cornette & Shanks (1992). */
        atmos_phase_mixture cs = single(ATMOS_PHASE_CORNETTE_SHANKS, g);
        CHECK_NEAR(sphere_integral(&cs, 0), 1.0, 1e-6);
        CHECK_NEAR(sphere_integral(&cs, 1), 3 * g * (4 + g * g) / (5 * (2 + g * g)), 1e-6);
        /* Nishita Eq. 5 is normalised to 4 pi: ours is it divided by 4 pi. */
        double mu = 0.3;
        double nishita = 3 * (1 - g * g) / (2 * (2 + g * g)) * (1 + mu * mu) / pow(1 + g * g - 2 * g * mu, 1.5);
        CHECK_REL(atmos_phase_cornette_shanks(mu, g), nishita / (4 * PI), 1e-13);
    }
    /* CS at g = 0 is Rayleigh (Nishita §3.3). */
    for (double mu = -1; mu <= 1; mu += 0.25) CHECK_REL(atmos_phase_cornette_shanks(mu, 0), atmos_phase_rayleigh(mu), 1e-14);

    /* Mixture (Nishita Eq. 4): 5 % Rayleigh + 95 % CS, and an unnormalised 4-lobe one. */
    atmos_phase_mixture m = {2, {ATMOS_PHASE_RAYLEIGH, ATMOS_PHASE_CORNETTE_SHANKS}, {0, 0.85}, {0.05, 0.95}};
    CHECK_NEAR(sphere_integral(&m, 0), 1.0, 1e-6);
    CHECK_NEAR(sphere_integral(&m, 1), 0.95 * 3 * 0.85 * (4 + 0.85 * 0.85) / (5 * (2 + 0.85 * 0.85)), 1e-6);
    atmos_phase_mixture m4 = {4,
                              {ATMOS_PHASE_HG, ATMOS_PHASE_HG, ATMOS_PHASE_ISOTROPIC, ATMOS_PHASE_CORNETTE_SHANKS},
                              {0.9, -0.4, 0, 0.6},
                              {3, 1, 0.5, 1.5}};
    CHECK_NEAR(sphere_integral(&m4, 0), 1.0, 1e-6);
    double g4 = (3 * 0.9 + 1 * -0.4 + 1.5 * 3 * 0.6 * (4 + 0.36) / (5 * (2 + 0.36))) / 6.0;
    CHECK_NEAR(sphere_integral(&m4, 1), g4, 1e-6);
}

static void test_edge_cases(void)
{
    CHECK_NEAR(atmos_phase_hg(0.3, 0.0), 1 / (4 * PI), 1e-15);
    /* |g| -> 1: finite everywhere, peak (1 + g) / (4 pi (1 - g)^2). */
    static const double gs[] = {0.999999, -0.999999, 1 - 1e-12};
    for (size_t i = 0; i < sizeof gs / sizeof *gs; i++)
        for (double mu = -1; mu <= 1.0001; mu += 0.125) {
            double h = atmos_phase_hg(mu, gs[i]), c = atmos_phase_cornette_shanks(mu, gs[i]);
            CHECK(isfinite(h) && h >= 0 && isfinite(c) && c >= 0);
        }
    /* Invalid g and arguments: 0, never NaN. */
    CHECK(atmos_phase_hg(0.5, 1.0) == 0 && atmos_phase_hg(0.5, -1.0) == 0 && atmos_phase_hg(0.5, NAN) == 0);
    CHECK(atmos_phase_cornette_shanks(0.5, 1.5) == 0 && atmos_phase_hg(NAN, 0.5) == 0);
    CHECK(atmos_phase_hg(1.5, 0.5) == atmos_phase_hg(1.0, 0.5)); /* |mu| > 1 clamped */

    atmos_phase_mixture bad[5];
    bad[0] = single(ATMOS_PHASE_HG, 1.0);
    bad[1] = single(ATMOS_PHASE_HG, 0.5);
    bad[1].weight[0] = 0; /* all zero */
    bad[2] = single(ATMOS_PHASE_HG, 0.5);
    bad[2].weight[0] = -1;
    bad[3] = single(ATMOS_PHASE_HG, 0.5);
    bad[3].count = 0;
    bad[4] = single((atmos_phase_kind)17, 0.5);
    for (int i = 0; i < 5; i++) {
        CHECK(atmos_phase_mixture_eval(&bad[i], 0.5) == 0);
        CHECK(atmos_phase_mixture_pdf(&bad[i], 0.5) == 0);
        double mu = atmos_phase_mixture_sample(&bad[i], 0.3, 0.7);
        CHECK(mu >= -1 && mu <= 1);
    }
    CHECK(atmos_phase_mixture_eval(NULL, 0.5) == 0);

    /* Samplers at the ends of [0, 1) and beyond stay in [-1, 1]. */
    static const atmos_phase_kind kinds[] = {ATMOS_PHASE_ISOTROPIC, ATMOS_PHASE_RAYLEIGH, ATMOS_PHASE_HG,
                                             ATMOS_PHASE_CORNETTE_SHANKS};
    static const double us[] = {0.0, 1e-300, 0.5, 1 - 1e-16, 1.0, -3.0, 7.0, NAN};
    for (int k = 0; k < 4; k++)
        for (size_t a = 0; a < 8; a++)
            for (size_t b = 0; b < 8; b++) {
                atmos_phase_mixture m = single(kinds[k], k >= 2 ? 0.999999 : 0);
                double mu = atmos_phase_mixture_sample(&m, us[a], us[b]);
                CHECK(mu >= -1 && mu <= 1);
            }
}

/* Exact inversions: the analytic CDFs of the sampled values give back u. */
static void test_inverse_cdfs(void)
{
    atmos_phase_mixture r = single(ATMOS_PHASE_RAYLEIGH, 0);
    double worst = 0;
    for (int i = 0; i <= 1000; i++) {
        double u = i / 1000.0 * (1 - 1e-15);
        double mu = atmos_phase_mixture_sample(&r, 0.5, u);
        double F = 0.375 * (mu + mu * mu * mu / 3) + 0.5; /* CDF of 3/8 (1 + mu^2) */
        if (fabs(F - u) > worst) worst = fabs(F - u);
    }
    CHECK_NEAR(worst, 0, 1e-13);
    static const double gs[] = {-0.9, -1e-9, 0.0, 1e-9, 0.5, 0.95};
    for (size_t k = 0; k < 6; k++) {
        double g = gs[k];
        atmos_phase_mixture hg = single(ATMOS_PHASE_HG, g);
        worst = 0;
        for (int i = 0; i <= 1000; i++) {
            double u = i / 1000.0 * (1 - 1e-15);
            double mu = atmos_phase_mixture_sample(&hg, 0.5, u);
            /* HG CDF in mu: (1 - g^2)/(2g) ((1 + g^2 - 2 g mu)^-1/2 - 1/(1 + g)); (1 + mu)/2 at g = 0. */
            double F = fabs(g) < 1e-6 ? 0.5 * (1 + mu)
                                      : (1 - g * g) / (2 * g) * (1 / sqrt(1 + g * g - 2 * g * mu) - 1 / (1 + g));
            if (fabs(F - u) > worst) worst = fabs(F - u);
        }
        CHECK_MSG(worst < 1e-9, "HG g = %g: max |F(sample(u)) - u| = %g", g, worst);
    }
}

static void test_sampling_chi2(void)
{
    const int N = 400000;
    static const double gs[] = {-0.7, 0.0, 0.3, 0.85, 0.95};
    char label[64];
    for (size_t i = 0; i < sizeof gs / sizeof *gs; i++) {
        atmos_phase_mixture hg = single(ATMOS_PHASE_HG, gs[i]);
        snprintf(label, sizeof label, "HG g=%g", gs[i]);
        CHECK_MSG(chi2_ratio(&hg, N, label) < 1, "%s", label);
        atmos_phase_mixture cs = single(ATMOS_PHASE_CORNETTE_SHANKS, gs[i]);
        snprintf(label, sizeof label, "CS g=%g", gs[i]);
        CHECK_MSG(chi2_ratio(&cs, N, label) < 1, "%s", label);
    }
    atmos_phase_mixture r = single(ATMOS_PHASE_RAYLEIGH, 0);
    CHECK(chi2_ratio(&r, N, "Rayleigh") < 1);
    atmos_phase_mixture iso = single(ATMOS_PHASE_ISOTROPIC, 0);
    CHECK(chi2_ratio(&iso, N, "isotropic") < 1);
    atmos_phase_mixture m = {3,
                             {ATMOS_PHASE_RAYLEIGH, ATMOS_PHASE_CORNETTE_SHANKS, ATMOS_PHASE_HG},
                             {0, 0.85, -0.5},
                             {0.05, 0.8, 0.15}};
    CHECK(chi2_ratio(&m, N, "mixture R+CS+HG") < 1);
    /* A zero-weight lobe is never chosen. */
    atmos_phase_mixture z = {2, {ATMOS_PHASE_HG, ATMOS_PHASE_HG}, {-0.9, 0.9}, {0, 1}};
    CHECK(chi2_ratio(&z, N, "zero-weight lobe") < 1);

    /* The test must be able to fail: a sampler for the wrong g is rejected. */
    atmos_phase_mixture wrong = single(ATMOS_PHASE_HG, 0.3);
    rng_state = 99;
    enum { B = 40 };
    long c[B] = {0};
    for (int s = 0; s < N; s++) {
        double mu = atmos_phase_mixture_sample(&wrong, uniform(), uniform());
        int b = (int)((mu + 1) / 2 * B);
        c[b < 0 ? 0 : b >= B ? B - 1 : b]++;
    }
    /* against HG g = 0.32: must exceed the threshold */
    atmos_phase_mixture other = single(ATMOS_PHASE_HG, 0.32);
    mix_arg a = {&other, 0};
    double chi2 = 0;
    for (int b = 0; b < B; b++) {
        double e = N * integrate(mix_integrand, &a, -1 + 2.0 * b / B, -1 + 2.0 * (b + 1) / B, 1e-12);
        chi2 += (c[b] - e) * (c[b] - e) / e;
    }
    CHECK_MSG(chi2 > B - 1 + 5 * sqrt(2.0 * (B - 1)), "chi2 %g does not detect g 0.30 vs 0.32", chi2);
}

static void test_pdf_equals_eval(void)
{
    atmos_phase_mixture m = {3,
                             {ATMOS_PHASE_RAYLEIGH, ATMOS_PHASE_CORNETTE_SHANKS, ATMOS_PHASE_HG},
                             {0, 0.7, 0.2},
                             {1, 2, 3}};
    for (double mu = -1; mu <= 1; mu += 0.01) CHECK(atmos_phase_mixture_pdf(&m, mu) == atmos_phase_mixture_eval(&m, mu));
}

int main(void)
{
    test_normalisation_and_moments();
    test_edge_cases();
    test_inverse_cdfs();
    test_sampling_chi2();
    test_pdf_equals_eval();
    return test_summary("test_phase_analytic");
}
