/* atmos bench: speed measurements, one machine-readable line per case. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, getpid, isatty, PATH_MAX */
#include "cli.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

static void help(void)
{
    printf("Usage: atmos bench sky [--size N] [--repeat R] [--threads T]\n\n"
           "  sky     renders an NxN sky (default 1024) with each camera (pinhole, fisheye,\n"
           "          equirect) and wavelength set (rgb, spectral 16), R times (default 5), and\n"
           "          prints per case the best wall time and megapixels per second:\n"
           "            bench=sky camera=pinhole wavelengths=rgb size=1024x1024 threads=2 seconds=0.0401 mpix_per_s=26.1\n"
           "          The time covers rendering the spectral image and converting it to linear sRGB.\n");
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

int cli_cmd_bench(int argc, char **argv)
{
    const char *C = "bench";
    int size = 1024, repeat = 5, threads = 0;
    const char *what = NULL;
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
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "unknown or incomplete option '%s'", argv[i]);
        } else if (!what) {
            what = argv[i];
        } else {
            return cli_usage_error(C, "unexpected argument '%s'", argv[i]);
        }
    }
    if (!what) return cli_usage_error(C, "which benchmark? (available: sky)");
    if (!strcmp(what, "sky")) return bench_sky(size, repeat, threads);
    return cli_usage_error(C, "unknown benchmark '%s' (available: sky)", what);
}
