/* atmos bench sky, the atmosphere models (bench_sky.h): per model the time to build the
 * atmosphere (its tables) cold and again with its cache, and the sky renderer's cost
 * through the plan API at 720x480 from the ground and from 36 000 km, there also with cloud
 * spheres (the spherical kinds). */
#define _POSIX_C_SOURCE 200809L /* getpid */
#include "bench_sky.h"
#include "atmos/cache.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static const struct {
    const char *name;
    atmos_atmosphere_kind kind;
} kinds[] = {{"riley", ATMOS_ATMOSPHERE_RILEY}, {"dobashi", ATMOS_ATMOSPHERE_DOBASHI},
             {"spherical", ATMOS_ATMOSPHERE_SPHERICAL}};

enum { FULL_W = 720, FULL_H = 480 };

/* Creation of the model's atmosphere at rgb: in an empty private cache (cold), then again
 * (cached: the same when the model keeps nothing in the cache). */
static atmos_status bench_precompute(atmos_context *ctx, atmos_atmosphere_kind kind, double *cold, double *cached)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    d.kind = kind;
    *cached = 1e30;
    for (int r = 0; r < 3; r++) {
        atmos_atmosphere *a = NULL;
        const double t0 = cli_now_s();
        atmos_status st = atmos_atmosphere_create(ctx, &d, &wl, &a);
        const double t = cli_now_s() - t0;
        atmos_atmosphere_destroy(a);
        if (st != ATMOS_OK) return st;
        if (r == 0) *cold = t;
        else if (t < *cached) *cached = t;
    }
    return ATMOS_OK;
}

/* A synthetic global cloud image (bench only; the satellite images live in the data folder):
 * brightness in 10 x 5 degree blocks from 0 to 0.9 plus a smooth wave, clear, thin and thick
 * clouds side by side; NULL when out of memory. */
static atmos_image *bench_cloud_image(atmos_context *ctx)
{
    atmos_image *img = NULL;
    const int w = 720, h = 360;
    if (atmos_image_create(ctx, w, h, 1, &img) != ATMOS_OK) return NULL;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const double lon = -180.0 + (x + 0.5) / 2.0, lat = 90.0 - (y + 0.5) / 2.0;
            const int i = (int)floor(lon / 10.0) + 7 * (int)floor(lat / 5.0);
            const double blocks = 0.1 * (double)(((i % 10) + 10) % 10);
            const double wave = 0.5 + 0.5 * sin(lon * 3.14159265358979 / 45.0) * cos(lat * 3.14159265358979 / 30.0);
            img->pixels[(size_t)y * w + x] = (float)(0.5 * blocks + 0.4 * wave);
        }
    return img;
}

/* The two views: from 2 m above the ground toward the horizon (90 degrees vertical field,
 * the sun 30 degrees high in view), and from 36 000 km straight down at the whole planet
 * (20 degrees vertical field: the disk, the limb and space; the sun 30 degrees high over
 * the origin, so the terminator crosses the disk). */
static void view_scene(atmos_scene *sc, atmos_atmosphere_kind kind, int space, int w, int h,
                       const atmos_image *clouds)
{
    atmos_scene_defaults(sc);
    sc->atmosphere.clouds.image = clouds; /* five spheres between 2 and 8 km by default */
    sc->width = w, sc->height = h;
    sc->wavelengths = ATMOS_WAVELENGTHS_RGB;
    sc->atmosphere.kind = kind;
    sc->renderer = ATMOS_RENDERER_SKY;
    double pos[3] = {0, space ? 36000e3 : 2, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &sc->camera);
    if (space) {
        sc->camera.look_at[0] = 0, sc->camera.look_at[1] = 1, sc->camera.look_at[2] = 0; /* straight down */
        sc->camera.up[0] = 0, sc->camera.up[1] = 0, sc->camera.up[2] = -1;
        sc->camera.fov_deg = 20;
    } else {
        atmos_direction_from_angles(5, 200, sc->camera.look_at);
        for (int k = 0; k < 3; k++) sc->camera.look_at[k] += pos[k];
        sc->camera.fov_deg = 90;
    }
}

/* Best wall time of `frames` frames of one plan, the camera moving 1 m east a frame (so
 * every frame is rendered, not reused; the sun stays, as in a walk or a level flight) or,
 * climb, 2 m up a frame (a climbing aircraft: the production sky's per-eye table is built
 * again every frame), and the best CPU time of the process (all threads) over the same
 * frames. */
static atmos_status time_frames(atmos_context *ctx, const atmos_scene *sc, int frames, int climb, double *best,
                                double *best_cpu)
{
    atmos_plan *p = NULL;
    atmos_image *img = NULL;
    atmos_frame f;
    atmos_status st = atmos_plan_create(ctx, sc, NULL, NULL, &p);
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, sc, &f);
    if (st == ATMOS_OK) st = atmos_plan_image_create(p, &f, &img);
    *best = *best_cpu = 1e30;
    atmos_direction_from_angles(30.0, 180.0, f.sun_dir);
    for (int i = 0; i < frames && st == ATMOS_OK; i++) {
        const int axis = climb ? 1 : 0;
        f.camera.position[axis] += climb ? 2.0 : 1.0;
        f.camera.look_at[axis] += climb ? 2.0 : 1.0;
        const double t0 = cli_now_s();
        const clock_t c0 = clock();
        st = atmos_plan_render(p, &f, NULL, img, NULL);
        const double t = cli_now_s() - t0, c = (double)(clock() - c0) / CLOCKS_PER_SEC;
        if (t < *best) *best = t;
        if (c < *best_cpu) *best_cpu = c;
    }
    atmos_image_destroy(img);
    atmos_plan_destroy(p);
    return st;
}

/* Frames timed at each size while the image grows: the best of 4, as a plan's first two frames
 * carry one-off work (space_clouds at 12x8: 47-60 and 55-230 ms of CPU, then 16-21 ms); with the
 * best of 2 that second frame's cost at 12x8, against a 1x1 frame without it, was taken for a
 * cost per pixel and stopped the growth at 12x8 (fps 0.001 extrapolated instead of about 3). */
enum { GROW_FRAMES = 4 };

/* One view of one model. A frame costs a fixed part (tables that depend on the camera or
 * the sun) plus a part per pixel. Starting from frames of 1x1 and 12x8 pixels (GROW_FRAMES),
 * the image grows through 45x30, 90x60, 180x120, 360x240 to 720x480 while the cost the last
 * two sizes predict for the next one (fixed + per pixel) fits budget_s for `repeat` frames;
 * the last size is measured with `repeat` frames when they fit (slow models: smaller). */
static atmos_status bench_view(atmos_context *ctx, const char *name, atmos_atmosphere_kind kind, int space,
                               int climb, const atmos_image *clouds, int repeat, double budget_s)
{
    static const int divs[] = {60, 16, 8, 4, 2, 1};
    atmos_scene sc;
    double t_prev, t, cpu;
    view_scene(&sc, kind, space, 1, 1, clouds);
    atmos_status st = time_frames(ctx, &sc, GROW_FRAMES, climb, &t_prev, &cpu);
    double px_prev = 1, px = (double)(FULL_W / divs[0]) * (FULL_H / divs[0]);
    view_scene(&sc, kind, space, FULL_W / divs[0], FULL_H / divs[0], clouds);
    if (st == ATMOS_OK) st = time_frames(ctx, &sc, GROW_FRAMES, climb, &t, &cpu);
    int i = 0;
    while (st == ATMOS_OK && i < 5) {
        const double per_px = fmax((t - t_prev) / (px - px_prev), 0.0), fixed = fmax(t - per_px * px, 0.0);
        const double px_next = (double)(FULL_W / divs[i + 1]) * (FULL_H / divs[i + 1]);
        if ((fixed + per_px * px_next) * (repeat > 2 ? repeat : 2) > budget_s) break;
        i++;
        view_scene(&sc, kind, space, FULL_W / divs[i], FULL_H / divs[i], clouds);
        t_prev = t, px_prev = px, px = px_next;
        st = time_frames(ctx, &sc, GROW_FRAMES, climb, &t, &cpu);
    }
    if (st == ATMOS_OK && repeat > 2 && t * repeat <= budget_s) st = time_frames(ctx, &sc, repeat, climb, &t, &cpu);
    if (st != ATMOS_OK) return st;
    const double scale = (double)FULL_W * FULL_H / px;
    const int threads = atmos_context_threads(ctx);
    printf("bench=sky case=%s model=%s wavelengths=rgb size=%dx%d threads=%d seconds=%.5f ns_per_pixel=%.1f "
           "cpu_ns_per_pixel=%.1f",
           space ? (clouds ? "space_clouds" : "space") : (climb ? "ground_climb" : "ground"), name, sc.width, sc.height, threads, t, t * threads * 1e9 / px, cpu * 1e9 / px);
    if (space) printf(" fps=%.3g", 1.0 / (t * scale));
    if (divs[i] > 1) printf(" extrapolated=1");
    printf("\n");
    fflush(stdout);
    return ATMOS_OK;
}

int bench_sky_models(int threads, int repeat, double budget_s, const char *models)
{
    const char *tmp = getenv("TMPDIR");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/atmos-bench-sky-cache-%ld", tmp && *tmp ? tmp : "/tmp", (long)getpid());
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    if (threads > 0) cd.threads = threads;
    cd.cache_dir = dir;
    cd.log_level = ATMOS_LOG_ERROR;
    cli_desc_progress(&cd);
    atmos_context *ctx = NULL;
    if (atmos_context_create(&cd, &ctx) != ATMOS_OK) return CLI_EXIT_RUNTIME;
    atmos_status st = ATMOS_OK;
    atmos_image *clouds = bench_cloud_image(ctx);
    for (size_t m = 0; m < sizeof kinds / sizeof kinds[0] && st == ATMOS_OK; m++) {
        if (models && !cli_list_has(models, kinds[m].name)) continue;
        double cold = 0, cached = 0;
        st = bench_precompute(ctx, kinds[m].kind, &cold, &cached);
        if (st != ATMOS_OK) break;
        printf("bench=sky case=precompute model=%s wavelengths=rgb threads=%d precompute_seconds=%.4f "
               "cached_seconds=%.4f\n",
               kinds[m].name, atmos_context_threads(ctx), cold, cached);
        fflush(stdout);
        /* ground, ground climbing, space, space with cloud spheres (the spherical kinds) */
        for (int v = 0; v < 4 && st == ATMOS_OK; v++) {
            if (v == 3 && (kinds[m].kind == ATMOS_ATMOSPHERE_RILEY || !clouds)) continue;
            st = bench_view(ctx, kinds[m].name, kinds[m].kind, v >= 2, v == 1, v == 3 ? clouds : NULL, repeat,
                            budget_s);
        }
    }
    atmos_image_destroy(clouds);
    int rc = st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error("bench", ctx, st);
    atmos_cache_clear(ctx, NULL);
    rmdir(dir);
    atmos_context_destroy(ctx);
    return rc;
}
