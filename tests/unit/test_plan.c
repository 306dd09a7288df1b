/* Plans and frames (plan.h): a frame rendered from a kept plan equals the same frame rendered
 * alone, whatever was rendered before (the caches do not leak between frames); regions equal
 * the whole frame's pixels and leave the rest alone; the path tracer's progressive samples
 * give the bytes of one render of the same total; the CLI writes atmos_render_scene's bytes;
 * what changed is reported; bad frames are refused. */
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static char cache_dir[4096];

/* The scene, with its volume (scene_json) and without (sky_json). */
#define SCENE_HEAD                                                                                                      \
    "{\"name\": \"plan test\", \"image\": {\"width\": 48, \"height\": 32},"                                             \
    " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 900, 0], \"look_at_m\": [0, 1500, -4000], \"fov_deg\": 40},"  \
    " \"sun\": {\"elevation_deg\": 30, \"azimuth_deg\": 160}"
static const char *sky_json = SCENE_HEAD "}";
static const char *scene_json =
    "{\"name\": \"plan test\", \"image\": {\"width\": 48, \"height\": 32},"
    " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 900, 0], \"look_at_m\": [0, 1500, -4000], \"fov_deg\": 40},"
    " \"particles\": {\"cloud\": {\"kind\": \"analytic\", \"lobes\": [{\"type\": \"hg\", \"g\": 0.8, \"weight\": 1}],"
    " \"sigma_ext_m2\": 2e-9, \"albedo\": 0.98}},"
    " \"volume\": {\"generate\": \"cumulus\", \"seed\": 3, \"scale\": 0.3, \"position_m\": [0, 1000, -4000]},"
    " \"sun\": {\"elevation_deg\": 30, \"azimuth_deg\": 160},"
    " \"slice\": {\"slices\": 48, \"light_size\": 64}, \"path\": {\"spp\": 4}, \"nishita\": {\"mc_cell\": 8},"
    " \"harris\": {\"max_particles\": 4000, \"sky_lights\": 2}}";

static atmos_context *make_ctx(int threads)
{
    return test_context(threads, cache_dir);
}

static void load_scene(atmos_context *ctx, atmos_renderer_kind r, atmos_scene *s)
{
    CHECK_OK(atmos_scene_parse(ctx, scene_json, strlen(scene_json), "plan test", s));
    s->renderer = r;
    if (r == ATMOS_RENDERER_SKY) s->volume.source[0] = '\0'; /* the sky renderer draws no volume */
}

static int same(const atmos_image *a, const atmos_image *b)
{
    return a && b && a->width == b->width && a->height == b->height && a->channels == b->channels &&
           !memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)a->width * a->height * a->channels);
}

/* A frame rendered from a fresh plan. */
static atmos_image *fresh(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v, const atmos_frame *f)
{
    atmos_plan *p = NULL;
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_create(ctx, s, v, NULL, &p));
    CHECK_OK(atmos_plan_image_create(p, f, &img));
    CHECK_OK(atmos_plan_render(p, f, NULL, img, NULL));
    atmos_plan_destroy(p);
    return img;
}

/* Frames A, B (camera moved), C (sun moved), A again from one plan: each equals itself from a
 * fresh plan; the plan reports what changed and reuses an unchanged frame. */
static void test_sequence(atmos_context *ctx, atmos_renderer_kind r, const atmos_volume *v)
{
    atmos_scene s;
    load_scene(ctx, r, &s);
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, v, NULL, &p));
    if (!p) exit(1);
    atmos_frame f[4];
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f[0]));
    f[1] = f[0], f[3] = f[0];
    atmos_frame_orbit(&f[1], p, 25);
    f[2] = f[1];
    atmos_direction_from_angles(12, 250, f[2].sun_dir);
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_image_create(p, &f[0], &img));
    const int cam[4] = {1, 1, 0, 1}, sun[4] = {1, 0, 1, 1};
    for (int i = 0; i < 4; i++) {
        CHECK_OK(atmos_plan_render(p, &f[i], NULL, img, NULL));
        atmos_plan_stats st;
        atmos_plan_get_stats(p, &st);
        CHECK_MSG(st.camera_changed == cam[i] && st.sun_changed == sun[i] && !st.reused,
                  "renderer %d frame %d: camera_changed %d sun_changed %d reused %d", (int)r, i, st.camera_changed,
                  st.sun_changed, st.reused);
        atmos_image *ref = fresh(ctx, &s, v, &f[i]);
        CHECK_MSG(same(img, ref), "renderer %d frame %d differs from a fresh plan's", (int)r, i);
        atmos_image_destroy(ref);
    }
    /* nothing changed: the kept image (the path tracer: the accumulator, no new samples) */
    atmos_image *again = NULL;
    CHECK_OK(atmos_plan_image_create(p, &f[3], &again));
    CHECK_OK(atmos_plan_render(p, &f[3], NULL, again, NULL));
    atmos_plan_stats st;
    atmos_plan_get_stats(p, &st);
    CHECK(same(img, again) && !st.camera_changed && !st.sun_changed);
    if (r != ATMOS_RENDERER_PATH) CHECK(st.reused);
    else CHECK(st.path.paths == 0);
    atmos_image_destroy(again);
    atmos_image_destroy(img);
    atmos_plan_destroy(p);
}

/* A frame with no_keep is not kept: the same frame next is rendered again (not copied), equal
 * to a fresh plan's, and kept; the one after it is copied. A frame that moved after a no_keep
 * one is rendered as always. */
static void test_no_keep(atmos_context *ctx, atmos_renderer_kind r, const atmos_volume *v)
{
    atmos_scene s;
    load_scene(ctx, r, &s);
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, v, NULL, &p));
    if (!p) exit(1);
    atmos_frame f, g;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    CHECK(f.no_keep == 0);
    g = f;
    atmos_frame_orbit(&g, p, 25);
    g.no_keep = 1;
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_image_create(p, &f, &img));
    atmos_plan_stats st;
    CHECK_OK(atmos_plan_render(p, &g, NULL, img, NULL)); /* moved, not kept */
    g.no_keep = 0;
    CHECK_OK(atmos_plan_render(p, &g, NULL, img, NULL)); /* the same view: rendered again */
    atmos_plan_get_stats(p, &st);
    CHECK_MSG(!st.reused && !st.camera_changed && !st.sun_changed, "renderer %d: a no_keep frame was kept (reused %d)",
              (int)r, st.reused);
    atmos_image *ref = fresh(ctx, &s, v, &g);
    CHECK_MSG(same(img, ref), "renderer %d: the frame after a no_keep one differs from a fresh plan's", (int)r);
    CHECK_OK(atmos_plan_render(p, &g, NULL, img, NULL)); /* now kept: copied */
    atmos_plan_get_stats(p, &st);
    CHECK_MSG(st.reused && same(img, ref), "renderer %d: the frame after the re-rendered one was not reused", (int)r);
    f.no_keep = 1;
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL)); /* moved back: rendered */
    atmos_plan_get_stats(p, &st);
    atmos_image_destroy(ref);
    ref = fresh(ctx, &s, v, &f);
    CHECK(!st.reused && st.camera_changed && same(img, ref));
    atmos_image_destroy(ref);
    atmos_image_destroy(img);
    atmos_plan_destroy(p);
}

/* A region of a frame: its pixels are the whole frame's, the others are left as they were. */
static void test_region(atmos_context *ctx, atmos_renderer_kind r, const atmos_volume *v, double eye_scale)
{
    atmos_scene s;
    load_scene(ctx, r, &s);
    atmos_frame f;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    f.eye_scale = eye_scale;
    atmos_image *whole = fresh(ctx, &s, v, &f), *part = NULL;
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, v, NULL, &p));
    CHECK_OK(atmos_plan_image_create(p, &f, &part));
    const size_t nv = (size_t)f.width * f.height * part->channels;
    for (size_t i = 0; i < nv; i++) part->pixels[i] = -7.0f;
    const atmos_region reg = {13, 9, 37, 23};
    CHECK_OK(atmos_plan_render(p, &f, &reg, part, NULL));
    int inside = 0, outside = 0;
    for (int y = 0; y < f.height; y++)
        for (int x = 0; x < f.width; x++)
            for (int c = 0; c < part->channels; c++) {
                const size_t i = ((size_t)y * f.width + x) * part->channels + c;
                const int in = x >= reg.x0 && x < reg.x1 && y >= reg.y0 && y < reg.y1;
                if (in) inside += part->pixels[i] != whole->pixels[i];
                else outside += part->pixels[i] != -7.0f;
            }
    CHECK_MSG(!inside && !outside, "renderer %d eye_scale %g: %d region values differ from the whole frame's, %d "
              "outside were written", (int)r, eye_scale, inside, outside);
    /* the rest of the frame afterwards: the image is the whole frame */
    CHECK_OK(atmos_plan_render(p, &f, NULL, part, NULL));
    CHECK_MSG(same(part, whole), "renderer %d: region then whole differs from whole", (int)r);
    atmos_image_destroy(part);
    atmos_image_destroy(whole);
    atmos_plan_destroy(p);
}

/* The path tracer's samples added in steps (1, then 3 more, then 2 more) give the bytes of 6
 * at once; a smaller budget starts again. */
static void test_progressive(atmos_context *ctx, const atmos_volume *v)
{
    atmos_scene s;
    load_scene(ctx, ATMOS_RENDERER_PATH, &s);
    atmos_frame f;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    f.spp = 6;
    atmos_image *once = fresh(ctx, &s, v, &f), *img = NULL;
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, v, NULL, &p));
    CHECK_OK(atmos_plan_image_create(p, &f, &img));
    const int steps[3] = {1, 4, 6};
    for (int i = 0; i < 3; i++) {
        f.spp = steps[i];
        CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
        atmos_plan_stats st;
        atmos_plan_get_stats(p, &st);
        CHECK(st.path.spp == steps[i] && st.path.paths == (long long)(steps[i] - (i ? steps[i - 1] : 0)) * 48 * 32);
    }
    CHECK_MSG(same(img, once), "6 samples in three steps differ from 6 at once");
    f.spp = 2;
    atmos_image *two = fresh(ctx, &s, v, &f);
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    CHECK_MSG(same(img, two), "a smaller budget after a larger one differs from that budget alone");
    atmos_image *var = NULL, *ord = NULL;
    CHECK_OK(atmos_plan_path_variance(p, &var));
    CHECK_OK(atmos_plan_path_order(p, &ord));
    CHECK(var && var->channels == 4 && ord && ord->channels == 1);
    atmos_image_destroy(var), atmos_image_destroy(ord);
    atmos_image_destroy(two), atmos_image_destroy(once), atmos_image_destroy(img);
    atmos_plan_destroy(p);
}

/* atmos render writes the bytes atmos_render_scene gives (through the same linear sRGB). */
static void test_cli_equals_library(atmos_context *ctx, atmos_renderer_kind r)
{
    const char *cli = getenv("ATMOS_CLI");
    if (!cli || !*cli) {
        printf("ATMOS_CLI not set: the CLI comparison is skipped\n");
        return;
    }
    static const char *const names[] = {"sky", "slice", "path"};
    char scene_path[4200], pfm[4200], cmd[13000];
    test_tmp_path(scene_path, sizeof scene_path, "plan_scene.json");
    test_tmp_path(pfm, sizeof pfm, "plan_cli.pfm");
    FILE *fp = fopen(scene_path, "w");
    CHECK(fp != NULL);
    if (!fp) return;
    fputs(r == ATMOS_RENDERER_SKY ? sky_json : scene_json, fp);
    fclose(fp);
    snprintf(cmd, sizeof cmd, "XDG_CACHE_HOME='%s/..' '%s' render '%s' --renderer %s --threads 2 -q --pfm '%s'",
             cache_dir, cli, scene_path, names[r], pfm);
    CHECK_MSG(system(cmd) == 0, "%s failed", cmd);
    atmos_scene s;
    CHECK_OK(atmos_scene_load(ctx, scene_path, &s));
    s.renderer = r;
    atmos_image *spec = NULL, *lin = NULL, *got = NULL;
    atmos_wavelengths wl;
    CHECK_OK(atmos_scene_wavelengths(ctx, &s, &wl));
    CHECK_OK(atmos_render_scene(ctx, &s, NULL, &spec, NULL));
    CHECK_OK(atmos_image_to_srgb(ctx, spec, &wl, &lin));
    CHECK_OK(atmos_read_pfm(ctx, pfm, &got));
    int diff = !got || !lin || got->width != lin->width || got->height != lin->height;
    for (size_t i = 0; !diff && i < (size_t)got->width * got->height; i++)
        for (int c = 0; c < 3; c++) diff += got->pixels[i * got->channels + c] != lin->pixels[i * 4 + c];
    CHECK_MSG(!diff, "renderer %s: the CLI's image differs from atmos_render_scene's in %d values", names[r], diff);
    atmos_image_destroy(spec), atmos_image_destroy(lin), atmos_image_destroy(got);
}

/* Orbiting keeps the distance to the volume's centre and comes back after 360 degrees. */
static void test_orbit(atmos_context *ctx, const atmos_volume *v)
{
    atmos_scene s;
    load_scene(ctx, ATMOS_RENDERER_SLICE, &s);
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, v, NULL, &p));
    atmos_frame f, g;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    double off[3], lo[3], hi[3], c[3];
    CHECK(atmos_plan_volume(p, off) == v);
    atmos_volume_bounds(v, lo, hi);
    for (int a = 0; a < 3; a++) c[a] = 0.5 * (lo[a] + hi[a]) + off[a];
    const double d0 = hypot(f.camera.position[0] - c[0], f.camera.position[2] - c[2]);
    g = f;
    atmos_frame_orbit(&g, p, 90);
    CHECK_NEAR(hypot(g.camera.position[0] - c[0], g.camera.position[2] - c[2]), d0, 1e-6 * d0);
    CHECK_NEAR(g.camera.position[1], f.camera.position[1], 1e-9);
    for (int i = 0; i < 3; i++) atmos_frame_orbit(&g, p, 90);
    for (int a = 0; a < 3; a++) CHECK_NEAR(g.camera.position[a], f.camera.position[a], 1e-6 * d0);
    atmos_plan_destroy(p);
}

static void test_bad_frames(atmos_context *ctx, const atmos_volume *v)
{
    atmos_scene s;
    load_scene(ctx, ATMOS_RENDERER_SLICE, &s);
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, v, NULL, &p));
    atmos_frame f;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    atmos_image *img = NULL, *small = NULL;
    CHECK_OK(atmos_plan_image_create(p, &f, &img));
    CHECK_OK(atmos_image_create(ctx, 8, 8, 4, &small));
    const atmos_region out_of = {0, 0, 49, 10}, empty = {5, 5, 5, 9};
    CHECK(atmos_plan_render(p, &f, &out_of, img, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_plan_render(p, &f, &empty, img, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_plan_render(p, &f, NULL, small, NULL) == ATMOS_E_INVALID_ARG);
    atmos_frame g = f;
    g.sun_dir[0] = g.sun_dir[1] = g.sun_dir[2] = 0;
    CHECK(atmos_plan_render(p, &g, NULL, img, NULL) == ATMOS_E_INVALID_ARG);
    g = f, g.slices = 9000;
    CHECK(atmos_plan_render(p, &g, NULL, img, NULL) == ATMOS_E_INVALID_ARG);
    g = f, g.camera.type = ATMOS_CAMERA_FISHEYE;
    CHECK(atmos_plan_render(p, &g, NULL, img, NULL) != ATMOS_OK);
    g = f, g.camera.fov_deg = 270;
    CHECK(atmos_plan_render(p, &g, NULL, img, NULL) == ATMOS_E_INVALID_ARG);
    atmos_image *no_var = NULL;
    CHECK(atmos_plan_path_variance(p, &no_var) == ATMOS_E_INVALID_ARG && !no_var);
    atmos_image_destroy(img);
    atmos_image_destroy(small);
    atmos_plan_destroy(p);
    /* a slice plan needs a volume; a scene naming none is refused */
    atmos_scene none = s;
    none.volume.source[0] = '\0';
    atmos_plan *q = NULL;
    CHECK(atmos_plan_create(ctx, &none, NULL, NULL, &q) == ATMOS_E_INVALID_ARG && !q);
    atmos_plan_destroy(NULL);
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "cache/atmos");
    setvbuf(stdout, NULL, _IONBF, 0);
    atmos_context *ctx = make_ctx(2);
    atmos_scene s;
    load_scene(ctx, ATMOS_RENDERER_SLICE, &s);
    atmos_volume *v = NULL;
    double off[3];
    CHECK_OK(atmos_scene_load_volume(ctx, &s, &v, off));
    for (int r = ATMOS_RENDERER_SKY; r <= ATMOS_RENDERER_PATH; r++) {
        test_sequence(ctx, (atmos_renderer_kind)r, v);
        test_region(ctx, (atmos_renderer_kind)r, v, 1.0);
        test_cli_equals_library(ctx, (atmos_renderer_kind)r);
    }
    test_no_keep(ctx, ATMOS_RENDERER_SKY, v);
    test_no_keep(ctx, ATMOS_RENDERER_SLICE, v);
    test_no_keep(ctx, ATMOS_RENDERER_HARRIS, v);
    test_region(ctx, ATMOS_RENDERER_SLICE, v, 0.6);
    test_progressive(ctx, v);
    test_orbit(ctx, v);
    test_bad_frames(ctx, v);
    atmos_volume_destroy(v);
    atmos_context_destroy(ctx);
    return test_summary("test_plan");
}
