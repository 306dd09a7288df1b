/* Physics of the spherical atmosphere kinds (DOBASHI, SPHERICAL) through the public
 * interface only, whatever their solvers do inside (docs/sky.md, "Measurements"):
 *  - Beer-Lambert: the transmittance of vertical paths equals the closed form over the
 *    documented exponential profiles, that of slanted, grazing and finite paths a
 *    quadrature of the extinction the interface reports at points; the ozone's optical
 *    depth is proportional to its column;
 *  - sunlight: none in the planet's shadow, the extraterrestrial sun above the air, redder
 *    and weaker toward the horizon, and equal to the sun times the transmittance;
 *  - the view radiance: finite and continuous as the view approaches the horizon from
 *    either side, unchanged as the observer moves along the ray out of the atmosphere (the
 *    radiance is invariant along a ray in vacuum), symmetric about the sun's vertical
 *    plane, finite and >= 0 on a grid of views from the ground to 36 000 km.
 * Tolerances allow a table-based solver's interpolation: 0.5 % of the optical depth,
 * 3 % for continuity, 1 % for invariance, 1e-3 for symmetry (the brute-force solvers meet
 * them by orders of magnitude). */
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>

#define DEG (3.14159265358979323846 / 180.0)
static const double R = 6360e3, TOP = 100e3;

static atmos_atmosphere *make(atmos_atmosphere_kind kind, int aerosols, double ozone_du, const atmos_wavelengths *wl)
{
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    d.kind = kind;
    d.hide_sun_disk = 1;
    if (!aerosols) d.aerosol = ATMOS_AEROSOL_NONE;
    if (ozone_du > 0) d.ozone_du = ozone_du;
    else d.no_ozone = 1;
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &d, wl, &a));
    return a;
}

static double ext_at(const atmos_atmosphere *a, double h, int k)
{
    double p[3] = {0, h, 0}, e[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_scattering(a, p, NULL, e);
    return e[k];
}

static double tau_of(const atmos_atmosphere *a, const double p[3], const double d[3], double dist, int k)
{
    double T[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_transmittance(a, p, d, dist, T);
    return -log(T[k]);
}

/* The positive distances along p + t d where |x - centre| = r (t0 <= t1); 0 if none. */
static int sphere(const double p[3], const double d[3], double r, double *t0, double *t1)
{
    const double q[3] = {p[0], p[1] + R, p[2]};
    const double b = q[0] * d[0] + q[1] * d[1] + q[2] * d[2], c = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - r * r;
    const double disc = b * b - c;
    if (disc < 0) return 0;
    *t0 = -b - sqrt(disc), *t1 = -b + sqrt(disc);
    return 1;
}

/* Optical depth of p + t d, t in [0, dist], by the midpoint rule on the extinction the
 * interface reports, over the part inside the top of the air and above the ground. */
static void tau_quad(const atmos_atmosphere *a, const double p[3], const double d[3], double dist, int n, double *tau)
{
    double t0, t1, g0, g1;
    for (int k = 0; k < n; k++) tau[k] = 0;
    if (!sphere(p, d, R + TOP, &t0, &t1)) return;
    t0 = fmax(t0, 0.0), t1 = fmin(t1, dist);
    if (sphere(p, d, R, &g0, &g1) && g0 >= 0 && g1 - g0 > 1e-3) t1 = fmin(t1, g0); /* not a tangent */
    const int N = 40000;
    const double dt = (t1 - t0) / N;
    for (int i = 0; i < N && dt > 0; i++) {
        const double t = t0 + (i + 0.5) * dt, x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
        double e[ATMOS_MAX_WAVELENGTHS];
        atmos_atmosphere_scattering(a, x, NULL, e);
        for (int k = 0; k < n; k++) tau[k] += e[k] * dt;
    }
}

/* Vertical paths over the documented profiles: air molecules exp(-h / 7994 m), aerosols
 * exp(-h / 1200 m) (Dobashi et al. 2002 Appendix A.1), in closed form:
 * tau = beta(0) H (exp(-h0 / H) - exp(-h1 / H)) per component. */
static void test_vertical(const atmos_atmosphere *air, const atmos_atmosphere *aer, const atmos_wavelengths *wl)
{
    const double HR = 7994, HM = 1200, up[3] = {0, 1, 0};
    for (int k = 0; k < wl->count; k++) {
        const double b = ext_at(air, 0, k);
        CHECK(b > 0);
        CHECK_REL(ext_at(air, 5000, k), b * exp(-5000 / HR), 1e-6);
        const double p0[3] = {0, 0, 0}, p10[3] = {0, 10e3, 0};
        CHECK_REL(tau_of(air, p0, up, INFINITY, k), b * HR * (1 - exp(-TOP / HR)), 5e-3);
        CHECK_REL(tau_of(air, p10, up, INFINITY, k), b * HR * (exp(-10e3 / HR) - exp(-TOP / HR)), 5e-3);
        CHECK_REL(tau_of(air, p0, up, 3000, k), b * HR * (1 - exp(-3000 / HR)), 5e-3);
        /* aerosols: the two exponentials from the extinction at 0 and 2 km, checked at 6 km */
        const double e0 = ext_at(aer, 0, k), e2 = ext_at(aer, 2000, k), r1 = exp(-2000 / HR), r2 = exp(-2000 / HM);
        const double bm = (e2 - e0 * r1) / (r2 - r1), br = e0 - bm;
        CHECK(bm > 0);
        CHECK_REL(br, b, 1e-6);
        CHECK_REL(ext_at(aer, 6000, k), br * exp(-6000 / HR) + bm * exp(-6000 / HM), 1e-6);
        const double tau = br * HR * (1 - exp(-TOP / HR)) + bm * HM * (1 - exp(-TOP / HM));
        CHECK_REL(tau_of(aer, p0, up, INFINITY, k), tau, 5e-3);
    }
}

/* Ozone: its vertical optical depth (with minus without) is proportional to the column,
 * and largest in the Chappuis band (peak near 600 nm) of rgb's three wavelengths. */
static void test_ozone(const atmos_atmosphere *none, const atmos_atmosphere *o300, const atmos_atmosphere *o600,
                       const atmos_wavelengths *wl)
{
    const double p0[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    double d300[ATMOS_MAX_WAVELENGTHS];
    for (int k = 0; k < wl->count; k++) {
        const double t0 = tau_of(none, p0, up, INFINITY, k);
        d300[k] = tau_of(o300, p0, up, INFINITY, k) - t0;
        CHECK(d300[k] > 0);
        CHECK_REL(tau_of(o600, p0, up, INFINITY, k) - t0, 2 * d300[k], 1e-2);
    }
    CHECK(d300[1] > d300[0] && d300[1] > d300[2]); /* 550 nm above 680 and 440 nm */
}

/* Slanted, grazing, finite and from-space paths against the quadrature (all constituents). */
static void test_slant(const atmos_atmosphere *a, const atmos_wavelengths *wl)
{
    static const struct {
        double h, el, dist;
    } paths[] = {{0, 30, INFINITY},   {0, 10, INFINITY},    {0, 2, INFINITY},         {0, 0, INFINITY},
                 {1000, 0, 20e3},     {10e3, -20, INFINITY}, {5e3, 45, 8e3},          {36000e3, -90, INFINITY},
                 {500e3, -22, INFINITY}, {100e3, -10, INFINITY}};
    for (size_t i = 0; i < sizeof paths / sizeof paths[0]; i++) {
        const double p[3] = {0, paths[i].h, 0};
        double d[3], q[ATMOS_MAX_WAVELENGTHS];
        atmos_direction_from_angles(paths[i].el, 90, d);
        tau_quad(a, p, d, paths[i].dist, wl->count, q);
        for (int k = 0; k < wl->count; k++) {
            const double t = tau_of(a, p, d, paths[i].dist, k);
            CHECK_MSG(fabs(t - q[k]) <= 5e-3 * q[k] + 1e-4, "path %zu wavelength %d: tau %.6g, quadrature %.6g", i,
                      k, t, q[k]);
        }
    }
}

static void sunlight(const atmos_atmosphere *a, double h, double el, double *E)
{
    const double p[3] = {0, h, 0};
    double s[3];
    atmos_direction_from_angles(el, 180, s);
    atmos_atmosphere_sunlight(a, p, s, E);
}

static void test_sunlight(const atmos_atmosphere *a, const atmos_wavelengths *wl)
{
    const int n = wl->count;
    double E[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    /* in the planet's shadow: on the ground after sunset, at 10 km at midnight, and from
     * 36 000 km with the sun 85 degrees below the horizon (the line to it passes 3700 km
     * from the centre) */
    static const double shadow[][2] = {{0, -5}, {0, -0.5}, {10e3, -90}, {36000e3, -85}};
    for (int i = 0; i < 4; i++) {
        sunlight(a, shadow[i][0], shadow[i][1], E);
        for (int k = 0; k < n; k++) CHECK_MSG(E[k] == 0, "shadow case %d: E = %g", i, E[k]);
    }
    /* at 10 km the sun 3 degrees below the horizon still shines (the dip is 3.2 degrees) */
    sunlight(a, 10e3, -3, E);
    CHECK(E[0] > 0);
    /* above the air: the extraterrestrial sun, whether it is 30 degrees up or 60 down */
    for (int i = 0; i < 2; i++) {
        sunlight(a, 36000e3, i ? -60 : 30, E);
        for (int k = 0; k < n; k++) CHECK_REL(E[k], wl->sun_irradiance[k], 1e-3);
    }
    /* from the ground: weaker and redder as the sun sinks; equal to the sun times the
     * transmittance toward it */
    static const double els[] = {60, 30, 10, 5, 2};
    double prev[ATMOS_MAX_WAVELENGTHS], ratio = INFINITY;
    for (int i = 0; i < 5; i++) {
        sunlight(a, 0, els[i], E);
        const double p[3] = {0, 0, 0};
        double s[3];
        atmos_direction_from_angles(els[i], 180, s);
        atmos_atmosphere_transmittance(a, p, s, INFINITY, T);
        for (int k = 0; k < n; k++) {
            CHECK_REL(E[k], wl->sun_irradiance[k] * T[k], 1e-2);
            if (i) CHECK(E[k] < prev[k]);
            prev[k] = E[k];
        }
        const double r = E[n - 1] / E[0] * (wl->sun_irradiance[0] / wl->sun_irradiance[n - 1]);
        CHECK_MSG(r < ratio, "sun %g: blue/red %g not below %g", els[i], r, ratio);
        ratio = r;
    }
}

static int finite_nonneg(const double *L, int n)
{
    for (int k = 0; k < n; k++)
        if (!(isfinite(L[k]) && L[k] >= 0)) return 0;
    return 1;
}

static void radiance(const atmos_atmosphere *a, const double p[3], double el, double az, double sun_el, double *L)
{
    double d[3], s[3];
    atmos_direction_from_angles(el, az, d);
    atmos_direction_from_angles(sun_el, 180, s);
    atmos_atmosphere_radiance(a, p, d, s, L, NULL);
}

static int close_rel(const double *a, const double *b, int n, double tol)
{
    for (int k = 0; k < n; k++)
        if (fabs(a[k] - b[k]) > tol * fmax(fabs(a[k]), fabs(b[k])) + 1e-12) return 0;
    return 1;
}

/* The horizon: approaching it from above and from below the radiance converges. */
static void test_horizon(const atmos_atmosphere *a, const atmos_wavelengths *wl)
{
    const int n = wl->count;
    for (int ih = 0; ih < 2; ih++) {
        const double h = ih ? 10e3 : 0, p[3] = {0, h, 0}, dip = acos(R / (R + h)) / DEG;
        for (int az = 0; az <= 180; az += 90) {
            for (int side = -1; side <= 1; side += 2) {
                double L1[ATMOS_MAX_WAVELENGTHS], L2[ATMOS_MAX_WAVELENGTHS];
                radiance(a, p, -dip + side * 0.01, 180 + az, 10, L1);
                radiance(a, p, -dip + side * 0.001, 180 + az, 10, L2);
                CHECK(finite_nonneg(L1, n) && finite_nonneg(L2, n));
                CHECK_MSG(close_rel(L1, L2, n, 3e-2), "h %g az %d side %d: %g vs %g", h, az, side, L1[1], L2[1]);
            }
        }
    }
}

/* The point where the ray x - s d (s > 0, backward from x) is at radius r. */
static void back_to(const double x[3], const double d[3], double r, double out[3])
{
    const double md[3] = {-d[0], -d[1], -d[2]};
    double t0, t1;
    sphere(x, md, r, &t0, &t1);
    for (int i = 0; i < 3; i++) out[i] = x[i] + t1 * md[i];
}

/* Crossing the top: the same ray seen from 0.5 km below the top, 50 km above it and from
 * 36 000 km gives the same radiance. */
static void test_top_crossing(const atmos_atmosphere *a, const atmos_wavelengths *wl)
{
    const int n = wl->count;
    static const struct {
        double h, el; /* a point of the ray and its elevation there */
    } rays[] = {{0, -90}, {0, -30}, {20e3, 0}, {60e3, 0}, {5e3, 0}};
    for (size_t i = 0; i < sizeof rays / sizeof rays[0]; i++)
        for (int sun = 0; sun < 2; sun++) {
            const double x[3] = {0, rays[i].h, 0};
            double d[3], pin[3], pout[3], pfar[3], s[3];
            double Lin[ATMOS_MAX_WAVELENGTHS], Lout[ATMOS_MAX_WAVELENGTHS], Lfar[ATMOS_MAX_WAVELENGTHS];
            atmos_direction_from_angles(rays[i].el, 90, d);
            atmos_direction_from_angles(sun ? 5 : 40, 180, s);
            back_to(x, d, R + TOP - 500, pin);
            back_to(x, d, R + TOP + 50e3, pout);
            back_to(x, d, R + 36000e3, pfar);
            atmos_atmosphere_radiance(a, pin, d, s, Lin, NULL);
            atmos_atmosphere_radiance(a, pout, d, s, Lout, NULL);
            atmos_atmosphere_radiance(a, pfar, d, s, Lfar, NULL);
            CHECK(finite_nonneg(Lin, n) && Lout[1] > 0);
            /* Dobashi's planes (an eye in the air) and sample spheres (an eye above it) are two
             * approximations of single scattering that differ by up to ~30 % at a low sun
             * (docs/sky.md, "Dobashi's tables"); the production sky's one march, 2 %. */
            const double tol = atmos_atmosphere_get_kind(a) == ATMOS_ATMOSPHERE_DOBASHI ? 0.35 : 2e-2;
            CHECK_MSG(close_rel(Lin, Lout, n, tol), "ray %zu sun %d: inside %g, outside %g", i, sun, Lin[1], Lout[1]);
            CHECK_MSG(close_rel(Lfar, Lout, n, 1e-2), "ray %zu sun %d: far %g, outside %g", i, sun, Lfar[1], Lout[1]);
        }
}

/* Views mirrored about the vertical plane of the sun and the observer see the same. */
static void test_mirror(const atmos_atmosphere *a, const atmos_wavelengths *wl)
{
    const int n = wl->count;
    static const double hs[] = {0, 10e3, 1000e3}, suns[] = {10, -4}, els[] = {30, 3, -20, -60}, daz[] = {30, 90, 150};
    for (int ih = 0; ih < 3; ih++)
        for (int is = 0; is < 2; is++)
            for (int ie = 0; ie < 4; ie++)
                for (int ia = 0; ia < 3; ia++) {
                    const double p[3] = {0, hs[ih], 0};
                    double L1[ATMOS_MAX_WAVELENGTHS], L2[ATMOS_MAX_WAVELENGTHS];
                    radiance(a, p, els[ie], 180 + daz[ia], suns[is], L1);
                    radiance(a, p, els[ie], 180 - daz[ia], suns[is], L2);
                    CHECK_MSG(close_rel(L1, L2, n, 1e-3), "h %g sun %g el %g daz %g: %g vs %g", hs[ih], suns[is],
                              els[ie], daz[ia], L1[1], L2[1]);
                }
}

/* Finite, non-negative radiance everywhere: observers from the ground to 36 000 km, the sun
 * from the zenith to 30 degrees below the horizon, views from the zenith to the nadir. */
static void test_grid(const atmos_atmosphere *a, const atmos_wavelengths *wl)
{
    const int n = wl->count;
    static const double hs[] = {0, 10e3, 100e3, 1000e3, 36000e3}, suns[] = {90, 10, -6, -30};
    static const double els[] = {-90, -60, -30, -10, -3, -1, 0, 1, 10, 45, 90}, azs[] = {0, 90, 180};
    int bad = 0, lit = 0;
    for (int ih = 0; ih < 5; ih++)
        for (int is = 0; is < 4; is++)
            for (int ie = 0; ie < 11; ie++)
                for (int ia = 0; ia < 3; ia++) {
                    const double p[3] = {0, hs[ih], 0};
                    double L[ATMOS_MAX_WAVELENGTHS];
                    radiance(a, p, els[ie], 180 + azs[ia], suns[is], L);
                    if (!finite_nonneg(L, n)) {
                        if (bad++ < 5)
                            fprintf(stderr, "h %g sun %g el %g az %g: L = %g %g %g\n", hs[ih], suns[is], els[ie],
                                    azs[ia], L[0], L[1], L[n - 1]);
                    }
                    lit += L[1] > 0;
                }
    CHECK_MSG(bad == 0, "%d views with negative or non-finite radiance", bad);
    CHECK_MSG(lit > 200, "only %d of 660 views lit", lit);
}

/* The tables as images (atmos_atmosphere_table): each kind lists some, each is finite and
 * as wide as a wavelength set; the production sky's transmittance at its first node (the
 * ground, straight up) is the interface's vertical transmittance; Dobashi's sun attenuation
 * lies in [0, 1]; each says its units (atmos:units); an unknown name is refused. */
static void test_tables(const atmos_atmosphere *a, const atmos_wavelengths *wl)
{
    const char *const *names = atmos_atmosphere_table_names(a);
    CHECK(names[0] != NULL);
    for (int i = 0; names[i]; i++) {
        atmos_image *t = NULL;
        CHECK_OK(atmos_atmosphere_table(NULL, a, names[i], &t));
        if (!t) continue;
        CHECK(t->channels == wl->count && t->width > 0 && t->height > 0);
        int bad = 0;
        for (size_t j = 0; j < (size_t)t->width * t->height * t->channels; j++) bad += !isfinite(t->pixels[j]);
        CHECK_MSG(bad == 0, "table %s: %d values not finite", names[i], bad);
        const char *units = atmos_image_get_meta(t, "atmos:units"); /* what a value is, in what units */
        CHECK_MSG(units && strlen(units) > 3, "table %s: no atmos:units", names[i]);
        if (!strcmp(names[i], "transmittance")) {
            const double p[3] = {0, 0, 0}, up[3] = {0, 1, 0};
            double T[ATMOS_MAX_WAVELENGTHS];
            atmos_atmosphere_transmittance(a, p, up, INFINITY, T);
            for (int k = 0; k < wl->count; k++) CHECK_REL(t->pixels[k], T[k], 2e-3);
        }
        if (!strcmp(names[i], "sun_attenuation"))
            for (size_t j = 0; j < (size_t)t->width * t->height * t->channels; j++)
                bad += !(t->pixels[j] >= 0 && t->pixels[j] <= 1);
        CHECK_MSG(bad == 0, "table %s: values out of range", names[i]);
        atmos_image_destroy(t);
    }
    atmos_image *t = NULL;
    CHECK(atmos_atmosphere_table(NULL, a, "no such table", &t) == ATMOS_E_INVALID_ARG && t == NULL);
}

int main(void)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    const atmos_atmosphere_kind kinds[] = {ATMOS_ATMOSPHERE_DOBASHI, ATMOS_ATMOSPHERE_SPHERICAL};
    for (int i = 0; i < 2; i++) {
        /* air molecules only; with aerosols; the defaults (300 DU of ozone); 600 DU */
        atmos_atmosphere *air = make(kinds[i], 0, 0, &wl), *aer = make(kinds[i], 1, 0, &wl);
        atmos_atmosphere *a = make(kinds[i], 1, 300, &wl), *o600 = make(kinds[i], 1, 600, &wl);
        if (!air || !aer || !a || !o600) return test_summary("test_sky_physics");
        test_vertical(air, aer, &wl);
        test_ozone(aer, a, o600, &wl);
        test_slant(a, &wl);
        test_sunlight(a, &wl);
        test_horizon(a, &wl);
        test_top_crossing(a, &wl);
        test_mirror(a, &wl);
        test_grid(a, &wl);
        test_tables(a, &wl);
        atmos_atmosphere_destroy(air);
        atmos_atmosphere_destroy(aer);
        atmos_atmosphere_destroy(a);
        atmos_atmosphere_destroy(o600);
    }
    return test_summary("test_sky_physics");
}
