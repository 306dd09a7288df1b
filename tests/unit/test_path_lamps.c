/* The path tracer with point lights, spotlights, fog and objects (src/render/path_lamps.c),
 * against closed forms and against the beam renderer:
 *   - single scattering of an isotropic point light in a homogeneous fog, against the
 *     closed form of Sun, Ramamoorthi, Narasimhan and Nayar 2005 (Eq. 7-8; the same integral
 *     test_beams checks the beam renderer against), within the path tracer's own noise;
 *   - a Lambertian plane under a point light in an absorbing fog:
 *     L = albedo / pi * I cos(theta) / r^2 * exp(-sigma_t r) * exp(-sigma_t t_eye);
 *   - Dobashi Fig. 4's scene (a spotlight, a sphere, its shadow in the air and on the floor),
 *     single scattering: the beam renderer's image (each pixel the mean of 4 x 4 rays, as the
 *     path tracer's pixels average their footprint) against the path tracer's, the mean
 *     relative error over the lit pixels within a bound made of the path tracer's measured
 *     noise; and all orders of scattering add light to single scattering; the same with a
 *     fog of cloud droplets (the Mie phase function tabulated: integrated by the beam
 *     renderer's table, sampled by the path tracer).
 */
#include "atmos/atmos.h"
#include "test.h"

#define ATMOS_PI 3.14159265358979323846

static atmos_context *ctx;

/* F(a, xi) = int_0^xi exp(-a tan z) dz by composite Simpson's rule. */
static double sun_F(double a, double xi)
{
    const int n = 2000;
    const double h = xi / n;
    double s = 0;
    for (int i = 0; i <= n; i++) {
        const double z = i * h;
        const double f = z >= 0.5 * ATMOS_PI - 1e-12 ? 0 : exp(-a * tan(z));
        s += f * (i == 0 || i == n ? 1 : i % 2 ? 4 : 2);
    }
    return s * h / 3;
}

/* Sun et al. 2005: the airlight of the whole ray o + t dir (unit), t > 0, from an isotropic
 * light of unit intensity at lp. */
static double airlight(const double o[3], const double dir[3], const double lp[3], double sig_t, double sig_s)
{
    const double Lp[3] = {lp[0] - o[0], lp[1] - o[1], lp[2] - o[2]};
    const double tq = Lp[0] * dir[0] + Lp[1] * dir[1] + Lp[2] * dir[2];
    const double dd = sqrt(Lp[0] * Lp[0] + Lp[1] * Lp[1] + Lp[2] * Lp[2]);
    const double v = sqrt(fmax(0, dd * dd - tq * tq));
    const double xa = 0.25 * ATMOS_PI + 0.5 * atan(-tq / v);
    return sig_s * exp(-sig_t * tq) / (2 * ATMOS_PI * v) * (sun_F(sig_t * v, 0.5 * ATMOS_PI) - sun_F(sig_t * v, xa));
}

static void path_scene(atmos_scene *s, int w, int h, int spp, int depth)
{
    atmos_scene_defaults(s);
    s->renderer = ATMOS_RENDERER_PATH;
    s->width = w, s->height = h;
    s->atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    s->atmosphere.background_radiance = 0;
    s->path.spp = spp, s->path.max_depth = depth;
    s->light_count = 1;
    atmos_scene_light *l = &s->lights[0];
    memset(l, 0, sizeof *l);
    l->type = ATMOS_LIGHT_POINT;
    l->intensity_w_sr = 400, l->colour[0] = l->colour[1] = l->colour[2] = 1; /* 1 W sr^-1 nm^-1 */
    l->range_m = 2000;
    l->direction[1] = -1;
}

/* A render through a plan; *var (may be NULL) the variance of each pixel's mean. */
static atmos_image *render(const atmos_scene *s, atmos_image **var)
{
    atmos_plan *plan = NULL;
    atmos_frame fr;
    atmos_image *img = NULL;
    atmos_status st = atmos_plan_create(ctx, s, NULL, NULL, &plan);
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, s, &fr);
    if (st == ATMOS_OK) st = atmos_plan_image_create(plan, &fr, &img);
    if (st == ATMOS_OK) st = atmos_plan_render(plan, &fr, NULL, img, NULL);
    if (st == ATMOS_OK && var) st = atmos_plan_path_variance(plan, var);
    CHECK_MSG(st == ATMOS_OK, "render: %s", atmos_context_error(ctx));
    atmos_plan_destroy(plan);
    if (st != ATMOS_OK) atmos_image_destroy(img), img = NULL;
    return img;
}

/* The mean of f over n x n rays spread over pixel (x, y). */
static double footprint(const atmos_camera *cam, int x, int y, int n, double (*f)(const double d[3], const void *),
                        const void *u)
{
    double s = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double d[3];
            atmos_camera_ray(cam, x + (i + 0.5) / n, y + (j + 0.5) / n, d);
            s += f(d, u);
        }
    return s / (n * n);
}

typedef struct {
    double eye[3], lp[3], sig_t, sig_s, albedo;
} setup;

static double air_f(const double d[3], const void *u)
{
    const setup *S = u;
    return airlight(S->eye, d, S->lp, S->sig_t, S->sig_s);
}

static void test_airlight(void)
{
    atmos_scene s;
    path_scene(&s, 20, 15, 256, 1);
    const setup S = {{0, 2, 0}, {3, 4, -20}, 0.05, 0.04, 0};
    s.fog.enabled = 1, s.fog.extinction_per_m = S.sig_t, s.fog.scattering_per_m = S.sig_s, s.fog.g = 0;
    memcpy(s.camera.position, S.eye, sizeof S.eye);
    s.camera.look_at[0] = 1, s.camera.look_at[1] = 2.5, s.camera.look_at[2] = -10;
    s.camera.fov_deg = 50;
    memcpy(s.lights[0].position_m, S.lp, sizeof S.lp);
    atmos_image *var = NULL, *img = render(&s, &var);
    if (!img || !var) return;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
    double sum = 0, sum2 = 0, worst_z = 0;
    const int n = s.width * s.height;
    for (int y = 0; y < s.height; y++)
        for (int x = 0; x < s.width; x++) {
            const size_t px = (size_t)y * s.width + x;
            const double want = footprint(&cam, x, y, 3, air_f, &S);
            const double got = img->pixels[px * img->channels + 1], sd = sqrt(var->pixels[px * var->channels + 1]);
            sum += got / want, sum2 += (got / want) * (got / want);
            worst_z = fmax(worst_z, fabs(got - want) / (sd + 1e-3 * want));
        }
    const double mean = sum / n, se = sqrt(fmax(0, sum2 / n - mean * mean) / (n - 1));
    printf("airlight: path / closed form over %d pixels %.5f +- %.5f (one standard error), worst pixel %.2f "
           "standard deviations\n", n, mean, se, worst_z);
    CHECK_MSG(fabs(mean - 1) <= 4 * se + 1e-3, "mean ratio %.5f, standard error %.5f", mean, se);
    CHECK_MSG(worst_z <= 5, "a pixel %.2f standard deviations off the closed form", worst_z);
    atmos_image_destroy(img);
    atmos_image_destroy(var);
}

/* The radiance of the plane y = 0 along d (0 if d misses it). */
static double plane_f(const double d[3], const void *u)
{
    const setup *S = u;
    if (!(d[1] < 0)) return 0;
    const double t = -S->eye[1] / d[1];
    const double P[3] = {S->eye[0] + t * d[0], 0, S->eye[2] + t * d[2]};
    const double w[3] = {S->lp[0] - P[0], S->lp[1] - P[1], S->lp[2] - P[2]};
    const double r2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], r = sqrt(r2);
    return S->albedo / ATMOS_PI * (w[1] / r) / r2 * exp(-S->sig_t * (r + t));
}

static void test_plane(void)
{
    atmos_scene s;
    path_scene(&s, 24, 16, 64, 1);
    const setup S = {{3, 10, 6}, {0.5, 5, -1}, 0.02, 0, 0.6};
    s.fog.enabled = 1, s.fog.extinction_per_m = S.sig_t, s.fog.scattering_per_m = 0;
    memcpy(s.camera.position, S.eye, sizeof S.eye);
    s.camera.look_at[0] = 0.5, s.camera.look_at[1] = 0, s.camera.look_at[2] = 0;
    s.camera.fov_deg = 30;
    memcpy(s.lights[0].position_m, S.lp, sizeof S.lp);
    s.object_count = 1;
    atmos_scene_object *o = &s.objects[0];
    memset(o, 0, sizeof *o);
    snprintf(o->mesh, sizeof o->mesh, "builtin:plane");
    o->scale[0] = o->scale[1] = o->scale[2] = 50;
    o->albedo[0] = o->albedo[1] = o->albedo[2] = S.albedo;
    atmos_image *var = NULL, *img = render(&s, &var);
    if (!img || !var) return;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
    double worst = 0, sum = 0, sum2 = 0;
    const int n = s.width * s.height;
    for (int y = 0; y < s.height; y++)
        for (int x = 0; x < s.width; x++) {
            const size_t px = (size_t)y * s.width + x;
            const double want = footprint(&cam, x, y, 16, plane_f, &S);
            const double got = img->pixels[px * img->channels + 1], sd = sqrt(var->pixels[px * var->channels + 1]);
            worst = fmax(worst, fabs(got - want) / (sd + 1e-4 * want));
            sum += got / want, sum2 += (got / want) * (got / want);
        }
    const double mean = sum / n, se = sqrt(fmax(0, sum2 / n - mean * mean) / (n - 1));
    printf("plane under a point light: path / closed form over %d pixels %.5f +- %.5f, worst pixel %.2f standard "
           "deviations (the pixels' noise: where in the pixel the rays go)\n", n, mean, se, worst);
    CHECK_MSG(fabs(mean - 1) <= 4 * se + 2e-4, "mean ratio %.5f, standard error %.5f", mean, se);
    CHECK_MSG(worst <= 5, "a pixel %.2f standard deviations off E = I cos / r^2 exp(-sigma r)", worst);
    atmos_image_destroy(img);
    atmos_image_destroy(var);
}

/* The beam renderer's image of s at k times the size, each k x k block averaged. */
static atmos_image *beams_footprint(const atmos_scene *base, int k)
{
    atmos_scene s = *base;
    s.renderer = ATMOS_RENDERER_BEAMS;
    s.width *= k, s.height *= k;
    atmos_image *big = render(&s, NULL), *out = NULL;
    if (!big) return NULL;
    CHECK_OK(atmos_image_create(ctx, base->width, base->height, big->channels, &out));
    const int C = big->channels;
    for (int y = 0; out && y < base->height; y++)
        for (int x = 0; x < base->width; x++)
            for (int c = 0; c < C; c++) {
                double v = 0;
                for (int j = 0; j < k; j++)
                    for (int i = 0; i < k; i++) v += big->pixels[((size_t)(y * k + j) * s.width + x * k + i) * C + c];
                out->pixels[((size_t)y * base->width + x) * C + c] = (float)(v / (k * k));
            }
    atmos_image_destroy(big);
    return out;
}

/* Fig. 4's scene at 60x90, single scattering, by the path tracer and the beam renderer
 * (4 x 4 rays a pixel): the mean relative difference over the lit pixels within a bound made
 * of the path tracer's measured noise; with all_orders, all orders add light to single
 * scattering. */
static void compare_fig04(const char *what, atmos_scene *s, int all_orders)
{
    s->width = 60, s->height = 90;
    s->renderer = ATMOS_RENDERER_PATH;
    s->path.spp = 256, s->path.max_depth = 1;
    atmos_image *var = NULL, *pt = render(s, &var), *bm = beams_footprint(s, 4);
    s->path.spp = 64, s->path.max_depth = 0;
    atmos_image *all = all_orders ? render(s, NULL) : NULL;
    if (!pt || !var || !bm || (all_orders && !all)) return;
    const int C = pt->channels, n = s->width * s->height;
    double top = 0;
    for (int i = 0; i < n; i++) top = fmax(top, bm->pixels[(size_t)i * C + 1]);
    double err = 0, noise = 0, single = 0, multi = 0;
    int lit = 0;
    for (int i = 0; i < n; i++) {
        const double b = bm->pixels[(size_t)i * C + 1], p = pt->pixels[(size_t)i * C + 1];
        single += p, multi += all ? all->pixels[(size_t)i * C + 1] : 0;
        if (!(b > 1e-3 * top)) continue;
        lit++;
        err += fabs(p - b) / b;
        noise += sqrt(var->pixels[(size_t)i * var->channels + 1]) / b;
    }
    err /= lit, noise /= lit;
    /* with the path tracer's noise alone the mean |error| would be sqrt(2 / pi) ~ 0.8 of its
     * mean relative standard deviation; the beam renderer may add its own 1 % (the
     * sub-planes' epsilon, the shadow map's texels, the table) */
    const double bound = 0.8 * noise * 1.25 + 0.01;
    printf("%s 60x90, single scattering: beams against the path tracer over %d lit pixels: mean relative "
           "difference %.4f (the path tracer's noise %.4f, bound %.4f); all orders / single %.3f\n", what, lit, err,
           noise, bound, multi / single);
    CHECK_MSG(err <= bound, "%s: beams vs path: %.4f > %.4f", what, err, bound);
    CHECK_MSG(!all_orders || multi > 1.02 * single, "%s: all orders %.4g, single %.4g", what, multi, single);
    atmos_image_destroy(pt), atmos_image_destroy(var), atmos_image_destroy(bm), atmos_image_destroy(all);
}

static void test_fig04(void)
{
    const char *src = getenv("ATMOS_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/dobashi_fig04_spotlight.json", src && *src ? src : ".");
    atmos_scene s;
    CHECK_OK(atmos_scene_load(ctx, path, &s));
    atmos_scene mie = s;
    compare_fig04("fig04", &s, 1);
    /* a fog of cloud droplets (Mie, forward-peaked): the beam renderer's table integrates the
     * tabulated phase function, the path tracer samples it; the droplets' side scattering is
     * weaker than the scene's g = 0.2, so the beam must come out dimmer seen from the side */
    mie.fog.extinction_per_m = 0.03, mie.fog.scattering_per_m = 0.03, mie.fog.g = 0;
    snprintf(mie.fog.particle, sizeof mie.fog.particle, "cloud");
    compare_fig04("fig04, Mie fog", &mie, 0); /* single scattering: a fog of albedo 1 has endless paths */
}

/* A scene the path tracer cannot yet trace with lights is refused with one message naming
 * every reason at once (not one per try), and the beam renderer's sun is never dropped
 * silently: a scene lit by it alone would come out black. */
static void test_refused(void)
{
    atmos_scene s;
    path_scene(&s, 8, 6, 1, 1);
    s.atmosphere.kind = ATMOS_ATMOSPHERE_RILEY;
    s.light_count = 0; /* the sun alone lights a fog thinning with height */
    s.fog.enabled = 1, s.fog.extinction_per_m = 0.05, s.fog.scattering_per_m = 0.04, s.fog.height_m = 100;
    s.beams.sun = 1;
    atmos_plan *plan = NULL;
    atmos_status st = atmos_plan_create(ctx, &s, NULL, NULL, &plan);
    const char *e = atmos_context_error(ctx);
    CHECK_MSG(st == ATMOS_E_INVALID_ARG && strstr(e, "background") && strstr(e, "/fog/height_m") && strstr(e, "/beams/sun"),
              "all three reasons in one error: %s", e);
    printf("refused: %s\n", e);
    atmos_plan_destroy(plan), plan = NULL;
    path_scene(&s, 8, 6, 1, 1); /* the sun alone is what the path tracer would leave out */
    s.beams.sun = 1;
    st = atmos_plan_create(ctx, &s, NULL, NULL, &plan);
    CHECK_MSG(st == ATMOS_E_INVALID_ARG && strstr(atmos_context_error(ctx), "/beams/sun") &&
                  !strstr(atmos_context_error(ctx), "background"),
              "beams/sun dropped: %s", atmos_context_error(ctx));
    atmos_plan_destroy(plan);
}

/* A spot's image (stained glass): a red window tints the light red in both renderers, through
 * the air and on the floor; a missing or corrupt file is an error naming it. */
static void test_image(void)
{
    char png[1024], bad[1024];
    test_tmp_path(png, sizeof png, "red_window.png");
    test_tmp_path(bad, sizeof bad, "corrupt_window.png");
    atmos_image *w = NULL;
    CHECK_OK(atmos_image_create(ctx, 4, 4, 3, &w));
    if (!w) return;
    for (int i = 0; i < 16; i++) w->pixels[3 * i] = 1;
    CHECK_OK(atmos_write_png(ctx, w, png, 8));
    atmos_image_destroy(w);
    FILE *f = fopen(bad, "wb");
    if (f) fputs("\x89PNG\r\n\x1a\nnot a png at all", f), fclose(f);
    for (int r = 0; r < 2; r++) {
        atmos_scene s;
        path_scene(&s, 12, 10, 16, 1);
        s.renderer = r ? ATMOS_RENDERER_BEAMS : ATMOS_RENDERER_PATH;
        s.fog.enabled = 1, s.fog.extinction_per_m = 0.05, s.fog.scattering_per_m = 0.04;
        atmos_scene_light *l = &s.lights[0];
        l->type = ATMOS_LIGHT_SPOT, l->position_m[1] = 6, l->cone_deg = 20, l->edge_deg = 2, l->range_m = 50;
        snprintf(l->image, sizeof l->image, "%s", png);
        s.camera.position[0] = 0, s.camera.position[1] = 3, s.camera.position[2] = 12;
        s.camera.look_at[0] = 0, s.camera.look_at[1] = 2, s.camera.look_at[2] = 0;
        s.object_count = 1;
        atmos_scene_object *o = &s.objects[0];
        memset(o, 0, sizeof *o);
        snprintf(o->mesh, sizeof o->mesh, "builtin:plane");
        o->scale[0] = o->scale[1] = o->scale[2] = 20;
        o->albedo[0] = o->albedo[1] = o->albedo[2] = 0.5;
        atmos_image *img = render(&s, NULL);
        if (img) {
            double sum[3] = {0, 0, 0};
            for (int i = 0; i < s.width * s.height; i++)
                for (int c = 0; c < 3; c++) sum[c] += img->pixels[(size_t)i * img->channels + c];
            printf("%s, a red window: r %.4g, g %.4g, b %.4g\n", r ? "beams" : "path", sum[0], sum[1], sum[2]);
            CHECK(sum[0] > 0 && sum[1] == 0 && sum[2] == 0);
            atmos_image_destroy(img);
        }
        /* the window on the second light: the error names its key and the file (a relative
         * one as relative to the current folder, where it was looked for) */
        s.light_count = 2, s.lights[1] = s.lights[0], s.lights[0].image[0] = 0;
        for (int k = 0; k < 2; k++) {
            snprintf(s.lights[1].image, sizeof s.lights[1].image, "%s", k ? bad : "no_such_window.png");
            atmos_plan *plan = NULL;
            const atmos_status st = atmos_plan_create(ctx, &s, NULL, NULL, &plan);
            const char *e = atmos_context_error(ctx);
            CHECK_MSG(st != ATMOS_OK && strstr(e, "/lights/1/image") && strstr(e, k ? bad : "no_such_window.png") &&
                          (k || strstr(e, "current folder")),
                      "%s", e);
            atmos_plan_destroy(plan);
        }
    }
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_airlight();
    test_plane();
    test_fig04();
    test_refused();
    test_image();
    atmos_context_destroy(ctx);
    return test_summary("test_path_lamps");
}
