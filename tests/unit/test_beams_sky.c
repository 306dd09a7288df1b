/* The sky's light on the beam renderer's surfaces (src/render/beams_sky.c, docs/beams.md
 * "The sky's light"): a flat Lambertian ground (a plane object of the atmosphere's ground
 * albedo) under the spherical sky model, seen from 2 m, against the model's own ground there
 * (the same scene without the object: the sky renderer's ground, albedo / pi times the
 * model's sky irradiance table, which the model integrates by its own quadrature from its
 * scattering, not from the radiance the beam renderer integrates). The sun is below the
 * horizon (-3 degrees: twilight, the sky alone), or 20 degrees up, its direct share
 * (albedo / pi times cos(zenith) times the atmosphere's sunlight there) taken off both.
 * Agreement within 3 % with the sun up (measured 0.1-0.2 %), 5 % in twilight (measured 2.7-3.0 %:
 * the model's radiance against its own irradiance table with the sun below the horizon; 96
 * rings of directions instead of 24 give the same ratios to 10^-4, so not the quadrature). */
#include "atmos/atmos.h"
#include "test.h"

static atmos_context *ctx;

/* The mean of each channel of the image of the scene (the sun's elevation, with or without the
 * plane) into mean[3]; sun_part[3]: cos(zenith) E_sun at the ground under the camera. */
static void mean_radiance(double sun_el, int plane, double *mean, double *sun_part)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 16, \"height\": 12},"
             " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 2, 0],"
             " \"view\": {\"elevation_deg\": -60, \"azimuth_deg\": 0}, \"fov_deg\": 30},"
             " \"sun\": {\"elevation_deg\": %g, \"azimuth_deg\": 90},"
             " \"atmosphere\": {\"model\": \"spherical\", \"ground_albedo\": 0.15},"
             " \"wavelengths\": {\"mode\": \"rgb\"}, \"renderer\": \"beams\", \"beams\": {\"sun\": true}%s}",
             sun_el,
             plane ? ", \"objects\": [{\"mesh\": \"builtin:plane\", \"position_m\": [0, 0, 0], \"scale\": 1000,"
                     " \"albedo\": 0.15}]"
                   : "");
    atmos_scene s;
    atmos_plan *plan = NULL;
    atmos_frame fr;
    atmos_image *img = NULL;
    for (int c = 0; c < 3; c++) mean[c] = -1, sun_part[c] = 0;
    CHECK_OK(atmos_scene_parse(ctx, json, strlen(json), "test", &s));
    atmos_status st = atmos_plan_create(ctx, &s, NULL, NULL, &plan);
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &s, &fr);
    if (st == ATMOS_OK) st = atmos_plan_image_create(plan, &fr, &img);
    if (st == ATMOS_OK) st = atmos_plan_render(plan, &fr, NULL, img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render: %s", atmos_context_error(ctx));
    if (st == ATMOS_OK) {
        const int n = img->width * img->height;
        for (int c = 0; c < 3; c++) {
            mean[c] = 0;
            for (int i = 0; i < n; i++) mean[c] += img->pixels[(size_t)i * img->channels + c] / n;
        }
        double d[3], E[3];
        atmos_direction_from_angles(sun_el, 90, d);
        const double g[3] = {0, 0, 0};
        atmos_atmosphere_sunlight(atmos_plan_atmosphere(plan), g, d, E);
        for (int c = 0; c < 3; c++) sun_part[c] = d[1] > 0 ? d[1] * E[c] : 0;
    }
    atmos_image_destroy(img);
    atmos_plan_destroy(plan);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    const double el[2] = {-3, 20};
    for (int i = 0; i < 2; i++) {
        double b[3], m[3], sp[3];
        mean_radiance(el[i], 1, b, sp);
        mean_radiance(el[i], 0, m, sp);
        for (int c = 0; c < 3; c++) {
            const double sun = 0.15 / 3.14159265358979323846 * sp[c];
            const double beams = b[c] - sun, model = m[c], want = model - sun;
            printf("sun at %g deg, channel %d: the ground's radiance from the sky, beam renderer %.5g, the model %.5g "
                   "(its ground %.5g less the sun's %.5g): ratio %.4f\n",
                   el[i], c, beams, want, model, sun, beams / want);
            CHECK_MSG(want > 0 && fabs(beams / want - 1) < (el[i] < 0 ? 0.05 : 0.03), "ratio %.4f", beams / want);
        }
    }
    atmos_context_destroy(ctx);
    return test_summary("test_beams_sky");
}
