/* The sky every few pixels (atmos_frame.sky_step, src/render/sky_render.c; the viewer's frames,
 * docs/viewer.md) against the sky at every pixel from the same plan: within a stated bound at
 * every pixel and wavelength (the horizon, the sun's disk and its aureole in view), the same on
 * one thread and on two, and refused outside [0, 16]. */
#include "test.h"

#include "atmos/atmos.h"

#include <stdlib.h>
#include <string.h>

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

static atmos_image *render(atmos_context *ctx, const char *json, int step, double *worst, double *mean)
{
    atmos_scene s;
    atmos_plan *p = NULL;
    atmos_image *img = NULL, *ref = NULL;
    CHECK_OK(atmos_scene_parse(ctx, json, strlen(json), "sky step test", &s));
    CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &p));
    atmos_frame f;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    if (!p) return NULL;
    CHECK_OK(atmos_plan_image_create(p, &f, &ref));
    CHECK_OK(atmos_plan_image_create(p, &f, &img));
    CHECK_OK(atmos_plan_render(p, &f, NULL, ref, NULL));
    f.sky_step = step;
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
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
    f.sky_step = 17;
    CHECK(atmos_plan_render(p, &f, NULL, img, NULL) == ATMOS_E_INVALID_ARG);
    f.sky_step = step;
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    atmos_image_destroy(ref);
    atmos_plan_destroy(p);
    return img;
}

int main(void)
{
    /* the low sun in view over the horizon (Riley's sky and the round planet's), a view up */
    static const char *scenes[] = {
        "{\"image\": {\"width\": 320, \"height\": 180}, \"atmosphere\": {\"model\": \"riley\", \"ground_albedo\": 0.15},"
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 1200, 0], \"view\": {\"elevation_deg\": 4,"
        " \"azimuth_deg\": 140}, \"fov_deg\": 60}, \"sun\": {\"elevation_deg\": 8, \"azimuth_deg\": 150}}",
        "{\"image\": {\"width\": 320, \"height\": 180}, \"atmosphere\": {\"model\": \"riley\"},"
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 500, 0], \"view\": {\"elevation_deg\": 50,"
        " \"azimuth_deg\": 0}, \"fov_deg\": 70}, \"sun\": {\"elevation_deg\": 35, \"azimuth_deg\": 140}}",
        "{\"image\": {\"width\": 256, \"height\": 160}, \"atmosphere\": {\"model\": \"spherical\"},"
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 1500, 0], \"view\": {\"elevation_deg\": 2,"
        " \"azimuth_deg\": 200}, \"fov_deg\": 50}, \"sun\": {\"elevation_deg\": 4, \"azimuth_deg\": 210}}",
    };
    atmos_context *one = make_ctx(1), *two = make_ctx(2);
    for (int q = 0; q < 3; q++)
        for (int step = 2; step <= 8; step *= 2) {
            double w1, m1, w2, m2;
            atmos_image *a = render(one, scenes[q], step, &w1, &m1), *b = render(two, scenes[q], step, &w2, &m2);
            printf("scene %d step %d: largest relative difference %.3g, mean %.3g\n", q, step, w1, m1);
            CHECK_MSG(w1 <= 3e-3, "scene %d step %d: largest relative difference %g", q, step, w1);
            CHECK_MSG(m1 <= 3e-4, "scene %d step %d: mean relative difference %g", q, step, m1);
            CHECK(a && b && !memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)a->width * a->height * a->channels));
            atmos_image_destroy(a), atmos_image_destroy(b);
        }
    atmos_context_destroy(one), atmos_context_destroy(two);
    return test_summary("test_sky_step");
}
