/* The sky-view table (atmos_frame.sky_table, src/render/sky_view.c; the viewer's frames,
 * docs/viewer.md) against the sky evaluated at every pixel by the same plan: within a stated
 * bound at every pixel and wavelength, for the cloud field's view, a low sun in view over the
 * horizon, views just above and below the horizon, a view down onto the ground and one up;
 * also after the eye rose by less than the height at which the table is made again (the
 * table then is the lower eye's). The same on one thread and on two. */
#include "test.h"

#include "atmos/atmos.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* the bound: relative to the pixel's value (or a thousandth of the image's mean, for the
 * darkest), the largest difference and the mean one over every pixel and wavelength */
#define WORST 1.5e-2
#define MEAN 1e-3

static atmos_context *make_ctx(int threads)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = threads;
    d.log = NULL;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&d, &ctx));
    return ctx;
}

static void compare(const atmos_image *img, const atmos_image *ref, double *worst, double *mean)
{
    const size_t npx = (size_t)img->width * img->height;
    const int C = img->channels;
    double sum = 0, ref_mean = 0;
    for (size_t i = 0; i < npx; i++) ref_mean += ref->pixels[i * C] / (double)npx;
    *worst = 0;
    for (size_t i = 0; i < npx; i++)
        for (int k = 0; k < C; k++) {
            const double a = img->pixels[i * C + k], b = ref->pixels[i * C + k];
            const double e = fabs(a - b) / fmax(fabs(b), 1e-3 * ref_mean);
            *worst = fmax(*worst, e), sum += e;
        }
    *mean = sum / (double)(npx * C);
}

/* The scene's frame from the table against the exact sky; rise > 0: the table made for the
 * scene's eye first, then the frame and the exact sky with the eye that much higher. */
static atmos_image *render(atmos_context *ctx, const char *json, double rise, int step, double *worst, double *mean)
{
    atmos_scene s;
    atmos_plan *p = NULL;
    atmos_image *img = NULL, *ref = NULL;
    CHECK_OK(atmos_scene_parse(ctx, json, strlen(json), "sky view test", &s));
    CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &p));
    atmos_frame f;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    if (!p) return NULL;
    CHECK_OK(atmos_plan_image_create(p, &f, &ref));
    CHECK_OK(atmos_plan_image_create(p, &f, &img));
    f.sky_table = 1, f.sky_step = step;
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    f.sky_table = 0, f.sky_step = 0;
    f.camera.position[1] += rise;
    CHECK_OK(atmos_plan_render(p, &f, NULL, ref, NULL));
    f.sky_table = 1, f.sky_step = step;
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    compare(img, ref, worst, mean);
    atmos_image_destroy(ref);
    atmos_plan_destroy(p);
    return img;
}

#define FIELD_SKY "\"atmosphere\": {\"model\": \"riley\", \"ground_albedo\": 0.15}, \"wavelengths\": {\"mode\": \"rgb\"},"

int main(void)
{
    static const char *scenes[] = {
        /* the cloud field's view (scenes/harris_cloud_field.json) without its clouds */
        "{\"image\": {\"width\": 320, \"height\": 180}, " FIELD_SKY
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 1200, 16500], \"view\": {\"elevation_deg\": 4,"
        " \"azimuth_deg\": 0}, \"fov_deg\": 60}, \"sun\": {\"elevation_deg\": 35, \"azimuth_deg\": 140}}",
        /* a low sun in view, the view straddling the horizon */
        "{\"image\": {\"width\": 320, \"height\": 180}, " FIELD_SKY
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 1200, 0], \"view\": {\"elevation_deg\": 1,"
        " \"azimuth_deg\": 145}, \"fov_deg\": 40}, \"sun\": {\"elevation_deg\": 2, \"azimuth_deg\": 150}}",
        /* the sun at 8 degrees behind, a narrow view just above and below the horizon */
        "{\"image\": {\"width\": 320, \"height\": 180}, \"atmosphere\": {\"model\": \"riley\"},"
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 2600, 0], \"view\": {\"elevation_deg\": 0,"
        " \"azimuth_deg\": 330}, \"fov_deg\": 10}, \"sun\": {\"elevation_deg\": 8, \"azimuth_deg\": 150}}",
        /* down onto the ground, and up past the sun */
        "{\"image\": {\"width\": 256, \"height\": 160}, " FIELD_SKY
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 2600, 0], \"view\": {\"elevation_deg\": -40,"
        " \"azimuth_deg\": 60}, \"fov_deg\": 70}, \"sun\": {\"elevation_deg\": 20, \"azimuth_deg\": 100}}",
        "{\"image\": {\"width\": 256, \"height\": 160}, " FIELD_SKY
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 500, 0], \"view\": {\"elevation_deg\": 55,"
        " \"azimuth_deg\": 0}, \"fov_deg\": 80}, \"sun\": {\"elevation_deg\": 60, \"azimuth_deg\": 20}}",
    };
    atmos_context *one = make_ctx(1), *two = make_ctx(2);
    for (int q = 0; q < 5; q++)
        for (int r = 0; r < 4; r++) {
            const double rise = r & 1 ? 0.9 * 4.0 : 0.0; /* below the height at which it is made again */
            const int step = r & 2 ? 4 : 1;                /* every pixel read, or the viewer's grid of 4 */
            double w1, m1, w2, m2;
            atmos_image *a = render(one, scenes[q], rise, step, &w1, &m1), *b = render(two, scenes[q], rise, step, &w2, &m2);
            printf("scene %d rise %g m step %d: largest relative difference %.3g, mean %.3g\n", q, rise, step, w1, m1);
            CHECK_MSG(w1 <= WORST, "scene %d rise %g: largest relative difference %g", q, rise, w1);
            CHECK_MSG(m1 <= MEAN, "scene %d rise %g: mean relative difference %g", q, rise, m1);
            CHECK_MSG(w1 > 0, "scene %d: the frame equals the exact sky: the table was not read", q);
            CHECK(a && b && !memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)a->width * a->height * a->channels));
            atmos_image_destroy(a), atmos_image_destroy(b);
        }
    atmos_context_destroy(one), atmos_context_destroy(two);
    return test_summary("test_sky_view");
}
