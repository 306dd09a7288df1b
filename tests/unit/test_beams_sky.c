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

#include <math.h>

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

/* The mean of channel c of scene json's image into mean[3]; its plan's atmosphere's sky (the
 * radiance without the sun's disk, seen from the origin) dimmed by a fog layer of vertical
 * optical depth C, exp(-C / mu), on an upward surface of albedo 0.15 into want[3]: an
 * independent quadrature (96 x 192 directions against the table's 24 x 48), the table's
 * layers of C interpolated in the renderer. */
static void fog_case(const char *json, double C, double *mean, double *want)
{
    atmos_scene s;
    atmos_plan *plan = NULL;
    atmos_frame fr;
    atmos_image *img = NULL;
    for (int c = 0; c < 3; c++) mean[c] = want[c] = -1;
    atmos_status st = atmos_scene_parse(ctx, json, strlen(json), "test", &s);
    CHECK_MSG(st == ATMOS_OK, "scene: %s", atmos_context_error(ctx));
    if (st == ATMOS_OK) st = atmos_plan_create(ctx, &s, NULL, NULL, &plan);
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &s, &fr);
    if (st == ATMOS_OK) st = atmos_plan_image_create(plan, &fr, &img);
    if (st == ATMOS_OK) st = atmos_plan_render(plan, &fr, NULL, img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render: %s", atmos_context_error(ctx));
    if (st == ATMOS_OK) {
        const int n = img->width * img->height, MU = 96, PHI = 192;
        const atmos_atmosphere *atm = atmos_plan_atmosphere(plan);
        const double o[3] = {0, 0, 0};
        double sun[3], D[3];
        atmos_direction_from_angles(s.sun.elevation_deg, s.sun.azimuth_deg, sun);
        atmos_atmosphere_sun_radiance(atm, o, sun, D);
        for (int c = 0; c < 3; c++) {
            mean[c] = 0, want[c] = 0;
            for (int i = 0; i < n; i++) mean[c] += img->pixels[(size_t)i * img->channels + c] / n;
        }
        for (int i = 0; i < MU; i++)
            for (int j = 0; j < PHI; j++) {
                const double mu = (i + 0.5) / MU, phi = 2 * 3.14159265358979323846 * (j + 0.5) / PHI;
                const double d[3] = {sqrt(1 - mu * mu) * cos(phi), mu, sqrt(1 - mu * mu) * sin(phi)};
                double L[3];
                atmos_atmosphere_hit hit;
                atmos_atmosphere_radiance(atm, o, d, sun, L, &hit);
                for (int c = 0; c < 3; c++)
                    want[c] += (hit.in_sun_disk ? fmax(0.0, L[c] - D[c]) : L[c]) * mu * exp(-C / mu) * 2 *
                               3.14159265358979323846 / (MU * PHI) * 0.15 / 3.14159265358979323846;
            }
    }
    atmos_image_destroy(img);
    atmos_plan_destroy(plan);
}

/* The sky through the scene's fog, as the eye's sky behind is: a surface in a uniform fog (no
 * top: the sky is not seen through it) gets none of it (the renderer's sun 3 degrees below the
 * horizon, the twilight sky alone: black); in a height-dependent fog the sky dimmed by the
 * layer above the surface, exp(-C / mu). */
static void test_fog(void)
{
    const char *fmt =
        "{\"image\": {\"width\": 16, \"height\": 12},"
        " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, %g, 0],"
        " \"view\": {\"elevation_deg\": -60, \"azimuth_deg\": 0}, \"fov_deg\": 30},"
        " \"sun\": {\"elevation_deg\": -3, \"azimuth_deg\": 90},"
        " \"atmosphere\": {\"model\": \"spherical\", \"ground_albedo\": 0.15},"
        " \"wavelengths\": {\"mode\": \"rgb\"}, \"renderer\": \"beams\", \"beams\": {\"sun\": true}, %s,"
        " \"objects\": [{\"mesh\": \"builtin:plane\", \"position_m\": [0, 0, 0], \"scale\": 1000, \"albedo\": 0.15}]}";
    char json[1400];
    double m[3], w[3];
    snprintf(json, sizeof json, fmt, 2.0, "\"fog\": {\"extinction_per_m\": 0.01, \"scattering_per_m\": 0.009, \"g\": 0.2}");
    fog_case(json, 0, m, w);
    for (int c = 0; c < 3; c++) {
        printf("uniform fog, channel %d: the ground %.5g (the sky without the fog would give %.5g)\n", c, m[c], w[c]);
        CHECK_MSG(m[c] == 0 && w[c] > 0, "a surface in a uniform fog lit by the sky: %g", m[c]);
    }
    /* sigma 0.002 per m at the ground, H 500 m: C = 1; the eye 5 cm up (its fog: 1e-4 of optical depth) */
    snprintf(json, sizeof json, fmt, 0.05,
             "\"fog\": {\"extinction_per_m\": 0.002, \"scattering_per_m\": 0.0018, \"g\": 0.2, \"height_m\": 500}");
    fog_case(json, 1.0, m, w);
    for (int c = 0; c < 3; c++) {
        printf("height fog (C = 1), channel %d: the ground %.5g, the sky dimmed by exp(-C / mu) %.5g: ratio %.4f\n", c,
               m[c], w[c], m[c] / w[c]);
        CHECK_MSG(w[c] > 0 && fabs(m[c] / w[c] - 1) < 0.02, "ratio %.4f", m[c] / w[c]);
    }
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_fog();
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
