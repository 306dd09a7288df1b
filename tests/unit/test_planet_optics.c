/* The spherical planet's optics against published values and second methods: Rayleigh
 * optical depths (Bodhaine et al. 1999), ozone's Chappuis band, the OPAC aerosol types'
 * Angstrom exponents, albedos and asymmetry parameters (Hess et al. 1998 Table 4), the
 * visibility and turbidity settings, and the phase functions' normalisation. */
#include "atmos/atmos.h"
#include "atmosphere/planet_optics.h"
#include "test.h"

#include <math.h>
#include <time.h>

#define PI 3.14159265358979323846

/* Bodhaine et al. 1999 Eq. 30: their fit to the Rayleigh optical depth of the standard
 * atmosphere (1013.25 hPa, 45 degrees latitude, 360 ppm CO2), lambda in um. */
static double bodhaine_fit(double nm)
{
    const double l = nm * 1e-3, l2 = l * l;
    return 0.0021520 * (1.0455996 - 341.29061 / l2 - 0.90230850 * l2) / (1.0 + 0.0027059889 / l2 - 85.968563 * l2);
}

static void make_planet(atmos__planet *pl, atmos_atmosphere_desc *d, const atmos_wavelengths *wl)
{
    CHECK_OK(atmos__planet_init(NULL, pl, d, wl));
}

static void defaults(atmos_atmosphere_desc *d, atmos_aerosol_type type)
{
    atmos_atmosphere_defaults(d);
    d->kind = ATMOS_ATMOSPHERE_SPHERICAL;
    d->aerosol = type;
}

/* Vertical optical depth from the ground to space by the planet's quadrature. */
static void vertical_depth(const atmos__planet *pl, double *tau)
{
    const double p[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    atmos__planet_optical_depth(pl, p, up, INFINITY, pl->n, NULL, tau);
}

static void test_rayleigh(void)
{
    /* the column: ~2.15e29 molecules m^-2 (Bodhaine et al. 1999 §4) */
    CHECK_REL(atmos__air_column(), 2.15e29, 0.005);
    const double nms[] = {400, 440, 500, 550, 600, 680, 700};
    for (int i = 0; i < 7; i++) {
        const double tau = atmos__air_rayleigh_cross_section(nms[i]) * atmos__air_column();
        CHECK_REL(tau, bodhaine_fit(nms[i]), 0.005);
    }
    /* Bodhaine et al. 1999 Table 3 lists sigma(550 nm) = 4.513e-27 cm^2 for 360 ppm CO2 */
    CHECK_REL(atmos__air_rayleigh_cross_section(550) * 1e4, 4.513e-27, 0.003);
    /* depolarization of air: about 0.028 at 550 nm, 0.030 in the blue (Bates 1984,
     * Young 1980's 0.0279 at 550 nm) */
    CHECK(atmos__air_depolarization(550) > 0.027 && atmos__air_depolarization(550) < 0.0295);
    CHECK(atmos__air_depolarization(400) > atmos__air_depolarization(700));
    /* the planet: the vertical Rayleigh depth (no aerosols, no ozone) equals the column's */
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere_desc d;
    defaults(&d, ATMOS_AEROSOL_NONE);
    d.no_ozone = 1;
    static atmos__planet pl;
    make_planet(&pl, &d, &wl);
    double tau[ATMOS_MAX_WAVELENGTHS];
    vertical_depth(&pl, tau);
    for (int k = 0; k < 3; k++) CHECK_REL(tau[k], bodhaine_fit(wl.nm[k]), 0.005);
    /* N(0) H = the column; with H = 7994 m, N(0) is air at 0 C and 1013.25 hPa */
    CHECK_REL(pl.rayleigh[1] / atmos__air_rayleigh_cross_section(550), 2.6867e25, 0.003);
    /* the depolarized phase function integrates to one and is less peaked than pure Rayleigh */
    double s = 0;
    const int n = 2000;
    for (int i = 0; i < n; i++) {
        const double mu = -1 + (i + 0.5) * 2.0 / n;
        s += 2 * PI * atmos__planet_rayleigh_phase(&pl, 1, mu) * 2.0 / n;
    }
    CHECK_NEAR(s, 1.0, 1e-6);
    CHECK(atmos__planet_rayleigh_phase(&pl, 1, 1.0) < atmos_phase_rayleigh(1.0));
    CHECK(atmos__planet_rayleigh_phase(&pl, 1, 0.0) > atmos_phase_rayleigh(0.0));
    /* the depolarization factor is the ratio of the parallel to the perpendicular intensity
     * scattered at 90 degrees from natural light, and at 0 degrees both equal the
     * perpendicular one: P(90) / P(0) = (1 + rho) / 2 */
    const double rho = atmos__air_depolarization(550);
    CHECK_REL(atmos__planet_rayleigh_phase(&pl, 1, 0.0) / atmos__planet_rayleigh_phase(&pl, 1, 1.0), 0.5 * (1 + rho),
              1e-12);
}

static void test_ozone(void)
{
    /* peak of the Chappuis band: about 5e-21 cm^2 near 600 nm (Serdyuchenko et al. 2014;
     * Burrows et al. 1999: 5.2e-21 at 602 nm) */
    double peak = 0, at = 0;
    for (double nm = 500; nm <= 700; nm += 1) {
        const double s = atmos__ozone_cross_section(nm);
        if (s > peak) peak = s, at = nm;
    }
    CHECK(peak * 1e4 > 4.6e-21 && peak * 1e4 < 5.4e-21);
    CHECK(at > 585 && at < 615);
    /* the Huggins-Chappuis minimum: 3.4e-24 cm^2 at 381.8 nm at 296 K (Axson et al. 2011,
     * Atmos. Chem. Phys. Discuss. 11, 21655); the table's 233 K values are lower there */
    CHECK(atmos__ozone_cross_section(381.8) * 1e4 > 1.5e-24 && atmos__ozone_cross_section(381.8) * 1e4 < 5e-24);
    CHECK(atmos__ozone_cross_section(380) * 1e4 < 5e-23);
    CHECK(atmos__ozone_cross_section(700) < 0.3 * peak);
    /* the bin mean of the linear interpolant between two table points (595 and 605 nm) */
    CHECK_REL(atmos__ozone_cross_section_mean(595, 605), 0.5 * (atmos__ozone_cross_section(595) +
                                                              atmos__ozone_cross_section(605)), 1e-3);
    /* the vertical ozone depth at 600 nm for 300 DU: the planet's quadrature of the tent
     * against the column times the bin's cross-section, and in 0.03-0.045 (300 DU is
     * 8.06e22 molecules m^-2; times 5e-25 m^2: 0.040) */
    atmos_wavelengths wl;
    CHECK_OK(atmos_wavelengths_spectral(10, &wl)); /* 40 nm bins: 580-620 is bin 5 */
    atmos_atmosphere_desc d;
    defaults(&d, ATMOS_AEROSOL_NONE);
    static atmos__planet with, without;
    make_planet(&with, &d, &wl);
    d.no_ozone = 1;
    make_planet(&without, &d, &wl);
    double t1[ATMOS_MAX_WAVELENGTHS], t0[ATMOS_MAX_WAVELENGTHS];
    vertical_depth(&with, t1);
    vertical_depth(&without, t0);
    int k600 = -1;
    for (int k = 0; k < wl.count; k++)
        if (fabs(wl.nm[k] - 600) < 1e-9) k600 = k;
    CHECK(k600 >= 0);
    if (k600 >= 0) {
        const double tau = t1[k600] - t0[k600];
        CHECK_REL(tau, 300 * 2.6867e20 * atmos__ozone_cross_section_mean(580, 620), 0.002);
        CHECK(tau > 0.03 && tau < 0.045);
        printf("ozone: vertical depth, 300 DU, 580-620 nm bin: %.4f; at 600 nm: %.4f\n", tau,
               300 * 2.6867e20 * atmos__ozone_cross_section(600));
    }
    for (int k = 0; k < wl.count; k++) CHECK(without.ozone[k] == 0.0);
}

/* OPAC's published optics of the types at 80 % relative humidity (Hess et al. 1998 Table
 * 4: single-scattering albedo and asymmetry parameter at 550 nm, Angstrom exponent over
 * 500-800 nm) with tolerances for our simplifications (one refractive index per component,
 * 440-680 nm). */
typedef struct { atmos_aerosol_type type; const char *name; double w, g, alpha, tw, tg, ta; } published;

static void test_aerosols(void)
{
    const published pub[4] = {
        {ATMOS_AEROSOL_CONTINENTAL, "continental", 0.925, 0.703, 1.42, 0.01, 0.015, 0.2},
        {ATMOS_AEROSOL_MARITIME, "maritime", 0.997, 0.772, 0.08, 0.003, 0.015, 0.2},
        {ATMOS_AEROSOL_URBAN, "urban", 0.817, 0.689, 1.43, 0.01, 0.015, 0.2},
        {ATMOS_AEROSOL_DESERT, "desert", 0.888, 0.729, 0.17, 0.01, 0.015, 0.2},
    };
    const double nm[3] = {440, 550, 680};
    for (int i = 0; i < 4; i++) {
        double ext[3], sca[3], g[3];
        static float phase[3][ATMOS__PLANET_PHASE_N];
        CHECK_OK(atmos__aerosol_optics(NULL, pub[i].type, 3, nm, ext, sca, phase, g));
        const double w = sca[1] / ext[1], alpha = -log(ext[0] / ext[2]) / log(440.0 / 680.0);
        printf("aerosol %-11s  Angstrom(440-680) %.3f  albedo(550) %.4f  g(550) %.3f\n", pub[i].name, alpha, w, g[1]);
        CHECK_NEAR(w, pub[i].w, pub[i].tw);
        CHECK_NEAR(g[1], pub[i].g, pub[i].tg);
        CHECK_NEAR(alpha, pub[i].alpha, pub[i].ta);
        /* the phase function on the grid integrates to ~1 and has the Mie g (grid: 0.25 deg) */
        double s = 0, gs = 0;
        const double dth = PI / (ATMOS__PLANET_PHASE_N - 1);
        for (int j = 0; j + 1 < ATMOS__PLANET_PHASE_N; j++) {
            const double a = j * dth, b = a + dth;
            const double fa = phase[1][j] * sin(a), fb = phase[1][j + 1] * sin(b);
            s += 2 * PI * 0.5 * (fa + fb) * dth;
            gs += 2 * PI * 0.5 * (fa * cos(a) + fb * cos(b)) * dth;
        }
        CHECK_NEAR(s, 1.0, 0.03);
        CHECK_NEAR(gs / s, g[1], 0.02);
    }
    /* NONE: nothing */
    double ext, sca;
    const double n550 = 550;
    CHECK_OK(atmos__aerosol_optics(NULL, ATMOS_AEROSOL_NONE, 1, &n550, &ext, &sca, NULL, NULL));
    CHECK(ext == 0 && sca == 0);
}

static void test_amount(void)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere_desc d;
    static atmos__planet pl;
    /* Koschmieder: ground extinction at 550 nm = 3.912 / V */
    defaults(&d, ATMOS_AEROSOL_CONTINENTAL);
    d.visibility_km = 20;
    make_planet(&pl, &d, &wl);
    CHECK(wl.nm[1] == 550.0);
    CHECK_REL(pl.rayleigh[1] + pl.mie_ext[1], 3.912 / 20e3, 1e-9);
    CHECK(pl.mie_ext[2] > pl.mie_ext[1] && pl.mie_ext[1] > pl.mie_ext[0]); /* blue attenuates more */
    /* the table is normalised and the planet's interpolant integrates to one */
    double s = 0;
    const int n = 20000;
    for (int i = 0; i < n; i++) {
        const double th = (i + 0.5) * PI / n;
        s += 2 * PI * atmos__planet_mie_phase(&pl, 1, cos(th)) * sin(th) * PI / n;
    }
    CHECK_NEAR(s, 1.0, 0.01);
    /* Linke's turbidity over the vertical at 550 nm, by the planet's quadrature */
    defaults(&d, ATMOS_AEROSOL_MARITIME);
    d.turbidity = 3.0;
    d.no_ozone = 1;
    make_planet(&pl, &d, &wl);
    double tau[ATMOS_MAX_WAVELENGTHS];
    vertical_depth(&pl, tau);
    const double tau_air = atmos__air_rayleigh_cross_section(550) * atmos__air_column();
    CHECK_REL(tau[1] / tau_air, 3.0, 0.005);
    /* a visibility beyond the air's own: no aerosols */
    defaults(&d, ATMOS_AEROSOL_URBAN);
    d.visibility_km = 400;
    make_planet(&pl, &d, &wl);
    CHECK(pl.mie_ext[1] == 0.0);
    defaults(&d, ATMOS_AEROSOL_NONE);
    make_planet(&pl, &d, &wl);
    for (int k = 0; k < 3; k++) CHECK(pl.mie_ext[k] == 0.0 && pl.mie_sca[k] == 0.0);
}

/* The planet's aerosol phase function: sampling draws the density it evaluates (a
 * histogram in cos theta against the integral of eval over each bin), and the samples'
 * mean cosine is the table's g. */
static void test_phase_sampling(void)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere_desc d;
    defaults(&d, ATMOS_AEROSOL_MARITIME);
    static atmos__planet pl;
    make_planet(&pl, &d, &wl);
    enum { NB = 40, NS = 400000 };
    /* bins uniform in theta (the forward peak would fill one bin uniform in cos) */
    double hist[NB] = {0}, mean = 0;
    atmos__rng rng;
    atmos__rng_seed(&rng, 12345);
    for (int i = 0; i < NS; i++) {
        const double c = atmos__planet_mie_sample(&pl, 0, atmos__rng_uniform(&rng));
        mean += c / NS;
        int b = (int)(acos(c) / PI * NB);
        if (b >= NB) b = NB - 1;
        hist[b] += 1.0 / NS;
    }
    int bad = 0;
    for (int b = 0; b < NB; b++) {
        double p = 0;
        const int m = 400;
        const double a = b * PI / NB, h = PI / NB / m;
        for (int i = 0; i < m; i++) {
            const double th = a + (i + 0.5) * h;
            p += 2 * PI * atmos__planet_mie_phase(&pl, 0, cos(th)) * sin(th) * h;
        }
        const double sd = sqrt(p * (1 - p) / NS) + 1e-7;
        if (fabs(hist[b] - p) > 5 * sd + 0.002 * p) {
            bad++;
            fprintf(stderr, "bin %d: sampled %.6f, eval %.6f\n", b, hist[b], p);
        }
    }
    CHECK(bad == 0);
    CHECK_NEAR(mean, pl.mie_g[0], 0.004);
}

/* The planet's quadrature: the vertical optical depth of all three constituents against
 * their columns in closed form; the sun seen from points on and just below the ground. */
static void test_planet_numerics(void)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere_desc d;
    defaults(&d, ATMOS_AEROSOL_URBAN);
    d.visibility_km = 10;
    static atmos__planet pl;
    make_planet(&pl, &d, &wl);
    double tau[ATMOS_MAX_WAVELENGTHS];
    vertical_depth(&pl, tau);
    const double top = pl.r_top - pl.r_ground;
    for (int k = 0; k < 3; k++) {
        const double exact = pl.rayleigh[k] * pl.h_rayleigh * -expm1(-top / pl.h_rayleigh) +
                             pl.mie_ext[k] * pl.h_mie * -expm1(-top / pl.h_mie) + pl.ozone[k] * pl.ozone_half_width;
        CHECK_REL(tau[k], exact, 1e-6);
    }
    /* the sun overhead of points on or just below the ground, anywhere on the planet */
    int hidden = 0;
    for (int i = 0; i < 200; i++) {
        const double a = 0.031 * i, r = pl.r_ground - (i % 4) * 0.37;
        const double p[3] = {r * sin(a), r * cos(a) - pl.r_ground, 0};
        const double up[3] = {sin(a), cos(a), 0};
        double T[ATMOS_MAX_WAVELENGTHS];
        atmos__planet_sun_transmittance(&pl, p, up, 3, NULL, T);
        if (!(T[1] > 0.5 * exp(-tau[1]))) hidden++;
    }
    CHECK_MSG(hidden == 0, "%d of 200 ground points see no sun overhead", hidden);
}

static void timing(void)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere_desc d;
    defaults(&d, ATMOS_AEROSOL_DESERT);
    static atmos__planet pl;
    struct timespec a, b;
    timespec_get(&a, TIME_UTC);
    make_planet(&pl, &d, &wl);
    timespec_get(&b, TIME_UTC);
    printf("planet init (desert, rgb, no cache): %.3f s\n", (double)(b.tv_sec - a.tv_sec) + 1e-9 * (double)(b.tv_nsec - a.tv_nsec));
}

int main(void)
{
    test_rayleigh();
    test_ozone();
    test_aerosols();
    test_amount();
    test_phase_sampling();
    test_planet_numerics();
    timing();
    return test_summary("test_planet_optics");
}
