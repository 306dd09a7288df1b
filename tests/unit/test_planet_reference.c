/* The Monte Carlo reference of the spherical atmosphere (atmos_atmosphere_reference_radiance,
 * src/atmosphere/planet_reference.c, planet_track.c), checked against methods that do not
 * share its code:
 *  - single scattering (max_order 1) against the quadrature of planet.c on views from the
 *    ground, from 10 km and from space, sun high, low and below the horizon;
 *  - energy: a conservative atmosphere over a white ground sends back to space all the
 *    solar power it intercepts (scattered, plus the sunlight that crosses the air's rim
 *    unscattered);
 *  - Beer-Lambert: with scattering switched off, the free flights' escape probability, the
 *    ratio-tracked transmittance and the radiance of a lit ground match the exponential
 *    profiles' optical depths integrated in closed form along vertical paths, and the
 *    quadrature along a slant one;
 *  - determinism: the same seed gives the same bytes on 1 and 2 threads;
 *  - a published reference: the phase curve of a planet with a deep Rayleigh atmosphere;
 *  - the path renderer draws the reference for a planet without a volume. */
#include "atmos/atmos.h"
#include "atmosphere/planet_solver.h"
#include "atmosphere/planet_track.h"
#include "core/vec.h"
#include "test.h"

#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static atmos_atmosphere *make_atm(atmos_context *ctx, double albedo)
{
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    d.kind = ATMOS_ATMOSPHERE_DOBASHI;
    d.ground_albedo = albedo;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &d, &wl, &a));
    return a;
}

static void dir_from(double elev_deg, double azim_deg, double out[3])
{
    const double e = elev_deg * ATMOS_DEG2RAD, z = azim_deg * ATMOS_DEG2RAD;
    out[0] = cos(e) * cos(z), out[1] = sin(e), out[2] = cos(e) * sin(z);
}

/* What a view sees scattered once, by planet.c's quadrature: the air's single scattering
 * plus the directly lit ground through the air. */
static void single_by_quadrature(const atmos_atmosphere *a, const double p[3], const double d[3],
                                 const double sun[3], double *out)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count;
    const double K = atmos__planet_ground_distance(pl, p, d);
    atmos__planet_single_scatter(pl, p, d, K, sun, n, NULL, out);
    for (int k = 0; k < n; k++) out[k] *= a->sun_e[k];
    if (K < INFINITY) {
        double g[3] = {p[0] + K * d[0], p[1] + K * d[1], p[2] + K * d[2]}, nrm[3], tau[ATMOS_MAX_WAVELENGTHS],
               Ts[ATMOS_MAX_WAVELENGTHS];
        atmos__planet_optical_depth(pl, p, d, K, n, NULL, tau);
        atmos__planet_ground_point(pl, g, nrm);
        const double cs = atmos__dot3(nrm, sun);
        if (cs > 0) {
            atmos__planet_sun_transmittance(pl, g, sun, n, NULL, Ts);
            for (int k = 0; k < n; k++) out[k] += pl->albedo / ATMOS_PI * cs * a->sun_e[k] * Ts[k] * exp(-tau[k]);
        }
    }
}

static void test_single(atmos_atmosphere *a)
{
    static const struct {
        const char *name;
        double y, elev, sun_elev, sun_azim;
    } views[] = {
        {"ground, zenith 30, sun 60", 0, 60, 60, 180},
        {"ground, horizon 3 deg, sun 5 deg ahead", 0, 3, 5, 20},
        {"10 km, down 30 deg, sun 30", 10e3, -30, 30, 90},
        {"10 km, up 10 deg, sun -4 deg ahead", 10e3, 10, -4, 10},
        {"500 km, down 60 deg, sun 45", 500e3, -60, 45, 0},
        {"36000 km, at the limb, sun 20 beyond it", 36000e3, 0, 20, 0},
    };
    for (size_t v = 0; v < sizeof views / sizeof views[0]; v++) {
        double p[3] = {0, views[v].y, 0}, d[3], sun[3];
        dir_from(views[v].elev, 0, d);
        dir_from(views[v].sun_elev, views[v].sun_azim, sun);
        if (views[v].y > 1e7) {
            /* look at the limb: the tangent point 20 km above the ground */
            const double R = a->planet->r_ground, H = R + views[v].y, rt = R + 20e3;
            const double el = -acos(rt / H) * 180.0 / ATMOS_PI;
            dir_from(el, 0, d);
        }
        double mc[3], se[3], ref[3];
        CHECK_OK(atmos_atmosphere_reference_radiance(a, p, d, sun, 20000, 7, 1, mc, se));
        single_by_quadrature(a, p, d, sun, ref);
        for (int k = 0; k < 3; k++) {
            const double tol = 4.5 * se[k] + 2e-3 * ref[k] + 1e-12;
            printf("%-40s k %d: MC %.6g +- %.2g, quadrature %.6g (%.2f sigma)\n", views[v].name, k, mc[k], se[k],
                   ref[k], se[k] > 0 ? (mc[k] - ref[k]) / se[k] : 0.0);
            CHECK_MSG(fabs(mc[k] - ref[k]) <= tol, "%s, wavelength %d", views[v].name, k);
        }
        /* every order is at least the first */
        double all[3];
        CHECK_OK(atmos_atmosphere_reference_radiance(a, p, d, sun, 4000, 8, 0, all, NULL));
        for (int k = 0; k < 3; k++) CHECK(all[k] >= 0.8 * ref[k]);
    }
}

/* Energy: every scatterer conservative, the ground white. The power leaving the top sphere
 * (radius Rt) is 4 pi Rt^2 M (M: the mean exitance, pi times the mean radiance leaving over
 * cosine-distributed directions at uniformly distributed points) plus the sunlight that
 * crosses the rim unscattered, E times the integral of 2 pi b T(b) db over the impact
 * parameters b from R to Rt; it must equal the intercepted pi Rt^2 E. */
static void test_energy(atmos_atmosphere *a)
{
    atmos__planet *pl = a->planet;
    for (int k = 0; k < pl->n; k++) pl->ozone[k] = 0, pl->mie_sca[k] = pl->mie_ext[k];
    pl->albedo = 1.0;
    const double sun[3] = {0, 0, 1}, R = pl->r_ground, Rt = pl->r_top;
    const int ks[2] = {2, 0};
    for (int j = 0; j < 2; j++) {
        const int k = ks[j];
        /* the unscattered rim: midpoint rule over b */
        const int NB = 2000;
        double rim = 0;
        for (int i = 0; i < NB; i++) {
            const double b = R + (i + 0.5) * (Rt - R) / NB;
            const double p[3] = {0, b - R, -2.0 * Rt};
            double tau;
            const int kw = k;
            atmos__planet_optical_depth(pl, p, sun, INFINITY, 1, &kw, &tau);
            rim += 2.0 * ATMOS_PI * b * exp(-tau) * (Rt - R) / NB;
        }
        rim /= ATMOS_PI * Rt * Rt;
        /* the scattered part: points stratified in z = n.sun, uniform in azimuth */
        const int N = 250000;
        double s = 0, s2 = 0, prev = 0;
        for (int i = 0; i < N; i++) {
            atmos__stream r;
            atmos__stream_seed(&r, 99, (uint64_t)k, (uint64_t)i);
            const double z = -1.0 + 2.0 * (i + atmos__stream_u(&r)) / N, ph = 2.0 * ATMOS_PI * atmos__stream_u(&r);
            const double st = sqrt(fmax(0.0, 1.0 - z * z));
            const double n[3] = {st * cos(ph), st * sin(ph), z};
            const double u = atmos__stream_u(&r), c = sqrt(u), sc = sqrt(1.0 - u), ph2 = 2.0 * ATMOS_PI * atmos__stream_u(&r);
            double t1[3], t2[3];
            const double ax[3] = {fabs(n[0]) < 0.6 ? 1.0 : 0.0, fabs(n[0]) < 0.6 ? 0.0 : 1.0, 0};
            atmos__cross3(n, ax, t1);
            atmos__normalize3(t1);
            atmos__cross3(n, t1, t2);
            double eye[3], view[3];
            for (int q = 0; q < 3; q++) {
                eye[q] = (Rt + 1.0) * n[q];
                view[q] = -(c * n[q] + sc * (cos(ph2) * t1[q] + sin(ph2) * t2[q]));
            }
            eye[1] -= R;
            const double L = atmos__atm_reference_walk(a, eye, view, sun, k, 0, &r);
            /* the stratified estimate's variance from the differences of neighbouring strata */
            s += ATMOS_PI * L;
            if (i & 1) s2 += 0.5 * (ATMOS_PI * L - prev) * (ATMOS_PI * L - prev);
            prev = ATMOS_PI * L;
        }
        const double E = a->sun_e[k], M = s / N, sd = sqrt(s2 / (0.5 * N)) / sqrt((double)N);
        const double out = 4.0 * M / E + rim, err = 4.0 * sd / E;
        printf("energy, wavelength %d: scattered out %.5f +- %.5f, unscattered rim %.5f, total %.5f of the incident\n",
               k, 4.0 * M / E, err, rim, out);
        CHECK_MSG(fabs(out - 1.0) < 0.01 && fabs(out - 1.0) < 4.5 * err + 1e-3, "wavelength %d: %.4f of the incident "
                  "power leaves", k, out);
    }
}

/* Closed-form optical depth of the vertical path between altitudes h0 < h1 at wavelength k:
 * sigma H (e^{-h0/H} - e^{-h1/H}) per exponential profile, and the tent's area. */
static double vertical_depth(const atmos__planet *pl, int k, double h0, double h1)
{
    double tau = pl->rayleigh[k] * pl->h_rayleigh * (exp(-h0 / pl->h_rayleigh) - exp(-h1 / pl->h_rayleigh)) +
                 pl->mie_ext[k] * pl->h_mie * (exp(-h0 / pl->h_mie) - exp(-h1 / pl->h_mie));
    /* the tent 1 - |h - c| / w on [c - w, c + w], integrated over [h0, h1] piecewise */
    const double c = pl->ozone_centre, w = pl->ozone_half_width;
    const double lo = fmax(h0, c - w), hi = fmin(h1, c + w);
    double oz = 0;
    if (hi > lo) {
        /* F(h) = integral from c - w to h of the tent */
        double F[2];
        const double hs[2] = {lo, hi};
        for (int i = 0; i < 2; i++) {
            const double x = hs[i];
            F[i] = x <= c ? (x - (c - w)) * (x - (c - w)) / (2 * w) : w / 2 + (x - c) - (x - c) * (x - c) / (2 * w);
        }
        oz = F[1] - F[0];
    }
    return tau + pl->ozone[k] * oz;
}

/* Free flights and ratio tracking follow the extinction whatever scatters: their escape
 * probability and their mean are the transmittance. Ozone made 30 times stronger to weigh. */
static void test_beer_lambert(atmos_atmosphere *a)
{
    atmos__planet *pl = a->planet;
    for (int k = 0; k < pl->n; k++) pl->ozone[k] = 30.0 * pl->ozone[k] + 1e-6;
    const double top = pl->r_top - pl->r_ground;
    const int N = 20000;
    for (int k = 0; k < pl->n; k++) {
        const double up[3] = {0, 1, 0};
        const struct {
            double h0, h1;
        } seg[] = {{0, top}, {5e3, 30e3}, {20e3, 26e3}};
        for (size_t s = 0; s < sizeof seg / sizeof seg[0]; s++) {
            const double p[3] = {0, seg[s].h0, 0}, T = exp(-vertical_depth(pl, k, seg[s].h0, seg[s].h1));
            double esc = 0, rt = 0, rt2 = 0;
            for (int i = 0; i < N; i++) {
                atmos__stream r;
                atmos__stream_seed(&r, 5, (uint64_t)(k * 10 + (int)s), (uint64_t)i);
                const double L = seg[s].h1 - seg[s].h0;
                esc += atmos__planet_free_flight(pl, p, up, L, k, &r) >= L;
                const double v = atmos__planet_ratio_track(pl, p, up, L, k, &r);
                rt += v, rt2 += v * v;
            }
            const double pe = esc / N, se_e = sqrt(T * (1 - T) / N), mr = rt / N;
            const double se_r = sqrt(fmax(rt2 / N - mr * mr, 0.0) / (N - 1));
            printf("Beer-Lambert k %d, vertical %g-%g m: T %.6f, escapes %.6f (+- %.1g), ratio tracking %.6f (+- %.1g)\n",
                   k, seg[s].h0, seg[s].h1, T, pe, se_e, mr, se_r);
            CHECK(fabs(pe - T) <= 4.5 * se_e + 1e-9);
            CHECK(fabs(mr - T) <= 4.5 * se_r + 1e-6 * T);
        }
        /* a slant path from the ground at 2 degrees, 300 km: against the quadrature */
        const double p[3] = {0, 0, 0};
        double d[3], tau;
        dir_from(2, 30, d);
        atmos__planet_optical_depth(pl, p, d, 300e3, 1, &k, &tau);
        double rt = 0, rt2 = 0;
        for (int i = 0; i < N; i++) {
            atmos__stream r;
            atmos__stream_seed(&r, 6, (uint64_t)k, (uint64_t)i);
            const double v = atmos__planet_ratio_track(pl, p, d, 300e3, k, &r);
            rt += v, rt2 += v * v;
        }
        const double mr = rt / N, se = sqrt(fmax(rt2 / N - mr * mr, 0.0) / (N - 1));
        printf("Beer-Lambert k %d, 2 deg slant 300 km: quadrature %.6f, ratio tracking %.6f (+- %.1g)\n", k, exp(-tau),
               mr, se);
        CHECK(fabs(mr - exp(-tau)) <= 4.5 * se + 1e-6);
    }
}

/* The whole estimator without scattering: a ground of albedo 0.5 under a zenith sun seen
 * straight down from 3 km is albedo / pi E T(0, top) T(0, 3 km). */
static void test_lit_ground(atmos_atmosphere *a)
{
    atmos__planet *pl = a->planet;
    pl->albedo = 0.5;
    for (int k = 0; k < pl->n; k++) pl->rayleigh[k] = 0, pl->mie_sca[k] = 0; /* absorption only */
    const double p[3] = {0, 3e3, 0}, d[3] = {0, -1, 0}, sun[3] = {0, 1, 0};
    double L[3], se[3];
    CHECK_OK(atmos_atmosphere_reference_radiance(a, p, d, sun, 20000, 3, 0, L, se));
    for (int k = 0; k < 3; k++) {
        const double top = pl->r_top - pl->r_ground;
        const double ref = 0.5 / ATMOS_PI * a->sun_e[k] * exp(-vertical_depth(pl, k, 0, top) - vertical_depth(pl, k, 0, 3e3));
        printf("lit ground k %d: MC %.6g +- %.2g, closed form %.6g\n", k, L[k], se[k], ref);
        CHECK(fabs(L[k] - ref) <= 4.5 * se[k] + 1e-9 * ref);
    }
}

static void test_threads(atmos_atmosphere *a)
{
#ifdef _OPENMP
    const double p[3] = {0, 100, 0}, sun[3] = {0.3, 0.2, sqrt(1 - 0.13)};
    double d[3], L1[3], L2[3], s1[3], s2[3];
    dir_from(15, 40, d);
    const int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    CHECK_OK(atmos_atmosphere_reference_radiance(a, p, d, sun, 3000, 42, 0, L1, s1));
    omp_set_num_threads(2);
    CHECK_OK(atmos_atmosphere_reference_radiance(a, p, d, sun, 3000, 42, 0, L2, s2));
    omp_set_num_threads(saved);
    CHECK(!memcmp(L1, L2, sizeof L1) && !memcmp(s1, s2, sizeof s1));
    double L3[3];
    CHECK_OK(atmos_atmosphere_reference_radiance(a, p, d, sun, 3000, 43, 0, L3, NULL));
    CHECK(memcmp(L1, L3, sizeof L1) != 0);
#else
    (void)a;
#endif
}

/* A published reference: Buenzli & Schmid 2009 (A&A 504, 259), Table 1: the reflectivity
 * I(alpha) of a planet with a conservative Rayleigh atmosphere of optical depth 30 over a
 * Lambert surface of albedo 1, disk-integrated at phase angle alpha and normalised to a
 * white Lambert disk at alpha = 0, by a Monte Carlo code with polarisation. Here the same
 * atmosphere (air molecules only, vertical optical depth 30, on a planet 100 times the
 * Earth's so that the 100 km of air are thin as in a locally plane-parallel model), seen
 * from far away along parallel rays through points uniform over the disk: I = (R_top / R)^2
 * pi <L> / E. The estimator is scalar, the published values vector: neglecting polarisation
 * changes a Rayleigh atmosphere's multiply scattered intensities by several per cent
 * (Mishchenko, Lacis & Travis 1994, JQSRT 51, 491: up to ~10 %). With 40 000 walks per angle
 * the scalar values are 5.5 % below at 2.5 deg, 3.5 % below at 32.5, 3.2 % above at 62.5 and
 * 4.5 % above at 92.5 (docs/sky.md); tolerance 7 % plus 3 standard errors. */
static void test_published(atmos_atmosphere *a)
{
    atmos__planet *pl = a->planet;
    pl->r_ground = 100.0 * 6360e3;
    pl->r_top = pl->r_ground + 100e3;
    pl->albedo = 1.0;
    const int k = 1;
    pl->rayleigh[k] = 30.0 / (pl->h_rayleigh * (1.0 - exp(-100e3 / pl->h_rayleigh)));
    pl->mie_ext[k] = pl->mie_sca[k] = pl->ozone[k] = 0;
    static const double table[][2] = {{2.5, 0.795}, {62.5, 0.368}, {92.5, 0.174}};
    const double Rg = pl->r_ground, Rt = pl->r_top, sun[3] = {0, 0, 1};
    const int N = 8000;
    for (int j = 0; j < 3; j++) {
        const double al = table[j][0] * ATMOS_DEG2RAD;
        const double o[3] = {sin(al), 0, cos(al)}, e1[3] = {cos(al), 0, -sin(al)}, e2[3] = {0, 1, 0};
        double s = 0, s2 = 0;
        for (int i = 0; i < N; i++) {
            atmos__stream r;
            atmos__stream_seed(&r, 3, (uint64_t)j, (uint64_t)i);
            const double rr = Rt * sqrt(atmos__stream_u(&r)), ph = 2.0 * ATMOS_PI * atmos__stream_u(&r);
            double eye[3], dir[3];
            for (int q = 0; q < 3; q++) {
                eye[q] = 2.0 * Rt * o[q] + rr * (cos(ph) * e1[q] + sin(ph) * e2[q]);
                dir[q] = -o[q];
            }
            eye[1] -= Rg;
            const double v = Rt * Rt / (Rg * Rg) * ATMOS_PI * atmos__atm_reference_walk(a, eye, dir, sun, k, 0, &r) /
                             a->sun_e[k];
            s += v, s2 += v * v;
        }
        const double m = s / N, se = sqrt(fmax(s2 / N - m * m, 0.0) / (N - 1));
        printf("Buenzli & Schmid 2009 Table 1, alpha %.1f deg: I %.4f +- %.4f, published (vector) %.3f\n", table[j][0], m,
               se, table[j][1]);
        CHECK(fabs(m - table[j][1]) <= 0.07 * table[j][1] + 3.0 * se);
    }
}

/* The path renderer over a planet without a volume draws the reference: a pinhole pixel of
 * 0.05 degrees agrees with the estimator along its centre within their errors, and a pixel
 * on the sun holds its disk; regions and progressive passes give the whole frame's bytes. */
static void path_scene(atmos_scene *s, double elev, double azim, double fov, int w, int h)
{
    atmos_scene_defaults(s);
    s->renderer = ATMOS_RENDERER_PATH;
    s->volume.source[0] = '\0';
    s->atmosphere.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    s->atmosphere.ground_albedo = 0.3;
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
    s->width = w, s->height = h;
    const double pos[3] = {0, 100, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    double d[3];
    atmos_direction_from_angles(elev, azim, d);
    for (int i = 0; i < 3; i++) s->camera.look_at[i] = pos[i] + d[i];
    s->camera.fov_deg = fov;
    s->sun.from_time = 0;
    s->sun.elevation_deg = 25;
    s->sun.azimuth_deg = 200;
}

static atmos_image *render_path(atmos_context *ctx, const atmos_scene *s, int spp, atmos_plan **pp)
{
    atmos_frame f;
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_create(ctx, s, NULL, NULL, pp));
    if (!*pp) return NULL;
    CHECK_OK(atmos_frame_from_scene(ctx, s, &f));
    f.spp = spp;
    CHECK_OK(atmos_plan_image_create(*pp, &f, &img));
    CHECK_OK(atmos_plan_render(*pp, &f, NULL, img, NULL));
    return img;
}

static void test_path_renderer(atmos_context *ctx)
{
    atmos_scene s;
    path_scene(&s, 20, 120, 0.05, 1, 1);
    atmos_plan *p = NULL;
    atmos_image *img = render_path(ctx, &s, 3000, &p), *var = NULL;
    if (img && p) {
        CHECK_OK(atmos_plan_path_variance(p, &var));
        double d[3], sun[3], L[3], se[3];
        atmos_direction_from_angles(20, 120, d);
        atmos_direction_from_angles(25, 200, sun);
        CHECK_OK(atmos_atmosphere_reference_radiance(atmos_plan_atmosphere(p), s.camera.position, d, sun, 3000, 11, 0,
                                                     L, se));
        for (int k = 0; k < 3 && var; k++) {
            const double px = img->pixels[k], sp = sqrt(var->pixels[k]);
            printf("path renderer k %d: pixel %.6g +- %.2g, reference %.6g +- %.2g\n", k, px, sp, L[k], se[k]);
            CHECK(sp > 0 && fabs(px - L[k]) <= 4.5 * sqrt(sp * sp + se[k] * se[k]));
        }
    }
    atmos_image_destroy(var), atmos_image_destroy(img), atmos_plan_destroy(p);
    /* the sun's disk */
    path_scene(&s, 25, 200, 0.05, 1, 1);
    p = NULL;
    img = render_path(ctx, &s, 16, &p);
    if (img && p) {
        double sun[3], Ls[3];
        atmos_direction_from_angles(25, 200, sun);
        atmos_atmosphere_sun_radiance(atmos_plan_atmosphere(p), s.camera.position, sun, Ls);
        printf("path renderer, the sun's disk: pixel %.6g, the disk %.6g\n", img->pixels[1], Ls[1]);
        for (int k = 0; k < 3; k++) CHECK(img->pixels[k] >= Ls[k] && img->pixels[k] < 1.01 * Ls[k]);
    }
    atmos_image_destroy(img), atmos_plan_destroy(p);
    /* a region, then the rest, and progressive passes: the whole frame's bytes */
    path_scene(&s, 5, 180, 60, 12, 8);
    p = NULL;
    atmos_image *whole = render_path(ctx, &s, 6, &p), *part = NULL;
    atmos_plan_destroy(p);
    p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &p));
    atmos_frame f;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    if (p && whole && atmos_plan_image_create(p, &f, &part) == ATMOS_OK) {
        const atmos_region reg = {3, 2, 9, 7};
        f.spp = 2;
        CHECK_OK(atmos_plan_render(p, &f, &reg, part, NULL));
        f.spp = 6;
        CHECK_OK(atmos_plan_render(p, &f, &reg, part, NULL));
        CHECK_OK(atmos_plan_render(p, &f, NULL, part, NULL));
        const size_t nv = (size_t)f.width * f.height * part->channels;
        CHECK(!memcmp(part->pixels, whole->pixels, nv * sizeof(float)));
        double sum = 0;
        for (size_t i = 0; i < nv; i++) sum += whole->pixels[i];
        CHECK(sum > 0 && isfinite(sum));
    }
    atmos_image_destroy(part), atmos_image_destroy(whole), atmos_plan_destroy(p);
}

int main(void)
{
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.log = NULL;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    atmos_atmosphere *a = make_atm(ctx, 0.3);
    if (a) {
        test_single(a);
        test_threads(a);
        double L[3];
        const double p[3] = {0, 0, 0}, d[3] = {0, 1, 0};
        CHECK(atmos_atmosphere_reference_radiance(a, p, d, d, 0, 1, 0, L, NULL) == ATMOS_E_INVALID_ARG);
    }
    atmos_atmosphere_destroy(a);
    a = make_atm(ctx, 1.0);
    if (a) test_energy(a);
    atmos_atmosphere_destroy(a);
    a = make_atm(ctx, 0.0);
    if (a) {
        test_beer_lambert(a);
        test_lit_ground(a);
    }
    atmos_atmosphere_destroy(a);
    a = make_atm(ctx, 1.0);
    if (a) test_published(a);
    atmos_atmosphere_destroy(a);
    atmos_atmosphere *riley = NULL;
    atmos_atmosphere_desc rd;
    atmos_atmosphere_defaults(&rd);
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    CHECK_OK(atmos_atmosphere_create(ctx, &rd, &wl, &riley));
    if (riley) {
        double L[3];
        const double p[3] = {0, 0, 0}, d[3] = {0, 1, 0};
        CHECK(atmos_atmosphere_reference_radiance(riley, p, d, d, 10, 1, 0, L, NULL) == ATMOS_E_INVALID_ARG);
    }
    atmos_atmosphere_destroy(riley);
    test_path_renderer(ctx);
    atmos_context_destroy(ctx);
    return test_summary("test_planet_reference");
}
