/* atmos bench: speed measurements, one machine-readable line per case. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, getpid, isatty, PATH_MAX */
#include "cli.h"
#include "atmos/cache.h"
#include "bench_render.h"
#include "bench_beams.h"
#include "bench_sky.h"
#include "bench_sim.h"

#include <math.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static void help(void)
{
    printf("Usage: atmos bench sky [--size N] [--repeat R] [--threads T] [--models LIST] [--budget S]\n"
           "       atmos bench sky-accuracy [--quick] [--paths N] ... (atmos bench sky-accuracy --help)\n"
           "       atmos bench optics [--fast] [--presets rain,cloud,...] [--threads T]\n"
           "       atmos bench volume [--file FILE] [--repeat R] [--threads T]\n"
           "       atmos bench slice [--file FILE] [--size N] [--repeat R] [--threads T] [--eye-scale S]\n"
           "                         [--no-diffuse | --slice-p1] [--no-air-shadows] [--cold-field]\n"
           "                         [--density-scale S] [--file-only] [--field-ratio] [--json]\n"
           "       atmos bench slice --aerial [--file FILE] [--models LIST] [--density-scale S] [--size N]\n"
           "                         [--repeat R] [--threads T] [--json]\n"
           "       atmos bench path [--file FILE] [--size N] [--spp N] [--density-scale S] [--threads T]\n"
           "                        [--no-forced] [--no-sky-nee] [--no-aureole] [--json]\n"
           "       atmos bench beams [--file SCENE] [--case NAME] [--repeat R] [--threads T]\n"
           "       atmos bench simulate [--size N] [--repeat R] [--threads T]\n\n"
           "  sky     renders an NxN sky (default 1024) with each camera (pinhole, fisheye,\n"
           "          equirect) and wavelength set (rgb, spectral 16), R times (default 5), and\n"
           "          prints per case the best wall time and megapixels per second:\n"
           "            bench=sky camera=pinhole wavelengths=rgb size=1024x1024 threads=2 seconds=0.0401\n"
           "              mpix_per_s=26.1\n"
           "          The time covers rendering the spectral image and converting it to linear sRGB.\n"
           "          Then per atmosphere model (--models, default riley,dobashi,spherical): the time to\n"
           "          create it at rgb (its tables) in an empty private cache and again (best of 2; the\n"
           "          same when the model keeps no cache):\n"
           "            bench=sky case=precompute model=spherical wavelengths=rgb threads=2\n"
           "              precompute_seconds=0.41 cached_seconds=0.01\n"
           "          and the sky renderer's cost per frame of one plan (the camera moving 1 m east a\n"
           "          frame, the sun fixed; best of R) at 720x480, from 2 m above the ground toward the\n"
           "          horizon (90 degree field; case=ground_climb: the camera rising 2 m a frame, so the\n"
           "          per-eye tables are built every frame) and from 36 000 km at the whole Earth (20\n"
           "          degree field; case=space_clouds, the spherical kinds: the same with a synthetic\n"
           "          cloud image on five cloud spheres), with\n"
           "          frames per second for the latter; ns_per_pixel = seconds x threads / pixels,\n"
           "          cpu_ns_per_pixel = the process's CPU time / pixels (best frame; on a loaded\n"
           "          machine the steadier of the two; OMP_WAIT_POLICY=passive leaves out the time\n"
           "          idle threads spend spinning):\n"
           "            bench=sky case=space model=spherical wavelengths=rgb size=720x480 threads=2\n"
           "              seconds=0.0123 ns_per_pixel=71.2 cpu_ns_per_pixel=68.0 fps=81.3\n"
           "          The image grows from 1x1 and 12x8 through 45x30 ... 720x480 (the best of 4 frames\n"
           "          a size: a plan's first two carry one-off work) while the time the last\n"
           "          two sizes predict (a fixed part per frame plus a part per pixel) fits --budget S\n"
           "          seconds per case (default 2); a model too slow for 720x480 is reported at the last\n"
           "          size with extrapolated=1 (fps scaled to 720x480). A larger --budget gives longer,\n"
           "          steadier runs.\n"
           "  optics  Mie scattering at x = 10000, m = 1.33 - 1e-8i, 1801 angles on one thread (best of 3):\n"
           "            bench=optics case=mie x=10000 angles=1801 threads=1 seconds=0.0123\n"
           "          then, per preset (default rain, cloud, ice, snow; --presets to choose) and wavelength\n"
           "          set (rgb, spectral:16), the phase table's cold build (no cache) and its load from the\n"
           "          cache, using a private temporary cache directory (your cache is not touched):\n"
           "            bench=optics case=table preset=rain wavelengths=rgb cold_seconds=1.23\n"
           "              cached_seconds=0.0004\n"
           "          and of the multiple-scattering phase functions built from each table:\n"
           "            bench=optics case=msphase preset=rain wavelengths=rgb orders=121 cold_seconds=...\n"
           "              cached_seconds=...\n"
           "          --fast builds preview-quality tables (atmos phase --fast).\n"
           "  volume  [--file FILE] loads FILE (if given; best of R loads, at most 3) and generates the\n"
           "          'cumulus' preset, then measures on one thread: trilinear samples per second at random\n"
           "          points and along coherent scanlines inside the active bounds, and optical-depth rays\n"
           "          per second (exact DDA with empty-space skipping) between random points on those\n"
           "          bounds; case= the file's name or generated_cumulus (load_s: its generation):\n"
           "            bench=volume case=generated_cumulus load_s=1.2 active_voxels=605554 ...\n"
           "  slice   the half-angle slicing renderer (Riley et al. 2004 Fig. 14: NxN, default 512, 256\n"
           "          slices) on the generated storm and, with --file, on that volume (the Disney cloud),\n"
           "          its densities times --density-scale S (default 1e8 m^-3 per unit of the file's values,\n"
           "          as the Disney cloud's scenes; the storm is in physical units; --file-only leaves the\n"
           "          storm out),\n"
           "          from one plan as an interactive session renders: 8 R frames (default R 3) with the\n"
           "          camera orbiting 3 degrees a frame, then with the sun turning 3 degrees a frame, then\n"
           "          with nothing moving; frames per second of each, end to end (the sky and the\n"
           "          composite included): fps_camera_moving, fps_sun_moving, fps_static; ms_per_frame\n"
           "          (sun moving), ns per sample and the breakdown of a frame (setup, light, eye, sky);\n"
           "          prepare_ms: making the plan (render grid, tables; the optics included).\n"
           "          --eye-scale S renders the eye passes on a buffer S times the image per axis, S in\n"
           "          (0, 1] or 2 (2: four rays per pixel, averaged).\n"
           "          field: the light scattered more than once, do (the default), p1 (--slice-p1: the\n"
           "          diffusion field) or none (--no-diffuse: Eq. 24/25 alone); field_ms: its build\n"
           "          (the source and the solve) after the sun's last move, field_sweeps its sweeps;\n"
           "          the solve starts from the last sun's field, as the viewer's frames do\n"
           "          (warm_field=1), or afresh with --cold-field (warm_field=0);\n"
           "          field_cold_ms, field_cold_sweeps: the plan's first frame's (no warm start).\n"
           "          --no-air-shadows leaves out the volume's shadow on the air (\"air_shadows\", on by\n"
           "          default); air_shadow_ms: its share of the last sun-moving frame (part of sky_ms).\n"
           "          cpu_ms_camera_moving, cpu_ms_sun_moving: the process's CPU time per frame (with\n"
           "          OMP_WAIT_POLICY=passive the work done; steadier than fps on a shared machine).\n"
           "          --field-ratio: instead, the field's cost: two plans of the view, with the field\n"
           "          and without (none), their 8 R sun-moving frames in turns, each frame's CPU time\n"
           "          on its own (bench=slice_field_ratio): cpu_ms_field, cpu_ms_none, ratio (of the\n"
           "          means) and ratio_median (of the frames' ratios: a change of the machine's load\n"
           "          falls on both frames of a pair).\n"
           "          --json prints one JSON object per case.\n"
           "          --aerial: instead, the cost of the atmosphere around a sliced volume: FILE (default\n"
           "          the generated storm) under each model of --models (default riley,spherical), 8 R\n"
           "          frames with the camera orbiting and 8 R with the sun turning; per frame on average\n"
           "          the frame, the sky image, the air in front of the volume (aerial perspective, its\n"
           "          table included) and the sunlight entering the light buffer, and their shares:\n"
           "            bench=slice case=aerial volume=wdas_cloud_sixteenth.vdb model=spherical motion=camera\n"
           "              size=512 threads=2 frames=24\n"
           "              ms_per_frame=98.1 sky_ms=9.5 aerial_ms=2.1 sunlight_ms=0.00 aerial_share=0.021\n"
           "              atmosphere_share=0.118 frame_rms_rel=1.2e-04 frame_max_rel=2.1e-03\n"
           "          aerial_share = (aerial + sunlight) / frame; atmosphere_share adds the sky image;\n"
           "          frame_*_rel: the first frame against one asking the air per pixel (the reference\n"
           "          passes), over the pixel values the volume changes. Densities times\n"
           "          --density-scale S (default 1e8 for FILE, as the Disney cloud's scenes).\n"
           "  path    the path tracer on FILE (default: the generated cumulus) at NxN (default 256), N\n"
           "          samples per pixel (default 16), densities times S (default 1e8 m^-3 per unit of a\n"
           "          VDB file's values, 1 for generated volumes), 'cloud' particles, sun 35° high; once in\n"
           "          vacuum (black background) and once in the sky. Prints paths/s, real scattering events/s,\n"
           "          tentative collisions/s, shadow rays/s, and the time to 1 %% noise extrapolated as\n"
           "          t * (e / 0.01)^2 for two statistics e: the mean over the volume's pixels of the\n"
           "          per-pixel relative standard error of the luminance (t_1pct_pixel_s) and the relative\n"
           "          standard error of the volume's mean luminance (t_1pct_mean_s); the renderer's own\n"
           "          figures over the pixels where a path met the volume (volume_pixels; the mean, median\n"
           "          and 90th percentile of their relative standard errors: volume_rel_se_mean,\n"
           "          volume_rel_se_median, volume_rel_se_p90) and the paths the default depth limit\n"
           "          stopped (cut_paths):\n"
           "            bench=path case=wdas_cloud_sixteenth.vdb background=vacuum size=256x256 spp=16 ...\n"
           "          and, from the same plan, frames per second of 1-sample frames with the camera moving,\n"
           "          the sun moving, or nothing moving (each adding one sample per pixel).\n"
           "          --no-forced, --no-sky-nee and --no-aureole turn off the forced single scattering of\n"
           "          camera rays, next-event estimation toward the sky and the aureole estimate\n"
           "          (docs/path.md), to measure what they gain.\n"
           "  beams   the beam renderer (docs/beams.md) on SCENE (default scenes/dobashi_fig04_spotlight.json,\n"
           "          from the current folder: Dobashi et al. 2002 Fig. 4 at 300x450) and its variants: no\n"
           "          sub-planes (planes at the scene's spacing, 0.3 m, 0.1 m), epsilon 0.03, 2 and 4 lights,\n"
           "          twice the size; without --file also the studio (Fig. 9a), the stained glass\n"
           "          (Fig. 9b), the searchlights and the mountains (Fig. 10a) at 720x480. One plan per\n"
           "          case, then 4 R frames (default 20) with the camera moving a degree round the scene\n"
           "          a frame; one line per case:\n"
           "            bench=beams scene=dobashi_fig04 size=300x450 lights=1 subplanes=on plane_spacing_m=1.2\n"
           "            epsilon=0.01 threads=2 frames=20 plan_seconds=0.05 frame_ms=40.1 best_ms=38.0\n"
           "            cpu_ms=75.2 fps=24.9\n"
           "          (frame_ms: mean wall time a frame; cpu_ms: the process's CPU time a frame, steadier on\n"
           "          a loaded machine; OMP_WAIT_POLICY=passive leaves out idle threads' spinning).\n"
           "          --case NAME runs only the case of that scene= name (e.g. dobashi_fig09a_studio).\n"
           "  simulate the cloud simulation (docs/clouds.md): the towering_cumulus preset on an N grid (default\n"
           "          64, then 128: 64x64x64 and 128x128x128 cells; --size N: N alone, 16..512), one warm-up\n"
           "          step from the initial state and then R steps (default 5); mean and best wall time a\n"
           "          step, the process's CPU time a step and the 1-minute load average:\n"
           "            bench=simulate preset=towering_cumulus grid=128 cells=128x128x128 threads=2 steps=5\n"
           "              ms_per_step=180.2 best_ms=170.1 cpu_ms_per_step=350.3 load=1.02\n");
    fputs(CLI_HELP_EXIT, stdout);
}

static int bench_sky(int size, int repeat, int threads, const char *models, double budget)
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
                double t0 = cli_now_s();
                atmos_status st = atmos_render_sky(ctx, &scene, &spec, NULL);
                if (st == ATMOS_OK) st = atmos_image_to_srgb(ctx, spec, &wl, &rgb);
                double t = cli_now_s() - t0;
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
    return bench_sky_models(threads, repeat, budget, models);
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
        double t0 = cli_now_s();
        atmos_status st = atmos_mie(one, m, 1e4, NANG, mu, s1, s2, &res);
        double t = cli_now_s() - t0;
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
    cli_desc_progress(&d);
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
            fprintf(stderr, "atmos bench: --presets: %s\n", atmos_context_error(ctx));
            rc = CLI_EXIT_USAGE;
            break;
        }
        if (fast) p.fast = 1;
        for (int spectral = 0; spectral < 2 && rc == CLI_EXIT_OK; spectral++) {
            atmos_wavelengths wl;
            if (spectral) atmos_wavelengths_spectral(16, &wl);
            else atmos_wavelengths_rgb(&wl);
            atmos_phase_table *t = NULL;
            atmos_phase_table_desc no = {1}, yes = {0};
            double t0 = cli_now_s();
            st = atmos_phase_table_build(ctx, &p, &wl, &no, &t);
            double cold = cli_now_s() - t0;
            atmos_phase_table_destroy(t);
            t = NULL;
            /* Fill the cache (untimed), then time the load, best of 3. */
            if (st == ATMOS_OK) st = atmos_phase_table_build(ctx, &p, &wl, &yes, &t);
            atmos_phase_table_destroy(t);
            double cached = 1e30;
            int hit = 1;
            for (int r = 0; r < 3 && st == ATMOS_OK; r++) {
                t = NULL;
                t0 = cli_now_s();
                st = atmos_phase_table_build(ctx, &p, &wl, &yes, &t);
                double dt = cli_now_s() - t0;
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
            t0 = cli_now_s();
            if (st == ATMOS_OK) st = atmos_msphase_build(ctx, t, &mno, &ms);
            double mcold = cli_now_s() - t0;
            int orders = ms ? atmos_msphase_max_order(ms) : 0;
            atmos_msphase_destroy(ms);
            ms = NULL;
            if (st == ATMOS_OK) st = atmos_msphase_build(ctx, t, &myes, &ms); /* fill */
            atmos_msphase_destroy(ms);
            double mcached = 1e30;
            for (int r = 0; r < 3 && st == ATMOS_OK; r++) {
                ms = NULL;
                t0 = cli_now_s();
                st = atmos_msphase_build(ctx, t, &myes, &ms);
                double dt = cli_now_s() - t0;
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

static uint64_t bench_rng = 0x9E3779B97F4A7C15ull;
static double bench_u01(void)
{
    bench_rng ^= bench_rng << 13;
    bench_rng ^= bench_rng >> 7;
    bench_rng ^= bench_rng << 17;
    return (double)(bench_rng >> 11) * (1.0 / 9007199254740992.0);
}

/* One line of volume figures: memory, sampling and optical-depth throughput. */
static void bench_volume_case(atmos_context *ctx, const char *name, const atmos_volume *v, double load_s)
{
    int nf = atmos_volume_field_count(v);
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, sigma[ATMOS_VOLUME_MAX_FIELDS];
    unsigned long long active = 0;
    for (int f = 0; f < nf; f++) {
        atmos_volume_field_stats s;
        atmos_volume_field_stats_get(ctx, v, f, &s);
        active += s.active_voxels;
        sigma[f] = s.max > 0 ? 0.05 / s.max : 0; /* ~0.05 optical depth per voxel-metre at the peak */
        if (!s.active_voxels) continue;
        for (int a = 0; a < 3; a++) {
            if (s.bounds_m[0][a] < lo[a]) lo[a] = s.bounds_m[0][a];
            if (s.bounds_m[1][a] > hi[a]) hi[a] = s.bounds_m[1][a];
        }
    }
    if (!active) {
        printf("bench=volume case=%s load_s=%.4f active_voxels=0 (empty volume)\n", name, load_s);
        return;
    }
    const int ns = 2000000, nr = 20000;
    double sink = 0, t0 = cli_now_s();
    for (int n = 0; n < ns; n++) {
        double p[3] = {lo[0] + (hi[0] - lo[0]) * bench_u01(), lo[1] + (hi[1] - lo[1]) * bench_u01(),
                       lo[2] + (hi[2] - lo[2]) * bench_u01()};
        sink += atmos_volume_sample(v, n % nf, p);
    }
    double t_rand = cli_now_s() - t0;
    double step = atmos_volume_get_desc(v)->voxel_size_m * 0.25;
    int per_line = (int)((hi[0] - lo[0]) / step) + 1;
    t0 = cli_now_s();
    for (int n = 0; n < ns;) {
        double p[3] = {lo[0], lo[1] + (hi[1] - lo[1]) * bench_u01(), lo[2] + (hi[2] - lo[2]) * bench_u01()};
        for (int m = 0; m < per_line && n < ns; m++, n++) {
            p[0] = lo[0] + m * step;
            sink += atmos_volume_sample(v, 0, p);
        }
    }
    double t_coh = cli_now_s() - t0;
    double tau_sum = 0;
    t0 = cli_now_s();
    for (int n = 0; n < nr; n++) {
        double a[3], b[3], d[3];
        for (int k = 0; k < 3; k++) {
            a[k] = lo[k] + (hi[k] - lo[k]) * bench_u01();
            b[k] = lo[k] + (hi[k] - lo[k]) * bench_u01();
        }
        int face = n % 3; /* start and end on opposite faces of the active bounds */
        a[face] = lo[face];
        b[face] = hi[face];
        for (int k = 0; k < 3; k++) d[k] = b[k] - a[k];
        tau_sum += atmos_volume_optical_depth(v, sigma, a, d, 0, 1);
    }
    double t_od = cli_now_s() - t0;
    printf("bench=volume case=%s load_s=%.4f active_voxels=%llu memory_bytes=%llu bytes_per_active_voxel=%.2f "
           "random_msamples_per_s=%.2f coherent_msamples_per_s=%.2f od_krays_per_s=%.2f mean_tau=%.3g threads=1%s\n",
           name, load_s, active, (unsigned long long)atmos_volume_memory(v),
           (double)atmos_volume_memory(v) / (double)active, ns / t_rand / 1e6, ns / t_coh / 1e6, nr / t_od / 1e3,
           tau_sum / nr, sink < 0 ? " " : "");
    fflush(stdout);
}

/* A file's values are read as they are (particles per m^3), the benches' density scales on
 * top, as before the density units: their figures stay comparable across versions. */
static const atmos_volume_load_desc bench_load = {.density_unit = ATMOS_DENSITY_PER_M3};

static int bench_volume(const char *file, int repeat, int threads)
{
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    int file_failed = 0;
    if (file) {
        double best = 1e30;
        atmos_volume *v = NULL;
        atmos_status st = ATMOS_OK;
        for (int r = 0; r < repeat && st == ATMOS_OK; r++) {
            atmos_volume_destroy(v);
            v = NULL;
            double t0 = cli_now_s();
            st = atmos_volume_load(ctx, file, &bench_load, &v);
            double t = cli_now_s() - t0;
            if (t < best) best = t;
        }
        if (st != ATMOS_OK) {
            printf("bench=volume case=file file=%s skipped=1 reason=\"%s\"\n", file, atmos_context_error(ctx));
            file_failed = 1;
        } else {
            const char *base = strrchr(file, '/');
            bench_volume_case(ctx, base ? base + 1 : file, v, best);
        }
        atmos_volume_destroy(v);
    }
    atmos_volume_generate_desc g = {.seed = 1};
    atmos_volume *v = NULL;
    double t0 = cli_now_s();
    atmos_status st = atmos_volume_generate(ctx, "cumulus", &g, &v);
    double t = cli_now_s() - t0;
    if (st != ATMOS_OK) {
        int rc = cli_runtime_error("bench", ctx, st);
        atmos_context_destroy(ctx);
        return rc;
    }
    bench_volume_case(ctx, "generated_cumulus", v, t);
    atmos_volume_destroy(v);
    atmos_context_destroy(ctx);
    return file_failed ? CLI_EXIT_RUNTIME : CLI_EXIT_OK; /* a named file that cannot be read is an error */
}

/* The path tracer's cases: FILE (or the generated cumulus), in vacuum then in the sky. */
static int bench_path(const char *file, const bench_path_opts *in, int threads)
{
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    bench_path_opts o = *in;
    atmos_volume *v = NULL;
    atmos_status st;
    const char *name = "generated_cumulus";
    if (file) {
        st = atmos_volume_load(ctx, file, &bench_load, &v);
        const char *base = strrchr(file, '/');
        name = base ? base + 1 : file;
        if (!(o.density_scale > 0)) o.density_scale = 1e8;
    } else {
        atmos_volume_generate_desc g = {.seed = 1};
        st = atmos_volume_generate(ctx, "cumulus", &g, &v);
        if (!(o.density_scale > 0)) o.density_scale = 1;
    }
    int rc = CLI_EXIT_OK;
    if (st != ATMOS_OK) rc = cli_runtime_error("bench", ctx, st);
    for (int vac = 1; rc == CLI_EXIT_OK && vac >= 0; vac--) rc = bench_path_case(ctx, name, v, &o, vac);
    atmos_volume_destroy(v);
    atmos_context_destroy(ctx);
    return rc;
}

/* The aerial-perspective cases: FILE (or the generated storm) under each model. */
static int bench_aerial(const char *file, int size, int frames, int threads, const char *models, double dscale, int json)
{
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_volume *v = NULL;
    atmos_volume_generate_desc g = {.seed = 1};
    atmos_status st = file ? atmos_volume_load(ctx, file, &bench_load, &v) : atmos_volume_generate(ctx, "storm", &g, &v);
    const char *base = file ? strrchr(file, '/') : NULL;
    const char *name = file ? (base ? base + 1 : file) : "generated_storm";
    int rc = st != ATMOS_OK ? cli_runtime_error("bench", ctx, st) : bench_slice_aerial(ctx, name, v, size, frames, models, dscale > 0 ? dscale : (file ? 1e8 : 1), json);
    atmos_volume_destroy(v);
    atmos_context_destroy(ctx);
    return rc;
}

/* The slice renderer's cases: the generated storm (unless file_only) and, with FILE, that volume. */
static int bench_slice(const char *file, int file_only, const bench_slice_opts *o, int threads, double dscale)
{
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    int rc = CLI_EXIT_OK;
    atmos_volume_generate_desc g = {.seed = 1};
    atmos_volume *v = NULL;
    atmos_status st = ATMOS_OK;
    int (*const run)(atmos_context *, const char *, atmos_volume *, double, const bench_slice_opts *) =
        o->field_ratio ? bench_slice_ratio : bench_slice_case;
    if (!file_only) {
        st = atmos_volume_generate(ctx, "storm", &g, &v);
        if (st != ATMOS_OK) rc = cli_runtime_error("bench", ctx, st);
        else rc = run(ctx, "generated_storm", v, 1, o);
        atmos_volume_destroy(v);
        v = NULL;
    }
    if (rc == CLI_EXIT_OK && file) {
        st = atmos_volume_load(ctx, file, &bench_load, &v);
        const char *base = strrchr(file, '/');
        if (st != ATMOS_OK) rc = cli_runtime_error("bench", ctx, st);
        else rc = run(ctx, base ? base + 1 : file, v, dscale > 0 ? dscale : 1e8, o);
        atmos_volume_destroy(v);
    }
    atmos_context_destroy(ctx);
    return rc;
}

/* A comma-separated list of riley, dobashi, spherical. */
static int model_list_ok(const char *list)
{
    static const char *const names[] = {"riley", "dobashi", "spherical"};
    if (!*list) return 0;
    for (const char *t = list; *t;) {
        const size_t len = strcspn(t, ",");
        int found = 0;
        for (int m = 0; m < 3; m++) found |= len == strlen(names[m]) && !strncmp(t, names[m], len);
        if (!found) return 0;
        t += len;
        if (*t == ',' && !*++t) return 0;
    }
    return 1;
}

int cli_cmd_bench(int argc, char **argv)
{
    const char *C = "bench";
    int size = 0, repeat = 5, threads = 0, fast = 0, json = 0, repeat_set = 0, spp = 16, aerial = 0;
    double dscale = 0, eye_scale = 0, budget = 2;
    int field = ATMOS_SLICE_FIELD_AUTO, air_shadows = 1, cold_field = 0, file_only = 0, field_ratio = 0;
    const char *what = NULL, *presets = NULL, *file = NULL, *models = NULL, *beams_case = NULL;
    if (argc > 1 && !strcmp(argv[1], "sky-accuracy")) return bench_sky_accuracy_main(argc - 1, argv + 1);
    bench_path_opts pflags;
    memset(&pflags, 0, sizeof pflags);
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            help();
            return CLI_EXIT_OK;
        } else if (!strcmp(argv[i], "--size") && i + 1 < argc) {
            if (!cli_parse_int(C, "--size", argv[++i], 16, 8192, &size)) return CLI_EXIT_USAGE;
        } else if (!strcmp(argv[i], "--repeat") && i + 1 < argc) {
            if (!cli_parse_int(C, "--repeat", argv[++i], 1, 1000, &repeat)) return CLI_EXIT_USAGE;
            repeat_set = 1;
        } else if (!strcmp(argv[i], "--spp") && i + 1 < argc) {
            if (!cli_parse_int(C, "--spp", argv[++i], 1, ATMOS_PATH_MAX_SPP, &spp)) return CLI_EXIT_USAGE;
        } else if (!strcmp(argv[i], "--density-scale") && i + 1 < argc) {
            if (!cli_parse_double(C, "--density-scale", argv[++i], &dscale)) return CLI_EXIT_USAGE; /* its message given */
            if (!(dscale > 0))
                return cli_usage_error(C, "--density-scale: expected a factor > 0");
        } else if (!strcmp(argv[i], "--eye-scale") && i + 1 < argc) {
            if (!cli_parse_double(C, "--eye-scale", argv[++i], &eye_scale)) return CLI_EXIT_USAGE; /* its message given */
            if (!(eye_scale > 0 && (eye_scale <= 1 || eye_scale == 2)))
                return cli_usage_error(C, "--eye-scale: expected a value in (0, 1] or 2");
        } else if (!strcmp(argv[i], "--no-forced")) {
            pflags.no_forced = 1;
        } else if (!strcmp(argv[i], "--no-sky-nee")) {
            pflags.no_sky_nee = 1;
        } else if (!strcmp(argv[i], "--no-aureole")) {
            pflags.no_aureole = 1;
        } else if (!strcmp(argv[i], "--json")) {
            json = 1;
        } else if (!strcmp(argv[i], "--aerial")) {
            aerial = 1;
        } else if (!strcmp(argv[i], "--diffuse") || !strcmp(argv[i], "--no-diffuse")) {
            field = argv[i][2] == 'd' ? ATMOS_SLICE_FIELD_AUTO : ATMOS_SLICE_FIELD_NONE;
        } else if (!strcmp(argv[i], "--slice-p1") || !strcmp(argv[i], "--slice-do")) {
            field = argv[i][8] == 'p' ? ATMOS_SLICE_FIELD_P1 : ATMOS_SLICE_FIELD_DO;
        } else if (!strcmp(argv[i], "--no-air-shadows")) {
            air_shadows = 0;
        } else if (!strcmp(argv[i], "--cold-field")) {
            cold_field = 1;
        } else if (!strcmp(argv[i], "--file-only")) {
            file_only = 1;
        } else if (!strcmp(argv[i], "--field-ratio")) {
            field_ratio = 1;
        } else if (!strcmp(argv[i], "--threads") && i + 1 < argc) {
            if (!cli_parse_int(C, "--threads", argv[++i], 1, 1024, &threads)) return CLI_EXIT_USAGE;
        } else if (!strcmp(argv[i], "--fast")) {
            fast = 1;
        } else if (!strcmp(argv[i], "--presets") && i + 1 < argc) {
            presets = argv[++i];
            if (!*presets || strlen(presets) >= 256) return cli_usage_error(C, "--presets: expected a list like rain,cloud");
        } else if (!strcmp(argv[i], "--models") && i + 1 < argc) {
            models = argv[++i];
            if (!model_list_ok(models))
                return cli_usage_error(C, "--models: expected a list of riley, dobashi, spherical, got '%s'", models);
        } else if (!strcmp(argv[i], "--budget") && i + 1 < argc) {
            if (!cli_parse_double(C, "--budget", argv[++i], &budget)) return CLI_EXIT_USAGE; /* its message given */
            if (!(budget > 0))
                return cli_usage_error(C, "--budget: expected seconds > 0");
        } else if (!strcmp(argv[i], "--case") && i + 1 < argc) {
            beams_case = argv[++i];
        } else if (!strcmp(argv[i], "--file") && i + 1 < argc) {
            file = argv[++i];
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "unknown or incomplete option '%s'", argv[i]);
        } else if (!what) {
            what = argv[i];
        } else {
            return cli_usage_error(C, "unexpected argument '%s'", argv[i]);
        }
    }
    if (!what) return cli_usage_error(C, "which benchmark? (available: sky, sky-accuracy, optics, volume, slice, path, beams, simulate)");
    if (!strcmp(what, "simulate") && size && (size < ATMOS_SIM_MIN_GRID || size > ATMOS_SIM_MAX_GRID))
        return cli_usage_error(C, "--size: the simulation's grid is in [%d, %d], got %d", ATMOS_SIM_MIN_GRID,
                               ATMOS_SIM_MAX_GRID, size);
    if (!strcmp(what, "simulate")) return bench_simulate(size, repeat, threads);
    if (!strcmp(what, "beams")) return bench_beams(file, 4 * (repeat_set ? repeat : 5), threads, beams_case);
    pflags.size = size ? size : 256, pflags.spp = spp, pflags.density_scale = dscale, pflags.json = json;
    if (!strcmp(what, "path")) return bench_path(file, &pflags, threads);
    if (!strcmp(what, "slice") && aerial)
        return bench_aerial(file, size ? size : 512, 8 * (repeat_set ? repeat : 3), threads, models, dscale, json);
    if (!strcmp(what, "slice")) {
        const bench_slice_opts so = {.size = size ? size : 512, .frames = 8 * (repeat_set ? repeat : 3),
                                     .eye_scale = eye_scale, .field = field, .air_shadows = air_shadows,
                                     .cold_field = cold_field, .field_ratio = field_ratio, .json = json};
        if (file_only && !file) return cli_usage_error(C, "--file-only: give the volume with --file");
        if (field_ratio && field == ATMOS_SLICE_FIELD_NONE)
            return cli_usage_error(C, "--field-ratio: a field to weigh against none (not with --no-diffuse)");
        return bench_slice(file, file_only, &so, threads, dscale);
    }
    if (!strcmp(what, "sky")) return bench_sky(size ? size : 1024, repeat, threads, models, budget);
    if (!strcmp(what, "optics")) return bench_optics(threads, fast, presets);
    if (!strcmp(what, "volume")) return bench_volume(file, repeat < 3 ? repeat : 3, threads);
    return cli_usage_error(C, "unknown benchmark '%s' (available: sky, sky-accuracy, optics, volume, slice, path, beams, simulate)", what);
}
