/* The sky renderer: agreement with the library's per-ray model, thread-count
 * independence, the sun disk's energy, coverage, cancellation. */
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>

static atmos_context *make_ctx(int threads)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = threads;
    d.log = NULL;
    atmos_context *ctx = NULL;
    atmos_context_create(&d, &ctx);
    return ctx;
}

static atmos_image *render(atmos_context *ctx, const atmos_scene *s)
{
    atmos_image *img = NULL;
    atmos_status st = atmos_render_sky(ctx, s, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render failed: %s", atmos_context_error(ctx));
    return img;
}

static void test_matches_model(atmos_atmosphere_kind kind)
{
    atmos_context *ctx = make_ctx(2);
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.atmosphere.kind = kind;
    s.atmosphere.thickness_m = 2000;
    s.width = 96;
    s.height = 64;
    s.atmosphere.hide_sun_disk = 1;
    s.atmosphere.ground_albedo = 0.3;
    const atmos_camera_type types[3] = {ATMOS_CAMERA_PINHOLE, ATMOS_CAMERA_FISHEYE, ATMOS_CAMERA_EQUIRECT};
    for (int t = 0; t < 3; t++) {
        double pos[3] = {0, 500, 0};
        atmos_camera_defaults(types[t], pos, &s.camera);
        if (types[t] == ATMOS_CAMERA_PINHOLE) {
            atmos_direction_from_angles(-5, 230, s.camera.look_at);
            for (int k = 0; k < 3; k++) s.camera.look_at[k] += pos[k];
        }
        for (int spectral = 0; spectral < 2; spectral++) {
            s.wavelengths = spectral ? ATMOS_WAVELENGTHS_SPECTRAL : ATMOS_WAVELENGTHS_RGB;
            s.spectral_samples = 7;
            atmos_image *img = render(ctx, &s);
            if (!img) continue;
            atmos_wavelengths wl;
            atmos_scene_wavelengths(ctx, &s, &wl);
            atmos_atmosphere_desc ad = s.atmosphere;
            atmos_atmosphere *sky = NULL;
            CHECK_OK(atmos_atmosphere_create(ctx, &ad, &wl, &sky));
            atmos_camera cam;
            CHECK_OK(atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam));
            double sun[3];
            CHECK_OK(atmos_scene_sun_direction(ctx, &s, sun, NULL, NULL));
            double L[ATMOS_MAX_WAVELENGTHS], d[3], max_err = 0;
            int outside = 0, bad_alpha = 0;
            CHECK(img->channels == wl.count + 1);
            for (int y = 0; y < s.height; y++)
                for (int x = 0; x < s.width; x++) {
                    const float *px = img->pixels + ((size_t)y * s.width + x) * img->channels;
                    if (!atmos_camera_ray(&cam, x + 0.5, y + 0.5, d)) {
                        outside++;
                        if (px[wl.count] != 0.0f) bad_alpha++;
                        continue;
                    }
                    if (px[wl.count] != 1.0f) bad_alpha++;
                    atmos_atmosphere_radiance(sky, cam.position, d, sun, L, NULL);
                    for (int k = 0; k < wl.count; k++) {
                        double e = fabs(px[k] - L[k]) / fmax(L[k], 1e-6);
                        if (e > max_err) max_err = e;
                    }
                }
            CHECK_MSG(max_err < 1e-3, "camera %d spectral %d: renderer vs model max rel err %.3g", t, spectral, max_err);
            CHECK(bad_alpha == 0);
            if (types[t] == ATMOS_CAMERA_FISHEYE) CHECK(outside > 0);
            else CHECK(outside == 0);
            atmos_atmosphere_destroy(sky);
            atmos_image_destroy(img);
        }
    }
    atmos_context_destroy(ctx);
}

static void test_threads_identical(void)
{
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.width = 200;
    s.height = 150;
    s.samples_per_pixel = 3;
    s.wavelengths = ATMOS_WAVELENGTHS_SPECTRAL;
    s.spectral_samples = 5;
    /* the sun in view, so the disk's supersampling is exercised too */
    double pos[3] = {0, 2, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s.camera);
    s.sun.from_time = 0;
    s.sun.elevation_deg = 8;
    s.sun.azimuth_deg = 0;
    atmos_direction_from_angles(6, 2, s.camera.look_at);
    for (int k = 0; k < 3; k++) s.camera.look_at[k] += pos[k];
    s.camera.fov_deg = 10;
    atmos_context *c1 = make_ctx(1), *c2 = make_ctx(2), *c3 = make_ctx(3);
    atmos_image *a = render(c1, &s), *b = render(c2, &s), *c = render(c3, &s);
    if (a && b && c) {
        size_t n = (size_t)a->width * a->height * a->channels * sizeof(float);
        CHECK(memcmp(a->pixels, b->pixels, n) == 0);
        CHECK(memcmp(a->pixels, c->pixels, n) == 0);
    }
    atmos_image_destroy(a);
    atmos_image_destroy(b);
    atmos_image_destroy(c);
    atmos_context_destroy(c1);
    atmos_context_destroy(c2);
    atmos_context_destroy(c3);
}

/* The disk's total flux in the image (radiance above the surrounding sky times
 * each pixel's solid angle) must equal the attenuated solar irradiance: the
 * antialiasing neither loses nor adds energy. */
static void test_sun_disk_energy(void)
{
    atmos_context *ctx = make_ctx(2);
    atmos_scene s, s_nodisk;
    atmos_scene_defaults(&s);
    s.width = s.height = 64;
    double pos[3] = {0, 100, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s.camera);
    s.sun.from_time = 0;
    s.sun.elevation_deg = 30;
    s.sun.azimuth_deg = 123;
    double sun[3];
    atmos_direction_from_angles(30.02, 123.03, sun); /* slightly off-centre */
    for (int k = 0; k < 3; k++) s.camera.look_at[k] = pos[k] + sun[k];
    s.camera.fov_deg = 1.5;
    s_nodisk = s;
    s_nodisk.atmosphere.hide_sun_disk = 1;
    atmos_image *a = render(ctx, &s), *b = render(ctx, &s_nodisk);
    if (a && b) {
        atmos_camera cam;
        atmos_camera_init(ctx, &s.camera, s.width, s.height, &cam);
        double flux[3] = {0, 0, 0};
        for (int y = 0; y < s.height; y++)
            for (int x = 0; x < s.width; x++) {
                /* pixel solid angle of a pinhole: (2 tan(fov/2)/H)^2 cos^3(off-axis angle) */
                double d[3];
                atmos_camera_ray(&cam, x + 0.5, y + 0.5, d);
                double ct = d[0] * cam.forward[0] + d[1] * cam.forward[1] + d[2] * cam.forward[2];
                double pix = pow(2 * cam.tan_half_fov / s.height, 2) * ct * ct * ct;
                const float *pa = a->pixels + ((size_t)y * s.width + x) * 4, *pb = b->pixels + ((size_t)y * s.width + x) * 4;
                for (int k = 0; k < 3; k++) flux[k] += (pa[k] - pb[k]) * pix;
            }
        atmos_wavelengths wl;
        atmos_wavelengths_rgb(&wl);
        atmos_atmosphere *sky = NULL;
        atmos_atmosphere_create(ctx, &s.atmosphere, &wl, &sky);
        double E[3], sdir[3];
        const double at[3] = {0, 100, 0};
        atmos_direction_from_angles(30, 123, sdir);
        atmos_atmosphere_sunlight(sky, at, sdir, E);
        for (int k = 0; k < 3; k++) CHECK_REL(flux[k], E[k], 0.01);
        atmos_atmosphere_destroy(sky);
    }
    atmos_image_destroy(a);
    atmos_image_destroy(b);
    atmos_context_destroy(ctx);
}

static int cancel_at_half(void *user, const char *stage, double f)
{
    (void)stage;
    (*(int *)user)++;
    return f >= 0.5;
}

static void test_cancel_and_progress(void)
{
    int calls = 0;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    /* One thread: with more, the calling thread (the only one that reports progress)
     * may get no band at all on a loaded machine, and the render legitimately finishes. */
    d.threads = 1;
    d.progress = cancel_at_half;
    d.progress_user = &calls;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&d, &ctx));
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.width = 64;
    s.height = 256;
    atmos_image *img = (atmos_image *)1;
    CHECK(atmos_render_sky(ctx, &s, &img, NULL) == ATMOS_E_CANCELLED);
    CHECK(img == NULL);
    CHECK(calls > 0);
    atmos_context_destroy(ctx);
}

static void test_bad_scene(void)
{
    atmos_context *ctx = make_ctx(1);
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.width = 0;
    atmos_image *img = NULL;
    CHECK(atmos_render_sky(ctx, &s, &img, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(img == NULL);
    CHECK(strstr(atmos_context_error(ctx), "width") != NULL);
    atmos_context_destroy(ctx);
}

/* Linear sRGB of the rendered image: rgb and spectral renderings of the same
 * sky agree in colour (chromaticity) to a few per cent. */
static void test_rgb_vs_spectral_colour(void)
{
    atmos_context *ctx = make_ctx(2);
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.width = 32;
    s.height = 32;
    s.atmosphere.hide_sun_disk = 1;
    double pos[3] = {0, 2, 0};
    atmos_camera_defaults(ATMOS_CAMERA_FISHEYE, pos, &s.camera);
    s.sun.from_time = 0;
    s.sun.elevation_deg = 45;
    atmos_image *out[2] = {NULL, NULL};
    for (int m = 0; m < 2; m++) {
        s.wavelengths = m ? ATMOS_WAVELENGTHS_SPECTRAL : ATMOS_WAVELENGTHS_RGB;
        s.spectral_samples = 40;
        atmos_image *img = render(ctx, &s);
        atmos_wavelengths wl;
        atmos_scene_wavelengths(ctx, &s, &wl);
        if (img) CHECK_OK(atmos_image_to_srgb(ctx, img, &wl, &out[m]));
        atmos_image_destroy(img);
    }
    if (out[0] && out[1]) {
        /* the zenith pixel */
        const float *a = out[0]->pixels + (16 * 32 + 16) * 4, *b = out[1]->pixels + (16 * 32 + 16) * 4;
        double sa = a[0] + a[1] + a[2], sb = b[0] + b[1] + b[2];
        printf("zenith linear sRGB: rgb mode (%.1f %.1f %.1f), spectral 40 (%.1f %.1f %.1f)\n", a[0], a[1], a[2], b[0], b[1], b[2]);
        for (int k = 0; k < 3; k++) CHECK_NEAR(a[k] / sa, b[k] / sb, 0.05);
        CHECK(b[2] > b[0]); /* blue sky */
        CHECK(b[1] > 1000 && b[1] < 20000); /* daylight zenith luminance, cd/m^2 order of magnitude */
    }
    atmos_image_destroy(out[0]);
    atmos_image_destroy(out[1]);
    atmos_context_destroy(ctx);
}

/* Backgrounds other than the sky are vacuum: exactly the given radiance, no disk;
 * a sun given by a flat irradiance scales the sky linearly. */
static void test_background_and_irradiance(void)
{
    atmos_context *ctx = make_ctx(2);
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.width = 48, s.height = 32;
    s.camera.look_at[0] = s.camera.position[0] + 1000 * sin(235 * 3.14159265358979 / 180); /* the sun's azimuth */
    s.camera.look_at[2] = s.camera.position[2] - 1000 * cos(235 * 3.14159265358979 / 180);
    s.camera.look_at[1] = s.camera.position[1] + 400;
    for (int b = 0; b < 2; b++) {
        s.atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
        s.atmosphere.background_radiance = b ? 0.25 : 0.0;
        atmos_image *img = render(ctx, &s);
        int bad = 0;
        for (int i = 0; img && i < s.width * s.height; i++) {
            const float *px = img->pixels + (size_t)i * img->channels;
            for (int c = 0; c < 3; c++) bad += px[c] != (b ? 0.25f : 0.0f);
            bad += px[3] != 1.0f;
        }
        CHECK_MSG(img && bad == 0, "background %d: %d values differ", b, bad);
        atmos_image_destroy(img);
    }
    s.atmosphere.kind = ATMOS_ATMOSPHERE_RILEY;
    s.atmosphere.background_radiance = 0;
    s.wavelengths = ATMOS_WAVELENGTHS_SPECTRAL;
    s.spectral_samples = 8;
    s.sun.irradiance_count = 1;
    s.sun.irradiance[0] = 1.0;
    atmos_wavelengths wl;
    CHECK_OK(atmos_scene_wavelengths(ctx, &s, &wl));
    for (int i = 0; i < wl.count; i++) CHECK(wl.sun_irradiance[i] == 1.0);
    atmos_image *a = render(ctx, &s);
    s.sun.irradiance[0] = 2.0;
    atmos_image *b2 = render(ctx, &s);
    double worst = 0;
    for (size_t i = 0; a && b2 && i < (size_t)s.width * s.height * a->channels; i++)
        if ((i + 1) % (size_t)a->channels)
            worst = fmax(worst, fabs(b2->pixels[i] - 2.0 * a->pixels[i]) / fmax(1e-30, 2.0 * a->pixels[i]));
    CHECK_MSG(worst < 1e-5, "sky radiance is not linear in the sun's irradiance: %g", worst);
    atmos_image_destroy(a);
    atmos_image_destroy(b2);
    s.wavelengths = ATMOS_WAVELENGTHS_RGB;
    s.sun.irradiance_count = 3;
    s.sun.irradiance[0] = 1, s.sun.irradiance[1] = 2, s.sun.irradiance[2] = 3;
    CHECK_OK(atmos_scene_wavelengths(ctx, &s, &wl));
    CHECK(wl.sun_irradiance[0] == 1 && wl.sun_irradiance[1] == 2 && wl.sun_irradiance[2] == 3);
    atmos_context_destroy(ctx);
}

int main(void)
{
    test_background_and_irradiance();
    test_matches_model(ATMOS_ATMOSPHERE_RILEY);
    test_matches_model(ATMOS_ATMOSPHERE_HOMOGENEOUS); /* the renderer knows no kind's insides */
    test_threads_identical();
    test_sun_disk_energy();
    test_cancel_and_progress();
    test_bad_scene();
    test_rgb_vs_spectral_colour();
    return test_summary("test_render");
}
