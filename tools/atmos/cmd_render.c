/* atmos render: a scene file (or the built-in default) to PNG / EXR / PFM. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, getpid, isatty, PATH_MAX */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <signal.h>
#include <unistd.h>

static void help(void)
{
    printf("Usage: atmos render [SCENE.json] [-o OUT.png] [--exr OUT.exr] [--pfm OUT.pfm] [options]\n\n"
           "Renders a scene file, or the built-in default scene when none is given.\n"
           "With no output option, writes NAME.png in the current directory (NAME = the scene's name).\n\n"
           "Outputs:\n"
           "  -o, --output FILE.png   tone-mapped sRGB PNG (8 or 16 bit, see --png-bits)\n"
           "      --exr FILE.exr      HDR OpenEXR: linear sRGB + alpha, Y in cd/m^2, scene metadata\n"
           "      --pfm FILE.pfm      HDR portable float map (linear sRGB, 3 channels)\n"
           "      --png-bits 8|16     PNG bit depth (default: scene, 8)\n"
           "      --exr-half          write EXR as 16-bit half floats (default: 32-bit float)\n\n"
           "Overrides of the scene's settings:\n"
           "      --width W --height H      image size in pixels\n"
           "      --spp N                   samples per pixel (1..256; path tracer: 1..1000000)\n"
           "      --camera TYPE             pinhole | fisheye (180 deg, looking up) | equirect (360x180 map)\n"
           "      --altitude M              camera altitude above sea level, metres\n"
           "      --sun-elevation E         sun elevation, degrees\n"
           "      --sun-azimuth A           sun azimuth, degrees clockwise from north\n"
           "      --time T --lat L --lon L  sun from a UTC time (2026-06-21T12:00:00Z) and a place\n"
           "      --spectral N              N spectral samples in 380-780 nm (default: the paper's rgb)\n"
           "      --rgb                     the paper's three channels (680, 550, 440 nm)\n"
           "      --exposure EV|auto        manual exposure (EV100, daylight ~15) or automatic\n"
           "      --exposure-comp STOPS     compensation added to automatic exposure\n"
           "      --tone filmic|reinhard|clamp   tone curve for the PNG\n"
           "      --threads N               worker threads (default: all cores)\n"
           "      --renderer sky|slice|path the analytic sky (default), Riley et al.'s half-angle slicing\n"
           "                                over a volume (default when a volume is given), or spectral\n"
           "                                Monte Carlo path tracing (the reference, docs/path.md)\n"
           "      --volume FILE|generate:PRESET   cloud volume (.vdb .nvdb .nc .json) or a generated one\n"
           "                                (cumulus, cumulonimbus, cumulus_field, cirrus, rain_shaft, storm)\n"
           "      --volume-position X,Y,Z   where the centre of the volume box's bottom face goes, metres\n"
           "                                (default: 3 widths, at least 4 km, in front of the camera)\n"
           "      --density-scale S         multiplies the volume's densities\n"
           "      --slices N --xi X         slicing planes (default 256); back-scatter term xi (sr^-1, 0 = none)\n"
           "      --eq24                    exact light-buffer update (Riley Eq. 24) instead of Eq. 25\n"
           "      --low-albedo              single scattering with the plain phase function (Riley Fig. 13)\n"
           "      --eye-scale S             slice: eye buffer resolution relative to the image, (0, 1] (default 1;\n"
           "                                0.5 renders the volume on a quarter of the rays, upsampled)\n"
           "      --tau FILE.pfm            also write the volume's optical depth along each pixel's ray\n"
           "                                (middle wavelength of the set; a key for atmos compare --by)\n"
           "      --time-budget S           path: stop after the pass during which S seconds have passed\n"
           "      --seed N                  path: random seed (default: the scene's, 1; same seed, same image)\n"
           "      --variance FILE.exr       path: per-pixel variance of the mean (channels var_<nm>nm per\n"
           "                                wavelength, then var_Y of the luminance)\n"
           "      --order FILE.pfm          path: per-pixel mean number of volume scattering events of the\n"
           "                                light reaching the pixel, weighted by luminance (1 channel;\n"
           "                                a key for atmos compare --by)\n"
           "      --truncate DEG            path: cut the phase functions' forward peak at DEG degrees\n"
           "                                (0..20; 0 = exact, the default): the part above P(DEG) inside\n"
           "                                the cone counts as unscattered. Far less noise in droplet\n"
           "                                clouds; changes light within ~DEG of the forward direction\n"
           "      --no-sky-nee              path: no next-event estimation toward the sky (same mean,\n"
           "                                more noise; for comparisons)\n"
           "      --no-forced               path: no forced single scattering on camera rays (same\n"
           "                                mean, more noise in thin media; for comparisons)\n"
           "      --no-aureole              path: no aureole estimate in droplet clouds (same mean,\n"
           "                                more fireflies; for comparisons)\n\n"
           "Animation (the sun moves; the volume and its optics tables are prepared once):\n"
           "      --frames N                render N frames (default: the scene's \"animation\", else 1);\n"
           "                                more than one frame numbers the outputs: -o out/sky.png writes\n"
           "                                out/sky_0001.png ...; --frames 1: the first frame, as named\n"
           "      --time-end T              the last frame's UTC time (a sun given by time); frames are\n"
           "                                spaced evenly in time from the scene's (or --time's) time\n"
           "      --sun-elevation-end E     the last frame's sun elevation (a sun given by angles)\n"
           "      --sun-azimuth-end A       the last frame's sun azimuth (the shorter way round)\n"
           "  -q, --quiet                   no progress bar or messages\n"
           "  -h, --help                    this help\n\n"
           "Examples:\n"
           "  atmos render -o sky.png --exr sky.exr\n"
           "  atmos render scenes/sunset_fisheye.json --spectral 32 -o sunset.png\n"
           "  atmos render --camera equirect --width 2048 --height 1024 --exr env.exr\n"
           "  atmos render scenes/fig01_cirrus_sunrise.json --frames 8 --time-end 2026-06-21T12:30:00Z -o out/cirrus.png\n");
}

/* Temporary names of the outputs (atmos__write_atomic writes PATH.tmpPID): on SIGINT or
 * SIGTERM they are removed before exiting, so an interrupted run leaves nothing behind. */
static char tmp_names[3][4200];
static void on_signal(int sig)
{
    for (int i = 0; i < 3; i++)
        if (tmp_names[i][0]) unlink(tmp_names[i]); /* async-signal-safe */
    signal(sig, SIG_DFL);
    raise(sig);
}

static void protect_outputs(const char *png, const char *exr, const char *pfm)
{
    const char *outs[3] = {png, exr, pfm};
    for (int i = 0; i < 3; i++) {
        tmp_names[i][0] = '\0';
        if (outs[i]) snprintf(tmp_names[i], sizeof tmp_names[i], "%s.tmp%ld", outs[i], (long)getpid());
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
}

/* The name of frame `frame` (1-based) of an animation: "_0001" before the extension of
 * the file name (out/sky.png -> out/sky_0001.png; no extension: appended). digits >= 4. */
static int frame_name(const char *base, int frame, int digits, char *buf, size_t cap)
{
    const char *slash = strrchr(base, '/'), *dot = strrchr(base, '.');
    size_t stem = dot && dot > (slash ? slash : base) && dot[1] ? (size_t)(dot - base) : strlen(base);
    int n = snprintf(buf, cap, "%.*s_%0*d%s", (int)stem, base, digits, frame, base + stem);
    return n > 0 && (size_t)n < cap;
}

static void default_png_name(const char *scene_name, char *buf, size_t cap)
{
    size_t j = 0;
    for (size_t i = 0; scene_name[i] && j + 5 < cap; i++) {
        char c = scene_name[i];
        buf[j++] = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ? c : '_';
    }
    if (j == 0) buf[j++] = 'a', buf[j++] = 't', buf[j++] = 'm', buf[j++] = 'o', buf[j++] = 's';
    snprintf(buf + j, cap - j, ".png");
}

enum {
    O_EXR = 256, O_PFM, O_PNGBITS, O_EXRHALF, O_W, O_H, O_SPP, O_CAM, O_ALT, O_SEL, O_SAZ, O_TIME, O_LAT, O_LON,
    O_SPECTRAL, O_RGB, O_EXPOSURE, O_EXPCOMP, O_TONE, O_THREADS, O_RENDERER, O_VOLUME, O_SLICES, O_XI, O_VPOS,
    O_DSCALE, O_EQ24, O_LOWALB, O_TAU, O_TBUDGET, O_SEED, O_VARIANCE, O_FRAMES, O_TIME_END, O_SEL_END, O_SAZ_END, O_ORDER,
    O_TRUNCATE
};
enum { O_EYESCALE = 512, O_NOSKYNEE, O_NOFORCED, O_NOAUREOLE }; /* slice renderer options added later */

/* The volume's optical depth along each pixel's ray at the middle wavelength of the
 * set, as a 1-channel PFM (the optics come from the cache the render just filled). */
static atmos_status write_tau(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *vol,
                              const double offset[3], const char *path)
{
    atmos_volume_optics o;
    atmos_status st = atmos_volume_optics_build(ctx, scene, vol, 1, &o);
    if (st != ATMOS_OK) return st;
    double sigma[ATMOS_VOLUME_MAX_FIELDS] = {0};
    for (int f = 0; f < o.count; f++) {
        int k = atmos_phase_table_wavelength_count(o.phase[f]) / 2;
        sigma[f] = atmos_phase_table_sigma_ext(o.phase[f], k) * scene->volume.density_scale;
    }
    atmos_volume_optics_free(&o);
    atmos_image *img = NULL;
    if ((st = atmos_render_optical_depth(ctx, scene, vol, sigma, offset, &img)) != ATMOS_OK) return st;
    st = atmos_write_pfm(ctx, img, path);
    atmos_image_destroy(img);
    return st;
}

/* A UTC time option; on failure reports it, destroys ctx and returns 0. */
static int parse_time_option(atmos_context *ctx, const char *option, const char *text, atmos_utc_time *out)
{
    if (atmos_parse_utc_time(ctx, text, out) == ATMOS_OK) return 1;
    fprintf(stderr, "atmos render: %s: %s\n", option, atmos_context_error(ctx));
    atmos_context_destroy(ctx);
    return 0;
}

/* The slice renderer's settings from a scene (the scene's xi 0 means "none"). */
static void slice_settings(const atmos_scene *s, const double offset[3], atmos_slice_settings *ss)
{
    atmos_slice_defaults(ss);
    ss->slices = s->slice.slices;
    ss->light_size = s->slice.light_size;
    ss->xi = s->slice.xi > 0 ? s->slice.xi : -1.0;
    ss->update = s->slice.eq24 ? ATMOS_SLICE_EQ24 : ATMOS_SLICE_EQ25;
    ss->low_albedo = s->slice.low_albedo;
    ss->grid_max_dim = s->slice.grid_max_dim;
    ss->eye_scale = s->slice.eye_scale;
    ss->density_scale = s->volume.density_scale;
    for (int k = 0; k < 3; k++) ss->offset_m[k] = offset[k];
}

int cli_cmd_render(int argc, char **argv)
{
    static const struct option opts[] = {
        {"output", required_argument, 0, 'o'}, {"exr", required_argument, 0, O_EXR},
        {"pfm", required_argument, 0, O_PFM}, {"png-bits", required_argument, 0, O_PNGBITS},
        {"exr-half", no_argument, 0, O_EXRHALF}, {"width", required_argument, 0, O_W},
        {"height", required_argument, 0, O_H}, {"spp", required_argument, 0, O_SPP},
        {"camera", required_argument, 0, O_CAM}, {"altitude", required_argument, 0, O_ALT},
        {"sun-elevation", required_argument, 0, O_SEL}, {"sun-azimuth", required_argument, 0, O_SAZ},
        {"time", required_argument, 0, O_TIME}, {"lat", required_argument, 0, O_LAT},
        {"lon", required_argument, 0, O_LON}, {"spectral", required_argument, 0, O_SPECTRAL},
        {"rgb", no_argument, 0, O_RGB}, {"exposure", required_argument, 0, O_EXPOSURE},
        {"exposure-comp", required_argument, 0, O_EXPCOMP}, {"tone", required_argument, 0, O_TONE},
        {"threads", required_argument, 0, O_THREADS}, {"quiet", no_argument, 0, 'q'},
        {"renderer", required_argument, 0, O_RENDERER}, {"volume", required_argument, 0, O_VOLUME},
        {"slices", required_argument, 0, O_SLICES}, {"xi", required_argument, 0, O_XI},
        {"volume-position", required_argument, 0, O_VPOS}, {"density-scale", required_argument, 0, O_DSCALE},
        {"eq24", no_argument, 0, O_EQ24}, {"low-albedo", no_argument, 0, O_LOWALB},
        {"tau", required_argument, 0, O_TAU}, {"eye-scale", required_argument, 0, O_EYESCALE},
        {"time-budget", required_argument, 0, O_TBUDGET}, {"seed", required_argument, 0, O_SEED},
        {"variance", required_argument, 0, O_VARIANCE},
        {"frames", required_argument, 0, O_FRAMES}, {"time-end", required_argument, 0, O_TIME_END},
        {"sun-elevation-end", required_argument, 0, O_SEL_END}, {"sun-azimuth-end", required_argument, 0, O_SAZ_END},
        {"order", required_argument, 0, O_ORDER}, {"truncate", required_argument, 0, O_TRUNCATE},
        {"no-sky-nee", no_argument, 0, O_NOSKYNEE}, {"no-forced", no_argument, 0, O_NOFORCED},
        {"no-aureole", no_argument, 0, O_NOAUREOLE},
        {"help", no_argument, 0, 'h'}, {0, 0, 0, 0}};
    const char *C = "render";
    const char *png = NULL, *exr = NULL, *pfm = NULL;
    const char *time_s = NULL;
    double lat = NAN, lon = NAN;
    int threads = 0, quiet = 0, c;
    /* Overrides are collected first and applied after the scene is loaded. */
    int w = 0, h = 0, spp = 0, png_bits = 0, exr_half = 0, spectral = 0, rgb = 0, cam_type = -1;
    double alt = NAN, sel = NAN, saz = NAN, ev = NAN, evcomp = NAN;
    int exposure_auto = 0, tone = -1;
    /* Volume renderers: these override the scene's "renderer", "volume" and "slice". */
    int renderer = -1, slices = 0, eq24 = 0, low_albedo = 0;
    const char *volume_arg = NULL, *tau_path = NULL;
    double xi = NAN, dscale = 0, vpos[3] = {0, 0, 0}, eye_scale = 0;
    int vpos_given = 0;
    /* The path tracer (path.h): these override the scene's "path". */
    double tbudget = 0, truncate = NAN;
    unsigned long long seed = 0;
    int seed_given = 0, no_sky_nee = 0, no_forced = 0, no_aureole = 0;
    const char *variance_out = NULL, *order_out = NULL;
    atmos_image *var_img = NULL, *order_img = NULL;
    atmos_path_stats pstats;
    memset(&pstats, 0, sizeof pstats);
    /* Animation. */
    int frames = 0;
    const char *time_end_s = NULL;
    double sel_end = NAN, saz_end = NAN;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:qh", opts, NULL)) != -1) {
        switch (c) {
        case 'o': png = optarg; break;
        case O_EXR: exr = optarg; break;
        case O_PFM: pfm = optarg; break;
        case O_PNGBITS:
            if (!cli_parse_int(C, "--png-bits", optarg, 8, 16, &png_bits) || (png_bits != 8 && png_bits != 16))
                return cli_usage_error(C, "--png-bits: must be 8 or 16");
            break;
        case O_EXRHALF: exr_half = 1; break;
        case O_W: if (!cli_parse_int(C, "--width", optarg, 1, ATMOS_SCENE_MAX_DIM, &w)) return CLI_EXIT_USAGE; break;
        case O_H: if (!cli_parse_int(C, "--height", optarg, 1, ATMOS_SCENE_MAX_DIM, &h)) return CLI_EXIT_USAGE; break;
        case O_SPP: if (!cli_parse_int(C, "--spp", optarg, 1, ATMOS_PATH_MAX_SPP, &spp)) return CLI_EXIT_USAGE; break;
        case O_CAM:
            if (!strcmp(optarg, "pinhole")) cam_type = ATMOS_CAMERA_PINHOLE;
            else if (!strcmp(optarg, "fisheye")) cam_type = ATMOS_CAMERA_FISHEYE;
            else if (!strcmp(optarg, "equirect")) cam_type = ATMOS_CAMERA_EQUIRECT;
            else return cli_usage_error(C, "--camera: expected pinhole, fisheye or equirect, got '%s'", optarg);
            break;
        case O_ALT: if (!cli_parse_double(C, "--altitude", optarg, &alt)) return CLI_EXIT_USAGE; break;
        case O_SEL: if (!cli_parse_double(C, "--sun-elevation", optarg, &sel)) return CLI_EXIT_USAGE; break;
        case O_SAZ: if (!cli_parse_double(C, "--sun-azimuth", optarg, &saz)) return CLI_EXIT_USAGE; break;
        case O_TIME: time_s = optarg; break;
        case O_LAT: if (!cli_parse_double(C, "--lat", optarg, &lat)) return CLI_EXIT_USAGE; break;
        case O_LON: if (!cli_parse_double(C, "--lon", optarg, &lon)) return CLI_EXIT_USAGE; break;
        case O_SPECTRAL: if (!cli_parse_int(C, "--spectral", optarg, 1, ATMOS_MAX_WAVELENGTHS, &spectral)) return CLI_EXIT_USAGE; break;
        case O_RGB: rgb = 1; break;
        case O_EXPOSURE:
            if (!strcmp(optarg, "auto")) exposure_auto = 1;
            else if (!cli_parse_double(C, "--exposure", optarg, &ev)) return CLI_EXIT_USAGE;
            break;
        case O_EXPCOMP: if (!cli_parse_double(C, "--exposure-comp", optarg, &evcomp)) return CLI_EXIT_USAGE; break;
        case O_TONE:
            if (!strcmp(optarg, "filmic")) tone = ATMOS_TONE_FILMIC;
            else if (!strcmp(optarg, "reinhard")) tone = ATMOS_TONE_REINHARD;
            else if (!strcmp(optarg, "clamp")) tone = ATMOS_TONE_CLAMP;
            else return cli_usage_error(C, "--tone: expected filmic, reinhard or clamp, got '%s'", optarg);
            break;
        case O_THREADS: if (!cli_parse_int(C, "--threads", optarg, 1, 1024, &threads)) return CLI_EXIT_USAGE; break;
        case O_RENDERER:
            if (!strcmp(optarg, "sky")) renderer = ATMOS_RENDERER_SKY;
            else if (!strcmp(optarg, "slice")) renderer = ATMOS_RENDERER_SLICE;
            else if (!strcmp(optarg, "path")) renderer = ATMOS_RENDERER_PATH;
            else return cli_usage_error(C, "--renderer: expected sky, slice or path, got '%s'", optarg);
            break;
        case O_VOLUME: volume_arg = optarg; break;
        case O_SLICES: if (!cli_parse_int(C, "--slices", optarg, 1, 8192, &slices)) return CLI_EXIT_USAGE; break;
        case O_XI:
            if (!cli_parse_double(C, "--xi", optarg, &xi) || !(xi >= 0 && xi <= 100))
                return cli_usage_error(C, "--xi: expected a value in [0, 100] sr^-1 (0 = no back-scatter term)");
            break;
        case O_EQ24: eq24 = 1; break;
        case O_EYESCALE:
            if (!cli_parse_double(C, "--eye-scale", optarg, &eye_scale) || !(eye_scale > 0 && eye_scale <= 1))
                return cli_usage_error(C, "--eye-scale: expected a value in (0, 1] (eye buffer resolution per axis)");
            break;
        case O_TAU: tau_path = optarg; break;
        case O_LOWALB: low_albedo = 1; break;
        case O_DSCALE:
            if (!cli_parse_double(C, "--density-scale", optarg, &dscale) || !(dscale > 0))
                return cli_usage_error(C, "--density-scale: expected a factor > 0");
            break;
        case O_VPOS: {
            char tail;
            if (sscanf(optarg, "%lf,%lf,%lf%c", &vpos[0], &vpos[1], &vpos[2], &tail) != 3 || !isfinite(vpos[0]) ||
                !isfinite(vpos[1]) || !isfinite(vpos[2]))
                return cli_usage_error(C, "--volume-position: expected X,Y,Z in metres, got '%s'", optarg);
            vpos_given = 1;
            break;
        }
        case O_TBUDGET:
            if (!cli_parse_double(C, "--time-budget", optarg, &tbudget) || !(tbudget > 0) || !isfinite(tbudget))
                return cli_usage_error(C, "--time-budget: expected seconds > 0");
            break;
        case O_SEED: {
            char *end = NULL;
            seed = strtoull(optarg, &end, 10);
            if (!*optarg || *end || optarg[0] == '-')
                return cli_usage_error(C, "--seed: expected a non-negative integer, got '%s'", optarg);
            seed_given = 1;
            break;
        }
        case O_VARIANCE: variance_out = optarg; break;
        case O_FRAMES: if (!cli_parse_int(C, "--frames", optarg, 1, ATMOS_SCENE_MAX_FRAMES, &frames)) return CLI_EXIT_USAGE; break;
        case O_TIME_END: time_end_s = optarg; break;
        case O_SEL_END: if (!cli_parse_double(C, "--sun-elevation-end", optarg, &sel_end)) return CLI_EXIT_USAGE; break;
        case O_SAZ_END: if (!cli_parse_double(C, "--sun-azimuth-end", optarg, &saz_end)) return CLI_EXIT_USAGE; break;
        case O_ORDER: order_out = optarg; break;
        case O_TRUNCATE:
            if (!cli_parse_double(C, "--truncate", optarg, &truncate) || !(truncate >= 0 && truncate <= 20))
                return cli_usage_error(C, "--truncate: expected degrees in [0, 20]");
            break;
        case O_NOSKYNEE: no_sky_nee = 1; break;
        case O_NOFORCED: no_forced = 1; break;
        case O_NOAUREOLE: no_aureole = 1; break;
        case 'q': quiet = 1; break;
        case 'h': help(); return CLI_EXIT_OK;
        default: return cli_usage_error(C, "unknown or incomplete option '%s'", argv[optind - 1]);
        }
    }
    const char *scene_path = NULL;
    if (optind < argc) scene_path = argv[optind++];
    if (optind < argc) return cli_usage_error(C, "unexpected argument '%s' (one scene file at most)", argv[optind]);
    if (spectral && rgb) return cli_usage_error(C, "--spectral and --rgb exclude each other");
    int use_time = time_s || !isnan(lat) || !isnan(lon);
    if (use_time && (!time_s || isnan(lat) || isnan(lon)))
        return cli_usage_error(C, "--time, --lat and --lon go together");
    if (use_time && (!isnan(sel) || !isnan(saz)))
        return cli_usage_error(C, "--time/--lat/--lon and --sun-elevation/--sun-azimuth exclude each other");
    if (exposure_auto && !isnan(ev)) return cli_usage_error(C, "--exposure given twice");
    if (renderer == ATMOS_RENDERER_SKY &&
        (volume_arg || slices || !isnan(xi) || dscale > 0 || vpos_given || eq24 || low_albedo || tau_path ||
         eye_scale > 0))
        return cli_usage_error(C, "--volume, --volume-position, --density-scale, --slices, --xi, --eq24, --low-albedo, "
                                  "--eye-scale and --tau go with a volume renderer, not --renderer sky");
    if (time_end_s && (!isnan(sel_end) || !isnan(saz_end)))
        return cli_usage_error(C, "--time-end (a sun given by time) and --sun-elevation-end/--sun-azimuth-end "
                                  "(a sun given by angles) exclude each other");
    if (volume_arg && strlen(volume_arg) >= sizeof(((atmos_scene *)0)->volume.source))
        return cli_usage_error(C, "--volume: the path is too long");

    cli_progress prog;
    cli_progress_init(&prog, quiet);
    atmos_context *ctx = cli_context_with_progress(threads, quiet, cli_progress_bar, &prog);
    if (!ctx) return CLI_EXIT_RUNTIME;

    atmos_scene scene;
    atmos_status st;
    const char *source = scene_path ? scene_path : "default scene";
    /* Released at fail: */
    atmos_volume *vol = NULL;
    atmos_volume_optics optics;
    memset(&optics, 0, sizeof optics);
    atmos_image *spec = NULL, *lin = NULL, *disp = NULL;
    int frame = 0, nframes = 1, numbered = 0;
    if (scene_path) {
        if ((st = atmos_scene_load(ctx, scene_path, &scene)) != ATMOS_OK) goto fail;
    } else {
        atmos_scene_defaults(&scene);
    }
    if (w) scene.width = w;
    if (h) scene.height = h;
    if (png_bits) scene.png_bits = png_bits;
    if (exr_half) scene.exr_half = 1;
    if (cam_type >= 0 && cam_type != (int)scene.camera.type) {
        /* A new camera type starts from that type's defaults, keeping the position. */
        double pos[3] = {scene.camera.position[0], scene.camera.position[1], scene.camera.position[2]};
        atmos_camera_defaults((atmos_camera_type)cam_type, pos, &scene.camera);
    }
    if (!isnan(alt)) {
        double dy = alt - scene.camera.position[1];
        scene.camera.position[1] = alt;
        scene.camera.look_at[1] += dy; /* keep the view direction */
    }
    if (!isnan(sel) || !isnan(saz)) {
        if (scene.sun.from_time) {
            /* Overriding one angle of a sun placed by time keeps the other one it had. */
            double dir[3], el = 0, az = 0;
            if (atmos_scene_sun_direction(ctx, &scene, dir, &el, &az) == ATMOS_OK)
                scene.sun.elevation_deg = el, scene.sun.azimuth_deg = az;
        }
        scene.sun.from_time = 0;
        if (!isnan(sel)) scene.sun.elevation_deg = sel;
        if (!isnan(saz)) scene.sun.azimuth_deg = saz;
    }
    if (use_time) {
        if (!parse_time_option(ctx, "--time", time_s, &scene.sun.time)) return CLI_EXIT_USAGE;
        scene.sun.from_time = 1;
        scene.sun.latitude_deg = lat;
        scene.sun.longitude_deg = lon;
    }
    /* A sun switched to the other form on the command line drops the scene's end of the old form. */
    if (use_time) scene.animation.elevation_end_set = scene.animation.azimuth_end_set = 0;
    if (!isnan(sel) || !isnan(saz)) scene.animation.time_end_set = 0;
    if (frames) scene.animation.frames = frames;
    if (time_end_s) {
        if (!parse_time_option(ctx, "--time-end", time_end_s, &scene.animation.time_end)) return CLI_EXIT_USAGE;
        scene.animation.time_end_set = 1;
    }
    if (!isnan(sel_end)) scene.animation.elevation_end_deg = sel_end, scene.animation.elevation_end_set = 1;
    if (!isnan(saz_end)) scene.animation.azimuth_end_deg = saz_end, scene.animation.azimuth_end_set = 1;
    if ((time_end_s || !isnan(sel_end) || !isnan(saz_end)) && scene.animation.frames < 2) {
        atmos_context_destroy(ctx);
        return cli_usage_error(C, "--time-end, --sun-elevation-end and --sun-azimuth-end need --frames N (N >= 2) "
                                  "or a scene with an \"animation\"");
    }
    if (spectral) scene.wavelengths = ATMOS_WAVELENGTHS_SPECTRAL, scene.spectral_samples = spectral;
    if (rgb) scene.wavelengths = ATMOS_WAVELENGTHS_RGB;
    if (exposure_auto) scene.tonemap.manual_exposure = 0;
    if (!isnan(ev)) scene.tonemap.manual_exposure = 1, scene.tonemap.exposure_ev = ev;
    if (!isnan(evcomp)) {
        if (scene.tonemap.manual_exposure) {
            atmos_context_destroy(ctx);
            return cli_usage_error(C, "--exposure-comp applies to automatic exposure only");
        }
        scene.tonemap.exposure_ev = evcomp;
    }
    if (tone >= 0) scene.tonemap.curve = (atmos_tone_curve)tone;
    if (volume_arg) {
        snprintf(scene.volume.source, sizeof scene.volume.source, "%s", volume_arg);
        if (scene.renderer == ATMOS_RENDERER_SKY) scene.renderer = ATMOS_RENDERER_SLICE;
    }
    if (renderer >= 0) scene.renderer = (atmos_renderer_kind)renderer;
    if (scene.renderer == ATMOS_RENDERER_PATH) {
        if (spp) scene.path.spp = spp;
        if (tbudget > 0) scene.path.time_budget_s = tbudget;
        if (seed_given) scene.path.seed = seed;
        if (!isnan(truncate)) scene.path.truncate_deg = truncate;
    } else if (spp > 256 || tbudget > 0 || seed_given || variance_out || order_out || !isnan(truncate) || no_sky_nee || no_forced || no_aureole) {
        atmos_context_destroy(ctx);
        return cli_usage_error(C, spp > 256 ? "--spp: must be in [1, 256] for this renderer (1..1000000 with --renderer path)"
                                            : "--time-budget, --seed, --variance, --order, --truncate and --no-* go with --renderer path");
    } else if (spp) {
        scene.samples_per_pixel = spp;
    }
    if (vpos_given) {
        scene.volume.placed = 1;
        memcpy(scene.volume.position_m, vpos, sizeof vpos);
    }
    if (dscale > 0) scene.volume.density_scale = dscale;
    if (slices) scene.slice.slices = slices;
    if (!isnan(xi)) scene.slice.xi = xi;
    if (eq24) scene.slice.eq24 = 1;
    if (low_albedo) scene.slice.low_albedo = 1;
    if (eye_scale > 0) scene.slice.eye_scale = eye_scale;
    if (tau_path && scene.renderer == ATMOS_RENDERER_SKY) {
        atmos_context_destroy(ctx);
        return cli_usage_error(C, "--tau needs a volume (--volume or a scene with one)");
    }
    if (!scene_path && scene.renderer == ATMOS_RENDERER_SLICE && !scene.volume.source[0]) {
        atmos_context_destroy(ctx);
        return cli_usage_error(C, "--renderer slice needs --volume FILE or --volume generate:PRESET");
    }
    if ((st = atmos_scene_validate(ctx, &scene, scene_path ? scene_path : "options")) != ATMOS_OK) {
        fprintf(stderr, "atmos render: %s\n", atmos_context_error(ctx));
        atmos_context_destroy(ctx);
        return scene_path ? CLI_EXIT_RUNTIME : CLI_EXIT_USAGE;
    }

    char default_png[160];
    if (!png && !exr && !pfm) {
        default_png_name(scene.name, default_png, sizeof default_png);
        png = default_png;
    }

    /* An animation writes numbered files; the volume and the optics tables are built once. */
    nframes = scene.animation.frames > 1 ? scene.animation.frames : 1;
    numbered = nframes > 1;
    int digits = 4;
    for (int n = nframes; n >= 10000; n /= 10) digits++;
    double offset[3] = {0, 0, 0};
    atmos_render_info info;
    atmos_wavelengths wl;
    static char png_i[4200], exr_i[4200], pfm_i[4200], var_i[4200], ord_i[4200];
    if ((st = atmos_scene_wavelengths(ctx, &scene, &wl)) != ATMOS_OK) goto fail;
    /* The path tracer may render without a volume (sky and ground only). */
    if (scene.volume.source[0] && scene.renderer != ATMOS_RENDERER_SKY) {
        if ((st = atmos_scene_load_volume(ctx, &scene, &vol, offset)) != ATMOS_OK) goto fail;
        if (scene.renderer == ATMOS_RENDERER_SLICE) st = atmos_volume_optics_build(ctx, &scene, vol, 1, &optics);
        else st = atmos_volume_optics_build(ctx, &scene, vol, 0, &optics);
        if (st != ATMOS_OK) goto fail;
        if (tau_path && (st = write_tau(ctx, &scene, vol, offset, tau_path)) != ATMOS_OK) goto fail;
    }
    double total_seconds = 0;
    for (frame = 1; frame <= nframes; frame++) {
        atmos_scene fs;
        if ((st = atmos_scene_animation_frame(ctx, &scene, frame - 1, &fs)) != ATMOS_OK) goto fail;
        const char *o_png = png, *o_exr = exr, *o_pfm = pfm, *o_var = variance_out, *o_ord = order_out;
        if (numbered) {
            if ((png && !frame_name(png, frame, digits, png_i, sizeof png_i)) ||
                (exr && !frame_name(exr, frame, digits, exr_i, sizeof exr_i)) ||
                (pfm && !frame_name(pfm, frame, digits, pfm_i, sizeof pfm_i)) ||
                (variance_out && !frame_name(variance_out, frame, digits, var_i, sizeof var_i)) ||
                (order_out && !frame_name(order_out, frame, digits, ord_i, sizeof ord_i))) {
                st = ATMOS_E_INVALID_ARG;
                fprintf(stderr, "atmos render: an output path is too long for numbered frames\n");
                goto fail_quiet;
            }
            o_png = png ? png_i : NULL, o_exr = exr ? exr_i : NULL, o_pfm = pfm ? pfm_i : NULL;
            o_var = variance_out ? var_i : NULL;
            o_ord = order_out ? ord_i : NULL;
        }
        protect_outputs(o_png, o_exr, o_pfm);
        if (scene.renderer == ATMOS_RENDERER_SLICE) {
            atmos_slice_settings ss;
            slice_settings(&fs, offset, &ss);
            ss.optics = &optics;
            if ((st = atmos_render_slice(ctx, &fs, vol, &ss, &spec, &info)) != ATMOS_OK) goto fail;
        } else if (scene.renderer == ATMOS_RENDERER_PATH) {
            atmos_path_settings ps;
            memset(&ps, 0, sizeof ps); /* zero: the scene's "path" settings */
            ps.density_scale = fs.volume.density_scale;
            memcpy(ps.offset_m, offset, sizeof offset);
            ps.optics = vol ? &optics : NULL;
            ps.variance = o_var ? &var_img : NULL;
            ps.order = o_ord ? &order_img : NULL;
            ps.stats = &pstats;
            ps.no_sky_nee = no_sky_nee;
            ps.no_forced = no_forced;
            ps.no_aureole = no_aureole;
            if ((st = atmos_render_path(ctx, &fs, vol, &ps, &spec, &info)) != ATMOS_OK) goto fail;
        } else if ((st = atmos_render_sky(ctx, &fs, &spec, &info)) != ATMOS_OK) {
            goto fail;
        }
        if ((st = atmos_image_to_srgb(ctx, spec, &wl, &lin)) != ATMOS_OK) goto fail;
        atmos_image_set_meta(lin, "atmos:source", source);
        if (numbered) {
            char buf[64];
            snprintf(buf, sizeof buf, "%d/%d", frame, nframes);
            atmos_image_set_meta(lin, "atmos:frame", buf);
        }
        if (o_exr) {
            atmos_exr_desc ed = {fs.exr_half, NULL};
            if ((st = atmos_write_exr(ctx, lin, o_exr, &ed)) != ATMOS_OK) goto fail;
        }
        if (o_pfm && (st = atmos_write_pfm(ctx, lin, o_pfm)) != ATMOS_OK) goto fail;
        if (var_img && o_var) {
            static char names[ATMOS_MAX_WAVELENGTHS + 1][24];
            const char *np[ATMOS_MAX_WAVELENGTHS + 1];
            for (int k = 0; k < wl.count; k++) {
                snprintf(names[k], sizeof names[k], "var_%.1fnm", wl.nm[k]);
                np[k] = names[k];
            }
            np[wl.count] = "var_Y";
            atmos_exr_desc ed = {0, np};
            atmos_image_set_meta(var_img, "atmos:source", source);
            if ((st = atmos_write_exr(ctx, var_img, o_var, &ed)) != ATMOS_OK) goto fail;
        }
        if (order_img && o_ord) {
            atmos_image_set_meta(order_img, "atmos:source", source);
            if ((st = atmos_write_pfm(ctx, order_img, o_ord)) != ATMOS_OK) goto fail;
        }
        if (o_png) {
            char buf[64];
            double scale = atmos_tonemap_scale(lin, &fs.tonemap);
            snprintf(buf, sizeof buf, "%.6g", scale);
            atmos_image_set_meta(lin, "atmos:exposure_scale", buf);
            if ((st = atmos_tonemap(ctx, lin, &fs.tonemap, &disp)) != ATMOS_OK) goto fail;
            if ((st = atmos_write_png(ctx, disp, o_png, fs.png_bits ? fs.png_bits : 8)) != ATMOS_OK) goto fail;
        }
        total_seconds += info.seconds;
        if (!quiet) {
            if (prog.shown) fputc('\n', stderr), prog.shown = 0;
            if (numbered) fprintf(stderr, "atmos render: frame %d/%d: ", frame, nframes);
            else fprintf(stderr, "atmos render: ");
            fprintf(stderr, "%s, %dx%d, sun at %.2f deg elevation / %.2f deg azimuth, %.3f s\n", source, fs.width,
                    fs.height, info.sun_elevation_deg, info.sun_azimuth_deg, info.seconds);
            if (o_png) fprintf(stderr, "  wrote %s\n", o_png);
            if (o_exr) fprintf(stderr, "  wrote %s\n", o_exr);
            if (o_pfm) fprintf(stderr, "  wrote %s\n", o_pfm);
            if (var_img && o_var) fprintf(stderr, "  wrote %s\n", o_var);
            if (order_img && o_ord) fprintf(stderr, "  wrote %s\n", o_ord);
            if (scene.renderer == ATMOS_RENDERER_PATH)
                fprintf(stderr, "  path: %d spp, %lld scattering events, mean relative standard error %.2f %%\n",
                        pstats.spp, pstats.events, 100.0 * pstats.mean_rel_error);
            if (scene.renderer == ATMOS_RENDERER_PATH && pstats.truncate_deg > 0)
                fprintf(stderr, "  path: forward peak truncated at %g deg: %.3f-%.3f of the scattering counted as unscattered\n",
                        pstats.truncate_deg, pstats.truncated_min, pstats.truncated_max);
            if (frame == 1 && tau_path) fprintf(stderr, "  wrote %s\n", tau_path);
        }
        atmos_image_destroy(var_img);
        atmos_image_destroy(order_img);
        var_img = order_img = NULL;
        atmos_image_destroy(spec);
        atmos_image_destroy(lin);
        atmos_image_destroy(disp);
        spec = lin = disp = NULL;
    }
    if (!quiet && nframes > 1)
        fprintf(stderr, "atmos render: %d frames, %.3f s rendering (volume and optics prepared once)\n", nframes,
                total_seconds);
    atmos_volume_optics_free(&optics);
    atmos_volume_destroy(vol);
    atmos_context_destroy(ctx);
    return CLI_EXIT_OK;
fail:
    if (prog.shown) fputc('\n', stderr);
    if (numbered && frame >= 1 && frame <= nframes) fprintf(stderr, "atmos render: frame %d/%d failed\n", frame, nframes);
    {
        int rc = cli_runtime_error(C, ctx, st);
        atmos_image_destroy(var_img);
    atmos_image_destroy(order_img);
        atmos_image_destroy(spec);
        atmos_image_destroy(lin);
        atmos_image_destroy(disp);
        atmos_volume_optics_free(&optics);
        atmos_volume_destroy(vol);
        atmos_context_destroy(ctx);
        return rc;
    }
fail_quiet:
    atmos_image_destroy(spec);
    atmos_image_destroy(lin);
    atmos_image_destroy(disp);
    atmos_volume_optics_free(&optics);
    atmos_volume_destroy(vol);
    atmos_context_destroy(ctx);
    return CLI_EXIT_USAGE;
}
