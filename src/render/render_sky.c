/* Renders a scene's sky (Riley et al. 2004 §4.1, §4.2.4) into a spectral image,
 * and converts spectral images to linear sRGB. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, getpid, isatty, PATH_MAX */
#include "core/internal.h"
#include "atmosphere/atmosphere_ops.h"

#include <stdlib.h>

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

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
    const atmos_atmosphere *atm;
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
            if (atmos_atmosphere_ground_distance(job->atm, job->cam->position, d) < INFINITY) continue;
            if (angle_between(d, job->sun) <= job->sun_radius) inside++;
        }
    return valid ? (double)inside / (S * S) : 0.0;
}

/* Directions of the rays through (x + sx, y + sy) for x in [0, W) into SoA arrays;
 * w[x] = 1 for a valid ray, 0 outside a fisheye's circle. The equirectangular
 * camera reads azimuth sines and cosines from a per-sample column table. */
static void row_rays(const sky_job *job, int y, double sx, double sy, const float *col_sc, float *dx, float *dy,
                     float *dz, float *w)
{
    const atmos_camera *cam = job->cam;
    const int W = cam->width;
    if (cam->type == ATMOS_CAMERA_EQUIRECT && col_sc) {
        double el = (90.0 - ((y + sy) / cam->height) * 180.0) * ATMOS_DEG2RAD;
        float ce = (float)cos(el), se = (float)sin(el);
        for (int x = 0; x < W; x++) {
            dx[x] = ce * col_sc[2 * x];
            dy[x] = se;
            dz[x] = -ce * col_sc[2 * x + 1];
            w[x] = 1.0f;
        }
        return;
    }
    if (cam->type == ATMOS_CAMERA_PINHOLE) {
        const double t = cam->tan_half_fov, H = cam->height;
        double v = (H - 2.0 * (y + sy)) / H * t;
        double bx = cam->forward[0] + v * cam->up[0], by = cam->forward[1] + v * cam->up[1],
               bz = cam->forward[2] + v * cam->up[2];
        for (int x = 0; x < W; x++) {
            double u = (2.0 * (x + sx) - W) / H * t;
            double ox = bx + u * cam->right[0], oy = by + u * cam->right[1], oz = bz + u * cam->right[2];
            double inv = 1.0 / sqrt(ox * ox + oy * oy + oz * oz);
            dx[x] = (float)(ox * inv), dy[x] = (float)(oy * inv), dz[x] = (float)(oz * inv);
            w[x] = 1.0f;
        }
        return;
    }
    if (cam->type == ATMOS_CAMERA_FISHEYE) {
        /* Equidistant: angle from the axis proportional to the distance from the centre. */
        const double S = W < cam->height ? W : cam->height;
        const float half = (float)(0.5 * cam->fov_deg * ATMOS_DEG2RAD);
        const float v = (float)((cam->height - 2.0 * (y + sy)) / S);
        float f[3], r[3], u[3];
        for (int k = 0; k < 3; k++) f[k] = (float)cam->forward[k], r[k] = (float)cam->right[k], u[k] = (float)cam->up[k];
        for (int x = 0; x < W; x++) {
            float uu = (float)((2.0 * (x + sx) - W) / S);
            float rr = sqrtf(uu * uu + v * v);
            float th = rr * half;
            float st = sinf(th), ct = cosf(th);
            float k1 = rr > 0 ? st / rr : half; /* sin(theta)/r -> half as r -> 0 */
            float ox = ct * f[0] + k1 * (uu * r[0] + v * u[0]);
            float oy = ct * f[1] + k1 * (uu * r[1] + v * u[1]);
            float oz = ct * f[2] + k1 * (uu * r[2] + v * u[2]);
            float inv = 1.0f / sqrtf(ox * ox + oy * oy + oz * oz);
            dx[x] = ox * inv, dy[x] = oy * inv, dz[x] = oz * inv;
            w[x] = rr <= 1.0f ? 1.0f : 0.0f;
        }
        return;
    }
    for (int x = 0; x < W; x++) {
        double d[3];
        int ok = atmos_camera_ray(cam, x + sx, y + sy, d);
        dx[x] = (float)d[0], dy[x] = (float)d[1], dz[x] = (float)d[2];
        w[x] = ok ? 1.0f : 0.0f;
    }
}

/* Sample offsets within the pixel: the centre for one sample, else a Hammersley
 * set (deterministic, identical for every pixel and thread). */
static void sample_offset(int s, int spp, double *sx, double *sy)
{
    *sx = spp == 1 ? 0.5 : (s + 0.5) / spp;
    *sy = spp == 1 ? 0.5 : radical_inverse2((unsigned)s);
}

typedef struct {
    float *dx, *dy, *dz, *w, *acc, *scratch, *hits;
} row_buffers;

static void shade_row(const sky_job *job, const atmos__atm_batch *batch, const float *col_sc, int y, row_buffers *rb,
                      float *dst, int C)
{
    const int W = job->cam->width, n = job->n, spp = job->spp;
    memset(rb->acc, 0, sizeof(float) * (size_t)W * n);
    memset(rb->hits, 0, sizeof(float) * (size_t)W);
    for (int s = 0; s < spp; s++) {
        double sx, sy;
        sample_offset(s, spp, &sx, &sy);
        row_rays(job, y, sx, sy, col_sc ? col_sc + (size_t)2 * W * s : NULL, rb->dx, rb->dy, rb->dz, rb->w);
        atmos__atm_batch_eval(batch, W, rb->dx, rb->dy, rb->dz, rb->w, rb->acc, rb->scratch);
        for (int x = 0; x < W; x++) rb->hits[x] += rb->w[x];
    }
    const float inv = 1.0f / spp;
    for (int x = 0; x < W; x++) {
        float *px = dst + (size_t)x * C;
        for (int i = 0; i < n; i++) px[i] = rb->acc[(size_t)i * W + x] * inv;
        px[n] = rb->hits[x] * inv;
    }
    if (!job->sun_visible) return;
    /* The sun's disk, antialiased by supersampling the few pixels near it. The
     * search uses the last sample's rays (within a pixel of the centre). */
    const float sx = (float)job->sun[0], sy = (float)job->sun[1], sz = (float)job->sun[2];
    const float cs = (float)job->cos_disk_search;
    for (int x = 0; x < W; x++) {
        if (rb->w[x] == 0.0f || rb->dx[x] * sx + rb->dy[x] * sy + rb->dz[x] * sz < cs) continue;
        double cov = sun_coverage(job, x, y);
        float *px = dst + (size_t)x * C;
        for (int i = 0; i < n; i++) px[i] += (float)(cov * job->sun_radiance[i]);
    }
}

atmos_status atmos_render_sky(atmos_context *ctx, const atmos_scene *scene, atmos_image **out, atmos_render_info *info)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render: missing scene or output");
    *out = NULL;
    double t0 = atmos__now();
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
    atmos_atmosphere *sky = NULL;
    if ((st = atmos_atmosphere_create(ctx, &scene->atmosphere, &wl, &sky)) != ATMOS_OK) return st;
    atmos_image *img = NULL;
    if ((st = atmos_image_create(ctx, scene->width, scene->height, wl.count + 1, &img)) != ATMOS_OK) {
        atmos_atmosphere_destroy(sky);
        return st;
    }
    job.atm = sky;
    job.cam = &cam;
    job.n = wl.count;
    job.spp = scene->samples_per_pixel > 0 ? scene->samples_per_pixel : 1;
    job.sun_radius = 0.5 * atmos_atmosphere_get_desc(sky)->sun_diameter_deg * ATMOS_DEG2RAD;
    atmos_atmosphere_sun_radiance(sky, cam.position, job.sun, job.sun_radiance);
    job.sun_visible = atmos_atmosphere_sun_disk_visible(sky, job.sun);
    /* Disk radius plus 2.5 pixel footprints: a sample ray is within one footprint
     * of the pixel centre, the pixel's far corner within another. */
    double foot = pixel_footprint(&cam);
    /* The equirect footprint grows towards the poles; search wider there. */
    if (cam.type == ATMOS_CAMERA_EQUIRECT) foot /= fmax(1e-3, sqrt(fmax(0.0, 1.0 - job.sun[1] * job.sun[1])));
    double search = job.sun_radius + 2.5 * foot;
    job.cos_disk_search = search >= ATMOS_PI ? -1.0 : cos(search);

    const int W = scene->width, H = scene->height, C = img->channels;
    const int band = 8; /* rows per work item: small enough for progress and balance */
    const int nbands = (H + band - 1) / band;
    int done = 0, cancelled = 0, nomem = 0;
    int threads = atmos__threads(ctx);
    atmos__atm_batch batch;
    atmos__atm_batch_init(&batch, sky, cam.position, job.sun);
    /* Equirectangular: per-sample tables of the columns' azimuth sines and cosines. */
    float *col_sc = NULL;
    if (cam.type == ATMOS_CAMERA_EQUIRECT && (size_t)job.spp * W <= ((size_t)1 << 22)) {
        col_sc = malloc(sizeof(float) * 2 * (size_t)W * job.spp);
        if (col_sc)
            for (int s = 0; s < job.spp; s++) {
                double sx, sy;
                sample_offset(s, job.spp, &sx, &sy);
                for (int x = 0; x < W; x++) {
                    double az = ((x + sx) / W - 0.5) * 2.0 * ATMOS_PI;
                    col_sc[(size_t)2 * W * s + 2 * x] = (float)sin(az);
                    col_sc[(size_t)2 * W * s + 2 * x + 1] = (float)cos(az);
                }
            }
    }
#pragma omp parallel num_threads(threads)
    {
        row_buffers rb = {0};
        size_t per = (size_t)W;
        float *mem = malloc(sizeof(float) * per * (5 + (size_t)job.n + ATMOS__ATM_BATCH_SCRATCH));
        if (mem) {
            rb.dx = mem, rb.dy = mem + per, rb.dz = mem + 2 * per, rb.w = mem + 3 * per, rb.hits = mem + 4 * per;
            rb.acc = mem + 5 * per;
            rb.scratch = rb.acc + per * job.n;
        } else {
#pragma omp atomic write
            nomem = 1;
        }
        /* Bands are handed out dynamically for balance; each pixel's value depends
         * only on its own position, so the image is identical for any thread count. */
#pragma omp for schedule(dynamic, 1)
        for (int b = 0; b < nbands; b++) {
            int stop;
#pragma omp atomic read
            stop = cancelled;
            if (stop || !mem) continue;
            for (int y = b * band; y < H && y < (b + 1) * band; y++)
                shade_row(&job, &batch, col_sc, y, &rb, img->pixels + (size_t)y * W * C, C);
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
        free(mem);
    }
    free(col_sc);
    if (!cancelled && !nomem) atmos__progress(ctx, "render sky", 1.0);
    if (nomem) {
        atmos_atmosphere_destroy(sky);
        atmos_image_destroy(img);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render: out of memory for row buffers");
    }
    atmos_atmosphere_destroy(sky);
    if (cancelled) {
        atmos_image_destroy(img);
        return atmos__error(ctx, ATMOS_E_CANCELLED, "render: cancelled");
    }
    double secs = atmos__now() - t0;
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
    const long long npx = (long long)spectral->width * spectral->height;
    const int C = spectral->channels;
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (long long p = 0; p < npx; p++) {
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
