/* Renders a scene's sky (Riley et al. 2004 §4.1, §4.2.4) into a spectral image,
 * and converts spectral images to linear sRGB. */
#include "core/internal.h"
#include "sky/sky_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

atmos_status atmos_scene_wavelengths(atmos_context *ctx, const atmos_scene *scene, atmos_wavelengths *out)
{
    if (scene->wavelengths == ATMOS_WAVELENGTHS_RGB) {
        atmos_wavelengths_rgb(out);
        return ATMOS_OK;
    }
    if (atmos_wavelengths_spectral(scene->spectral_samples, out) != ATMOS_OK)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "wavelengths/samples: must be in [1, %d], got %d",
                            ATMOS_MAX_WAVELENGTHS, scene->spectral_samples);
    return ATMOS_OK;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Van der Corput radical inverse in base 2: the second coordinate of the
 * Hammersley set used for deterministic, thread-independent pixel samples. */
static double radical_inverse2(unsigned i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x55555555u) << 1) | ((i & 0xAAAAAAAAu) >> 1);
    i = ((i & 0x33333333u) << 2) | ((i & 0xCCCCCCCCu) >> 2);
    i = ((i & 0x0F0F0F0Fu) << 4) | ((i & 0xF0F0F0F0u) >> 4);
    i = ((i & 0x00FF00FFu) << 8) | ((i & 0xFF00FF00u) >> 8);
    return i * (1.0 / 4294967296.0);
}

typedef struct {
    const atmos_sky *sky;
    const atmos_camera *cam;
    double sun[3];
    int spp;
    int n;
    double sun_radius;      /* radians */
    double sun_radiance[ATMOS_MAX_WAVELENGTHS];
    int sun_visible;        /* disk drawn and sun above the horizon */
    double cos_disk_search; /* cos(sun radius + 1.5 pixel footprints) */
} sky_job;

/* An upper bound on the angle one pixel spans, radians. */
static double pixel_footprint(const atmos_camera *cam)
{
    switch (cam->type) {
    case ATMOS_CAMERA_PINHOLE: return 2.0 * cam->tan_half_fov / cam->height; /* largest at the centre */
    case ATMOS_CAMERA_FISHEYE: return cam->fov_deg * ATMOS_DEG2RAD / (cam->width < cam->height ? cam->width : cam->height);
    default: return fmax(2.0 * ATMOS_PI / cam->width, ATMOS_PI / cam->height);
    }
}

static double angle_between(const double a[3], const double b[3])
{
    double c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), c);
}

/* Fraction of the pixel (x, y) covered by the sun's disk, by 16x16 supersampling;
 * called only for pixels near the sun so that the 0.5° disk is antialiased even
 * when it spans a few pixels. */
static double sun_coverage(const sky_job *job, int x, int y)
{
    const int S = 16;
    int inside = 0, valid = 0;
    double d[3];
    for (int j = 0; j < S; j++)
        for (int i = 0; i < S; i++) {
            if (!atmos_camera_ray(job->cam, x + (i + 0.5) / S, y + (j + 0.5) / S, d)) continue;
            valid++;
            if (atmos_sky_ground_distance(job->cam->position[1], d) < INFINITY) continue;
            if (angle_between(d, job->sun) <= job->sun_radius) inside++;
        }
    return valid ? (double)inside / (S * S) : 0.0;
}

static void shade_pixel(const sky_job *job, int x, int y, float *px)
{
    const int n = job->n;
    double acc[ATMOS_MAX_WAVELENGTHS] = {0}, L[ATMOS_MAX_WAVELENGTHS];
    double d[3];
    int hits = 0;
    atmos_sky_sample info;
    /* The disk is drawn separately (antialiased) so the per-sample evaluation hides it. */
    for (int s = 0; s < job->spp; s++) {
        double sx = job->spp == 1 ? 0.5 : (s + 0.5) / job->spp;
        double sy = job->spp == 1 ? 0.5 : radical_inverse2((unsigned)s);
        if (!atmos_camera_ray(job->cam, x + sx, y + sy, d)) continue;
        hits++;
        atmos_sky_radiance(job->sky, job->cam->position, d, job->sun, L, &info);
        if (info.in_sun_disk)
            for (int i = 0; i < n; i++) L[i] -= job->sun_radiance[i];
        for (int i = 0; i < n; i++) acc[i] += L[i];
    }
    double inv = 1.0 / job->spp;
    if (hits && job->sun_visible) {
        /* Only pixels whose centre is within the disk's radius plus the pixel's
         * angular footprint get the (antialiased) disk. */
        double c[3];
        if (atmos_camera_ray(job->cam, x + 0.5, y + 0.5, c) &&
            c[0] * job->sun[0] + c[1] * job->sun[1] + c[2] * job->sun[2] >= job->cos_disk_search) {
            double cov = sun_coverage(job, x, y);
            for (int i = 0; i < n; i++) acc[i] += cov * job->sun_radiance[i] * job->spp;
        }
    }
    for (int i = 0; i < n; i++) px[i] = (float)(acc[i] * inv);
    px[n] = (float)(hits * inv);
}

atmos_status atmos_render_sky(atmos_context *ctx, const atmos_scene *scene, atmos_image **out, atmos_render_info *info)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render: missing scene or output");
    *out = NULL;
    double t0 = now_seconds();
    atmos_status st = atmos_scene_validate(ctx, scene, "scene");
    if (st != ATMOS_OK) return st;
    atmos_wavelengths wl;
    if ((st = atmos_scene_wavelengths(ctx, scene, &wl)) != ATMOS_OK) return st;
    atmos_camera cam;
    if ((st = atmos_camera_init(ctx, &scene->camera, scene->width, scene->height, &cam)) != ATMOS_OK) return st;
    sky_job job;
    memset(&job, 0, sizeof job);
    double sun_el = 0, sun_az = 0;
    if ((st = atmos_scene_sun_direction(ctx, scene, job.sun, &sun_el, &sun_az)) != ATMOS_OK) return st;
    atmos_sky *sky = NULL;
    if ((st = atmos_sky_create(ctx, &scene->atmosphere, &wl, &sky)) != ATMOS_OK) return st;
    atmos_image *img = NULL;
    if ((st = atmos_image_create(ctx, scene->width, scene->height, wl.count + 1, &img)) != ATMOS_OK) {
        atmos_sky_destroy(sky);
        return st;
    }
    job.sky = sky;
    job.cam = &cam;
    job.n = wl.count;
    job.spp = scene->samples_per_pixel > 0 ? scene->samples_per_pixel : 1;
    job.sun_radius = 0.5 * sky->desc.sun_diameter_deg * ATMOS_DEG2RAD;
    atmos_sky_sun_radiance(sky, cam.position[1], job.sun, job.sun_radiance);
    job.sun_visible = !sky->desc.hide_sun_disk && job.sun[1] > 0;
    double search = job.sun_radius + 1.5 * pixel_footprint(&cam);
    /* The equirect footprint grows towards the poles; search wider there. */
    if (cam.type == ATMOS_CAMERA_EQUIRECT) search = job.sun_radius + 1.5 * pixel_footprint(&cam) / fmax(1e-3, sqrt(fmax(0.0, 1.0 - job.sun[1] * job.sun[1])));
    job.cos_disk_search = search >= ATMOS_PI ? -1.0 : cos(search);

    const int W = scene->width, H = scene->height, C = img->channels;
    const int band = 8; /* rows per work item: small enough for progress and balance */
    const int nbands = (H + band - 1) / band;
    int done = 0, cancelled = 0;
    int threads = atmos__threads(ctx);
#pragma omp parallel num_threads(threads)
    {
        /* Bands are handed out dynamically for balance; each pixel's value depends
         * only on its own position, so the image is identical for any thread count. */
#pragma omp for schedule(dynamic, 1)
        for (int b = 0; b < nbands; b++) {
            int stop;
#pragma omp atomic read
            stop = cancelled;
            if (stop) continue;
            for (int y = b * band; y < H && y < (b + 1) * band; y++)
                for (int x = 0; x < W; x++) shade_pixel(&job, x, y, img->pixels + ((size_t)y * W + x) * C);
            int d;
#pragma omp atomic capture
            d = ++done;
#ifdef _OPENMP
            if (omp_get_thread_num() == 0)
#endif
            {
                if (atmos__progress(ctx, "render sky", (double)d / nbands)) {
#pragma omp atomic write
                    cancelled = 1;
                }
            }
        }
    }
    atmos_sky_destroy(sky);
    if (cancelled) {
        atmos_image_destroy(img);
        return atmos__error(ctx, ATMOS_E_CANCELLED, "render: cancelled");
    }
    double secs = now_seconds() - t0;
    char buf[256];
    atmos_image_set_meta(img, "atmos:version", atmos_version());
    atmos_image_set_meta(img, "atmos:scene", scene->name);
    atmos_image_set_meta(img, "atmos:renderer", "sky (Riley et al. 2004, analytic single scattering)");
    snprintf(buf, sizeof buf, "%.6f", sun_el);
    atmos_image_set_meta(img, "atmos:sun_elevation_deg", buf);
    snprintf(buf, sizeof buf, "%.6f", sun_az);
    atmos_image_set_meta(img, "atmos:sun_azimuth_deg", buf);
    snprintf(buf, sizeof buf, "%s, %d samples", wl.mode == ATMOS_WAVELENGTHS_RGB ? "rgb" : "spectral", wl.count);
    atmos_image_set_meta(img, "atmos:wavelengths", buf);
    snprintf(buf, sizeof buf, "%.6f", secs);
    atmos_image_set_meta(img, "atmos:render_seconds", buf);
    snprintf(buf, sizeof buf, "%d", threads);
    atmos_image_set_meta(img, "atmos:threads", buf);
    if (info) {
        info->seconds = secs;
        info->sun_elevation_deg = sun_el;
        info->sun_azimuth_deg = sun_az;
    }
    *out = img;
    return ATMOS_OK;
}

atmos_status atmos_image_to_srgb(atmos_context *ctx, const atmos_image *spectral, const atmos_wavelengths *wl,
                                 atmos_image **out)
{
    if (!spectral || !wl || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "to_srgb: missing argument");
    *out = NULL;
    int n = wl->count;
    if (spectral->channels != n + 1 && spectral->channels != n)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "to_srgb: image has %d channels, wavelength set %d (+alpha)",
                            spectral->channels, n);
    int has_alpha = spectral->channels == n + 1;
    atmos_image *rgb = NULL;
    atmos_status st = atmos_image_create(ctx, spectral->width, spectral->height, 4, &rgb);
    if (st != ATMOS_OK) return st;
    float w[ATMOS_MAX_WAVELENGTHS][3];
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) w[i][c] = (float)wl->to_srgb[i][c];
    size_t npx = (size_t)spectral->width * spectral->height;
    const int C = spectral->channels;
    for (size_t p = 0; p < npx; p++) {
        const float *s = spectral->pixels + p * C;
        float r = 0, g = 0, b = 0;
        for (int i = 0; i < n; i++) {
            r += w[i][0] * s[i];
            g += w[i][1] * s[i];
            b += w[i][2] * s[i];
        }
        float *o = rgb->pixels + p * 4;
        o[0] = r, o[1] = g, o[2] = b;
        o[3] = has_alpha ? s[n] : 1.0f;
    }
    for (int i = 0; i < spectral->meta_count; i++) atmos_image_set_meta(rgb, spectral->meta[i].key, spectral->meta[i].value);
    atmos_image_set_meta(rgb, "atmos:units", "linear sRGB (Rec. 709 primaries, D65), Y = luminance in cd/m^2");
    *out = rgb;
    return ATMOS_OK;
}
