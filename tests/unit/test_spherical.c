/* The production sky (SPHERICAL kind, src/atmosphere/spherical*.c) against independent
 * answers: its single scattering against the brute-force quadrature of planet.c, its
 * transmittance against Beer-Lambert on paths with closed-form optical depth and against
 * the quadrature, the sunlight (the planet's shadow, reddening), the ozone's part in the
 * twilight zenith's colour, the energy bookkeeping of the multiple-scattering table, the
 * continuity of the radiance across the horizon and the top of the air, and the sky
 * renderer's table against the one-ray path. */
#include "atmos/atmos.h"
#include "atmos/cache.h"
#include "atmosphere/spherical.h"
#include "core/vec.h"
#include "test.h"

#include <math.h>
#include <string.h>

static atmos_atmosphere *make(int aerosol_none, int no_ozone, double albedo)
{
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    ad.ground_albedo = albedo;
    ad.hide_sun_disk = 1;
    if (aerosol_none) ad.aerosol = ATMOS_AEROSOL_NONE;
    ad.no_ozone = no_ozone;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, &wl, &a));
    return a;
}

static void dir_el_az(double el, double az, double d[3]) { atmos_direction_from_angles(el, az, d); }

static double lum(const double *c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* Single scattering of the march (Psi_ms left out) against atmos__planet_single_scatter. */
static void single_scattering(atmos_atmosphere *a)
{
    const atmos__planet *pl = a->planet;
    const double alts[] = {0, 10e3, 99e3, 1000e3, 36000e3};
    const double suns[] = {90, 45, 10, 2, -2, -6};
    double sum2 = 0, worst = 0;
    int cnt = 0;
    for (int ia = 0; ia < 5; ia++)
        for (int is = 0; is < 6; is++)
            for (int v = 0; v < 4; v++) {
                const double p[3] = {0, alts[ia], 0};
                double d[3], sun[3];
                dir_el_az(suns[is], 0, sun);
                /* from orbit: toward the planet's disk and its limb; below: up, the
                 * horizon, toward and away from the sun */
                const double lim = alts[ia] > 200e3 ? -asin(pl->r_top / (pl->r_ground + alts[ia])) * 57.29578 : 0;
                const double els[4] = {alts[ia] > 200e3 ? -89 : 60, alts[ia] > 200e3 ? lim - 0.02 : 3,
                                       alts[ia] > 200e3 ? -80 : 20, alts[ia] > 200e3 ? lim + 0.5 : -20};
                dir_el_az(els[v], 40.0 * v, d);
                const double K = atmos__planet_ground_distance(pl, p, d);
                double ref[3], t0, t1, got[3] = {0, 0, 0};
                atmos__planet_single_scatter(pl, p, d, K, sun, 3, NULL, ref);
                if (atmos__planet_clip(pl, p, d, K, &t0, &t1)) {
                    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
                    atmos__sph_sums s;
                    atmos__sph_march(pl, a->model, q, d, t0, t1, sun, ATMOS__SPH_STEPS, 0, 3, NULL, &s);
                    const double nu = atmos__dot3(d, sun);
                    for (int k = 0; k < 3; k++)
                        got[k] = atmos__planet_rayleigh_phase(pl, k, nu) * s.sr[k] + atmos__planet_mie_phase(pl, k, nu) * s.sm[k];
                }
                if (lum(ref) < 1e-9 * 0.1) continue; /* deep in the shadow: nothing to compare */
                const double e = lum(got) / lum(ref) - 1.0;
                sum2 += e * e, cnt++;
                if (fabs(e) > fabs(worst)) worst = e;
                if (fabs(e) > 0.01)
                    fprintf(stderr, "single: alt %g sun %g el %g: %.6g vs %.6g (%.3f %%)\n", alts[ia], suns[is],
                            els[v], lum(got), lum(ref), 100 * e);
            }
    const double rms = sqrt(sum2 / cnt);
    printf("single scattering vs quadrature: %d views, rms %.3f %%, worst %.3f %%\n", cnt, 100 * rms, 100 * worst);
    CHECK(cnt > 60);
    CHECK(rms < 0.005);
    CHECK(fabs(worst) < 0.015);
}

/* Optical depth by the midpoint rule over 200 000 equal steps (a third method). */
static void brute_depth(const atmos__planet *pl, const double p[3], const double d[3], double dist, double *out)
{
    double t0, t1;
    out[0] = out[1] = out[2] = 0;
    if (!atmos__planet_clip(pl, p, d, dist, &t0, &t1)) return;
    const int N = 200000;
    const double dt = (t1 - t0) / N;
    for (int i = 0; i < N; i++) {
        const double t = t0 + (i + 0.5) * dt, x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
        const double h = atmos__planet_altitude(pl, x);
        for (int k = 0; k < 3; k++) out[k] += atmos__planet_extinction(pl, h, k) * dt;
    }
}

/* Optical depths with closed forms: the vertical from the ground to the top is
 * sum sigma H (1 - e^{-top/H}) plus the ozone tent's area (peak * half width). */
static void transmittance(atmos_atmosphere *a)
{
    const atmos__planet *pl = a->planet;
    const double top = pl->r_top - pl->r_ground, up[3] = {0, 1, 0}, p0[3] = {0, 0, 0};
    double T[3], Tl[3];
    atmos_atmosphere_transmittance(a, p0, up, INFINITY, T);
    atmos__sph_sun_t(a->model, pl->r_ground, 1.0, 3, NULL, Tl);
    for (int k = 0; k < 3; k++) {
        const double tau = pl->rayleigh[k] * pl->h_rayleigh * (1 - exp(-top / pl->h_rayleigh)) +
                           pl->mie_ext[k] * pl->h_mie * (1 - exp(-top / pl->h_mie)) +
                           pl->ozone[k] * pl->ozone_half_width;
        /* Gauss-Legendre across the ozone tent's kinks: ~1e-4 in depth */
        CHECK_NEAR(-log(T[k]), tau, 2e-4);
        CHECK_NEAR(-log(Tl[k]), tau, 2e-4);
    }
    /* a vertical piece from 2 to 7 km */
    const double p1[3] = {0, 2e3, 0};
    atmos_atmosphere_transmittance(a, p1, up, 5e3, T);
    for (int k = 0; k < 3; k++) {
        const double tau = pl->rayleigh[k] * pl->h_rayleigh * (exp(-2e3 / pl->h_rayleigh) - exp(-7e3 / pl->h_rayleigh)) +
                           pl->mie_ext[k] * pl->h_mie * (exp(-2e3 / pl->h_mie) - exp(-7e3 / pl->h_mie));
        CHECK_REL(T[k], exp(-tau), 1e-5);
    }
    /* slant and grazing paths against planet.c's quadrature, and the table's sunlight */
    double worst = 0, worst_lut = 0;
    for (int i = 0; i < 20; i++) {
        const double h = (i % 5) * (i % 5) * 4e3, el = -8.0 + 0.9 * i;
        const double p[3] = {0, h, 0};
        double d[3], ref[3], got[3];
        dir_el_az(el, 10.0 * i, d);
        const double dist = (i % 3) ? INFINITY : 50e3 * (1 + i);
        atmos_atmosphere_transmittance(a, p, d, dist, got);
        brute_depth(pl, p, d, dist, ref);
        for (int k = 0; k < 3; k++) {
            const double e = fabs(-log(fmax(got[k], 1e-300)) - ref[k]) / (ref[k] + 0.1);
            if (e > 1e-3) fprintf(stderr, "segment: h %g el %g dist %g k %d: depth %.6g vs %.6g\n", h, el, dist, k, -log(got[k]), ref[k]);
            worst = fmax(worst, e);
        }
        if (atmos__planet_ground_distance(pl, p, d) < INFINITY) continue;
        brute_depth(pl, p, d, INFINITY, ref);
        atmos__sph_sun_t(a->model, pl->r_ground + h, d[1], 3, NULL, got);
        for (int k = 0; k < 3; k++) {
            const double e = fabs(-log(fmax(got[k], 1e-300)) - ref[k]) / (ref[k] + 0.1);
            if (e > 3e-3) fprintf(stderr, "sun table: h %g el %g k %d: depth %.6g vs %.6g\n", h, el, k, -log(got[k]), ref[k]);
            worst_lut = fmax(worst_lut, e);
        }
    }
    /* errors in depth relative to depth + 0.1: relative where the air is thick, absolute
     * (1e-4 in T) where it is thin */
    printf("transmittance: segment depth worst %.2e, sun table worst %.2e\n", worst, worst_lut);
    CHECK(worst < 1e-3);
    CHECK(worst_lut < 4e-3);
}

static void sunlight(atmos_atmosphere *a)
{
    double sun[3], E[3], E0[3];
    const double g[3] = {0, 0, 0}, high[3] = {0, 100e3 - 1, 0}, space[3] = {0, 2000e3, 0};
    dir_el_az(90, 0, sun);
    atmos_atmosphere_sunlight(a, g, sun, E0);
    /* the night side: sun at the nadir, -1 deg on the ground, -12 deg at 100 km (the
     * geometric horizon there is at -10.1 deg), behind the planet from 2000 km */
    const double *pts[4] = {g, g, high, space};
    const double els[4] = {-90, -1, -12, -90};
    for (int i = 0; i < 4; i++) {
        dir_el_az(els[i], 0, sun);
        atmos_atmosphere_sunlight(a, pts[i], sun, E);
        for (int k = 0; k < 3; k++) CHECK(E[k] == 0.0);
    }
    /* ... and lit at 100 km with the sun at -5 deg, fully from space with the sun above */
    dir_el_az(-5, 0, sun);
    atmos_atmosphere_sunlight(a, high, sun, E);
    CHECK(E[0] > 0.05 * E0[0]);
    dir_el_az(30, 0, sun);
    atmos_atmosphere_sunlight(a, space, sun, E);
    const double *e = atmos__atm_sun_irradiance(a);
    for (int k = 0; k < 3; k++) CHECK_REL(E[k], e[k], 1e-12);
    /* reddened at a low sun: red/blue at 2 deg well above red/blue at the zenith */
    dir_el_az(2, 0, sun);
    atmos_atmosphere_sunlight(a, g, sun, E);
    const double rb_low = E[0] / E[2], rb_high = E0[0] / E0[2];
    printf("sunlight red/blue: sun 90 deg %.3f, sun 2 deg %.3f\n", rb_high, rb_low);
    CHECK(rb_low > 3.0 * rb_high);
}

/* Sun at -4 deg: the zenith's blue/red ratio with ozone clearly above the one without. */
static void ozone_twilight(void)
{
    atmos_atmosphere *with = make(0, 0, 0.1), *without = make(0, 1, 0.1);
    double sun[3], L1[3], L0[3];
    const double p[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    dir_el_az(-4, 0, sun);
    atmos_atmosphere_radiance(with, p, up, sun, L1, NULL);
    atmos_atmosphere_radiance(without, p, up, sun, L0, NULL);
    const double r1 = L1[2] / L1[0], r0 = L0[2] / L0[0];
    printf("twilight zenith blue/red at sun -4 deg: with ozone %.3f, without %.3f\n", r1, r0);
    CHECK(r1 > 1.1 * r0);
    atmos_atmosphere_destroy(with);
    atmos_atmosphere_destroy(without);
}

/* A non-absorbing atmosphere (air only, no ozone): light scattered isotropically at a point
 * either scatters again or leaves the air (ground or space), so f_ms = 1 - <T to the
 * boundary> over the sphere, the latter from planet.c's quadrature. Over a white ground
 * with the sun at the zenith, the upward flux at the top above the subsolar point returns
 * what came in (plane-parallel conservation; the sphere's curvature is negligible there). */
static void energy(void)
{
    atmos_atmosphere *a = make(1, 1, 1.0);
    const atmos__planet *pl = a->planet;
    double worst = 0;
    const double alts[3] = {0, 5e3, 30e3};
    for (int ia = 0; ia < 3; ia++) {
        double mt[3] = {0, 0, 0};
        const int NM = 200, NP = 8;
        for (int i = 0; i < NM; i++)
            for (int j = 0; j < NP; j++) {
                const double mu = -1 + 2 * (i + 0.5) / NM, sn = sqrt(1 - mu * mu), ph = 2 * ATMOS_PI * (j + 0.5) / NP;
                const double p[3] = {0, alts[ia], 0}, d[3] = {sn * cos(ph), mu, sn * sin(ph)};
                double tau[3];
                atmos__planet_optical_depth(pl, p, d, INFINITY, 3, NULL, tau);
                for (int k = 0; k < 3; k++) mt[k] += exp(-tau[k]) / (NM * NP);
            }
        for (int k = 0; k < 3; k++) {
            const double f = atmos__sph_fms(a->model, pl->r_ground + alts[ia], 0.5, k);
            worst = fmax(worst, fabs(f - (1 - mt[k])) / (1 - mt[k]));
        }
    }
    printf("f_ms vs 1 - <T>: worst relative difference %.3f %%\n", 100 * worst);
    CHECK(worst < 0.01);
    /* the flux budget at the top above the subsolar point */
    const double sun[3] = {0, 1, 0}, p[3] = {0, 100e3 - 1, 0};
    const double *e = atmos__atm_sun_irradiance(a);
    double up[3] = {0, 0, 0};
    const int NM = 24, NP = 12;
    for (int i = 0; i < NM; i++)
        for (int j = 0; j < NP; j++) {
            const double mu = -(i + 0.5) / NM, sn = sqrt(1 - mu * mu), ph = 2 * ATMOS_PI * (j + 0.5) / NP;
            const double d[3] = {sn * cos(ph), mu, sn * sin(ph)};
            double L[3];
            atmos_atmosphere_radiance(a, p, d, sun, L, NULL);
            for (int k = 0; k < 3; k++) up[k] += L[k] * -mu * (1.0 / NM) * (2 * ATMOS_PI / NP);
        }
    for (int k = 0; k < 3; k++) printf("white ground, sun at zenith: up/in flux at the top, wavelength %d: %.4f\n", k,
                                       up[k] / e[k]);
    /* J_ms's two iterations from Psi_ms truncate the ground-air interreflections of a
     * white ground (docs/sky.md: 0.96 / 0.96 / 0.95; Psi_ms alone gave 0.97 / 0.95 / 0.90):
     * the budget may fall a little short, never above */
    for (int k = 0; k < 3; k++) CHECK(up[k] / e[k] > 0.93 && up[k] / e[k] < 1.005);
    atmos_atmosphere_destroy(a);
}

/* The radiance approaching the horizon from either side converges (no spike or jump
 * between neighbouring elevations), and is the same just below and just above the top of
 * the air. */
static void continuity(atmos_atmosphere *a)
{
    const atmos__planet *pl = a->planet;
    double sun[3];
    dir_el_az(10, 0, sun);
    const double alts[2] = {10e3, 30e3};
    for (int ia = 0; ia < 2; ia++) {
        const double p[3] = {0, alts[ia], 0};
        const double elh = -acos(pl->r_ground / (pl->r_ground + alts[ia])) * 57.29577951308232;
        for (int side = -1; side <= 1; side += 2) {
            double prev = -1, worst = 0;
            for (int i = 0; i < 12; i++) {
                const double delta = 0.125 * pow(0.5, i);
                double d[3], L[3];
                dir_el_az(elh + side * delta, 30, d);
                atmos_atmosphere_radiance(a, p, d, sun, L, NULL);
                const double l = lum(L);
                CHECK(isfinite(l) && l > 0);
                if (prev > 0) worst = fmax(worst, fabs(l / prev - 1));
                prev = l;
            }
            printf("horizon at %g m, %s: largest step between halved offsets %.3f %%\n", alts[ia],
                   side > 0 ? "above" : "below", 100 * worst);
            CHECK(worst < 0.03);
        }
    }
    /* across the top of the air */
    const double top = pl->r_top - pl->r_ground;
    const double els[5] = {90, 0, -10, -30, -89};
    for (int i = 0; i < 5; i++) {
        const double pin[3] = {0, top - 0.5, 0}, pout[3] = {0, top + 0.5, 0};
        double d[3], L0[3], L1[3];
        dir_el_az(els[i], 70, d);
        atmos_atmosphere_radiance(a, pin, d, sun, L0, NULL);
        atmos_atmosphere_radiance(a, pout, d, sun, L1, NULL);
        for (int k = 0; k < 3; k++) CHECK_NEAR(L0[k], L1[k], 1e-4 * fmax(L0[k], 1e-3));
    }
}

/* The renderers' batch against the one-ray radiance for eyes in the air: at the sky-view
 * table's nodes equal (float precision) to the march with the table's steps; between nodes
 * within the table's interpolation error (reported; test_spherical_views measures both
 * per-eye tables over dense sets of directions). */
static void batch(atmos_atmosphere *a)
{
    enum { N = 600 };
    static float dx[N], dy[N], dz[N], w[N], out[3 * N], scratch[N * ATMOS__ATM_BATCH_SCRATCH];
    const double alts[3] = {0, 10e3, 60e3}, suns[4] = {45, 2, -4, 90};
    double node_worst = 0, sum2 = 0, worst = 0;
    int cnt = 0;
    for (int ia = 0; ia < 3; ia++)
        for (int is = 0; is < 4; is++) {
            const double eye[3] = {0, alts[ia], 0};
            double sun[3];
            dir_el_az(suns[is], 120, sun);
            const double e1[3] = {sun[0] / hypot(sun[0], sun[2]), 0, sun[2] / hypot(sun[0], sun[2])};
            const double up[3] = {0, 1, 0};
            double e2[3];
            atmos__cross3(up, e1, e2);
            const double rr = a->planet->r_ground / (a->planet->r_ground + alts[ia]), muh = -sqrt(1 - rr * rr);
            for (int i = 0; i < N; i++) {
                double d[3];
                if (i < N / 2) { /* nodes */
                    const int row = (i * 7) % (2 * ATMOS__SPH_SV_ROWS), col = (i * 3) % ATMOS__SPH_SV_AZ;
                    const int lower = row >= ATMOS__SPH_SV_ROWS;
                    const double v = (double)(lower ? row - ATMOS__SPH_SV_ROWS : row) / (ATMOS__SPH_SV_ROWS - 1);
                    const double x = fmax(v * v, 1e-7), mu = lower ? muh - x * (1 + muh) : muh + x * (1 - muh);
                    const double ph = ATMOS_PI * col / (ATMOS__SPH_SV_AZ - 1), sn = sqrt(1 - mu * mu);
                    for (int c = 0; c < 3; c++) d[c] = mu * up[c] + sn * (cos(ph) * e1[c] + sin(ph) * e2[c]);
                } else {
                    const double t = (i + 0.5) / N * 2 - 1;
                    dir_el_az(90.0 * t * t * t, 37.3 * i, d);
                }
                dx[i] = (float)d[0], dy[i] = (float)d[1], dz[i] = (float)d[2], w[i] = 1;
            }
            atmos__atm_batch b;
            atmos__atm_batch_init(&b, a, eye, sun, 0);
            memset(out, 0, sizeof out);
            atmos__atm_batch_eval(&b, N, dx, dy, dz, w, out, scratch);
            atmos__atm_batch_release(&b);
            for (int i = 0; i < N; i++) {
                double d[3] = {dx[i], dy[i], dz[i]}, L[3];
                const double l = sqrt(atmos__dot3(d, d));
                for (int c = 0; c < 3; c++) d[c] /= l; /* the direction the batch sees */
                if (i < N / 2) atmos__sph_radiance(a, eye, d, sun, ATMOS__SPH_STEPS_SKYVIEW, L, NULL);
                else atmos_atmosphere_radiance(a, eye, d, sun, L, NULL);
                const double got[3] = {out[i], out[N + i], out[2 * N + i]};
                const double e = fabs(lum(got) / fmax(lum(L), 1e-12) - 1);
                if (lum(L) < 1e-6 * 0.1) continue; /* night: nothing to compare */
                /* the grazing rows (x = 1e-7) change with the float rounding of the direction
                 * itself: left to the between-nodes statistics */
                const int grazing = i < N / 2 && ((i * 7) % ATMOS__SPH_SV_ROWS) == 0;
                if (grazing) continue;
                if (i < N / 2 && e > 1e-3)
                    fprintf(stderr, "batch: alt %g sun %g ray %d (el %.5f): %.7g vs %.7g\n", alts[ia], suns[is], i,
                            asin(d[1]) * 57.29578, lum(got), lum(L));
                if (i < N / 2) node_worst = fmax(node_worst, e);
                else sum2 += e * e, cnt++, worst = fmax(worst, e);
            }
        }
    printf("batch vs one ray: at nodes worst %.2e; between nodes rms %.3f %%, worst %.3f %%\n", node_worst,
           100 * sqrt(sum2 / cnt), 100 * worst);
    /* (5.7e-4 near the horizon, where the rows crowd: the float rounding of the direction
     * moves the look-up off the node, between values kept as logarithms) */
    CHECK(node_worst < 1e-3);
    CHECK(sqrt(sum2 / cnt) < 0.01);
}

/* The tables through the on-disk cache: a second atmosphere loads them (one file, no
 * rebuild) and answers with the same bytes as the built one. */
static void cache(void)
{
    char dir[1024];
    test_tmp_path(dir, sizeof dir, "sphcache");
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.cache_dir = dir;
    cd.log_level = ATMOS_LOG_ERROR;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    if (!ctx) return;
    CHECK_OK(atmos_cache_clear(ctx, NULL));
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    ad.ground_albedo = 0.2;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *built = NULL, *loaded = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &ad, &wl, &built));
    CHECK_OK(atmos_atmosphere_create(ctx, &ad, &wl, &loaded));
    if (built && loaded) {
        const atmos__sph_model *mb = built->model, *ml = loaded->model;
        CHECK(mb->build_seconds > 0 && ml->build_seconds == 0); /* the second came from the cache */
        CHECK(memcmp(mb->block, ml->block, mb->block_floats * sizeof(float)) == 0);
        double sun[3], d[3], L0[3], L1[3];
        const double p[3] = {0, 1500, 0};
        dir_el_az(7, 10, sun);
        dir_el_az(3, 40, d);
        atmos_atmosphere_radiance(built, p, d, sun, L0, NULL);
        atmos_atmosphere_radiance(loaded, p, d, sun, L1, NULL);
        CHECK(memcmp(L0, L1, sizeof L0) == 0);
    }
    int removed = 0;
    CHECK_OK(atmos_cache_clear(ctx, &removed));
    CHECK(removed >= 1); /* the tables (and the aerosols' Mie results, cached by the optics) */
    atmos_atmosphere_destroy(built);
    atmos_atmosphere_destroy(loaded);
    atmos_context_destroy(ctx);
}

int main(void)
{
    atmos_atmosphere *a = make(0, 0, 0.3);
    single_scattering(a);
    transmittance(a);
    sunlight(a);
    ozone_twilight();
    energy();
    continuity(a);
    batch(a);
    cache();
    atmos_atmosphere_destroy(a);
    return test_summary("test_spherical");
}
