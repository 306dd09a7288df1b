/* Harris's impostors made within a frame's budget (atmos_frame.impostor_budget, the viewer's
 * frames): a frame makes at most the budget's impostors in full. Those never made before that
 * it leaves are made at a quarter of their resolution (the first frame, a view turned to clouds
 * not seen yet), the out-of-date ones are drawn as they were; the next frames make both in
 * full. Once caught up, the image is the same, byte for byte, as that of a plan that made them
 * all at once (those one a thread, a frame's two one after the other, each on both threads),
 * and as that of the same frames on one thread. A frame's remakes also keep within the
 * budget's units of texels: through a narrow lens, fewer than 2 a frame. */
#include "atmos/atmos.h"
#include "test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 160, H = 90 };

static atmos_plan *plan(atmos_context *ctx)
{
    const char *json =
        "{\"image\": {\"width\": 160, \"height\": 90}, \"renderer\": \"harris\", \"wavelengths\": {\"mode\": \"rgb\"},"
        "\"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 1200, 16500], \"view\": {\"elevation_deg\": 4,"
        " \"azimuth_deg\": 0}, \"fov_deg\": 60}, \"sun\": {\"elevation_deg\": 35, \"azimuth_deg\": 140},"
        "\"atmosphere\": {\"model\": \"riley\"},"
        "\"volume\": {\"generate\": \"harris_field\", \"seed\": 7, \"position_m\": [0, 1440, 0]},"
        "\"harris\": {\"sky_lights\": 0, \"impostors\": true, \"impostor_tolerance_deg\": 0.15}}";
    atmos_scene s;
    CHECK_OK(atmos_scene_parse(ctx, json, strlen(json), "test", &s));
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &p));
    return p;
}

static double fov = 60; /* the frames' field of view, degrees */

/* The frame with the eye x metres east of the scene's camera, budget b. */
static atmos_frame frame(double x, int b)
{
    atmos_frame f;
    memset(&f, 0, sizeof f);
    const double eye[3] = {x, 1200, 16500};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, eye, &f.camera);
    f.camera.look_at[0] = x, f.camera.look_at[1] = 1200 + 1000 * 0.0699, f.camera.look_at[2] = 16500 - 1000;
    f.camera.fov_deg = fov;
    f.width = W, f.height = H, f.samples_per_pixel = 1, f.impostor_budget = b;
    atmos_direction_from_angles(35, 140, f.sun_dir);
    return f;
}

static int coarse, kept_old; /* the last render's impostors made coarse, and held (drawn as they were) */

/* Renders frame(x, b) into img; returns the impostors made in full. */
static int render(atmos_plan *p, double x, int b, atmos_image *img)
{
    const atmos_frame f = frame(x, b);
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    atmos_plan_stats st;
    atmos_plan_get_stats(p, &st);
    coarse = st.impostors_coarse, kept_old = st.impostors_held;
    return st.impostor_updates;
}

static int spread; /* catch_up's frames that went on with a make spread over frames and began none */

/* Renders frame(x, 2) into img until a frame makes nothing and holds nothing (a large make
 * spread over frames holds its old impostor until it is done); each makes at most 2 in full
 * and none coarse. Returns the impostors made (a spread one counted in its first frame);
 * *frames the frames that made or held some. */
static int catch_up(atmos_plan *p, double x, atmos_image *img, int *frames)
{
    int sum = 0, n;
    *frames = spread = 0;
    while (((n = render(p, x, 2, img)) > 0 || kept_old > 0) && *frames < 100) {
        CHECK(n <= 2 && coarse == 0);
        sum += n, ++*frames, spread += n == 0;
    }
    return sum;
}

int main(void)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 2;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&d, &ctx));
    atmos_plan *all = plan(ctx), *held = plan(ctx);
    atmos_image *a = NULL, *b = NULL;
    const atmos_frame f0 = frame(0, 0);
    CHECK_OK(atmos_plan_image_create(all, &f0, &a));
    CHECK_OK(atmos_plan_image_create(held, &f0, &b));
    /* the first frame: every impostor in view made at once (budget 0); with a budget of 2, two
     * in full and the others coarse, then two a frame in full */
    const int first = render(all, 0, 0, a), first_held = render(held, 0, 2, b), first_coarse = coarse;
    printf("first frame: %d impostors made (budget 0); budget 2: %d in full, %d coarse\n", first, first_held,
           first_coarse);
    CHECK(first > 2 && first_held == 2 && first_coarse == first - 2);
    int frames, sum = catch_up(held, 0, b, &frames);
    printf("budget 2, still: %d made in full over %d more frames\n", sum, frames);
    /* (a far cloud's coarse impostor may already have all the texels it needs: 8) */
    CHECK(sum > 2 && sum <= first - 2 && frames == (sum + 1) / 2);
    CHECK(memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)W * H * (size_t)a->channels) == 0);
    /* 60 m east: the near clouds' impostors go out of date */
    const int stale = render(all, 60, 0, a);
    sum = catch_up(held, 60, b, &frames);
    printf("60 m east: %d stale impostors made at once; with a budget of 2, %d over %d frames\n", stale, sum, frames);
    CHECK(stale > 2);
    CHECK(sum == stale && frames == (stale + 1) / 2);
    CHECK(memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)W * H * (size_t)a->channels) == 0);
    CHECK(render(all, 60, 0, a) == 0);
    /* the same frames on one thread: the same bytes */
    d.threads = 1;
    atmos_context *ctx1 = NULL;
    CHECK_OK(atmos_context_create(&d, &ctx1));
    atmos_plan *one = plan(ctx1);
    atmos_image *c = NULL;
    CHECK_OK(atmos_plan_image_create(one, &f0, &c));
    CHECK(render(one, 0, 2, c) == 2);
    catch_up(one, 0, c, &frames);
    catch_up(one, 60, c, &frames);
    const int differ = memcmp(b->pixels, c->pixels, sizeof(float) * (size_t)W * H * (size_t)b->channels) != 0;
    printf("one thread against two, budget 2, 60 m east: %s\n", differ ? "differ" : "the same bytes");
    CHECK(!differ);
    /* through a 4 degree lens the clouds ahead need up to their particles' texels: a frame's
     * remakes keep within 2 units of 32 x 32 texels (a larger one alone, at twice the tolerance
     * or when nothing else is left), so the budget of 2 takes more frames than 2 a frame would,
     * and ends at the same image */
    fov = 4;
    const int tele = render(all, 60, 0, a);
    sum = catch_up(held, 60, b, &frames);
    printf("4 degree lens: %d impostors made at once; with a budget of 2, %d over %d frames\n", tele, sum, frames);
    CHECK(sum == tele && frames > (tele + 1) / 2);
    CHECK(memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)W * H * (size_t)a->channels) == 0);
    /* then 120 m further east: impostors of more than the 2 units go out of date by the angle
     * (their old ones as fine as the view needs) and are made over frames, a piece of their rows
     * a frame, the old one drawn meanwhile; the image ends the same, byte for byte (a make
     * spread over frames gives the same values as one made at once) */
    const int moved = render(all, 180, 0, a);
    sum = catch_up(held, 180, b, &frames);
    printf("4 degree lens, 180 m east: %d impostors made at once; with a budget of 2, %d over %d frames (%d going "
           "on with a make spread over frames)\n", moved, sum, frames, spread);
    CHECK(sum == moved && spread > 0);
    CHECK(memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)W * H * (size_t)a->channels) == 0);
    atmos_image_destroy(c), atmos_plan_destroy(one), atmos_context_destroy(ctx1);
    atmos_image_destroy(a), atmos_image_destroy(b);
    atmos_plan_destroy(all), atmos_plan_destroy(held);
    atmos_context_destroy(ctx);
    return test_summary("test_harris_budget");
}
