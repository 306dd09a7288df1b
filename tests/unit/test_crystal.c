/* Ice and snow crystal phase functions (src/optics/crystal.c): physics checks.
 *
 * Halo positions are compared with the prism minimum deviation computed here from
 * Snell's law, D_min = 2 arcsin(n sin(A / 2)) - A (A = 60° for the 22° halo, 90° for
 * the 46° halo), cross-sections with Cauchy's theorem, energies per ray with the
 * Fresnel equations written out independently. Fast mode keeps the run short. */
#include "atmos/atmos.h"
#include "optics/crystal_internal.h"
#include "optics/optics_internal.h"
#include "test.h"

#include <math.h>

#define PI 3.14159265358979323846

/* The sanitizer twin checks memory and undefined behaviour, not statistics: it skips
 * the middle wavelength and traces half the rays to stay fast (the tracer runs ~5x
 * slower under ASan). */
#if defined(__SANITIZE_ADDRESS__)
#define SANITIZED 1
#else
#define SANITIZED 0
#endif

static double dmin_deg(double n, double apex_deg)
{
    double a = apex_deg * PI / 180.0;
    return (2.0 * asin(n * sin(a / 2.0)) - a) * 180.0 / PI;
}

static int all_finite(int n, const double *v)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]) || v[i] < 0.0) return 0;
    return 1;
}

/* P at theta by linear interpolation on the grid. */
static double at(int n, const double *th, const double *P, double t)
{
    for (int i = 1; i < n; i++)
        if (th[i] >= t) {
            double f = (t - th[i - 1]) / (th[i] - th[i - 1]);
            return P[i - 1] + f * (P[i] - P[i - 1]);
        }
    return P[n - 1];
}

/* Inner edge of a halo near d: the angle of the steepest rise of P (central differences
 * over +-0.05°) within d +- 1.5°; and the maximum of P in the same window. */
static void halo(int n, const double *th, const double *P, double d, double *edge, double *peak)
{
    double best_slope = -1.0, best = -1.0;
    *edge = *peak = 0.0;
    for (int i = 1; i + 1 < n; i++) {
        if (th[i] < d - 1.5 || th[i] > d + 1.5) continue;
        double s = (P[i + 1] - P[i - 1]) / (th[i + 1] - th[i - 1]);
        if (s > best_slope) {
            best_slope = s;
            *edge = th[i];
        }
        if (P[i] > best) {
            best = P[i];
            *peak = th[i];
        }
    }
}

static double g_of(int n, const double *th, const double *P)
{
    double *f = malloc(sizeof(double) * (size_t)n);
    for (int i = 0; i < n; i++) f[i] = P[i] * cos(th[i] * PI / 180.0);
    double g = atmos__sphere_integral(n, th, f);
    free(f);
    return g;
}

static int cancel_progress(void *user, double fraction)
{
    int *calls = user;
    (*calls)++;
    return fraction >= 0.25; /* cancel once a quarter is done */
}

static int count_progress(void *user, double fraction)
{
    double *last = user;
    CHECK(fraction >= *last && fraction <= 1.0);
    *last = fraction;
    return 0;
}

/* Fresnel against the textbook formulas with transmittance computed separately
 * (Born & Wolf §1.5.3: T = n2 cos_t / (n1 cos_i) |t|^2). */
static void test_fresnel(void)
{
    const double n = 1.31;
    CHECK_NEAR(atmos__fresnel(1.0, n, 1.0, NULL), pow((n - 1) / (n + 1), 2), 1e-15);
    for (double deg = 0.0; deg < 90.0; deg += 7.5) {
        double ci = cos(deg * PI / 180.0), ct;
        double R = atmos__fresnel(1.0, n, ci, &ct);
        double ts = 2 * ci / (ci + n * ct), tp = 2 * ci / (n * ci + ct);
        double T = n * ct / ci * 0.5 * (ts * ts + tp * tp);
        CHECK_NEAR(R + T, 1.0, 1e-12);
    }
    /* Total internal reflection beyond the critical angle asin(1/n) = 49.8°. */
    CHECK(atmos__fresnel(n, 1.0, cos(50.5 * PI / 180.0), NULL) == 1.0);
    CHECK(atmos__fresnel(n, 1.0, cos(49.0 * PI / 180.0), NULL) < 1.0);
}

/* Every ray's energy is accounted for, with and without absorption and tilts. */
static void test_energy_per_ray(void)
{
    atmos__crystal c;
    atmos__crystal_init(&c, 100e-6, 400e-6);
    atmos__crystal_optics o[3] = {{1.31, 0.0, 0.0, 30, 0.0}, {1.31, 2000.0, 0.0, 30, 0.0}, {1.31, 50.0, 0.3, 30, 1e-7}};
    for (int k = 0; k < 3; k++) {
        atmos__rng rng;
        atmos__rng_seed(&rng, 1234 + (uint64_t)k);
        atmos__crystal_ray ray;
        double worst = 0.0, absorbed = 0.0, lost = 0.0, sum_t = 0.0;
        int bad = 0;
        for (int i = 0; i < 5000; i++) {
            atmos__crystal_trace(&c, &o[k], &rng, &ray);
            double e = ray.reflected + ray.transmitted + ray.absorbed + ray.lost;
            worst = fmax(worst, fabs(e - 1.0));
            double exits = 0.0;
            for (int j = 0; j < ray.n_exit; j++) {
                exits += ray.weight[j];
                if (!(ray.theta[j] >= 0.0 && ray.theta[j] <= PI) || !(ray.weight[j] >= 0.0)) bad++;
            }
            worst = fmax(worst, fabs(exits - ray.reflected - ray.transmitted));
            absorbed += ray.absorbed;
            lost += ray.lost;
            sum_t += ray.transmitted;
        }
        CHECK_MSG(worst < 1e-12, "optics %d: energy balance off by %g", k, worst);
        CHECK(bad == 0);
        CHECK(lost / 5000 < 2e-3);
        if (k == 1) CHECK_MSG(absorbed / 5000 > 0.05, "absorbed %g", absorbed / 5000);
        if (k == 0) CHECK(absorbed == 0.0);
        if (k != 1) CHECK(sum_t / 5000 > 0.85);
    }
}

/* Cauchy: the mean projected area of a convex body is a quarter of its surface. */
static void test_cauchy(void)
{
    const double R = 50e-6, L = 30e-6; /* a plate */
    atmos__crystal c;
    atmos__crystal_init(&c, R, L);
    double S = 2.0 * (3.0 * sqrt(3.0) / 2.0 * R * R) + 6.0 * R * L;
    CHECK_REL(c.surface_area, S, 1e-12);
    atmos__rng rng;
    atmos__rng_seed(&rng, 99);
    double sum = 0.0;
    const int N = 50000;
    for (int i = 0; i < N; i++) {
        double z = 1.0 - 2.0 * atmos__rng_uniform(&rng), phi = 2.0 * PI * atmos__rng_uniform(&rng);
        double s = sqrt(1.0 - z * z), d[3] = {s * cos(phi), s * sin(phi), z};
        sum += atmos__crystal_projected_area(&c, d);
    }
    CHECK_REL(sum / N, S / 4.0, 6e-3); /* ~4.5 standard errors */
    /* Projected area seen along the axis is the hexagon, across it a rectangle 2R x L
     * (looking at a corner) or sqrt(3) R x L (looking at a face). */
    double ax[3] = {0, 0, 1}, corner[3] = {1, 0, 0}, face[3] = {cos(PI / 6), sin(PI / 6), 0};
    CHECK_REL(atmos__crystal_projected_area(&c, ax), 1.5 * sqrt(3.0) * R * R, 1e-12);
    CHECK_REL(atmos__crystal_projected_area(&c, corner), sqrt(3.0) * R * L, 1e-12);
    CHECK_REL(atmos__crystal_projected_area(&c, face), 2.0 * R * L, 1e-12);
}

/* ice columns at three wavelengths: halos, chromatic order, normalisation */
static double test_ice_columns(atmos_context *ctx2, atmos_particle_desc *ice_out, int n, const double *th,
                               double *P)
{
    atmos_particle_desc ice = {0};
    ice.kind = ATMOS_PARTICLE_ICE;
    ice.habit = ATMOS_CRYSTAL_COLUMN;
    ice.size.r_m = 100e-6;
    ice.fast = 1;
    if (SANITIZED) ice.rays = 100000;
    const double wl[3] = {440.0, 550.0, 680.0};
    double edge22[3], peak22[3], edge46[3], contrast_ice = 0.0;
    for (int k = 0; k < 3; k++) {
        if (SANITIZED && k == 1) continue;
        atmos__phase_result r;
        atmos__crystal_stats st;
        double last = 0.0;
        CHECK_OK(atmos__crystal_phase_ex(ctx2, &ice, wl[k], n, th, P, &r, count_progress, &last, &st));
        CHECK(last == 1.0);
        CHECK(all_finite(n, P));
        CHECK_NEAR(atmos__sphere_integral(n, th, P), 1.0, 1e-4);
        double nr = atmos_refractive_index_ice(wl[k]).re;
        CHECK(st.n_real == nr);
        double d22 = dmin_deg(nr, 60.0), d46 = dmin_deg(nr, 90.0), peak46;
        halo(n, th, P, d22, &edge22[k], &peak22[k]);
        halo(n, th, P, d46, &edge46[k], &peak46);
        printf("ice %3.0f nm: n %.5f  22° halo: D_min %.3f edge %.3f max %.3f | 46° halo: D_min %.3f edge %.3f "
               "max %.3f | g %.4f\n",
               wl[k], nr, d22, edge22[k], peak22[k], d46, edge46[k], peak46, r.g);
        CHECK_NEAR(edge22[k], d22, 0.3);
        CHECK_NEAR(edge46[k], d46, 0.3);
        /* Random orientation: the maximum lies just outside the edge (skew rays deviate
         * more than the principal-plane minimum), moved a little further by the kernel. */
        CHECK(peak22[k] >= d22 - 0.1 && peak22[k] <= d22 + 0.5);
        CHECK(peak46 >= d46 - 0.1 && peak46 <= d46 + 0.6);
        /* The halo is bright against the dark region inside it. */
        double c = at(n, th, P, peak22[k]) / at(n, th, P, 18.0);
        CHECK_MSG(c > 5.0, "22° halo contrast %g", c);
        if (k == 2) contrast_ice = at(n, th, P, 22.0) / at(n, th, P, 18.0);
        /* Energy bookkeeping over all rays; absorption negligible in the visible. */
        CHECK_NEAR(st.reflected + st.transmitted + st.absorbed + st.lost, 1.0, 1e-9);
        CHECK(st.lost < 2e-3);
        CHECK(st.absorbed < 1e-3);
        CHECK(r.albedo > 0.999 && r.albedo <= 1.0);
        /* sigma_ext = 2 <A> = S / 2 (Cauchy), S computed here. */
        double R = 100e-6, L = 2.0 * R * 2.0; /* default column aspect 2 */
        double S = 3.0 * sqrt(3.0) * R * R + 6.0 * R * L;
        CHECK_REL(r.sigma_ext_m2, S / 2.0, 1e-12);
        CHECK_REL(st.length_m, L, 1e-12);
        /* g: geometric optics + diffraction for columns (Macke et al. 1996 report ~0.8). */
        CHECK_MSG(r.g > 0.75 && r.g < 0.85, "g %g", r.g);
        CHECK_NEAR(r.g, g_of(n, th, P), 1e-12);
    }
    /* Chromatic order: n is larger for blue, so red deviates least and is inside. */
    if (SANITIZED) edge22[1] = 0.5 * (edge22[0] + edge22[2]);
    CHECK(edge22[2] < edge22[1] && edge22[1] < edge22[0]);
    CHECK(peak22[2] < peak22[0]);
    CHECK(edge46[2] < edge46[0]);
    *ice_out = ice;
    return contrast_ice;
}

/* size from sigma_ext_m2 (Riley Table 2's ice), and plates */
static void test_plates(atmos_context *ctx2, const atmos_particle_desc *ice, int n, const double *th, double *P)
{
    atmos_particle_desc p = *ice;
    atmos__phase_result r;
    atmos__crystal_stats st;
    p.size.r_m = 0.0;
    p.sigma_ext_m2 = 1.82e-6;
    p.habit = ATMOS_CRYSTAL_PLATE;
    p.rays = 20000;
    CHECK_OK(atmos__crystal_phase_ex(ctx2, &p, 550.0, n, th, P, &r, NULL, NULL, &st));
    CHECK_REL(r.sigma_ext_m2, 1.82e-6, 1e-12);
    CHECK_REL(st.length_m, 0.2 * 2.0 * st.radius_m, 1e-12);
    double S = 3.0 * sqrt(3.0) * st.radius_m * st.radius_m + 6.0 * st.radius_m * st.length_m;
    CHECK_REL(S / 2.0, 1.82e-6, 1e-12);
    CHECK(all_finite(n, P));
    CHECK_NEAR(atmos__sphere_integral(n, th, P), 1.0, 1e-4);
    CHECK_MSG(r.g > 0.7 && r.g < 0.9, "plate g %g", r.g);
    /* No size at all: 100 µm. */
    p.sigma_ext_m2 = 0.0;
    CHECK_OK(atmos__crystal_phase_ex(ctx2, &p, 550.0, n, th, P, &r, NULL, NULL, &st));
    CHECK(st.radius_m == 100e-6);
}

/* snow: distorted crystals, no sharp halo, smooth */
static void test_snow(atmos_context *ctx2, const atmos_particle_desc *ice, double contrast_ice, int n,
                      const double *th, double *P)
{
    atmos_particle_desc snow = *ice;
    snow.kind = ATMOS_PARTICLE_SNOW;
    snow.habit = ATMOS_CRYSTAL_PLATE;
    atmos__phase_result r;
    atmos__crystal_stats st;
    CHECK_OK(atmos__crystal_phase_ex(ctx2, &snow, 680.0, n, th, P, &r, NULL, NULL, &st));
    CHECK(all_finite(n, P));
    CHECK_NEAR(atmos__sphere_integral(n, th, P), 1.0, 1e-4);
    CHECK(st.tilt_rad == 0.3);
    CHECK_NEAR(st.reflected + st.transmitted + st.absorbed + st.lost, 1.0, 1e-9);
    double contrast = at(n, th, P, 22.0) / at(n, th, P, 18.0);
    printf("22°/18° contrast: ice %.2f, snow %.2f; snow g %.4f\n", contrast_ice, contrast, r.g);
    CHECK_MSG(contrast < 1.3 && contrast < 0.2 * contrast_ice, "snow contrast %g (ice %g)", contrast, contrast_ice);
    double c46 = at(n, th, P, 46.5) / at(n, th, P, 42.0);
    CHECK_MSG(c46 < 1.1, "snow 46°/42° contrast %g", c46);
    /* Smooth where the halos would be: relative second differences at 1° spacing
     * from 10° to 60° (ice has ~20 at its halo edges; fast-mode noise is ~0.1). */
    double worst = 0.0;
    for (double t = 10.0; t <= 60.0; t += 1.0) {
        double a = at(n, th, P, t - 1.0), b = at(n, th, P, t), c = at(n, th, P, t + 1.0);
        worst = fmax(worst, fabs(a - 2.0 * b + c) / b);
    }
    CHECK_MSG(worst < 0.35, "snow roughness %g", worst);
    CHECK_MSG(r.g > 0.6 && r.g < 0.9, "snow g %g", r.g);
}

/* determinism: 1 and 2 threads give the same bits */
static void test_determinism(atmos_context *ctx1, atmos_context *ctx2, const atmos_particle_desc *ice, int n,
                             const double *th, double *P, double *Q)
{
    atmos_particle_desc p = *ice;
    p.rays = 12800;
    atmos__phase_result r1, r2;
    CHECK_OK(atmos__crystal_phase(ctx1, &p, 500.0, n, th, P, &r1, NULL, NULL));
    CHECK_OK(atmos__crystal_phase(ctx2, &p, 500.0, n, th, Q, &r2, NULL, NULL));
    CHECK(memcmp(P, Q, sizeof(double) * (size_t)n) == 0);
    CHECK(r1.g == r2.g && r1.albedo == r2.albedo && r1.sigma_ext_m2 == r2.sigma_ext_m2);
    p.kind = ATMOS_PARTICLE_SNOW;
    CHECK_OK(atmos__crystal_phase(ctx1, &p, 500.0, n, th, P, &r1, NULL, NULL));
    CHECK_OK(atmos__crystal_phase(ctx2, &p, 500.0, n, th, Q, &r2, NULL, NULL));
    CHECK(memcmp(P, Q, sizeof(double) * (size_t)n) == 0);
}

/* cancellation and bad input */
static void test_bad_input(atmos_context *ctx2, const atmos_particle_desc *ice, int n, const double *th, double *P)
{
    atmos_particle_desc p = *ice;
    p.rays = 6400;
    int calls = 0;
    CHECK(atmos__crystal_phase(ctx2, &p, 550.0, n, th, P, NULL, cancel_progress, &calls) == ATMOS_E_CANCELLED);
    CHECK(calls >= 1);
    p.kind = ATMOS_PARTICLE_WATER;
    CHECK(atmos__crystal_phase(ctx2, &p, 550.0, n, th, P, NULL, NULL, NULL) == ATMOS_E_INVALID_ARG);
    p.kind = ATMOS_PARTICLE_ICE;
    p.aspect_ratio = -1.0;
    CHECK(atmos__crystal_phase(ctx2, &p, 550.0, n, th, P, NULL, NULL, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx2), "aspect_ratio") != NULL);
    p.aspect_ratio = NAN;
    CHECK(atmos__crystal_phase(ctx2, &p, 550.0, n, th, P, NULL, NULL, NULL) == ATMOS_E_INVALID_ARG);
    p.aspect_ratio = 0.0;
    p.rays = 1L << 40;
    CHECK(atmos__crystal_phase(ctx2, &p, 550.0, n, th, P, NULL, NULL, NULL) == ATMOS_E_LIMIT);
    p.rays = 6400;
    CHECK(atmos__crystal_phase(ctx2, &p, NAN, n, th, P, NULL, NULL, NULL) == ATMOS_E_INVALID_ARG);
    p.size.r_m = -1.0;
    CHECK(atmos__crystal_phase(ctx2, &p, 550.0, n, th, P, NULL, NULL, NULL) == ATMOS_E_INVALID_ARG);
    p.size.r_m = 100e-6;
    p.distortion = 5.0;
    p.kind = ATMOS_PARTICLE_SNOW;
    CHECK(atmos__crystal_phase(ctx2, &p, 550.0, n, th, P, NULL, NULL, NULL) == ATMOS_E_INVALID_ARG);
    /* Extremes stay finite: a needle and a thin plate, tiny and huge crystals. */
    p.distortion = 0.0;
    const double aspects[4] = {100.0, 0.01, 2.0, 0.2};
    const double radii[4] = {1e-6, 1e-6, 0.1, 5e-3};
    for (int i = 0; i < 4; i++) {
        p.aspect_ratio = aspects[i];
        p.size.r_m = radii[i];
        p.kind = i % 2 ? ATMOS_PARTICLE_ICE : ATMOS_PARTICLE_SNOW;
        atmos__phase_result r;
        atmos_status s = atmos__crystal_phase(ctx2, &p, 400.0, n, th, P, &r, NULL, NULL);
        CHECK_MSG(s == ATMOS_OK || s == ATMOS_E_INVALID_ARG, "extreme %d: %s", i, atmos_status_string(s));
        if (s == ATMOS_OK) {
            CHECK(all_finite(n, P));
            CHECK(isfinite(r.g) && isfinite(r.albedo) && isfinite(r.sigma_ext_m2));
        }
    }
}

int main(void)
{
    test_fresnel();
    test_energy_per_ray();
    test_cauchy();

    const double *th;
    int n = atmos_phase_grid(&th);
    double *P = malloc(sizeof(double) * (size_t)n), *Q = malloc(sizeof(double) * (size_t)n);
    atmos_context *ctx1 = NULL, *ctx2 = NULL;
    atmos_context_desc cd = {0};
    cd.threads = 1;
    CHECK_OK(atmos_context_create(&cd, &ctx1));
    cd.threads = 2;
    CHECK_OK(atmos_context_create(&cd, &ctx2));

    atmos_particle_desc ice;
    double contrast_ice = test_ice_columns(ctx2, &ice, n, th, P);
    test_plates(ctx2, &ice, n, th, P);
    test_snow(ctx2, &ice, contrast_ice, n, th, P);
    test_determinism(ctx1, ctx2, &ice, n, th, P, Q);
    test_bad_input(ctx2, &ice, n, th, P);

    atmos_context_destroy(ctx1);
    atmos_context_destroy(ctx2);
    free(P);
    free(Q);
    return test_summary("test_crystal");
}
