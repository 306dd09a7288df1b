/* The path tracer's Russian roulette by the lights' nearness in a fog that absorbs nothing
 * (src/render/path_lamps.c, docs/path.md "Lights, fog and objects"):
 *   - unbiased: a point light in a conservative fog (albedo 1) inside a black sphere of
 *     radius 10 mean free paths, all orders; the image's mean with the roulette against the
 *     estimator without it (which walks every path until the black wall takes it), within
 *     four combined standard errors of the two means, and the roulette makes far fewer
 *     scattering events;
 *   - the same image with --order: the scattering-order image is still written and its
 *     light-weighted mean order is near the one without the roulette (within 30 %: it has no
 *     variance to bound it by);
 *   - in an unbounded conservative fog the roulette ends the paths (none reaches the default
 *     depth limit), the image the same on one thread as on all, and without the roulette the
 *     render warns as soon as a path does, before the count at the end.
 */
#include "atmos/atmos.h"
#include "test.h"

static atmos_context *ctx;
static int told_early, told_end;

static void logger(void *user, atmos_log_level level, const char *msg)
{
    (void)user;
    if (level != ATMOS_LOG_WARN) return;
    if (strstr(msg, "the render goes on")) told_early++;
    if (strstr(msg, "paths (") && strstr(msg, "reached the default limit")) told_end++;
}

/* A point light (1 W sr^-1 nm^-1 per channel) in a conservative isotropic fog of sigma 1 m^-1,
 * seen from 2 m away; with radius > 0 inside a black sphere of that radius. */
static void fog_scene(atmos_scene *s, int w, int h, int spp, double radius, int roulette)
{
    atmos_scene_defaults(s);
    s->renderer = ATMOS_RENDERER_PATH;
    s->width = w, s->height = h;
    s->atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    s->atmosphere.background_radiance = 0;
    s->path.spp = spp, s->path.roulette = roulette;
    s->fog.enabled = 1, s->fog.extinction_per_m = 1, s->fog.scattering_per_m = 1, s->fog.g = 0;
    s->camera.position[0] = 0, s->camera.position[1] = 0, s->camera.position[2] = 2;
    s->camera.look_at[0] = s->camera.look_at[1] = s->camera.look_at[2] = 0;
    s->camera.fov_deg = 60;
    s->light_count = 1;
    atmos_scene_light *l = &s->lights[0];
    memset(l, 0, sizeof *l);
    l->type = ATMOS_LIGHT_POINT;
    l->intensity_w_sr = 400, l->colour[0] = l->colour[1] = l->colour[2] = 1;
    l->range_m = 100;
    l->position_m[0] = 0.3, l->position_m[1] = 0.2, l->position_m[2] = -0.4;
    l->direction[1] = -1;
    s->object_count = 0;
    if (radius > 0) {
        s->object_count = 1;
        atmos_scene_object *o = &s->objects[0];
        memset(o, 0, sizeof *o);
        snprintf(o->mesh, sizeof o->mesh, "builtin:sphere");
        o->scale[0] = o->scale[1] = o->scale[2] = radius;
    }
}

typedef struct {
    double mean, se, order, events_per_path;
    long long cut;
} result;

/* The image's mean green radiance with its standard error (from the pixels' variances), the
 * light-weighted mean of the order image, the events per path and the paths cut. */
static result render(const atmos_scene *s)
{
    result r = {0, 0, 0, 0, 0};
    atmos_plan *plan = NULL;
    atmos_frame fr;
    atmos_image *img = NULL, *var = NULL, *ord = NULL;
    atmos_plan_stats ps;
    atmos_status e = atmos_plan_create(ctx, s, NULL, NULL, &plan);
    if (e == ATMOS_OK) e = atmos_frame_from_scene(ctx, s, &fr);
    if (e == ATMOS_OK) e = atmos_plan_image_create(plan, &fr, &img);
    if (e == ATMOS_OK) e = atmos_plan_render(plan, &fr, NULL, img, NULL);
    if (e == ATMOS_OK) e = atmos_plan_path_variance(plan, &var);
    if (e == ATMOS_OK) e = atmos_plan_path_order(plan, &ord);
    CHECK_MSG(e == ATMOS_OK, "render: %s", atmos_context_error(ctx));
    if (e == ATMOS_OK) {
        atmos_plan_get_stats(plan, &ps);
        const atmos_path_stats st = ps.path;
        const int n = s->width * s->height;
        double v = 0, yo = 0, y = 0;
        for (int i = 0; i < n; i++) {
            const double g = img->pixels[(size_t)i * img->channels + 1];
            r.mean += g / n;
            v += var->pixels[(size_t)i * var->channels + 1];
            yo += g * ord->pixels[(size_t)i * ord->channels], y += g;
        }
        r.se = sqrt(v) / n;
        r.order = y > 0 ? yo / y : 0;
        r.events_per_path = (double)st.events / (double)(st.paths ? st.paths : 1);
        r.cut = st.cut_paths;
    }
    atmos_image_destroy(img), atmos_image_destroy(var), atmos_image_destroy(ord);
    atmos_plan_destroy(plan);
    return r;
}

static void test_unbiased(void)
{
    atmos_scene s;
    result r[2];
    for (int k = 0; k < 2; k++) {
        fog_scene(&s, 8, 6, k ? 256 : 128, 10, k);
        r[k] = render(&s);
        printf("conservative fog in a black sphere, roulette %s: mean %.6g +- %.2g, order %.3f, %.1f events/path\n",
               k ? "on " : "off", r[k].mean, r[k].se, r[k].order, r[k].events_per_path);
    }
    const double se = sqrt(r[0].se * r[0].se + r[1].se * r[1].se);
    CHECK_MSG(fabs(r[1].mean - r[0].mean) <= 4 * se, "means %.6g and %.6g differ by %.2f combined standard errors",
              r[1].mean, r[0].mean, fabs(r[1].mean - r[0].mean) / se);
    CHECK_MSG(r[1].events_per_path < 0.5 * r[0].events_per_path, "events per path %.1f with the roulette, %.1f without",
              r[1].events_per_path, r[0].events_per_path);
    /* the order image is noisier than the image (no variance to bound it by): the high orders
     * must be there (orders past 4 not cut) and the mean near the one without the roulette */
    CHECK_MSG(fabs(r[1].order - r[0].order) <= 0.3 * r[0].order && r[1].order > 8,
              "mean scattering order %.3f with the roulette, %.3f without", r[1].order, r[0].order);
}

static void test_unbounded(void)
{
    atmos_scene s;
    fog_scene(&s, 4, 3, 16, 0, 1);
    told_early = told_end = 0;
    result r = render(&s);
    /* the same bytes on one thread (the roulette draws from the path's own stream) */
    atmos_context *all = ctx, *one = NULL;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 1;
    CHECK_OK(atmos_context_create(&d, &one));
    ctx = one;
    const result r1 = render(&s);
    ctx = all;
    atmos_context_destroy(one);
    CHECK_MSG(r1.mean == r.mean && r1.order == r.order && r1.events_per_path == r.events_per_path,
              "one thread: mean %.9g, order %.9g; all: %.9g, %.9g", r1.mean, r1.order, r.mean, r.order);
    printf("unbounded conservative fog, roulette on: %.1f events/path, %lld paths cut\n", r.events_per_path, r.cut);
    CHECK(r.cut == 0 && told_early == 0 && told_end == 0);
    fog_scene(&s, 2, 1, 1, 0, 0);
    r = render(&s);
    printf("unbounded conservative fog, roulette off: %.1f events/path, %lld paths cut, warned early %d, at the end %d\n",
           r.events_per_path, r.cut, told_early, told_end);
    CHECK(r.cut > 0 && told_early == 1 && told_end == 1);
}

int main(void)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.log = logger;
    CHECK_OK(atmos_context_create(&d, &ctx));
    test_unbiased();
    test_unbounded();
    atmos_context_destroy(ctx);
    return test_summary("test_path_roulette");
}
