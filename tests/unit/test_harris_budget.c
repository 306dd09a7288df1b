/* Harris's impostors made again within a frame's budget (atmos_frame.impostor_budget, the
 * viewer's frames): after the eye moves, a frame makes at most the budget's impostors, the
 * others are drawn as they were and caught up by the next frames; once caught up, the image is
 * the same, byte for byte, as that of a plan that made them all at once. */
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

/* The frame with the eye x metres east of the scene's camera, budget b. */
static atmos_frame frame(double x, int b)
{
    atmos_frame f;
    memset(&f, 0, sizeof f);
    const double eye[3] = {x, 1200, 16500};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, eye, &f.camera);
    f.camera.look_at[0] = x, f.camera.look_at[1] = 1200 + 1000 * 0.0699, f.camera.look_at[2] = 16500 - 1000;
    f.camera.fov_deg = 60;
    f.width = W, f.height = H, f.samples_per_pixel = 1, f.impostor_budget = b;
    atmos_direction_from_angles(35, 140, f.sun_dir);
    return f;
}

/* Renders frame(x, b) into img; returns the impostors made. */
static int render(atmos_plan *p, double x, int b, atmos_image *img)
{
    const atmos_frame f = frame(x, b);
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    atmos_plan_stats st;
    atmos_plan_get_stats(p, &st);
    return st.impostor_updates;
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
    /* the first frame makes every impostor in view, budget or not */
    const int first = render(all, 0, 0, a), first_held = render(held, 0, 2, b);
    printf("first frame: %d impostors made (budget 0), %d (budget 2)\n", first, first_held);
    CHECK(first > 2 && first_held == first);
    /* 60 m east: the near clouds' impostors go out of date */
    const int stale = render(all, 60, 0, a);
    int sum = 0, frames = 0, n;
    while ((n = render(held, 60, 2, b)) > 0 && frames < 100) {
        printf("budget 2, frame %d: %d made\n", frames, n);
        CHECK(n <= 2);
        sum += n, frames++;
    }
    printf("60 m east: %d stale impostors made at once; with a budget of 2, %d over %d frames\n", stale, sum, frames);
    CHECK(stale > 2);
    CHECK(sum == stale && frames == (stale + 1) / 2);
    CHECK(memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)W * H * (size_t)a->channels) == 0);
    CHECK(render(all, 60, 0, a) == 0);
    atmos_image_destroy(a), atmos_image_destroy(b);
    atmos_plan_destroy(all), atmos_plan_destroy(held);
    atmos_context_destroy(ctx);
    return test_summary("test_harris_budget");
}
