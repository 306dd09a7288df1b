/* The eye inside a cloud of Harris's renderer (Harris §3.1; atmos_frame.screen_layer_px, the
 * viewer's frames): the cloud is a screen-sized impostor at 1/4 resolution, its near particles
 * on request in coarser depth layers. Against an independent reference, the cloud splatted
 * particle by particle at the frame's full resolution (impostors off), along a short flight
 * inside the cumulus: the layered image (4 and 8 pixels) stays within a stated bound of it,
 * its mean difference within 1 % of the mean radiance of the 1/4 image's and its worst pixel
 * within the mean radiance; as the layers' pixel criterion grows the layered image converges
 * to the 1/4 one, and with none of the particles in a layer it is that image byte for byte; it
 * does not depend on the thread count. */
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 320, H = 180, STOPS = 3 };

/* The flight of bench/viewer/inside_cumulus.json: eye and look-at at its keyframes. */
static const double EYE[STOPS][3] = {{0, 1650, 250}, {0, 1700, 0}, {100, 1650, -250}};
static const double AT[STOPS][3] = {{0, 1650, -2000}, {2000, 1750, 0}, {0, 1600, -2000}};

static atmos_plan *plan(atmos_context *ctx, int impostors)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d}, \"renderer\": \"harris\", \"wavelengths\": {\"mode\": \"rgb\"},"
             "\"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 1650, 250], \"look_at_m\": [0, 1650, -2000],"
             " \"fov_deg\": 60}, \"sun\": {\"elevation_deg\": 40, \"azimuth_deg\": 150},"
             "\"atmosphere\": {\"model\": \"riley\", \"ground_albedo\": 0.15},"
             "\"volume\": {\"generate\": \"harris_cumulus\", \"seed\": 3, \"position_m\": [0, 1440, 0]},"
             "\"harris\": {\"sky_lights\": 0, \"impostors\": %s}}",
             W, H, impostors ? "true" : "false");
    atmos_scene s;
    CHECK_OK(atmos_scene_parse(ctx, json, strlen(json), "test", &s));
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &p));
    return p;
}

static atmos_frame frame(int stop, double px)
{
    atmos_frame f;
    memset(&f, 0, sizeof f);
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, EYE[stop], &f.camera);
    memcpy(f.camera.look_at, AT[stop], sizeof f.camera.look_at);
    f.camera.fov_deg = 60;
    f.width = W, f.height = H, f.samples_per_pixel = 1, f.screen_layer_px = px;
    atmos_direction_from_angles(40, 150, f.sun_dir);
    return f;
}

static void render(atmos_plan *p, int stop, double px, atmos_image *img)
{
    const atmos_frame f = frame(stop, px);
    CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
}

/* The mean and largest difference of a from b over the radiance channels, relative to b's mean. */
static void diff(const atmos_image *a, const atmos_image *b, double *mean, double *worst)
{
    const int C = a->channels;
    double s = 0, ref = 0, mx = 0;
    size_t n = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        for (int k = 0; k < C - 1; k++, n++) {
            const double d = fabs((double)a->pixels[i * C + k] - b->pixels[i * C + k]);
            s += d, ref += b->pixels[i * C + k], mx = d > mx ? d : mx;
        }
    *mean = s / ref, *worst = mx / (ref / (double)n);
}

static int same(const atmos_image *a, const atmos_image *b)
{
    return !memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)W * H * (size_t)a->channels);
}

int main(void)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 2;
    atmos_context *ctx = NULL, *one = NULL;
    CHECK_OK(atmos_context_create(&d, &ctx));
    d.threads = 1;
    CHECK_OK(atmos_context_create(&d, &one));
    atmos_plan *imp = plan(ctx, 1), *direct = plan(ctx, 0), *imp1 = plan(one, 1);
    const atmos_frame f0 = frame(0, 0);
    atmos_image *ref = NULL, *quarter = NULL, *lay = NULL, *tmp = NULL;
    CHECK_OK(atmos_plan_image_create(imp, &f0, &ref));
    CHECK_OK(atmos_plan_image_create(imp, &f0, &quarter));
    CHECK_OK(atmos_plan_image_create(imp, &f0, &lay));
    CHECK_OK(atmos_plan_image_create(imp, &f0, &tmp));
    const double pxs[] = {4, 8, 16, 64};
    double worst_lay = 0;
    for (int stop = 0; stop < STOPS; stop++) {
        render(direct, stop, 0, ref);
        render(imp, stop, 0, quarter);
        double mq, wq;
        diff(quarter, ref, &mq, &wq);
        printf("stop %d: 1/4 against full-resolution splats: mean %.4f, worst %.3f (of the mean)\n", stop, mq, wq);
        double conv[4];
        for (int j = 0; j < 4; j++) {
            render(imp, stop, pxs[j], lay);
            double ml, wl, mc, wc;
            diff(lay, ref, &ml, &wl);
            diff(lay, quarter, &mc, &wc);
            conv[j] = mc;
            printf("  layers at %2.0f px: against full resolution mean %.4f, worst %.3f; against 1/4 mean %.4f, worst %.3f\n",
                   pxs[j], ml, wl, mc, wc);
            if (pxs[j] <= 8) { /* the viewer's 4 and 8 */
                /* the layers are used (the image differs from the 1/4 one) and stay near the reference */
                CHECK(mc > 0);
                CHECK(ml <= mq + 0.01);
                worst_lay = wl > worst_lay ? wl : worst_lay;
                /* thread-count independence */
                render(imp1, stop, pxs[j], tmp);
                CHECK(same(tmp, lay));
            }
        }
        /* converging to the 1/4 image as the criterion grows */
        CHECK(conv[0] > conv[1] && conv[1] > conv[2] && conv[2] >= conv[3]);
        /* a criterion no particle meets: no layer, the 1/4 image byte for byte */
        render(imp, stop, 1000, lay);
        CHECK(same(lay, quarter));
    }
    printf("layers at 4 and 8 px: worst pixel %.3f of the mean from the full-resolution splats\n", worst_lay);
    CHECK(worst_lay < 1.0);
    /* bad values refused */
    atmos_frame bad = frame(0, 0.5);
    CHECK(atmos_plan_render(imp, &bad, NULL, lay, NULL) == ATMOS_E_INVALID_ARG);
    bad.screen_layer_px = -1;
    CHECK(atmos_plan_render(imp, &bad, NULL, lay, NULL) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(ref), atmos_image_destroy(quarter), atmos_image_destroy(lay), atmos_image_destroy(tmp);
    atmos_plan_destroy(imp), atmos_plan_destroy(direct), atmos_plan_destroy(imp1);
    atmos_context_destroy(ctx), atmos_context_destroy(one);
    return test_summary("test_harris_inside");
}
