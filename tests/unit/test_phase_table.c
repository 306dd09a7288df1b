/* Phase tables of the kinds built here (AIR, ANALYTIC): normalisation, agreement with the
 * analytic functions, sampling, interpolation, the disk cache (hits, corrupt and stale
 * entries, keys, no_cache), progress and cancellation. Caches live under
 * $ATMOS_TEST_TMP, never in the user's ~/.cache. */
#define _POSIX_C_SOURCE 200809L /* opendir, truncate */
#include "atmos/atmos.h"
#include "atmos/cache.h"
#include "test.h"

#include <dirent.h>
#include <stdint.h>
#include <sys/stat.h>
#include <unistd.h>

#define PI 3.14159265358979323846

/* ---- logging: count warnings, keep the last one */
static int warnings;
static char last_warning[1024];
static void log_fn(void *user, atmos_log_level level, const char *msg)
{
    (void)user;
    if (level == ATMOS_LOG_WARN) {
        warnings++;
        snprintf(last_warning, sizeof last_warning, "%s", msg);
    }
}

/* ---- progress: record fractions; cancel once the fraction reaches cancel_at */
typedef struct {
    int calls, monotone, bad_stage;
    double last, cancel_at;
    char stage[64];
} progress_rec;
static int progress_fn(void *user, const char *stage, double f)
{
    progress_rec *p = user;
    if (p->calls && f < p->last) p->monotone = 0;
    if (strcmp(stage, p->stage) != 0) p->bad_stage = 1;
    p->last = f;
    p->calls++;
    return f >= p->cancel_at;
}

static char cache_dir[1024];

static atmos_context *make_ctx(const char *dir, progress_rec *prog)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.cache_dir = dir;
    d.log = log_fn;
    d.log_level = ATMOS_LOG_WARN;
    if (prog) {
        d.progress = progress_fn;
        d.progress_user = prog;
    }
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) {
        fprintf(stderr, "cannot create a context\n");
        exit(1);
    }
    return ctx;
}

/* Number of cache entries in dir; *name gets the last one's path. */
static int count_entries(const char *dir, char *name, size_t cap)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (l > 11 && !strcmp(e->d_name + l - 11, ".atmoscache")) {
            n++;
            if (name) snprintf(name, cap, "%s/%s", dir, e->d_name);
        }
    }
    closedir(d);
    return n;
}

static atmos_particle_desc air(void)
{
    atmos_particle_desc p;
    memset(&p, 0, sizeof p);
    snprintf(p.name, sizeof p.name, "air");
    p.kind = ATMOS_PARTICLE_AIR;
    return p;
}

static atmos_particle_desc analytic(double g)
{
    atmos_particle_desc p;
    memset(&p, 0, sizeof p);
    snprintf(p.name, sizeof p.name, "test-mixture");
    p.kind = ATMOS_PARTICLE_ANALYTIC;
    /* Nishita §3.3: a little Rayleigh plus a forward Cornette-Shanks lobe, and a back lobe. */
    p.analytic.count = 3;
    p.analytic.kind[0] = ATMOS_PHASE_RAYLEIGH;
    p.analytic.kind[1] = ATMOS_PHASE_CORNETTE_SHANKS;
    p.analytic.kind[2] = ATMOS_PHASE_HG;
    p.analytic.g[1] = g;
    p.analytic.g[2] = -0.3;
    p.analytic.weight[0] = 0.05;
    p.analytic.weight[1] = 0.85;
    p.analytic.weight[2] = 0.10;
    p.sigma_ext_m2 = 6.28e-10;
    return p;
}

/* Trapezoid 2 pi int P sin(theta) dtheta over the table's own grid (moment 1: with cos). */
static double table_integral(const atmos_phase_table *t, int k, int moment)
{
    const double *th;
    int n = atmos_phase_grid(&th);
    const double *v = atmos_phase_table_values(t, k);
    double s = 0;
    for (int i = 0; i + 1 < n; i++) {
        double a = th[i] * PI / 180, b = th[i + 1] * PI / 180;
        double fa = v[i] * sin(a) * (moment ? cos(a) : 1), fb = v[i + 1] * sin(b) * (moment ? cos(b) : 1);
        s += 0.5 * (fa + fb) * (b - a);
    }
    return 2 * PI * s;
}

static uint64_t rng_state = 2024;
static double uniform(void)
{
    return test_uniform_from(&rng_state);
}

/* Chi-square of table_sample against the table's own density over 90 bins uniform in
 * theta (merged to >= 20 expected); expected counts by fine Simpson in theta of
 * 2 pi eval(cos theta) sin theta. Returns chi2 / (dof + 5 sqrt(2 dof)). */
static double table_chi2(const atmos_phase_table *t, int k, int n_samples)
{
    enum { BINS = 90, SUB = 400 };
    long counts[BINS] = {0};
    for (int s = 0; s < n_samples; s++) {
        double mu = atmos_phase_table_sample(t, k, uniform());
        if (!(mu >= -1 && mu <= 1)) return 1e9;
        int b = (int)(acos(mu) * 180 / PI / (180.0 / BINS));
        counts[b < 0 ? 0 : b >= BINS ? BINS - 1 : b]++;
    }
    double chi2 = 0, e_acc = 0, o_acc = 0;
    int dof = -1;
    for (int b = 0; b < BINS; b++) {
        double a = b * PI / BINS, h = PI / BINS / SUB, e = 0;
        for (int j = 0; j < SUB; j++) {
            double x0 = a + j * h, x1 = x0 + h, xm = 0.5 * (x0 + x1);
            e += h / 6 * (atmos_phase_table_eval(t, k, cos(x0)) * sin(x0) + 4 * atmos_phase_table_eval(t, k, cos(xm)) * sin(xm) +
                          atmos_phase_table_eval(t, k, cos(x1)) * sin(x1));
        }
        e_acc += n_samples * 2 * PI * e;
        o_acc += counts[b];
        if (e_acc >= 20 || b == BINS - 1) {
            chi2 += (o_acc - e_acc) * (o_acc - e_acc) / (e_acc > 0 ? e_acc : 1e-300);
            dof++;
            e_acc = o_acc = 0;
        }
    }
    double thr = dof + 5 * sqrt(2.0 * dof);
    if (chi2 > thr) fprintf(stderr, "table sampling: chi2 %.1f dof %d threshold %.1f\n", chi2, dof, thr);
    return chi2 / thr;
}

static void test_air(void)
{
    atmos_context *ctx = make_ctx(cache_dir, NULL);
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_particle_desc p = air();
    atmos_phase_table *t = NULL;
    atmos_phase_table_desc td = {1};
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (!t) {
        atmos_context_destroy(ctx);
        return;
    }
    const double *th;
    int n = atmos_phase_grid(&th);
    CHECK(atmos_phase_table_wavelength_count(t) == 3);
    /* Riley Table 3 / Eq. 9 (= Table 2's air values to 1 %). */
    static const double beta[3] = {5.8e-6, 1.35e-5, 3.31e-5}, table2[3] = {2.28e-31, 5.33e-31, 1.30e-30};
    for (int k = 0; k < 3; k++) {
        CHECK(atmos_phase_table_wavelength_nm(t, k) == wl.nm[k]);
        CHECK_NEAR(table_integral(t, k, 0), 1.0, 1e-4);
        CHECK_NEAR(table_integral(t, k, 1), 0.0, 1e-6);
        CHECK_REL(atmos_phase_table_sigma_ext(t, k), beta[k] / 2.55e25, 1e-12);
        CHECK_REL(atmos_phase_table_sigma_ext(t, k), table2[k], 0.01);
        CHECK(atmos_phase_table_albedo(t, k) == 1.0);
        CHECK_NEAR(atmos_phase_table_g(t, k), 0.0, 1e-12);
        const double *v = atmos_phase_table_values(t, k);
        double worst = 0;
        for (int i = 0; i < n; i++) {
            double e = fabs(v[i] / atmos_phase_rayleigh(cos(th[i] * PI / 180)) - 1);
            if (e > worst) worst = e;
        }
        CHECK_MSG(worst < 1e-6, "air table vs Riley Eq. 1: max rel err %g", worst);
    }
    CHECK(table_chi2(t, 1, 300000) < 1);
    /* Outside the table: NULL / 0, never a crash. */
    CHECK(atmos_phase_table_values(t, 3) == NULL && atmos_phase_table_values(t, -1) == NULL);
    CHECK(atmos_phase_table_eval(t, 5, 0.5) == 0 && atmos_phase_table_wavelength_count(NULL) == 0);
    CHECK(atmos_phase_table_pdf(t, -1, 0.5) == 0 && atmos_phase_table_pdf(NULL, 0, 0.5) == 0);
    CHECK(atmos_phase_table_sample(NULL, 0, 0.5) == 1.0 && atmos_phase_table_sample(t, 3, 0.5) == 1.0);
    atmos_phase_table_destroy(t);

    /* Spectral: the lambda^-4 law between the channels. */
    atmos_wavelengths_spectral(16, &wl);
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (t)
        for (int k = 0; k < 16; k++)
            CHECK_REL(atmos_phase_table_sigma_ext(t, k), 1.35e-5 / 2.55e25 * pow(550 / wl.nm[k], 4), 1e-12);
    atmos_phase_table_destroy(t);

    /* Overrides (Riley Table 2 presets set sigma_ext; albedo below 1). */
    p.sigma_ext_m2 = 5.33e-31;
    p.albedo = 0.9;
    atmos_wavelengths_rgb(&wl);
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (t) CHECK(atmos_phase_table_sigma_ext(t, 0) == 5.33e-31 && atmos_phase_table_albedo(t, 2) == 0.9);
    atmos_phase_table_destroy(t);
    atmos_context_destroy(ctx);
}

static void test_analytic(void)
{
    atmos_context *ctx = make_ctx(cache_dir, NULL);
    atmos_wavelengths wl;
    atmos_wavelengths_spectral(4, &wl);
    atmos_particle_desc p = analytic(0.9);
    atmos_phase_table *t = NULL;
    atmos_phase_table_desc td = {1};
    int w0 = warnings;
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    CHECK_MSG(warnings == w0, "unexpected warning: %s", last_warning);
    if (!t) {
        atmos_context_destroy(ctx);
        return;
    }
    const double *th;
    int n = atmos_phase_grid(&th);
    double g_exp = 0.85 * 3 * 0.9 * (4 + 0.81) / (5 * (2 + 0.81)) + 0.10 * -0.3;
    for (int k = 0; k < 4; k++) {
        CHECK_NEAR(table_integral(t, k, 0), 1.0, 1e-4);
        CHECK_NEAR(atmos_phase_table_g(t, k), g_exp, 1e-12);
        CHECK_NEAR(table_integral(t, k, 1), g_exp, 1e-4); /* the table itself has that mean cosine */
        CHECK(atmos_phase_table_sigma_ext(t, k) == 6.28e-10 && atmos_phase_table_albedo(t, k) == 1.0);
        const double *v = atmos_phase_table_values(t, k);
        double worst = 0;
        for (int i = 0; i < n; i++) {
            double e = fabs(v[i] / atmos_phase_mixture_eval(&p.analytic, cos(th[i] * PI / 180)) - 1);
            if (e > worst) worst = e;
        }
        CHECK_MSG(worst < 1e-5, "analytic table vs mixture: max rel err %g", worst);
    }
    CHECK(table_chi2(t, 0, 300000) < 1);

    /* Evaluation between and at grid angles: the sampled density, f(theta) / sin(theta) with
     * f linear in theta through f_i = P_i sin(theta_i) (the table is normalised, so f's own
     * normaliser is 1 to rounding): the grid values back at grid angles, O(h^2) from P
     * interpolated linearly in theta between them, the finite limits at the poles, clamped
     * |mu| > 1. */
    const double *v = atmos_phase_table_values(t, 2);
    double worst = 0, worst_mid = 0, worst_lin = 0;
    for (int i = 0; i + 1 < n; i++) {
        const double a = th[i] * PI / 180, b = th[i + 1] * PI / 180, mid = 0.5 * (a + b);
        if (th[i] >= 1.0) { /* acos(cos(theta)) loses digits at tiny theta */
            double e = fabs(atmos_phase_table_eval(t, 2, cos(a)) - v[i]) / v[i];
            if (e > worst) worst = e;
        }
        if (i > 0 && i + 2 < n) {
            double want = 0.5 * (v[i] * sin(a) + v[i + 1] * sin(b)) / sin(mid);
            double e = fabs(atmos_phase_table_eval(t, 2, cos(mid)) - want) / want;
            if (e > worst_mid) worst_mid = e;
        }
        double el = fabs(atmos_phase_table_eval(t, 2, cos(mid)) - 0.5 * (v[i] + v[i + 1])) / v[i];
        if (el > worst_lin) worst_lin = el;
    }
    CHECK_MSG(worst < 1e-9, "eval at grid angles: max rel err %g", worst);
    CHECK_MSG(worst_mid < 1e-9, "eval between grid angles: max rel err %g", worst_mid);
    CHECK_MSG(worst_lin < 1e-4, "eval vs P linear in theta: max rel difference %g", worst_lin);
    printf("analytic table: eval vs P interpolated linearly in theta: %.2g at most\n", worst_lin);
    const double h = th[1] * PI / 180, hn = (180 - th[n - 2]) * PI / 180;
    CHECK_REL(atmos_phase_table_eval(t, 2, 1.0), v[1] * sin(h) / h, 1e-12);
    CHECK(atmos_phase_table_eval(t, 2, 1.5) == atmos_phase_table_eval(t, 2, 1.0));
    CHECK_REL(atmos_phase_table_eval(t, 2, cos(1e-6)), atmos_phase_table_eval(t, 2, 1.0), 1e-9);
    CHECK_REL(atmos_phase_table_eval(t, 2, -1.0), v[n - 2] * sin(th[n - 2] * PI / 180) / hn, 1e-9);
    CHECK(atmos_phase_table_eval(t, 2, -7.0) == atmos_phase_table_eval(t, 2, -1.0));
    CHECK_REL(atmos_phase_table_eval(t, 2, cos(PI - 1e-5)), atmos_phase_table_eval(t, 2, -1.0), 1e-9);
    CHECK(atmos_phase_table_eval(t, 2, NAN) == 0 && atmos_phase_table_pdf(t, 2, NAN) == 0);
    for (int i = 0; i < 8; i++) {
        double mu = atmos_phase_table_sample(t, 2, (double[]){0, 1e-300, 0.5, 1 - 1e-16, 1, -1, 2, NAN}[i]);
        CHECK(mu >= -1 && mu <= 1);
    }
    atmos_phase_table_destroy(t);

    /* Invalid particles: refused with a message, no table. */
    atmos_particle_desc bad = analytic(0.9);
    bad.analytic.weight[0] = bad.analytic.weight[1] = bad.analytic.weight[2] = 0;
    t = (atmos_phase_table *)&bad;
    CHECK(atmos_phase_table_build(ctx, &bad, &wl, &td, &t) == ATMOS_E_INVALID_ARG && t == NULL);
    CHECK(strstr(atmos_context_error(ctx), "weights") != NULL);
    bad = analytic(1.0);
    CHECK(atmos_phase_table_build(ctx, &bad, &wl, &td, &t) == ATMOS_E_INVALID_ARG && t == NULL);
    CHECK(strstr(atmos_context_error(ctx), "(-1, 1)") != NULL);
    bad = analytic(0.5);
    bad.albedo = 2;
    CHECK(atmos_phase_table_build(ctx, &bad, &wl, &td, &t) == ATMOS_E_INVALID_ARG && t == NULL);
    bad = analytic(0.5);
    bad.kind = (atmos_particle_kind)42;
    CHECK(atmos_phase_table_build(ctx, &bad, &wl, &td, &t) == ATMOS_E_INVALID_ARG && t == NULL);
    atmos_wavelengths none = wl;
    none.count = 0;
    p = analytic(0.5);
    CHECK(atmos_phase_table_build(ctx, &p, &none, &td, &t) == ATMOS_E_INVALID_ARG && t == NULL);
    atmos_context_destroy(ctx);
}

/* ---- the eval / sample / pdf triple */

/* 2 pi int eval(cos theta) sin(theta) dtheta over [a, b] (radians) inside one grid interval,
 * where eval times sin is linear in theta: two Gauss points are exact. */
static double mass_in(const atmos_phase_table *t, int k, double a, double b)
{
    const double c = 0.5 * (a + b), r = 0.5 * (b - a) / sqrt(3.0);
    return PI * (b - a) * (atmos_phase_table_eval(t, k, cos(c - r)) * sin(c - r) + atmos_phase_table_eval(t, k, cos(c + r)) * sin(c + r));
}

/* The probability of [0, theta] under eval, interval by interval; cum[i] = up to grid angle i. */
static double mass_to(const atmos_phase_table *t, int k, const double *cum, const double *th, int n, double theta)
{
    int i = 0;
    while (i + 2 < n && th[i + 1] * PI / 180 <= theta) i++;
    return cum[i] + mass_in(t, k, th[i] * PI / 180, theta);
}

/* Chi-square of samples against eval in bins given by their edges (degrees); expected counts
 * are exact integrals of eval. Returns chi2 / (dof + 5 sqrt(2 dof)). */
static double binned_chi2(const atmos_phase_table *t, int k, const double *cum, const double *th, int n,
                          const double *edges, int nb, long samples)
{
    long *counts = calloc((size_t)nb, sizeof *counts);
    if (!counts) return 1e9;
    for (long q = 0; q < samples; q++) {
        const double x = acos(atmos_phase_table_sample(t, k, uniform())) * 180 / PI;
        int b = 0;
        while (b + 1 < nb && x >= edges[b + 1]) b++;
        counts[b]++;
    }
    double chi2 = 0;
    for (int b = 0; b < nb; b++) {
        double e = samples * (mass_to(t, k, cum, th, n, edges[b + 1] * PI / 180) - mass_to(t, k, cum, th, n, edges[b] * PI / 180));
        chi2 += (counts[b] - e) * (counts[b] - e) / e;
    }
    free(counts);
    const double thr = (nb - 1) + 5 * sqrt(2.0 * (nb - 1));
    if (chi2 > thr) fprintf(stderr, "binned chi2 %.1f over %d bins, threshold %.1f\n", chi2, nb, thr);
    return chi2 / thr;
}

/* eval is the density sample draws from, per steradian, and pdf is eval: pdf = eval bit for
 * bit; eval integrates to 1 over the sphere to rounding; the probability eval gives to
 * [0, theta(u)] is u for a sampled theta(u) (the sampler inverts eval's own CDF); a
 * histogram of samples fine in the forward peak matches eval. */
static void check_triple(const char *name, const atmos_phase_table *t, int k, int chi2_forward)
{
    const double *th;
    const int n = atmos_phase_grid(&th);
    int same = 1;
    for (int q = 0; q < 100000; q++) {
        double mu = q < n ? cos(th[q] * PI / 180) : q % 3 ? 2 * uniform() - 1 : cos(0.02 * uniform());
        same &= atmos_phase_table_pdf(t, k, mu) == atmos_phase_table_eval(t, k, mu);
    }
    CHECK_MSG(same, "%s: pdf differs from eval", name);

    double *cum = malloc(sizeof(double) * (size_t)n);
    if (!cum) return;
    cum[0] = 0;
    for (int i = 0; i + 1 < n; i++) cum[i + 1] = cum[i] + mass_in(t, k, th[i] * PI / 180, th[i + 1] * PI / 180);
    CHECK_MSG(fabs(cum[n - 1] - 1) < 1e-12, "%s: eval integrates to 1 + %.3g over the sphere", name, cum[n - 1] - 1);

    double worst = 0;
    for (int q = 0; q <= 4000; q++) {
        const double u = q == 0 ? 0 : q == 4000 ? 1 - 1e-16 : q == 1 ? 1e-12 : (q - 0.5) / 4000 + 1e-4 * uniform();
        const double theta = acos(atmos_phase_table_sample(t, k, u));
        const double e = fabs(mass_to(t, k, cum, th, n, theta) - u);
        if (e > worst) worst = e;
    }
    CHECK_MSG(worst < 1e-10, "%s: probability of [0, sample(u)] differs from u by %.3g", name, worst);

    if (chi2_forward) {
        /* 40 bins of 0.05° in the peak, 36 of 5° beyond 2° */
        double edges[77];
        int nb = 0;
        for (int b = 0; b < 40; b++) edges[nb++] = 0.05 * b;
        for (int b = 0; b < 36; b++) edges[nb++] = b == 0 ? 2.0 : 5.0 * b;
        edges[nb] = 180;
        CHECK(binned_chi2(t, k, cum, th, n, edges, nb, 400000) < 1);
    }
    printf("%s: pdf = eval, integral 1 %+.2g, CDF at samples within %.2g of u\n", name, cum[n - 1] - 1, worst);
    free(cum);
}

static void test_triple(void)
{
    atmos_context *ctx = make_ctx(cache_dir, NULL);
    atmos_phase_table_desc td = {1};
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_phase_table *t = NULL;
    atmos_particle_desc p = air();
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (t) check_triple("air", t, 1, 0);
    atmos_phase_table_destroy(t);
    p = analytic(0.9);
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (t) check_triple("mixture", t, 2, 1);
    atmos_phase_table_destroy(t);
    /* a sharp forward peak, 1.4° wide at half maximum */
    p = analytic(0.9);
    p.analytic.count = 1;
    p.analytic.kind[0] = ATMOS_PHASE_HG;
    p.analytic.g[0] = 0.995;
    p.analytic.weight[0] = 1;
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (t) check_triple("HG 0.995", t, 0, 1);
    atmos_phase_table_destroy(t);
    atmos_context_destroy(ctx);
}

/* Builds and checks that the result matches ref bit for bit; returns from_cache. */
static int build_same(atmos_context *ctx, const atmos_particle_desc *p, const atmos_wavelengths *wl,
                      const atmos_phase_table *ref)
{
    atmos_phase_table *t = NULL;
    atmos_status st = atmos_phase_table_build(ctx, p, wl, NULL, &t);
    CHECK_OK(st);
    if (!t) return -1;
    const double *th;
    int n = atmos_phase_grid(&th), same = 1;
    for (int k = 0; k < wl->count; k++) {
        same &= !memcmp(atmos_phase_table_values(t, k), atmos_phase_table_values(ref, k), (size_t)n * sizeof(double));
        same &= atmos_phase_table_sigma_ext(t, k) == atmos_phase_table_sigma_ext(ref, k) &&
                atmos_phase_table_albedo(t, k) == atmos_phase_table_albedo(ref, k) &&
                atmos_phase_table_g(t, k) == atmos_phase_table_g(ref, k);
        for (int j = 0; j < 50; j++) {
            double u = j / 50.0;
            same &= atmos_phase_table_sample(t, k, u) == atmos_phase_table_sample(ref, k, u);
        }
    }
    CHECK_MSG(same, "table differs from the reference");
    int fc = atmos_phase_table_from_cache(t);
    atmos_phase_table_destroy(t);
    return fc;
}

/* Rewrites a file with a modification applied to its bytes. */
typedef void (*mutator)(unsigned char *b, long *n);
static void mutate_file(const char *path, mutator m)
{
    FILE *f = fopen(path, "rb");
    if (!f) return;
    static unsigned char buf[1 << 22];
    long n = (long)fread(buf, 1, sizeof buf, f);
    fclose(f);
    m(buf, &n);
    f = fopen(path, "wb");
    if (!f) return;
    fwrite(buf, 1, (size_t)n, f);
    fclose(f);
}
static void flip_payload(unsigned char *b, long *n) { b[*n - 100] ^= 0x10; }
static void truncate_half(unsigned char *b, long *n) { (void)b, *n /= 2; }
static void truncate_header(unsigned char *b, long *n) { (void)b, *n = 20; }
static void bad_magic(unsigned char *b, long *n) { (void)n, b[0] = 'X'; }
static void bad_version(unsigned char *b, long *n) { (void)n, b[8] = 99; }
static void key_byte(unsigned char *b, long *n) { (void)n, b[40] ^= 1; }
static void huge_size(unsigned char *b, long *n) { (void)n, b[16 + 5] = 0x7f; } /* payload size ~ 2^46 */
static void trailing(unsigned char *b, long *n) { b[(*n)++] = 0; }
static void empty(unsigned char *b, long *n) { (void)b, *n = 0; }
static void zero_header_size(unsigned char *b, long *n) { (void)n, memset(b + 16, 0, 8); }

static void test_cache(void)
{
    int removed = -1;
    atmos_context *ctx = make_ctx(cache_dir, NULL);
    CHECK_OK(atmos_cache_clear(ctx, &removed));
    CHECK(count_entries(cache_dir, NULL, 0) == 0);
    atmos_wavelengths wl;
    atmos_wavelengths_spectral(8, &wl);
    atmos_particle_desc p = analytic(0.8);

    atmos_phase_table *ref = NULL;
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, NULL, &ref));
    if (!ref) {
        atmos_context_destroy(ctx);
        return;
    }
    CHECK(atmos_phase_table_from_cache(ref) == 0);
    char entry[1200] = "";
    CHECK(count_entries(cache_dir, entry, sizeof entry) == 1);
    int w0 = warnings;
    CHECK(build_same(ctx, &p, &wl, ref) == 1); /* second build: from the cache, identical */
    CHECK(warnings == w0);

    /* Corrupt or stale entries: warned (naming the file), removed, rebuilt, never fatal;
     * the rebuilt entry is then good again. */
    static const struct {
        const char *name;
        mutator m;
    } bad[] = {{"flipped payload byte", flip_payload}, {"truncated payload", truncate_half},
               {"truncated header", truncate_header},  {"wrong magic", bad_magic},
               {"wrong version", bad_version},         {"different key", key_byte},
               {"huge payload size", huge_size},       {"trailing bytes", trailing},
               {"empty file", empty},                  {"zero payload size", zero_header_size}};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        mutate_file(entry, bad[i].m);
        w0 = warnings;
        int fc = build_same(ctx, &p, &wl, ref);
        CHECK_MSG(fc == 0, "%s: loaded a corrupt entry", bad[i].name);
        CHECK_MSG(warnings > w0 && strstr(last_warning, entry) != NULL, "%s: no warning naming %s (last: %s)",
                  bad[i].name, entry, last_warning);
        CHECK_MSG(build_same(ctx, &p, &wl, ref) == 1, "%s: not rebuilt into the cache", bad[i].name);
    }
    /* A directory in place of the entry: a miss, and the build still succeeds. */
    remove(entry);
    mkdir(entry, 0755);
    CHECK(build_same(ctx, &p, &wl, ref) == 0);
    rmdir(entry);

    /* Different parameters, overrides or wavelengths give different entries. */
    int before = count_entries(cache_dir, NULL, 0);
    atmos_particle_desc q = analytic(0.8000001);
    atmos_phase_table *t = NULL;
    CHECK_OK(atmos_phase_table_build(ctx, &q, &wl, NULL, &t));
    CHECK(t && !atmos_phase_table_from_cache(t));
    atmos_phase_table_destroy(t);
    q = analytic(0.8);
    q.sigma_ext_m2 = 1e-9;
    CHECK_OK(atmos_phase_table_build(ctx, &q, &wl, NULL, &t));
    CHECK(t && !atmos_phase_table_from_cache(t) && atmos_phase_table_sigma_ext(t, 0) == 1e-9);
    atmos_phase_table_destroy(t);
    atmos_wavelengths wl2;
    atmos_wavelengths_spectral(9, &wl2);
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl2, NULL, &t));
    CHECK(t && !atmos_phase_table_from_cache(t));
    atmos_phase_table_destroy(t);
    CHECK(count_entries(cache_dir, NULL, 0) == before + 3);
    /* ... while the name does not matter. */
    q = analytic(0.8);
    snprintf(q.name, sizeof q.name, "renamed");
    CHECK(build_same(ctx, &q, &wl, ref) == 1);

    /* atmos_cache_clear removes the entries and nothing else. */
    char other[1200];
    snprintf(other, sizeof other, "%s/keep-me.txt", cache_dir);
    FILE *f = fopen(other, "w");
    if (f) fclose(f);
    CHECK_OK(atmos_cache_clear(ctx, &removed));
    CHECK(removed == before + 3 && count_entries(cache_dir, NULL, 0) == 0);
    CHECK(access(other, F_OK) == 0);
    remove(other);
    atmos_phase_table_destroy(ref);
    atmos_context_destroy(ctx);

    /* no_cache reads and writes nothing: the directory is not even created. */
    char fresh[1100];
    snprintf(fresh, sizeof fresh, "%s-nocache", cache_dir);
    ctx = make_ctx(fresh, NULL);
    atmos_phase_table_desc nc = {1};
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &nc, &t));
    CHECK(t && !atmos_phase_table_from_cache(t));
    atmos_phase_table_destroy(t);
    struct stat st;
    CHECK(stat(fresh, &st) != 0);
    atmos_context_destroy(ctx);

    /* A cache directory that cannot be created: warned, the table is still built. */
    char blocked[1080];
    snprintf(blocked, sizeof blocked, "%s-file", cache_dir);
    f = fopen(blocked, "w");
    if (f) fclose(f);
    snprintf(fresh, sizeof fresh, "%s/sub", blocked);
    ctx = make_ctx(fresh, NULL);
    w0 = warnings;
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, NULL, &t));
    CHECK(t != NULL && warnings > w0);
    atmos_phase_table_destroy(t);
    atmos_context_destroy(ctx);
    remove(blocked);
}

static void test_progress_and_cancel(void)
{
    atmos_wavelengths wl;
    atmos_wavelengths_spectral(16, &wl);
    atmos_particle_desc p = analytic(0.7);
    progress_rec pr = {0, 1, 0, 0, 2.0, "phase test-mixture"};
    atmos_context *ctx = make_ctx(cache_dir, &pr);
    atmos_phase_table_desc nc = {1};
    atmos_phase_table *t = NULL;
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &nc, &t));
    CHECK(pr.calls >= 16 && pr.monotone && !pr.bad_stage && pr.last == 1.0);
    atmos_phase_table_destroy(t);
    atmos_context_destroy(ctx);

    /* Cancel half-way, and at the very start: ATMOS_E_CANCELLED, no table, nothing cached. */
    static const double at[2] = {0.5, 0.0};
    for (int i = 0; i < 2; i++) {
        char dir[1100];
        snprintf(dir, sizeof dir, "%s-cancel%d", cache_dir, i);
        progress_rec c = {0, 1, 0, 0, at[i], "phase test-mixture"};
        ctx = make_ctx(dir, &c);
        t = (atmos_phase_table *)&c;
        CHECK(atmos_phase_table_build(ctx, &p, &wl, NULL, &t) == ATMOS_E_CANCELLED);
        CHECK(t == NULL);
        CHECK(atmos_context_error_status(ctx) == ATMOS_E_CANCELLED);
        CHECK(count_entries(dir, NULL, 0) == 0);
        atmos_context_destroy(ctx);
    }
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "phase-cache");
    test_air();
    test_analytic();
    test_triple();
    test_cache();
    test_progress_and_cancel();
    return test_summary("test_phase_table");
}
