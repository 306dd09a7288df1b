/* Phase functions of water-drop ensembles (src/optics/water.c) and the particle presets
 * against geometric optics and published numbers: Descartes' rainbow angles, Alexander's
 * dark band, the colour order of the bows, the glory and corona of cloud droplets,
 * Q_ext -> 2 for large drops, Riley et al. 2004 Table 2. Fast quality keeps it quick. */
#include "atmos/atmos.h"
#include "optics/optics_internal.h"
#include "test.h"

/* The sanitizer twin checks memory safety on the same code paths with less work:
 * the rain test skips 550 nm (the colour order needs only 680 and 440) and the cloud
 * test runs at 550 nm only. */
#if defined(__SANITIZE_ADDRESS__)
#define SANITIZED 1
#else
#define SANITIZED 0
#endif

#define PI 3.14159265358979323846

/* Scattering angle (degrees) of minimum deviation after k internal reflections in a
 * sphere of index n (Descartes; Humphreys, Physics of the Air, 1964, ch. IV):
 * cos^2 i = (n^2 - 1) / (k (k + 2)), D = k pi + 2 i - 2 (k + 1) r. */
static double descartes_theta(double n, int k)
{
    double i = acos(sqrt((n * n - 1.0) / (k * (k + 2.0)))), r = asin(sin(i) / n);
    double d = k * PI + 2.0 * i - 2.0 * (k + 1.0) * r;
    d = fmod(d, 2.0 * PI);
    return (d > PI ? 2.0 * PI - d : d) * 180.0 / PI;
}

static int argmax_in(int n, const double *th, const double *p, double lo, double hi)
{
    int best = -1;
    for (int i = 0; i < n; i++)
        if (th[i] >= lo && th[i] <= hi && (best < 0 || p[i] > p[best])) best = i;
    return best;
}

static double mean_in(int n, const double *th, const double *p, double lo, double hi)
{
    double s = 0;
    int c = 0;
    for (int i = 0; i < n; i++)
        if (th[i] >= lo && th[i] <= hi) s += p[i], c++;
    return c ? s / c : NAN;
}

static void test_rain(atmos_context *ctx)
{
    atmos_particle_desc p;
    CHECK_OK(atmos_particle_preset(ctx, "rain", &p));
    p.fast = 1;

    /* Bows: a grid of 0.05° from 118° to 146° (positions and ratios do not need the
     * rest of the sphere; the normalisation is tested on the cloud, whose Mie cost is
     * 100 times smaller, to keep this test quick under the sanitizers). */
    enum { NB = 561 };
    static double th[NB], ph[NB];
    for (int i = 0; i < NB; i++) th[i] = 118.0 + 0.05 * i;
    const double nms[3] = {680.0, 550.0, 440.0};
    double bow1[3], bow2[3];
    for (int w = 0; w < 3; w++) {
        /* a wavelength's cost is fixed by the size budget (6 s under the sanitizers): one
         * there, the colour order below without them */
        if (SANITIZED && w != 0) continue;
        atmos__phase_result r;
        CHECK_OK(atmos__water_phase(ctx, &p, nms[w], NB, th, ph, &r, NULL, NULL));
        double n = atmos_refractive_index_water(nms[w]).re;
        double d1 = descartes_theta(n, 1), d2 = descartes_theta(n, 2);
        int i1 = argmax_in(NB, th, ph, d1 - 4.0, d1 + 4.0);
        int i2 = argmax_in(NB, th, ph, d2 - 4.0, d2 + 4.0);
        CHECK(i1 >= 0 && i2 >= 0);
        if (i1 < 0 || i2 < 0) continue;
        bow1[w] = th[i1], bow2[w] = th[i2];
        CHECK_MSG(fabs(bow1[w] - d1) <= 0.3, "%g nm: primary bow at %.3f°, Descartes %.3f°", nms[w], bow1[w], d1);
        CHECK_MSG(fabs(bow2[w] - d2) <= 0.5, "%g nm: secondary bow at %.3f°, Descartes %.3f°", nms[w], bow2[w], d2);
        /* Alexander's dark band between the bows: darker than both maxima and than the
         * sky inside the primary / outside the secondary */
        double band = mean_in(NB, th, ph, bow2[w] + 1.0, bow1[w] - 1.0);
        double inside = mean_in(NB, th, ph, bow1[w] + 1.0, bow1[w] + 6.0);
        double outside = mean_in(NB, th, ph, bow2[w] - 6.0, bow2[w] - 1.0);
        CHECK_MSG(band < 0.2 * ph[i1] && band < 0.2 * ph[i2], "%g nm: band %g, bows %g %g", nms[w], band, ph[i1], ph[i2]);
        CHECK_MSG(band < inside && band < outside, "%g nm: band %g, inside %g, outside %g", nms[w], band, inside, outside);
        CHECK(ph[i1] > ph[i2]); /* the primary is the brighter bow */
        CHECK(r.albedo > 0.999 && r.albedo <= 1.0);
        CHECK(r.g > 0.85 && r.g < 0.9);
        /* Q_ext -> 2 for drops of x ~ 1e4: sigma_ext ~ 2 pi <r^2>, lognormal
         * <r^2> = r_m^2 exp(2 sigma^2) (slightly less: r_max cuts the tail) */
        double geo = 2.0 * PI * p.size.r_m * p.size.r_m * exp(2.0 * p.size.sigma * p.size.sigma);
        CHECK_MSG(fabs(r.sigma_ext_m2 / geo - 1.0) < 0.01, "%g nm: sigma_ext %g, 2 pi <r^2> %g", nms[w],
                  r.sigma_ext_m2, geo);
    }
    /* colour order: red outside in the primary (larger radius 180 - theta, i.e. smaller
     * scattering angle), inside in the secondary */
    if (!SANITIZED) {
        CHECK_MSG(bow1[0] < bow1[2], "primary: 680 nm at %.3f°, 440 nm at %.3f°", bow1[0], bow1[2]);
        CHECK_MSG(bow2[0] > bow2[2], "secondary: 680 nm at %.3f°, 440 nm at %.3f°", bow2[0], bow2[2]);
    }

}

static void test_cloud(atmos_context *ctx)
{
    atmos_particle_desc p;
    CHECK_OK(atmos_particle_preset(ctx, "cloud", &p));
    p.fast = 1;
    const double *grid;
    int n = atmos_phase_grid(&grid);
    double *P = malloc((size_t)n * sizeof *P), *Pc = malloc((size_t)n * sizeof *Pc);
    const double nms[3] = {680.0, 550.0, 440.0};
    for (int w = 0; w < 3; w++) {
        if (SANITIZED && w != 1) continue;
        atmos__phase_result r;
        CHECK_OK(atmos__water_phase(ctx, &p, nms[w], n, grid, P, &r, NULL, NULL));
        /* g of water clouds in the visible: 0.84 - 0.88 (Hansen & Travis 1974 Fig. 12) */
        CHECK_MSG(r.g > 0.84 && r.g < 0.88, "%g nm: g = %g", nms[w], r.g);
        CHECK_NEAR(atmos__sphere_integral(n, grid, P), 1.0, 1e-4);
        for (int i = 0; i < n; i++) Pc[i] = P[i] * cos(grid[i] * PI / 180.0);
        CHECK_NEAR(atmos__sphere_integral(n, grid, Pc), r.g, 1e-3);
        /* the glory: P rises towards 180° over the last 2° */
        int i178 = argmax_in(n, grid, grid, 0.0, 178.0), i180 = n - 1;
        CHECK_MSG(P[i180] > 1.3 * P[i178] && P[i178] > mean_in(n, grid, P, 170.0, 175.0),
                  "%g nm: P(175) %g P(178) %g P(180) %g", nms[w], mean_in(n, grid, P, 170.0, 175.0), P[i178], P[i180]);
        /* sigma_ext = pi <r^2> Q_ext with Q_ext ~ 2.1 at x ~ 100 and, for the gamma
         * distribution r^7 exp(-r/1um), <r^2> = 8 * 9 um^2 */
        CHECK_MSG(r.sigma_ext_m2 > 2.0 * PI * 72e-12 && r.sigma_ext_m2 < 2.2 * PI * 72e-12, "%g nm: sigma_ext %g",
                  nms[w], r.sigma_ext_m2);
    }
    /* The corona needs a narrow distribution (thin altocumulus); the preset's effective
     * variance 0.1 washes the rings out. Lognormal, 10 um, sigma 0.05: the first ring
     * lies near x sin(theta) = 5.14 (Airy pattern's first secondary maximum), ~2.6° at
     * 550 nm. */
    atmos_particle_desc q = p;
    q.size = (atmos_size_distribution){.kind = ATMOS_SIZE_LOGNORMAL, .r_m = 10e-6, .sigma = 0.05};
    atmos__phase_result r;
    CHECK_OK(atmos__water_phase(ctx, &q, 550.0, n, grid, P, &r, NULL, NULL));
    double x = 2.0 * PI * 10e-6 / 550e-9, ring = asin(5.14 / x) * 180.0 / PI;
    int im = argmax_in(n, grid, P, ring - 0.8, ring + 0.8);
    CHECK_MSG(im >= 0 && P[im] > P[argmax_in(n, grid, grid, 0.0, ring - 0.8)] &&
                  P[im] > P[argmax_in(n, grid, grid, 0.0, ring + 0.8)],
              "no corona ring near %.2f°", ring);
    free(P), free(Pc);
}

static int cancel_at_half(void *user, double f)
{
    (void)user;
    return f >= 0.5;
}

static void test_presets_and_errors(atmos_context *ctx)
{
    /* Riley et al. 2004 Table 2 */
    const struct {
        const char *name;
        double sigma;
        atmos_particle_kind kind;
    } t2[] = {{"cloud", 6.28e-10, ATMOS_PARTICLE_WATER},
              {"rain", 6.28e-6, ATMOS_PARTICLE_WATER},
              {"ice", 1.82e-6, ATMOS_PARTICLE_ICE},
              {"snow", 1.41e-5, ATMOS_PARTICLE_SNOW},
              {"air", 0.0, ATMOS_PARTICLE_AIR}};
    for (int i = 0; i < 5; i++) {
        atmos_particle_desc p;
        CHECK_OK(atmos_particle_preset(ctx, t2[i].name, &p));
        CHECK(p.sigma_ext_m2 == t2[i].sigma);
        CHECK(p.kind == t2[i].kind);
        CHECK(p.albedo == 0.0);
        CHECK(!strcmp(p.name, t2[i].name));
    }
    atmos_particle_desc p;
    CHECK_OK(atmos_particle_preset(ctx, "ice", &p));
    CHECK(p.habit == ATMOS_CRYSTAL_COLUMN && p.aspect_ratio == 2.0 && p.size.r_m == 0.0);
    CHECK_OK(atmos_particle_preset(ctx, "snow", &p));
    CHECK(p.habit == ATMOS_CRYSTAL_PLATE);
    /* Table 2's cross-sections are 2 pi r^2 of Riley's 0.01 mm and 1 mm spheres */
    CHECK_REL(2.0 * PI * 1e-10, 6.28e-10, 1e-3);
    CHECK_REL(2.0 * PI * 1e-6, 6.28e-6, 1e-3);
    int count = 0;
    for (const char *const *n = atmos_particle_preset_names(); *n; n++) count++;
    CHECK(count == 5);
    CHECK(atmos_particle_preset(ctx, "fog", &p) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "fog") && strstr(atmos_context_error(ctx), "rain"));

    /* bad distributions are refused with the value named; cancellation */
    CHECK_OK(atmos_particle_preset(ctx, "cloud", &p));
    p.fast = 1;
    double th[3] = {0.0, 90.0, 180.0}, ph[3];
    atmos__phase_result r;
    atmos_particle_desc b = p;
    b.size.r_m = -1.0;
    CHECK(atmos__water_phase(ctx, &b, 550.0, 3, th, ph, &r, NULL, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "-1") != NULL);
    b = p;
    b.size.kind = ATMOS_SIZE_LOGNORMAL;
    b.size.sigma = 0.0;
    CHECK(atmos__water_phase(ctx, &b, 550.0, 3, th, ph, &r, NULL, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(atmos__water_phase(ctx, &p, 550.0, 3, th, ph, &r, cancel_at_half, NULL) == ATMOS_E_CANCELLED);
    b = p; /* a 5 cm "drop" exceeds the Mie limit x <= 1e5 */
    b.size = (atmos_size_distribution){.kind = ATMOS_SIZE_MONODISPERSE, .r_m = 0.05};
    CHECK(atmos__water_phase(ctx, &b, 550.0, 3, th, ph, &r, NULL, NULL) == ATMOS_E_LIMIT);
}

/* Same result for any thread count (fixed-order reduction). */
static void test_threads(void)
{
    atmos_particle_desc p;
    CHECK_OK(atmos_particle_preset(NULL, "cloud", &p));
    p.fast = 1;
    const double *grid;
    int n = atmos_phase_grid(&grid);
    double *a = malloc((size_t)n * sizeof *a), *b = malloc((size_t)n * sizeof *b);
    atmos__phase_result ra, rb;
    atmos_context *c1, *c3;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 1;
    CHECK_OK(atmos_context_create(&d, &c1));
    d.threads = 3;
    CHECK_OK(atmos_context_create(&d, &c3));
    CHECK_OK(atmos__water_phase(c1, &p, 500.0, n, grid, a, &ra, NULL, NULL));
    CHECK_OK(atmos__water_phase(c3, &p, 500.0, n, grid, b, &rb, NULL, NULL));
    CHECK(memcmp(a, b, (size_t)n * sizeof *a) == 0);
    CHECK(ra.g == rb.g && ra.sigma_ext_m2 == rb.sigma_ext_m2 && ra.albedo == rb.albedo);
    atmos_context_destroy(c1);
    atmos_context_destroy(c3);
    free(a), free(b);
}

/* Progress within a batch: on the tables' grid rain affords a few dozen sizes a wavelength,
 * one or two batches of 32 (tens of seconds of a batch job's silence in normal quality when
 * reported only after each); the calling thread reports after each size, so no step between
 * reports exceeds 1/8 of the wavelength's work, the fractions grow and the last is 1. A callback asking to stop cancels the computation. */
typedef struct {
    int calls, cancel_at;
    double last, max_step;
} water_progress;

static int water_progress_fn(void *user, double f)
{
    water_progress *w = user;
    CHECK(f >= w->last);
    if (f - w->last > w->max_step) w->max_step = f - w->last;
    w->last = f;
    return ++w->calls == w->cancel_at;
}

static void test_progress(void)
{
    atmos_particle_desc p;
    CHECK_OK(atmos_particle_preset(NULL, "rain", &p));
    p.fast = 1;
    /* the tables' whole grid: so many angles that the budget affords a few dozen sizes */
    const double *th;
    const int NB = atmos_phase_grid(&th);
    double *ph = malloc((size_t)NB * sizeof *ph);
    atmos__phase_result r;
    atmos_context *c1;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 1;
    CHECK_OK(atmos_context_create(&d, &c1));
    /* the whole computation is reported on without the sanitizers (7 s with them); the
     * cancelled one below runs the same calls in both builds */
    if (!SANITIZED) {
        water_progress w = {0, -1, 0, 0};
        CHECK_OK(atmos__water_phase(c1, &p, 680.0, NB, th, ph, &r, water_progress_fn, &w));
        printf("rain, fast, 680 nm: %d progress reports, largest step %.3f\n", w.calls, w.max_step);
        CHECK(w.calls >= 8 && w.max_step <= 0.125 && w.last == 1.0);
    }
    water_progress c = {0, 2, 0, 0};
    CHECK(atmos__water_phase(c1, &p, 680.0, NB, th, ph, &r, water_progress_fn, &c) == ATMOS_E_CANCELLED);
    CHECK(c.calls == 2);
    atmos_context_destroy(c1);
    free(ph);
}

int main(void)
{
    atmos_context *ctx;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    CHECK_OK(atmos_context_create(&d, &ctx));
    test_rain(ctx);
    test_cloud(ctx);
    test_presets_and_errors(ctx);
    test_threads();
    test_progress();
    atmos_context_destroy(ctx);
    return test_summary("test_water_optics");
}
