/* atmos view [SCENE] [options]: the interactive viewer's command and its loop (view.h).
 *
 * Interactive by design: each renderer keeps one plan, and a frame is rendered from it with
 * only what changed (the slice renderer's light when the sun moves, the sky's tables when
 * the eye moves far enough, the path tracer's samples when anything moves). While the
 * camera or the sun moves, the slice renderer draws its eye buffer at half resolution and
 * the path tracer one sample per pixel; when nothing moves the slice renderer draws the
 * scene's own quality and the path tracer adds a sample per pixel each frame up to the
 * scene's budget. A saved frame (F12, P) is always rendered at the scene's quality. */
#include "render_opts.h"
#include "render_scene.h"
#include "view.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


static void help(void)
{
    printf("Usage: atmos view [SCENE.json] [--volume SOURCE] [--size WxH] [--script FLIGHT.json]\n"
           "                  [--frames N] [--record DIR] [--headless] [--press KEYS] [--save-base BASE]\n"
           "                  [--impostor-budget N] [--screen-layer-px PX] [--preview]\n"
           "                  [atmos render's scene options]\n\n"
           "Opens a window on a scene (or the built-in default; a volume with --volume SOURCE: a file,\n"
           "generate:PRESET or simulate:PRESET, as atmos render's) and renders it with atmos's renderers\n"
           "on the CPU as you fly around it, move the sun or scrub the time of day. The renderers keep\n"
           "their plans: a frame recomputes only what changed. While the camera or the sun moves the\n"
           "slice renderer draws a preview (half resolution, 48 slices, half the light buffer's side, no\n"
           "shadows on the air, the diffuse field of the sun before the move) and the path tracer one\n"
           "sample per pixel; the first still frame is the full render (the slice renderer's the same as\n"
           "atmos render's), and the path tracer keeps adding samples up to the scene's budget\n"
           "(\"path\": {\"spp\": N}). Scripted frames (--script, --frames) are full renders unless\n"
           "--preview.\n\n"
           "Options:\n"
           "  --size WxH         the rendered frame's size (default 960x540; the window scales it)\n"
           "  --script FILE      play a flight: {\"fps\": 24, \"keys\": [{\"t\": 0, \"position_m\": [x, y, z],\n"
           "                     \"look_at_m\": [x, y, z], \"sun\": {\"elevation_deg\": e, \"azimuth_deg\": a},\n"
           "                     \"press\": \"NAME\"}, ...]} (camera and sun interpolated, the sun between the\n"
           "                     keys that give one, held before the first and after the last; \"press\"\n"
           "                     acts at t as its key's tap; unknown keys are errors, as in scene files).\n"
           "                     Frame i is at t = i / fps; without --frames the flight stops at its last\n"
           "                     key frame (T: T fps + 1 frames), a window closing then too\n"
           "  --frames N         play N frames and exit: of the script (N = T fps + 1 ends at its last key\n"
           "                     frame, t = T; later frames hold it), or else a full turn of the scene's\n"
           "                     camera about the vertical through the volume's centre (no volume: the\n"
           "                     point it looks at), its pitch kept: frame 0 is atmos render's view\n"
           "  --record DIR       write every frame as DIR/frame_NNNNN.png and DIR/frames.csv (frame, ms =\n"
           "                     the frame's wall time including presentation, renderer, impostor_updates,\n"
           "                     camera, sun (empty when lamps alone light it), preview, impostors_coarse);\n"
           "                     a DIR holding frames.csv or frame_*.png of an earlier run is refused\n"
           "  --headless         no window (with --frames or --script: render and record only)\n"
           "  --press KEYS       press these keys (key or script names as below, comma-separated) at the\n"
           "                     second frame (so --frames 2 at least): through the window's event queue\n"
           "                     as a user's keys; --headless, each acts on the view as a tap (1/30 s)\n"
           "  --save-base BASE   where F12/P saves: BASE_NNN.exr, .png, .json (default view_NNN in the\n"
           "                     current folder); the .json renders the same frame with atmos render\n"
           "  --impostor-budget N  Harris's renderer: make at most N impostors a frame in full, those\n"
           "                     never made first, then the most out of date; the others are drawn as\n"
           "                     they are (never made: at 1/4 resolution) and caught up over the next\n"
           "                     frames (default 2; 0: all of them every frame, as F12's saves and atmos\n"
           "                     render do)\n"
           "  --preview          scripted frames too: previews while the camera or the sun moves, the\n"
           "                     full render when still (as an interactive session)\n"
           "  --screen-layer-px PX  Harris's renderer, the eye inside a cloud: its near particles, whose\n"
           "                     splats are large, drawn in coarser layers where each is still PX pixels\n"
           "                     in radius (default 4; 0: all at the 1/4 resolution F12 and atmos render\n"
           "                     draw them at)\n"
           "  -h, --help         show this help\n"
           "Scene options are atmos render's (atmos render --help): --renderer, --volume, --sun-elevation,\n"
           "--time, --spp, -D KEY=VALUE, --threads, ...; not its outputs (-o, --exr, ...), --width/--height\n"
           "or --mpi: refused (the frame is --size's; F12 and --record write files)\n\n");
    view_keys_help(stdout);
    fputs(CLI_HELP_EXIT, stdout);
}

/* --size WxH: each number read as atmos render's --width and --height are (cli_parse_int). */
static int size(const char *v, view_opts *o)
{
    const char *x = v ? strchr(v, 'x') : NULL;
    if (!x) return cli_usage_error("view", "--size: expected WxH (960x540), got '%s'", v ? v : ""), 0;
    char w[32];
    snprintf(w, sizeof w, "%.*s", (int)(x - v < 31 ? x - v : 31), v);
    return cli_parse_int("view", "--size's width", w, 1, 8192, &o->width) &&
           cli_parse_int("view", "--size's height", x + 1, 1, 8192, &o->height);
}

/* Takes the viewer's own options out of argv; the rest goes to atmos render's parser. */
static int parse(int argc, char **argv, view_opts *o)
{
    memset(o, 0, sizeof *o);
    o->width = 960, o->height = 540, o->impostor_budget = 2, o->screen_layer_px = 4;
    o->pass = calloc((size_t)argc + 1, sizeof *o->pass);
    if (!o->pass) return CLI_EXIT_RUNTIME;
    o->pass[o->passed++] = argv[0];
    for (int i = 1; i < argc; i++) {
        const char *v = NULL;
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) return help(), -1;
        if (!strcmp(argv[i], "--headless")) o->headless = 1;
        else if (!strcmp(argv[i], "--preview")) o->preview = 1;
        else if (cli_take_value(argc, argv, &i, "--size", &v)) {
            if (!size(v, o)) return CLI_EXIT_USAGE;
        } else if (cli_take_value(argc, argv, &i, "--frames", &v)) {
            if (!v || !cli_parse_int("view", "--frames", v, 1, VIEW_FRAMES_MAX, &o->frames)) return CLI_EXIT_USAGE;
        } else if (cli_take_value(argc, argv, &i, "--impostor-budget", &v)) {
            if (!v || !cli_parse_int("view", "--impostor-budget", v, 0, 1000000, &o->impostor_budget)) return CLI_EXIT_USAGE;
        } else if (cli_take_value(argc, argv, &i, "--screen-layer-px", &v)) {
            char *end = NULL;
            o->screen_layer_px = v ? strtod(v, &end) : -1;
            if (!v || end == v || *end || !(o->screen_layer_px == 0 || (o->screen_layer_px >= 1 && o->screen_layer_px <= 1000)))
                return cli_usage_error("view", "--screen-layer-px: expected 0 (off) or a number of pixels in [1, 1000], got '%s'",
                                       v ? v : "");
        } else if (cli_take_value(argc, argv, &i, "--script", &v)) {
            if (!(o->script = v)) return cli_usage_error("view", "--script needs a file");
        } else if (cli_take_value(argc, argv, &i, "--record", &v)) {
            if (!(o->record = v)) return cli_usage_error("view", "--record needs a folder");
        } else if (cli_take_value(argc, argv, &i, "--press", &v)) {
            if (!(o->press = v)) return cli_usage_error("view", "--press needs key names");
        } else if (cli_take_value(argc, argv, &i, "--save-base", &v)) {
            if (!(o->save_base = v)) return cli_usage_error("view", "--save-base needs a name");
        } else {
            o->pass[o->passed++] = argv[i];
        }
    }
    if (o->headless && !o->frames && !o->script) return cli_usage_error("view", "--headless needs --frames N or --script");
    if (o->press && o->frames == 1)
        return cli_usage_error("view", "--press acts at the second frame: it needs --frames 2 or more");
    return CLI_EXIT_OK;
}

/* The first of atmos render's options that the viewer takes but would not use (its outputs,
 * the image size, --mpi), as the user wrote it, or NULL: refused rather than ignored. */
static const char *render_only(const render_opts *ro)
{
    return ro->png        ? "-o"
           : ro->exr      ? "--exr"
           : ro->pfm      ? "--pfm"
           : ro->variance ? "--variance"
           : ro->order    ? "--order"
           : ro->tau      ? "--tau"
           : ro->exr_layers ? "--exr-layers"
           : ro->png_bits ? "--png-bits"
           : ro->exr_half ? "--exr-half"
           : ro->width > 0 || ro->height > 0 ? "--width/--height"
           : ro->mpi ? "--mpi"
                     : NULL;
}

int cli_cmd_view(int argc, char **argv)
{
    view_opts vo;
    int rc = parse(argc, argv, &vo);
    render_opts ro;
    if (rc == CLI_EXIT_OK) {
        rc = render_opts_parse(vo.passed, vo.pass, &ro);
        if (rc == -1) rc = CLI_EXIT_OK, vo.frames = -1; /* atmos render's --help was shown */
    }
    if (rc != CLI_EXIT_OK || vo.frames < 0) {
        free(vo.pass);
        render_opts_free(&ro);
        return rc == -1 ? CLI_EXIT_OK : rc;
    }
    const char *unused = render_only(&ro);
    if (unused) {
        free(vo.pass);
        render_opts_free(&ro);
        return cli_usage_error("view", "%s: atmos render's; the viewer's frame is --size WxH, F12 saves it as EXR and PNG "
                                       "(--save-base BASE), --record DIR writes every frame", unused);
    }
    int codes[16];
    if (vo.press && view_key_codes(vo.press, codes, 16) < 0) {
        free(vo.pass);
        render_opts_free(&ro);
        return cli_usage_error("view", "--press: unknown key in '%s' (atmos view --help lists the keys)", vo.press);
    }
    vo.quiet = ro.quiet;
    atmos_context *ctx = cli_context(ro.threads, 0); /* -q keeps warnings */
    atmos_scene sc;
    atmos_volume *vol = NULL;
    char *text = NULL;
    view_script script = {0};
    if (!ctx) rc = CLI_EXIT_RUNTIME;
    /* the flight read first: its mistakes said before any work on the scene */
    if (rc == CLI_EXIT_OK && vo.script) rc = view_script_load(ctx, vo.script, &script);
    if (rc == CLI_EXIT_OK && vo.script && !vo.frames && view_script_frames(&script) > VIEW_FRAMES_MAX)
        rc = cli_usage_error("view", "--script %s: the flight lasts %g s: at %g fps more than the %d frames a session "
                                     "plays (--frames's cap); shorten it, lower its fps or give --frames N",
                             vo.script, script.k[script.n - 1].t, script.fps, VIEW_FRAMES_MAX);
    if (rc == CLI_EXIT_OK) rc = render_scene_make(ctx, &ro, &sc, &vol);
    if (rc == CLI_EXIT_OK && ro.scene_path && strcmp(ro.scene_path, "-")) text = cli_read_text(ro.scene_path, CLI_TEXT_MAX);
    if (rc == CLI_EXIT_OK) {
        sc.width = vo.width, sc.height = vo.height;
        rc = view_loop(ctx, &vo, vo.script ? &script : NULL, &sc, vol, text ? text : "{}");
    }
    view_script_free(&script);
    free(text);
    atmos_volume_destroy(vol);
    atmos_context_destroy(ctx);
    free(vo.pass);
    render_opts_free(&ro);
    return rc;
}
