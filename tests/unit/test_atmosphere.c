/* The atmosphere interface, for every kind, against a second method: numerical
 * quadrature of the defining integrals over the coefficients the interface reports at
 * points (atmos_atmosphere_scattering), so that a kind's closed forms are checked against
 * its own medium, and Monte Carlo checks of the renderers' point sampling. */
#include "atmos/atmos.h"
#include "atmosphere/atmosphere_ops.h"
#include "test.h"

#include <math.h>

#define PI 3.14159265358979323846

static atmos_atmosphere *make(atmos_atmosphere_kind kind, const atmos_wavelengths *wl)
{
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    d.kind = kind;
    d.thickness_m = 2500;
    d.background_radiance = 0.03;
    d.ground_albedo = 0.25;
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &d, wl, &a));
    return a;
}

/* Optical depth along p + t d, t in [0, D], by the midpoint rule on the extinction the
 * interface reports at points (D capped at 400 km: the air is negligible beyond). */
static void depth_quad(const atmos_atmosphere *a, const double p[3], const double d[3], double D, int n, double *tau)
{
    const int N = 200000;
    /* an endless ray: up to 200 km above the start (beyond any air here) or 400 km level */
    if (isinf(D)) D = d[1] > 1e-9 ? fmin(2e5 / d[1], 1e8) : 4e5;
    for (int k = 0; k < n; k++) tau[k] = 0;
    const double dt = D / N;
    for (int i = 0; i < N; i++) {
        const double t = (i + 0.5) * dt, x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
        double e[ATMOS_MAX_WAVELENGTHS];
        atmos_atmosphere_scattering(a, x, NULL, e);
        for (int k = 0; k < n; k++) tau[k] += e[k] * dt;
    }
}

static const double points[][3] = {{0, 10, 0}, {50, 1200, -30}, {0, 2499, 0}, {0, 4000, 0}, {0, 9000, 0}};
static const double dirs_el[] = {-60, -5, -0.2, 0, 0.2, 5, 60, 90};

static void test_transmittance_and_sunlight(atmos_atmosphere_kind kind)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = make(kind, &wl);
    double worst = 0;
    for (size_t ip = 0; ip < sizeof points / sizeof points[0]; ip++)
        for (size_t id = 0; id < sizeof dirs_el / sizeof dirs_el[0]; id++) {
            double d[3], T[3], tau[3];
            atmos_direction_from_angles(dirs_el[id], 40, d);
            const double Dg = atmos_atmosphere_ground_distance(a, points[ip], d);
            const double D = fmin(Dg, 30000.0);
            atmos_atmosphere_transmittance(a, points[ip], d, D, T);
            depth_quad(a, points[ip], d, D, 3, tau);
            for (int k = 0; k < 3; k++) worst = fmax(worst, fabs(T[k] - exp(-tau[k])));
            /* sunlight: the same integral toward the sun, from outside the air */
            double E[3];
            atmos_atmosphere_sunlight(a, points[ip], d, E);
            if (d[1] > 0) {
                depth_quad(a, points[ip], d, INFINITY, 3, tau);
                for (int k = 0; k < 3; k++)
                    worst = fmax(worst, fabs(E[k] / (wl.sun_irradiance[k]) - exp(-tau[k])));
            } else if (kind != ATMOS_ATMOSPHERE_VACUUM) {
                for (int k = 0; k < 3; k++) CHECK(E[k] == 0.0); /* the sun below a flat earth's horizon */
            }
        }
    printf("kind %d: transmittance and sunlight vs quadrature: largest difference %.2e\n", (int)kind, worst);
    CHECK(worst < 2e-5);
    atmos_atmosphere_destroy(a);
}

/* In-scatter: integral of sigma_s(t) P(theta) E(x(t)) T(p, t) over the segment. */
static void test_inscatter(atmos_atmosphere_kind kind)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = make(kind, &wl);
    double sun[3], worst = 0;
    atmos_direction_from_angles(25, 200, sun);
    for (size_t ip = 0; ip < sizeof points / sizeof points[0]; ip++)
        for (size_t id = 0; id < sizeof dirs_el / sizeof dirs_el[0]; id++) {
            double d[3], L[3], Q[3] = {0, 0, 0};
            atmos_direction_from_angles(dirs_el[id], 170, d);
            const double D = fmin(atmos_atmosphere_ground_distance(a, points[ip], d), 5000.0);
            atmos_atmosphere_inscatter(a, points[ip], d, D, sun, L);
            const int N = 200000; /* steps of 2.5 cm: a segment may cross the layer's top in a metre */
            const double dt = D / N, P = atmos_phase_rayleigh(d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2]);
            double tau[3] = {0, 0, 0};
            for (int i = 0; i < N; i++) {
                const double t = (i + 0.5) * dt, x[3] = {points[ip][0] + t * d[0], points[ip][1] + t * d[1],
                                                         points[ip][2] + t * d[2]};
                double s[3], e[3], E[3];
                atmos_atmosphere_scattering(a, x, s, e);
                atmos_atmosphere_sunlight(a, x, sun, E);
                for (int k = 0; k < 3; k++) {
                    /* the transmittance from p to the middle of this step */
                    const double tm = tau[k] + 0.5 * e[k] * dt;
                    Q[k] += s[k] * P * E[k] * exp(-tm) * dt;
                    tau[k] += e[k] * dt;
                }
            }
            for (int k = 0; k < 3; k++) {
                const double e = fabs(L[k] - Q[k]) / fmax(Q[k], 1e-4);
                if (e > 2e-3) printf("  point %zu el %g: %.6g vs quadrature %.6g\n", ip, dirs_el[id], L[k], Q[k]);
                worst = fmax(worst, e);
            }
        }
    printf("kind %d: in-scatter vs quadrature: largest relative difference %.2e\n", (int)kind, worst);
    CHECK(worst < 2e-3);
    atmos_atmosphere_destroy(a);
}

/* The renderers' scattering point: the mean of ratio_i over many draws is the integral of
 * sigma_s,i T_i over the segment, 1 - T_i(D) for air that absorbs nothing, and the mean of
 * ratio_i t is the integral of sigma_s,i T_i t (the distribution, not just its mass). */
static void test_scatter_point(atmos_atmosphere_kind kind)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = make(kind, &wl);
    const double p[3] = {0, 1500, 0};
    const double els[] = {-10, 0, 30};
    const int k[3] = {2, 0, 1}; /* a subset, in another order */
    for (int e = 0; e < 3; e++) {
        double d[3];
        atmos_direction_from_angles(els[e], 0, d);
        const double D = fmin(atmos_atmosphere_ground_distance(a, p, d), 40000.0);
        const double w[3] = {1, 1, 1};
        atmos__stream rng;
        atmos__stream_seed(&rng, 5, (uint64_t)e, 0);
        const int n = 200000;
        double m0[3] = {0, 0, 0}, m1[3] = {0, 0, 0};
        int got = 0;
        for (int i = 0; i < n; i++) {
            double t, r[3];
            if (!atmos__atm_scatter_point(a, p, d, D, 3, k, w, &rng, &t, r)) continue;
            got++;
            for (int j = 0; j < 3; j++) m0[j] += r[j] / n, m1[j] += r[j] * t / n;
        }
        CHECK(got > n * 0.99);
        double T[3];
        atmos__atm_transmittance_sub(a, p, d, D, 3, k, T);
        /* the first moment by quadrature */
        const int N = 100000;
        double q1[3] = {0, 0, 0}, tau[3] = {0, 0, 0};
        for (int i = 0; i < N; i++) {
            const double dt = D / N, t = (i + 0.5) * dt, x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
            double s[3];
            atmos_atmosphere_scattering(a, x, s, NULL);
            for (int j = 0; j < 3; j++) {
                q1[j] += s[k[j]] * exp(-(tau[j] + 0.5 * s[k[j]] * dt)) * t * dt;
                tau[j] += s[k[j]] * dt;
            }
        }
        for (int j = 0; j < 3; j++) {
            printf("kind %d el %g wl %d: mean ratio %.5f vs 1 - T %.5f; mean ratio t %.5g vs %.5g\n", (int)kind,
                   els[e], k[j], m0[j], 1 - T[j], m1[j], q1[j]);
            CHECK_REL(m0[j], 1 - T[j], 0.01);
            CHECK_REL(m1[j], q1[j], 0.02);
        }
    }
    atmos_atmosphere_destroy(a);
}

/* A vacuum: nothing in the way, the background from every direction, no ground, no disk. */
static void test_vacuum(void)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = make(ATMOS_ATMOSPHERE_VACUUM, &wl);
    const double p[3] = {0, 300, 0}, down[3] = {0, -1, 0}, sun[3] = {0, 1, 0};
    double T[3], E[3], L[3];
    atmos_atmosphere_hit hit;
    CHECK(isinf(atmos_atmosphere_ground_distance(a, p, down)));
    atmos_atmosphere_transmittance(a, p, down, INFINITY, T);
    atmos_atmosphere_sunlight(a, p, sun, E);
    atmos_atmosphere_radiance(a, p, sun, sun, L, &hit);
    for (int k = 0; k < 3; k++) {
        CHECK(T[k] == 1.0);
        CHECK(E[k] == wl.sun_irradiance[k]);
        CHECK(L[k] == 0.03);
    }
    CHECK(!hit.in_sun_disk && !hit.hits_ground && !atmos_atmosphere_sun_disk_visible(a, sun));
    CHECK(atmos_atmosphere_ground_albedo(a) == 0.0);
    atmos_atmosphere_destroy(a);
}

/* What a view ray sees is the in-scatter, plus the ground lit by the sun and the sky, or the
 * disk. */
static void test_radiance_parts(atmos_atmosphere_kind kind)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = make(kind, &wl);
    const double p[3] = {0, 700, 0};
    double sun[3], down[3], L[3], I[3], E[3], T[3], S[3];
    atmos_direction_from_angles(40, 90, sun);
    atmos_direction_from_angles(-20, 10, down);
    atmos_atmosphere_hit hit;
    atmos_atmosphere_radiance(a, p, down, sun, L, &hit);
    CHECK(hit.hits_ground && fabs(hit.distance_m - 700 / sin(20 * PI / 180)) < 1e-6);
    atmos_atmosphere_inscatter(a, p, down, hit.distance_m, sun, I);
    const double g[3] = {p[0] + hit.distance_m * down[0], 0, p[2] + hit.distance_m * down[2]};
    atmos_atmosphere_sunlight(a, g, sun, E);
    atmos_atmosphere_transmittance(a, p, down, hit.distance_m, T);
    /* the ground lit by the sun and by the sky: the sky's irradiance summed here finely over
     * the whole upper hemisphere from the kind's own in-scatter */
    double Es[3] = {0, 0, 0};
    const double o[3] = {0, 0, 0};
    for (int i = 0; i < 64; i++)
        for (int j = 0; j < 128; j++) {
            const double mu = (i + 0.5) / 64, s = sqrt(1 - mu * mu), phi = (j + 0.5) * 2 * PI / 128;
            const double d[3] = {s * cos(phi), mu, s * sin(phi)};
            double Ls[3];
            atmos_atmosphere_inscatter(a, o, d, INFINITY, sun, Ls);
            for (int k = 0; k < 3; k++) Es[k] += mu * Ls[k] * (1.0 / 64) * (2 * PI / 128);
        }
    for (int k = 0; k < 3; k++) {
        const double want = I[k] + 0.25 / PI * (sun[1] * E[k] + Es[k]) * T[k];
        printf("kind %d channel %d: ground %.6g, sun and sky %.6g (%+.4f %%), sky's share %.3f\n", (int)kind, k, L[k],
               want, 100 * (L[k] / want - 1), Es[k] / (sun[1] * E[k] + Es[k]));
        CHECK_REL(L[k], want, 2e-3);
    }
    atmos_atmosphere_radiance(a, p, sun, sun, L, &hit);
    atmos_atmosphere_inscatter(a, p, sun, INFINITY, sun, I);
    atmos_atmosphere_sun_radiance(a, p, sun, S);
    CHECK(hit.in_sun_disk && !hit.hits_ground);
    for (int k = 0; k < 3; k++) CHECK_REL(L[k], I[k] + S[k], 1e-12);
    atmos_atmosphere_destroy(a);
}

static void test_bad_input(void)
{
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    atmos_atmosphere *a = NULL;
    d.kind = (atmos_atmosphere_kind)7;
    CHECK(atmos_atmosphere_create(ctx, &d, &wl, &a) == ATMOS_E_INVALID_ARG && !a);
    CHECK(strstr(atmos_context_error(ctx), "kind") != NULL);
    atmos_atmosphere_defaults(&d);
    d.kind = ATMOS_ATMOSPHERE_HOMOGENEOUS;
    d.thickness_m = -5;
    CHECK(atmos_atmosphere_create(ctx, &d, &wl, &a) == ATMOS_E_INVALID_ARG && !a);
    CHECK(strstr(atmos_context_error(ctx), "thickness_m") != NULL);
    atmos_atmosphere_defaults(&d);
    d.background_radiance = NAN;
    CHECK(atmos_atmosphere_create(ctx, &d, &wl, &a) == ATMOS_E_INVALID_ARG && !a);
    atmos_atmosphere_destroy(NULL);
    atmos_context_destroy(ctx);
}

/* A kind's table names without making the atmosphere (atmos sky --table list uses them):
 * empty for the kinds without tables and for an unknown kind. */
static void test_kind_table_names(void)
{
    const atmos_atmosphere_kind none[] = {ATMOS_ATMOSPHERE_RILEY, ATMOS_ATMOSPHERE_VACUUM, ATMOS_ATMOSPHERE_HOMOGENEOUS,
                                          (atmos_atmosphere_kind)99};
    for (int i = 0; i < 4; i++) CHECK(atmos_atmosphere_kind_table_names(none[i])[0] == NULL);
    const char *const *d = atmos_atmosphere_kind_table_names(ATMOS_ATMOSPHERE_DOBASHI);
    const char *const *s = atmos_atmosphere_kind_table_names(ATMOS_ATMOSPHERE_SPHERICAL);
    CHECK(d[0] && !strcmp(d[0], "sun_attenuation"));
    CHECK(s[0] && !strcmp(s[0], "transmittance"));
}

int main(void)
{
    const atmos_atmosphere_kind kinds[] = {ATMOS_ATMOSPHERE_RILEY, ATMOS_ATMOSPHERE_HOMOGENEOUS,
                                           ATMOS_ATMOSPHERE_VACUUM};
    for (int i = 0; i < 3; i++) {
        test_transmittance_and_sunlight(kinds[i]);
        test_inscatter(kinds[i]);
    }
    for (int i = 0; i < 2; i++) {
        test_scatter_point(kinds[i]);
        test_radiance_parts(kinds[i]);
    }
    test_vacuum();
    test_bad_input();
    test_kind_table_names();
    return test_summary("test_atmosphere");
}
