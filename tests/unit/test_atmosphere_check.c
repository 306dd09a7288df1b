/* What the public questions of an atmosphere refuse (include/atmos/atmosphere.h): an
 * observer under the ground or inside the planet (its centre used to crash the spherical
 * kind), a NaN, zero or non-unit direction. Each answers NaN and atmos_atmosphere_check_ray
 * names the fault; good rays, and points within the tolerance, still answer. */
#include "atmos/atmos.h"
#include "atmosphere/atmosphere_check.h"
#include "test.h"

#include <math.h>
#include <string.h>

static atmos_context *ctx;

static int all_nan(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isnan(v[i])) return 0;
    return 1;
}

static int all_finite(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* Every view question from p along d answers NaN, and the check names why. */
static void refused(const atmos_atmosphere *a, int n, const double p[3], const double d[3], const char *why)
{
    const double sun[3] = {0, 0.5, -0.8660254037844386};
    double L[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS], S[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_hit h = {0, 1, 1};
    atmos_atmosphere_radiance(a, p, d, sun, L, &h);
    atmos_atmosphere_transmittance(a, p, d, INFINITY, T);
    atmos_atmosphere_inscatter(a, p, d, 1000.0, sun, S);
    CHECK(all_nan(L, n) && all_nan(T, n) && all_nan(S, n));
    CHECK(isnan(h.distance_m) && !h.hits_ground && !h.in_sun_disk);
    CHECK(atmos_atmosphere_check_ray(ctx, a, p, d, sun) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), why) != NULL);
}

static void answered(const atmos_atmosphere *a, int n, const double p[3], const double d[3])
{
    const double sun[3] = {0, 0.5, -0.8660254037844386};
    double L[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_hit h;
    atmos_atmosphere_radiance(a, p, d, sun, L, &h);
    atmos_atmosphere_transmittance(a, p, d, INFINITY, T);
    CHECK(all_finite(L, n) && all_finite(T, n) && !isnan(h.distance_m));
    CHECK_OK(atmos_atmosphere_check_ray(ctx, a, p, d, sun));
}

static void test_kind(atmos_atmosphere_kind kind, const atmos_wavelengths *wl)
{
    atmos_atmosphere_desc desc;
    atmos_atmosphere_defaults(&desc);
    desc.kind = kind;
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &desc, wl, &a));
    if (!a) return;
    const int n = wl->count, planet = kind == ATMOS_ATMOSPHERE_SPHERICAL || kind == ATMOS_ATMOSPHERE_DOBASHI;
    const char *below = planet ? "inside the planet" : "below the ground";
    const double up[3] = {0, 1, 0}, ground[3] = {0, 0, 0}, nan3[3] = {NAN, 0, 0}, zero[3] = {0, 0, 0},
                 five[3] = {0, 5, 0}, inf3[3] = {INFINITY, 0, 0};
    const double centre[3] = {0, -6360e3, 0}, km_below[3] = {0, -1000, 0}, deep[3] = {0, -3e6, 0};
    refused(a, n, centre, up, below);
    refused(a, n, km_below, up, below);
    refused(a, n, deep, up, below);
    refused(a, n, inf3, up, "position is not finite");
    refused(a, n, ground, nan3, "not a finite unit vector");
    refused(a, n, ground, zero, "not a finite unit vector");
    refused(a, n, ground, five, "not a finite unit vector");
    /* the sunlight: a point under the ground counts as on it; a bad sun is refused */
    double E[ATMOS_MAX_WAVELENGTHS], E0[ATMOS_MAX_WAVELENGTHS];
    const double sun[3] = {0, 0.5, -0.8660254037844386}, sun5[3] = {0, 2.5, -4.330127018922193};
    atmos_atmosphere_sunlight(a, km_below, sun, E);
    atmos_atmosphere_sunlight(a, ground, sun, E0);
    CHECK(all_finite(E, n) && fabs(E[0] - E0[0]) <= 1e-3 * E0[0]);
    atmos_atmosphere_sunlight(a, ground, sun5, E);
    CHECK(all_nan(E, n));
    atmos_atmosphere_sun_radiance(a, ground, nan3, E);
    CHECK(all_nan(E, n));
    CHECK(isnan(atmos_atmosphere_ground_distance(a, ground, nan3)));
    CHECK(isnan(atmos_atmosphere_ground_distance(a, nan3, up)));
    /* good rays, a direction normalised in single precision, and an observer within the
     * tolerance below the ground still answer */
    const double fup[3] = {(float)0.6, (float)0.8, 0}, half_m_below[3] = {0, -0.5, 0};
    answered(a, n, ground, up);
    answered(a, n, ground, fup);
    answered(a, n, half_m_below, up);
    atmos_atmosphere_destroy(a);
}

/* A point under the ground moved onto it: along the planet's radius, or to y = 0. */
static void test_onto_ground(const atmos_wavelengths *wl)
{
    atmos_atmosphere_desc desc;
    atmos_atmosphere_defaults(&desc);
    desc.kind = ATMOS_ATMOSPHERE_DOBASHI;
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &desc, wl, &a));
    if (!a) return;
    const double R = desc.planet_radius_m, p[3] = {3000, -500, 4000}, above[3] = {10, 20, 30};
    double q[3];
    atmos__atm_onto_ground(a, p, q);
    const double r = sqrt(q[0] * q[0] + (q[1] + R) * (q[1] + R) + q[2] * q[2]);
    CHECK(fabs(r - R) < 1e-6 && fabs(q[0] / q[2] - 0.75) < 1e-12);
    atmos__atm_onto_ground(a, above, q);
    CHECK(!memcmp(q, above, sizeof q));
    atmos_atmosphere_destroy(a);
}

int main(void)
{
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.log = NULL;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    atmos_scene sc;
    atmos_scene_defaults(&sc);
    atmos_wavelengths wl;
    CHECK_OK(atmos_scene_wavelengths(ctx, &sc, &wl));
    const atmos_atmosphere_kind kinds[] = {ATMOS_ATMOSPHERE_RILEY, ATMOS_ATMOSPHERE_HOMOGENEOUS,
                                           ATMOS_ATMOSPHERE_DOBASHI, ATMOS_ATMOSPHERE_SPHERICAL};
    for (int i = 0; i < 4; i++) test_kind(kinds[i], &wl);
    test_onto_ground(&wl);
    atmos_context_destroy(ctx);
    return test_summary("test_atmosphere_check");
}
