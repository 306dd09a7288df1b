/* Harris's renderer with the particles' phase table past its size cap (particles/pphase.h,
 * docs/viewer.md): the plan makes no table and the eye pass looks Ams_n up exactly
 * (atmos__msphase_eval_all), so the plan still renders. Checked against the same scene with
 * the table: the two images agree within the table's stated error (mean 1e-4 of the mean
 * radiance, worst pixel 1e-2) but are not the same bytes (the cap did switch the path). */
#include "atmos/atmos.h"
#include "render/harris_internal.h"
#include "test.h"

#include <math.h>
#include <string.h>

enum { W = 96, H = 54 };

/* The scene's image (4 channels: rgb and alpha), NULL on failure. */
static atmos_image *render(atmos_context *ctx)
{
    atmos_image *img = NULL;
    static const char json[] =
        "{\"image\": {\"width\": 96, \"height\": 54}, \"renderer\": \"harris\", \"wavelengths\": {\"mode\": \"rgb\"},"
        "\"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 1650, 3000], \"look_at_m\": [0, 1650, 0],"
        " \"fov_deg\": 60}, \"sun\": {\"elevation_deg\": 40, \"azimuth_deg\": 150},"
        "\"atmosphere\": {\"model\": \"riley\", \"ground_albedo\": 0.15},"
        "\"volume\": {\"generate\": \"harris_cumulus\", \"seed\": 3, \"position_m\": [0, 1440, 0]},"
        "\"harris\": {\"sky_lights\": 2}}";
    atmos_scene s;
    CHECK_OK(atmos_scene_parse(ctx, json, strlen(json), "test", &s));
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, NULL, NULL, &p));
    atmos_frame f;
    CHECK_OK(atmos_frame_from_scene(ctx, &s, &f));
    if (p && atmos_plan_image_create(p, &f, &img) == ATMOS_OK) CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    atmos_plan_destroy(p);
    return img;
}

int main(void)
{
    atmos_context *ctx = test_context(2, NULL);
    atmos_image *tab = render(ctx);
    const size_t cap = atmos__harris_pphase_max_bytes;
    atmos__harris_pphase_max_bytes = 1000; /* far below rgb's 6.4 MB */
    atmos_image *exact = render(ctx);
    atmos__harris_pphase_max_bytes = cap;
    CHECK(tab && exact && tab->channels == 4 && exact->channels == 4);
    if (!tab || !exact || tab->channels != 4 || exact->channels != 4) return test_summary("test_harris_pphase_cap");
    double s = 0, ref = 0, mx = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        for (int k = 0; k < 3; k++) {
            const double d = fabs((double)exact->pixels[4 * i + k] - tab->pixels[4 * i + k]);
            s += d, ref += exact->pixels[4 * i + k], mx = d > mx ? d : mx;
        }
    const double mean = s / ref, worst = mx / (ref / (3.0 * W * H));
    printf("past the cap: mean difference %.2e, worst %.2e of the mean radiance %.3g\n", mean, worst, ref / (3.0 * W * H));
    CHECK(ref > 0);
    CHECK(mean < 1e-4 && worst < 1e-2);
    CHECK(memcmp(tab->pixels, exact->pixels, sizeof(float) * 4 * W * H) != 0);
    atmos_image_destroy(tab);
    atmos_image_destroy(exact);
    atmos_context_destroy(ctx);
    return test_summary("test_harris_pphase_cap");
}
