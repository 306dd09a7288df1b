/* Riley's sky at the edges of its valid ranges: an eye far above the air (up to 1e4
 * scale heights), a sun disk of 1e-6 degrees (both gave NaN images with exit status 0), a
 * sun grazing the horizon over a thin atmosphere (negative radiance) or a thick homogeneous
 * layer (NaN);
 * here they are checked against physics that does not depend on the evaluator. */
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>

static atmos_context *make_ctx(void)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 2;
    d.log = NULL;
    atmos_context *ctx = NULL;
    atmos_context_create(&d, &ctx);
    return ctx;
}

/* An equirectangular sky (every direction, up and down) from altitude y. */
static atmos_image *render_from(atmos_context *ctx, double scale_height, double y)
{
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.atmosphere.scale_height_m = scale_height;
    s.atmosphere.hide_sun_disk = 1;
    s.atmosphere.ground_albedo = 0.3;
    s.width = 32;
    s.height = 16;
    const double pos[3] = {0, y, 0};
    atmos_camera_defaults(ATMOS_CAMERA_EQUIRECT, pos, &s.camera);
    atmos_image *img = NULL;
    atmos_status st = atmos_render_sky(ctx, &s, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render from %g m (H %g m) failed: %s", y, scale_height, atmos_context_error(ctx));
    return img;
}

/* Above ~40 scale heights the air adds nothing (e^-40 of its column): the sky seen from
 * 40 H and from far higher must be the same image, finite everywhere. */
static void test_high_eye(atmos_context *ctx, double H, double y_high)
{
    atmos_image *lo = render_from(ctx, H, 40.0 * H), *hi = render_from(ctx, H, y_high);
    if (!lo || !hi) goto done;
    const int n = lo->channels * lo->width * lo->height;
    double peak = 0, max_err = 0;
    int nonfinite = 0;
    for (int i = 0; i < n; i++) peak = fmax(peak, fabs(lo->pixels[i]));
    for (int i = 0; i < n; i++) {
        if (!isfinite(hi->pixels[i])) {
            nonfinite++;
            continue;
        }
        double e = fabs(hi->pixels[i] - lo->pixels[i]) / (fabs(lo->pixels[i]) + 1e-6 * peak);
        if (e > max_err) max_err = e;
    }
    printf("H %g m, eye %g m (%g H): %d non-finite values, max relative difference to 40 H %.3e\n", H, y_high,
           y_high / H, nonfinite, max_err);
    CHECK(nonfinite == 0);
    CHECK(peak > 0);
    CHECK(max_err < 1e-3);
done:
    atmos_image_destroy(lo);
    atmos_image_destroy(hi);
}

/* Straight down from far above, the transmittance is that of the whole column,
 * exp(-beta_sl H), independently of the eye's altitude. */
static void test_column_transmittance(double H, double y)
{
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.scale_height_m = H;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *sky = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, &wl, &sky));
    if (!sky) return;
    const double eye[3] = {0, y, 0}, down[3] = {0, -1, 0};
    double T[ATMOS_MAX_WAVELENGTHS], T0[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_transmittance(sky, eye, down, y, T);
    const double ground[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    atmos_atmosphere_transmittance(sky, ground, up, INFINITY, T0); /* the column from below */
    for (int k = 0; k < wl.count; k++) CHECK_MSG(isfinite(T[k]) && fabs(T[k] - T0[k]) < 1e-9 * T0[k] + 1e-12,
                                                 "H %g eye %g: T %.9g, column %.9g", H, y, T[k], T0[k]);
    atmos_atmosphere_destroy(sky);
}

/* A sun disk of 1e-6 degrees: the solid angle pi r^2 (not 0, which 2 pi (1 - cos r) gives),
 * and a sky render around the sun without NaN. */
static void test_tiny_sun(atmos_context *ctx)
{
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.sun_diameter_deg = 1e-6;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *sky = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, &wl, &sky));
    const double r = 0.5e-6 * 3.14159265358979323846 / 180.0;
    if (sky) CHECK_REL(atmos_atmosphere_sun_solid_angle(sky), 3.14159265358979323846 * r * r, 1e-9);
    atmos_atmosphere_destroy(sky);

    atmos_scene s;
    atmos_scene_defaults(&s);
    s.atmosphere.sun_diameter_deg = 1e-6;
    s.width = 24;
    s.height = 16;
    double sun[3];
    CHECK_OK(atmos_scene_sun_direction(ctx, &s, sun, NULL, NULL));
    for (int k = 0; k < 3; k++) s.camera.look_at[k] = s.camera.position[k] + sun[k];
    atmos_image *img = NULL;
    atmos_status st = atmos_render_sky(ctx, &s, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "tiny sun render failed: %s", atmos_context_error(ctx));
    if (img) {
        int bad = 0;
        for (int i = 0; i < img->channels * img->width * img->height; i++) bad += !isfinite(img->pixels[i]);
        printf("sun diameter 1e-6 deg: %d non-finite values\n", bad);
        CHECK(bad == 0);
    }
    atmos_image_destroy(img);
}

/* The sun 0.001 degrees above the horizon through a 375 m scale height: the sun's optical
 * depth at the eye, ~165 at 440 nm, underflows e^{-ts0} in float, and the in-scatter
 * difference (e^{-ts0} - e^{-(tau_v + tau_s)}) came out a tiny negative in every pixel. */
static void test_grazing_sun(atmos_context *ctx)
{
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.atmosphere.scale_height_m = 375.0;
    s.atmosphere.beta_sl_550 = 3.18e-6;
    s.atmosphere.ground_albedo = 0.6;
    s.sun.elevation_deg = 0.001;
    s.sun.azimuth_deg = 112.5;
    s.width = 16, s.height = 12;
    const double pos[3] = {0, 4.9, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s.camera);
    atmos_direction_from_angles(-77.8, 146.3, s.camera.look_at);
    for (int k = 0; k < 3; k++) s.camera.look_at[k] += pos[k];
    atmos_image *img = NULL;
    atmos_status st = atmos_render_sky(ctx, &s, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "grazing sun render failed: %s", atmos_context_error(ctx));
    if (!img) return;
    int neg = 0;
    for (int i = 0; i < img->channels * img->width * img->height; i++) neg += !(img->pixels[i] >= 0.0f);
    printf("sun at 0.001 degrees, 375 m scale height: %d negative or non-finite values\n", neg);
    CHECK(neg == 0);
    atmos_image_destroy(img);
}

/* A thick homogeneous layer (optical depth 35) with the sun 0.001 degrees high, seen from
 * inside it: along steep upward views the sun's depth at the segment's start underflows
 * while the in-scatter integral overflows; every upward pixel was NaN (found by the sweep,
 * scene 915). */
static void test_thick_layer(atmos_context *ctx)
{
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.atmosphere.kind = ATMOS_ATMOSPHERE_HOMOGENEOUS;
    s.atmosphere.thickness_m = 157000.0;
    s.atmosphere.beta_sl_550 = 2.2e-4;
    s.sun.elevation_deg = 0.001;
    s.sun.azimuth_deg = 103.0;
    s.width = 32, s.height = 16;
    const double pos[3] = {0, 49600.0, 0};
    atmos_camera_defaults(ATMOS_CAMERA_EQUIRECT, pos, &s.camera);
    atmos_image *img = NULL;
    atmos_status st = atmos_render_sky(ctx, &s, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "thick layer render failed: %s", atmos_context_error(ctx));
    if (!img) return;
    int bad = 0;
    for (int i = 0; i < img->channels * img->width * img->height; i++) bad += !(img->pixels[i] >= 0.0f && isfinite(img->pixels[i]));
    printf("homogeneous layer of optical depth 35, sun at 0.001 degrees: %d negative or non-finite values\n", bad);
    CHECK(bad == 0);
    atmos_image_destroy(img);
}

int main(void)
{
    atmos_context *ctx = make_ctx();
    test_high_eye(ctx, 8000.0, 700000.0);  /* the issue's --altitude 700000 */
    test_high_eye(ctx, 100.0, 10000.0);    /* scale_height_m 100, eye at 10 km */
    test_high_eye(ctx, 100.0, 1e6);        /* both ranges' extremes: 1e4 scale heights */
    test_column_transmittance(8000.0, 700000.0);
    test_column_transmittance(100.0, 1e6);
    test_tiny_sun(ctx);
    test_grazing_sun(ctx);
    test_thick_layer(ctx);
    atmos_context_destroy(ctx);
    return test_summary("test_sky_extremes");
}
