/* atmos bench: speed measurements, one machine-readable line per case. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, getpid, isatty, PATH_MAX */
#include "cli.h"
#include "atmos/cache.h"

#include <math.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static void help(void)
{
    printf("Usage: atmos bench sky [--size N] [--repeat R] [--threads T]\n"
           "       atmos bench optics [--fast] [--presets rain,cloud,...] [--threads T]\n\n"
           "  sky     renders an NxN sky (default 1024) with each camera (pinhole, fisheye,\n"
           "          equirect) and wavelength set (rgb, spectral 16), R times (default 5), and\n"
           "          prints per case the best wall time and megapixels per second:\n"
           "            bench=sky camera=pinhole wavelengths=rgb size=1024x1024 threads=2 seconds=0.0401 mpix_per_s=26.1\n"
           "          The time covers rendering the spectral image and converting it to linear sRGB.\n"
           "  optics  Mie scattering at x = 10000, m = 1.33 - 1e-8i, 1801 angles on one thread (best of 3):\n"
           "            bench=optics case=mie x=10000 angles=1801 threads=1 seconds=0.0123\n"
           "          then, per preset (default rain, cloud, ice, snow; --presets to choose) and wavelength\n"
           "          set (rgb, spectral:16), the phase table's cold build (no cache) and its load from the\n"
           "          cache, using a private temporary cache directory (your cache is not touched):\n"
           "            bench=optics case=table preset=rain wavelengths=rgb cold_seconds=1.23 cached_seconds=0.0004\n"
           "          and of the multiple-scattering phase functions built from each table:\n"
           "            bench=optics case=msphase preset=rain wavelengths=rgb orders=121 cold_seconds=... cached_seconds=...\n"
           "          --fast builds preview-quality tables (atmos phase --fast).\n");
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int bench_sky(int size, int repeat, int threads)
{
    static const struct {
        const char *name;
        atmos_camera_type type;
    } cams[] = {{"pinhole", ATMOS_CAMERA_PINHOLE}, {"fisheye", ATMOS_CAMERA_FISHEYE}, {"equirect", ATMOS_CAMERA_EQUIRECT}};
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    for (int c = 0; c < 3; c++)
        for (int spectral = 0; spectral < 2; spectral++) {
            atmos_scene scene;
            atmos_scene_defaults(&scene);
            scene.width = size;
            scene.height = size;
            double pos[3] = {0, 2, 0};
            atmos_camera_defaults(cams[c].type, pos, &scene.camera);
            if (cams[c].type == ATMOS_CAMERA_PINHOLE) {
                /* looking towards the horizon so the ground and the sun are both in view */
                atmos_direction_from_angles(5, 225, scene.camera.look_at);
                for (int k = 0; k < 3; k++) scene.camera.look_at[k] += pos[k];
                scene.camera.fov_deg = 90;
            }
            scene.wavelengths = spectral ? ATMOS_WAVELENGTHS_SPECTRAL : ATMOS_WAVELENGTHS_RGB;
            scene.spectral_samples = 16;
            atmos_wavelengths wl;
            atmos_scene_wavelengths(ctx, &scene, &wl);
            double best = 1e30;
            for (int r = 0; r < repeat; r++) {
                atmos_image *spec = NULL, *rgb = NULL;
                double t0 = now_s();
                atmos_status st = atmos_render_sky(ctx, &scene, &spec, NULL);
                if (st == ATMOS_OK) st = atmos_image_to_srgb(ctx, spec, &wl, &rgb);
                double t = now_s() - t0;
                atmos_image_destroy(spec);
                atmos_image_destroy(rgb);
                if (st != ATMOS_OK) {
                    int rc = cli_runtime_error("bench", ctx, st);
                    atmos_context_destroy(ctx);
                    return rc;
                }
                if (t < best) best = t;
            }
            printf("bench=sky camera=%s wavelengths=%s size=%dx%d threads=%d seconds=%.4f mpix_per_s=%.2f\n",
                   cams[c].name, spectral ? "spectral16" : "rgb", scene.width, scene.height,
                   atmos_context_threads(ctx), best, (double)scene.width * scene.height / best / 1e6);
            fflush(stdout);
        }
    atmos_context_destroy(ctx);
    return CLI_EXIT_OK;
}

/* Removes the private cache directory of bench_optics (only our entries are in it). */
static void remove_cache_dir(atmos_context *ctx, const char *dir)
{
    atmos_cache_clear(ctx, NULL);
    rmdir(dir);
}

static int bench_optics(int threads, int fast, const char *presets)
{
    atmos_context *one = cli_context(1, 1);
    if (!one) return CLI_EXIT_RUNTIME;
    /* Mie at a raindrop's size parameter: the table builder's inner cost. */
    enum { NANG = 1801 };
    static double mu[NANG];
    static atmos_complex s1[NANG], s2[NANG];
    for (int i = 0; i < NANG; i++) mu[i] = cos(i * 0.1 * 3.14159265358979323846 / 180.0);
    atmos_complex m = {1.33, -1e-8};
    double best = 1e30;
    for (int r = 0; r < 3; r++) {
        atmos_mie_result res;
        double t0 = now_s();
        atmos_status st = atmos_mie(one, m, 1e4, NANG, mu, s1, s2, &res);
        double t = now_s() - t0;
        if (st != ATMOS_OK) {
            int rc = cli_runtime_error("bench", one, st);
            atmos_context_destroy(one);
            return rc;
        }
        if (t < best) best = t;
    }
    printf("bench=optics case=mie x=10000 angles=%d threads=1 seconds=%.4f\n", NANG, best);
    fflush(stdout);
    atmos_context_destroy(one);

    /* Tables: cold and cached, in a private cache directory. */
    const char *tmp = getenv("TMPDIR");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/atmos-bench-cache-%ld", tmp && *tmp ? tmp : "/tmp", (long)getpid());
    atmos_context_desc d;
    atmos_context_defaults(&d);
    if (threads > 0) d.threads = threads;
    d.cache_dir = dir;
    d.log_level = ATMOS_LOG_ERROR;
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) return CLI_EXIT_RUNTIME;
    char list[256];
    snprintf(list, sizeof list, "%s", presets ? presets : "rain,cloud,ice,snow");
    int rc = CLI_EXIT_OK;
    for (char *save = NULL, *name = strtok_r(list, ",", &save); name && rc == CLI_EXIT_OK;
         name = strtok_r(NULL, ",", &save)) {
        atmos_particle_desc p;
        atmos_status st = atmos_particle_preset(ctx, name, &p);
        if (st != ATMOS_OK) {
            rc = cli_runtime_error("bench", ctx, st);
            break;
        }
        if (fast) p.fast = 1;
        for (int spectral = 0; spectral < 2 && rc == CLI_EXIT_OK; spectral++) {
            atmos_wavelengths wl;
            if (spectral) atmos_wavelengths_spectral(16, &wl);
            else atmos_wavelengths_rgb(&wl);
            atmos_phase_table *t = NULL;
            atmos_phase_table_desc no = {1}, yes = {0};
            double t0 = now_s();
            st = atmos_phase_table_build(ctx, &p, &wl, &no, &t);
            double cold = now_s() - t0;
            atmos_phase_table_destroy(t);
            t = NULL;
            /* Fill the cache (untimed), then time the load, best of 3. */
            if (st == ATMOS_OK) st = atmos_phase_table_build(ctx, &p, &wl, &yes, &t);
            atmos_phase_table_destroy(t);
            double cached = 1e30;
            int hit = 1;
            for (int r = 0; r < 3 && st == ATMOS_OK; r++) {
                t = NULL;
                t0 = now_s();
                st = atmos_phase_table_build(ctx, &p, &wl, &yes, &t);
                double dt = now_s() - t0;
                if (st == ATMOS_OK) hit &= atmos_phase_table_from_cache(t);
                atmos_phase_table_destroy(t);
                if (dt < cached) cached = dt;
            }
            if (st != ATMOS_OK) {
                rc = cli_runtime_error("bench", ctx, st);
                break;
            }
            printf("bench=optics case=table preset=%s wavelengths=%s%s threads=%d cold_seconds=%.4f cached_seconds=%.5f%s\n",
                   name, spectral ? "spectral16" : "rgb", fast ? " quality=fast" : "", atmos_context_threads(ctx), cold,
                   cached, hit ? "" : " cache=unwritable");
            fflush(stdout);
            /* Multiple-scattering phase functions from the (cached) table: cold, then cached. */
            t = NULL;
            st = atmos_phase_table_build(ctx, &p, &wl, &yes, &t);
            atmos_msphase *ms = NULL;
            atmos_msphase_desc mno = {0}, myes = {0};
            mno.no_cache = 1;
            t0 = now_s();
            if (st == ATMOS_OK) st = atmos_msphase_build(ctx, t, &mno, &ms);
            double mcold = now_s() - t0;
            int orders = ms ? atmos_msphase_max_order(ms) : 0;
            atmos_msphase_destroy(ms);
            ms = NULL;
            if (st == ATMOS_OK) st = atmos_msphase_build(ctx, t, &myes, &ms); /* fill */
            atmos_msphase_destroy(ms);
            double mcached = 1e30;
            for (int r = 0; r < 3 && st == ATMOS_OK; r++) {
                ms = NULL;
                t0 = now_s();
                st = atmos_msphase_build(ctx, t, &myes, &ms);
                double dt = now_s() - t0;
                atmos_msphase_destroy(ms);
                if (dt < mcached) mcached = dt;
            }
            atmos_phase_table_destroy(t);
            if (st != ATMOS_OK) {
                rc = cli_runtime_error("bench", ctx, st);
                break;
            }
            printf("bench=optics case=msphase preset=%s wavelengths=%s%s threads=%d orders=%d cold_seconds=%.4f cached_seconds=%.5f\n",
                   name, spectral ? "spectral16" : "rgb", fast ? " quality=fast" : "", atmos_context_threads(ctx), orders,
                   mcold, mcached);
            fflush(stdout);
        }
    }
    remove_cache_dir(ctx, dir);
    atmos_context_destroy(ctx);
    return rc;
}

int cli_cmd_bench(int argc, char **argv)
{
    const char *C = "bench";
    int size = 1024, repeat = 5, threads = 0, fast = 0;
    const char *what = NULL, *presets = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            help();
            return CLI_EXIT_OK;
        } else if (!strcmp(argv[i], "--size") && i + 1 < argc) {
            if (!cli_parse_int(C, "--size", argv[++i], 16, 8192, &size)) return CLI_EXIT_USAGE;
        } else if (!strcmp(argv[i], "--repeat") && i + 1 < argc) {
            if (!cli_parse_int(C, "--repeat", argv[++i], 1, 1000, &repeat)) return CLI_EXIT_USAGE;
        } else if (!strcmp(argv[i], "--threads") && i + 1 < argc) {
            if (!cli_parse_int(C, "--threads", argv[++i], 1, 1024, &threads)) return CLI_EXIT_USAGE;
        } else if (!strcmp(argv[i], "--fast")) {
            fast = 1;
        } else if (!strcmp(argv[i], "--presets") && i + 1 < argc) {
            presets = argv[++i];
            if (!*presets || strlen(presets) >= 256) return cli_usage_error(C, "--presets: expected a list like rain,cloud");
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "unknown or incomplete option '%s'", argv[i]);
        } else if (!what) {
            what = argv[i];
        } else {
            return cli_usage_error(C, "unexpected argument '%s'", argv[i]);
        }
    }
    if (!what) return cli_usage_error(C, "which benchmark? (available: sky, optics)");
    if (!strcmp(what, "sky")) return bench_sky(size, repeat, threads);
    if (!strcmp(what, "optics")) return bench_optics(threads, fast, presets);
    return cli_usage_error(C, "unknown benchmark '%s' (available: sky, optics)", what);
}
