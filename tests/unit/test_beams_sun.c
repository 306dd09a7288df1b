/* The sun of the beam renderer (render/beams_sun.h) against an independent numeric
 * quadrature of the single-scattering integral
 *     L = int_0^T sigma_s(t) p(theta) H(t) exp(-tau(t)) dt   (per unit of sunlight),
 * tau by its own cumulative quadrature, H by casting a ray toward the sun through the mesh:
 *   - uniform and height-dependent (exponential) fog without shadows: the closed form between
 *     the ends, to 1e-6; in a height-dependent fog the sunlight is dimmed on its way in too
 *     (the layer's optical depth above the point along the sun, sigma(y) H / sin(elevation));
 *     a uniform fog is lit undimmed (it has no top);
 *   - a wall floating in uniform fog casting a shadow across the rays: the renderer's steps
 *     (epsilon 1e-3) with the shadow map against the quadrature with exact shadow rays;
 *   - the steps' visibility read through the map's min/max tiles (runs proven lit or dark not
 *     read) against every step's middle read one by one (atmos__beams_sun_visibility), on rays
 *     crossing a wall's shadow, starting inside it, leaving the map and endless: to 1e-9;
 *   - the eye's factors kept once a frame (atmos__beams_fog_eye): the same bits from the eye,
 *     another point's own values;
 *   - the steps' placement's ln(1 + x) (atmos__log1p_fast, core/fastmath.h) against the
 *     library's log1p over x in (-1, 10], tiny arguments of both signs included: within
 *     1e-15 of it, relative;
 *   - the Fig. 10(a) scene small: the same image with one thread and with two, byte for byte;
 *     finite, non-negative pixels; the sunlit sky above the ridge brighter than the shadowed
 *     ground below it. */
#include "atmos/atmos.h"
#include "render/beams_sun.h"
#include "core/fastmath.h"
#include "test.h"

static atmos_context *ctx;

/* sigma_t at the point p of the fog */
static double sigma_at(const atmos__beams_fog *f, const double p[3])
{
    return f->height_m > 0 ? f->sigma0 * exp(-(p[1] - f->base_m) / f->height_m) : f->sigma0;
}

/* The integral by the midpoint rule over n steps up to T (finite), H from shadow rays
 * through mesh (NULL: none). */
static double quadrature(const atmos__beams_fog *f, const double sun[3], const atmos_mesh *mesh, const double o[3],
                         const double d[3], double T, int n)
{
    const double h = T / n;
    double tau = 0, sum = 0;
    for (int i = 0; i < n; i++) {
        const double t = (i + 0.5) * h, p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        const double s = sigma_at(f, p);
        const double tau_mid = tau + 0.5 * s * h; /* the optical depth to the step's middle */
        const int lit = !mesh || !atmos_mesh_intersect(mesh, p, sun, 0, 1e9, NULL);
        const double in = f->height_m > 0 ? s * f->height_m / sun[1] : 0; /* the fog above p, toward the sun */
        sum += f->albedo * s * exp(-tau_mid - in) * lit * h;
        tau += s * h;
    }
    return sum * atmos_phase_hg(sun[0] * d[0] + sun[1] * d[1] + sun[2] * d[2], f->g);
}

static void unit(double v[3])
{
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int a = 0; a < 3; a++) v[a] /= l;
}

static void test_no_shadow(void)
{
    atmos__beams_sun s;
    memset(&s, 0, sizeof s);
    double sun[3] = {0.3, 0.5, -0.8};
    unit(sun);
    CHECK_OK(atmos__beams_sun_build(ctx, &s, sun, NULL, 0, 64));
    const atmos__beams_fog uniform = {.sigma0 = 2e-3, .albedo = 0.9, .g = 0.6},
                           layer = {.sigma0 = 5e-3, .albedo = 0.8, .g = 0.3, .base_m = 100, .height_m = 250};
    const atmos__beams_fog *fogs[2] = {&uniform, &layer};
    const double o[3] = {0, 20, 0};
    double worst = 0;
    for (int fi = 0; fi < 2; fi++)
        for (int r = 0; r < 6; r++) {
            double d[3] = {cos(r), 0.4 * sin(1.7 * r) - 0.1, sin(r)};
            unit(d);
            const double T = 300 + 400 * r;
            const double got = atmos__beams_sun_airlight(&s, fogs[fi], o, d, T, 0.01, 1000);
            const double want = quadrature(fogs[fi], sun, NULL, o, d, T, 200000);
            worst = fmax(worst, fabs(got - want) / want);
            /* the optical depth too */
            double tau = 0;
            for (int i = 0; i < 20000; i++) {
                const double t = (i + 0.5) * T / 20000, p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
                tau += sigma_at(fogs[fi], p) * T / 20000;
            }
            CHECK_REL(atmos__beams_fog_tau(fogs[fi], o, d, T), tau, 1e-6);
        }
    printf("sun airlight without shadows against the quadrature: worst relative error %.2e\n", worst);
    CHECK(worst < 1e-6);
    /* an upward ray through the exponential layer: a finite optical depth to infinity */
    const double up[3] = {0, 1, 0};
    CHECK_REL(atmos__beams_fog_tau(&layer, o, up, INFINITY), 5e-3 * 250 * exp(-(20 - 100) / 250.0), 1e-12);
    CHECK(atmos__beams_fog_tau(&uniform, o, up, INFINITY) == INFINITY);
    atmos__beams_sun_free(&s);
}

/* A wall 40 m wide hanging 40 m up, 60 m away, and the sun's shadow map of it (size texels a
 * side) for a sun up to the right; NULL if the box could not be made. */
static atmos_mesh *wall_and_sun(atmos__beams_sun *s, double sun[3], int size)
{
    atmos_mesh *wall = NULL;
    CHECK_OK(atmos_mesh_load(ctx, "builtin:box", 0, &wall));
    if (!wall) return NULL;
    atmos_mesh_transform t;
    atmos_mesh_transform_identity(&t);
    t.position_m[1] = 40, t.position_m[2] = -60, t.scale[0] = 40, t.scale[1] = 15, t.scale[2] = 15;
    CHECK_OK(atmos_mesh_apply_transform(ctx, wall, &t));
    sun[0] = 0.2, sun[1] = 0.5, sun[2] = 0.6;
    unit(sun);
    memset(s, 0, sizeof *s);
    CHECK_OK(atmos__beams_sun_build(ctx, s, sun, &wall, 1, size));
    return wall;
}

static void test_shadow(void)
{
    atmos__beams_sun s;
    double sun[3];
    atmos_mesh *wall = wall_and_sun(&s, sun, 2048);
    if (!wall) return;
    /* a uniform fog, and a layer thinning upward (the sunlight dimmed on its way in) */
    const atmos__beams_fog fogs[2] = {{.sigma0 = 4e-3, .albedo = 1, .g = 0.2},
                                      {.sigma0 = 4e-3, .albedo = 1, .g = 0.2, .base_m = 60}};
    const double o[3] = {0, 5, 0};
    for (int fi = 0; fi < 2; fi++) {
        const atmos__beams_fog *fog = &fogs[fi];
        double worst = 0, lost = 0;
        int shadowed = 0;
        for (int r = 0; r < 21; r++) { /* rays fanning across the wall's shadow below it */
            double d[3] = {-0.6 + 0.06 * r, 0.02 + 0.1 * fi, -1};
            unit(d);
            const double T = 400;
            const double got = atmos__beams_sun_airlight(&s, fog, o, d, T, 1e-3, 100000);
            const double want = quadrature(fog, sun, wall, o, d, T, 100000);
            const double full = quadrature(fog, sun, NULL, o, d, T, 100000);
            shadowed += want < 0.99 * full;
            worst = fmax(worst, fabs(got - want) / full);
            lost = fmax(lost, (full - want) / full);
        }
        printf("sun airlight with a wall's shadow, %s fog: %d of 21 rays shadowed (up to %.1f %% of their light), "
               "worst error %.2e of the unshadowed light\n", fi ? "layered" : "uniform", shadowed, 100 * lost, worst);
        CHECK(shadowed >= 8 && lost > 0.1);
        CHECK(worst < 3e-3);
    }
    atmos__beams_sun_free(&s);
    atmos_mesh_destroy(wall);
}

/* The sun's airlight with H read at every step's middle: the steps of equal share of the
 * closed-form integral in a uniform fog (tau = -ln(1 - q), t = tau / sigma), each read by
 * atmos__beams_sun_visibility. */
static double every_step(const atmos__beams_sun *s, const atmos__beams_fog *f, const double o[3], const double d[3], double T,
                         int n)
{
    const double whole = -expm1(-f->sigma0 * T);
    double sum = 0;
    for (int i = 0; i < n; i++) {
        const double t = fmin(T, -log1p(-(i + 0.5) * whole / n) / f->sigma0);
        const double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
        sum += atmos__beams_sun_visibility(s, p);
    }
    const double c = s->dir[0] * d[0] + s->dir[1] * d[1] + s->dir[2] * d[2];
    return f->albedo * atmos_phase_hg(c, f->g) * whole * sum / n;
}

static void test_skipped_runs(void)
{
    atmos__beams_sun s;
    double sun[3];
    atmos_mesh *wall = wall_and_sun(&s, sun, 256);
    if (!wall) return;
    const atmos__beams_fog fog = {.sigma0 = 4e-3, .albedo = 1, .g = 0.2};
    /* below the wall looking across its shadow, inside the shadow looking along it (away from
     * the sun), far off looking away from it */
    const double eyes[3][3] = {{0, 5, 0}, {-15, 5, -104}, {-300, 60, 100}};
    double worst = 0, dark = 0, lit = 0;
    for (int e = 0; e < 3; e++)
        for (int r = 0; r < 40; r++) {
            double d[3] = {-0.8 + 0.04 * r, -0.3 + 0.02 * r, -1 + 0.05 * r};
            if (e == 1) d[0] = -sun[0] + 0.01 * (r % 7 - 3), d[1] = -sun[1] + 0.01 * (r / 7 - 3), d[2] = -sun[2];
            if (e == 2) d[0] = -1, d[1] = 0.5 - 0.02 * r, d[2] = 0.3;
            unit(d);
            const double T = r % 4 == 3 ? INFINITY : 50 + 40 * r;
            const double got = atmos__beams_sun_airlight(&s, &fog, eyes[e], d, T, 2e-3, 100000);
            const double want = every_step(&s, &fog, eyes[e], d, T, 500);
            const double full = every_step(&(atmos__beams_sun){.n = 0}, &fog, eyes[e], d, T, 500);
            worst = fmax(worst, fabs(got - want) / full);
            dark += want < 0.5 * full, lit += want > (1 - 1e-12) * full;
        }
    printf("sun airlight through the map's tiles against every step read: worst difference %.2e of the unshadowed "
           "light (%g of 120 rays half dark or more, %g wholly lit)\n", worst, dark, lit);
    CHECK(dark >= 10 && lit >= 10);
    CHECK(worst < 1e-9);
    atmos__beams_sun_free(&s);
    atmos_mesh_destroy(wall);
}

/* The scene file at w x h rendered with the given threads. */
static atmos_image *render_file(const char *path, int w, int h, int threads)
{
    atmos_context_desc d;
    memset(&d, 0, sizeof d);
    d.threads = threads;
    atmos_context *c = NULL;
    atmos_image *img = NULL;
    atmos_scene s;
    CHECK_OK(atmos_context_create(&d, &c));
    if (!c) return NULL;
    if (atmos_scene_load(c, path, &s) == ATMOS_OK) {
        s.width = w, s.height = h;
        const atmos_status st = atmos_render_scene(c, &s, NULL, &img, NULL);
        CHECK_MSG(st == ATMOS_OK, "%s: %s", path, atmos_context_error(c));
    } else
        CHECK_MSG(0, "%s: %s", path, atmos_context_error(c));
    atmos_context_destroy(c);
    return img;
}

/* atmos__log1p_fast against log1p: x from -1 + 2^-40 to 10 on a grid, and +-10^-k (k 1..300)
 * times a spread of mantissas, where 1 + x loses the most of x. */
/* The eye's factors kept once a frame (atmos__beams_fog_eye): the optical depths, the sunlight's
 * dimming and the airlight from the eye the same bits as computed ray by ray, and from a point
 * at another height (or with no eye kept) the values of that point, not the eye's. */
static void test_eye_kept(void)
{
    atmos__beams_sun s;
    memset(&s, 0, sizeof s);
    double sun[3] = {0.3, 0.2, -0.8};
    unit(sun);
    CHECK_OK(atmos__beams_sun_build(ctx, &s, sun, NULL, 0, 64));
    atmos__beams_fog f = {.sigma0 = 5e-3, .albedo = 0.8, .g = 0.3, .base_m = 100, .height_m = 250};
    const double o[3] = {3, 20, -7}, q[3] = {40, 70, 5};
    double want[4][5], got[4][5];
    for (int kept = 0; kept < 2; kept++) {
        if (kept) atmos__beams_fog_eye(&f, o, s.dir);
        CHECK(f.eye_set == kept);
        for (int r = 0; r < 4; r++) {
            double d[3] = {cos(r), 0.3 * sin(1.3 * r), sin(r)};
            unit(d);
            double *v = kept ? got[r] : want[r];
            v[0] = atmos__beams_fog_tau(&f, o, d, 500 + 300 * r), v[1] = atmos__beams_fog_tau(&f, q, d, INFINITY);
            v[2] = atmos__beams_sun_airlight(&s, &f, o, d, 800, 0.01, 1000);
            v[3] = atmos__beams_sun_airlight(&s, &f, q, d, 800, 0.01, 1000);
            v[4] = atmos__beams_sun_fog_in(&f, s.dir, r & 1 ? o : q);
        }
    }
    CHECK(!memcmp(want, got, sizeof want));
    CHECK(f.eye_e == exp(-(o[1] - f.base_m) / f.height_m) && f.eye_expC == exp(-atmos__beams_sun_fog_in(&f, s.dir, o)));
    atmos__beams_sun_free(&s);
}

static void test_log1p(void)
{
    double worst = 0, at = 0;
    for (int i = 1; i < 400000; i++) {
        const double x[2] = {-1 + 0x1p-40 + 11.0 * i / 400000, (i % 2 ? 1 : -1) * (1 + (i % 997) / 997.0) * pow(10, -1 - i % 300)};
        for (int j = 0; j < 2; j++) {
            const double exact = log1p(x[j]);
            if (exact == 0) continue;
            const double e = fabs(atmos__log1p_fast(x[j]) - exact) / fabs(exact);
            if (e > worst) worst = e, at = x[j];
        }
    }
    printf("log1p_fast: worst relative error %.3g at x = %.17g\n", worst, at);
    CHECK_MSG(worst <= 1e-15, "worst %g at %.17g", worst, at);
}

static void test_scene(void)
{
    const char *src = getenv("ATMOS_SOURCE_DIR");
    if (!src) {
        printf("ATMOS_SOURCE_DIR not set: the scene test skipped\n");
        return;
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/dobashi_fig10a_mountain_shafts.json", src);
    atmos_image *a = render_file(path, 48, 32, 1), *b = render_file(path, 48, 32, 2);
    if (a && b) {
        const size_t n = (size_t)a->width * a->height * a->channels;
        CHECK(!memcmp(a->pixels, b->pixels, n * sizeof(float)));
        int ok = 1;
        for (size_t i = 0; i < n; i++) ok &= isfinite(a->pixels[i]) && a->pixels[i] >= 0;
        CHECK(ok);
        double top = 0, bottom = 0;
        for (int x = 0; x < a->width; x++)
            for (int k = 0; k + 1 < a->channels; k++) { /* the last channel is alpha */
                top += a->pixels[((size_t)2 * a->width + x) * a->channels + k];
                bottom += a->pixels[((size_t)(a->height - 3) * a->width + x) * a->channels + k];
            }
        CHECK_MSG(top > 10 * bottom, "sky %g, ground %g", top, bottom);
    }
    atmos_image_destroy(a), atmos_image_destroy(b);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_no_shadow();
    test_shadow();
    test_skipped_runs();
    test_eye_kept();
    test_log1p();
    test_scene();
    atmos_context_destroy(ctx);
    return test_summary("test_beams_sun");
}
