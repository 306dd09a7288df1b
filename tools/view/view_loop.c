/* The viewer's loop (view.h, view_cmd.c): the plans, one frame after another, the display,
 * the overlay, the recording and the saved views. */
#include "outputs.h"
#include "view.h"

#include <SDL2/SDL_keycode.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>


typedef struct loop {
    atmos_context *ctx;
    atmos_scene *sc;             /* the scene; renderer and wavelengths follow the state */
    const atmos_volume *vol;
    atmos_plan *plan[ATMOS_RENDERER_LAST + 1]; /* per renderer kind, made when first used */
    int spectral;                /* the wavelengths the plans were made for */
    atmos_image *img, *lin, *disp;
    unsigned char *rgba;         /* the window's frame */
    size_t rgba_cap;
    double log_scale;            /* the exposure's smoothed log scale (automatic exposure) */
    int have_scale, spp, saves;
    int impostor_updates;        /* the last frame's */
    int impostors_coarse;        /* the last frame's (never made: made at 1/4 resolution) */
    int impostor_budget;         /* view_opts's */
    double screen_layer_px;      /* view_opts's */
    int said_pinhole;            /* the stand-in pinhole for the scene's camera was announced */
    int progress_log;            /* off a terminal: the progress log, kept for the plans' making */
    int quiet;                   /* -q: nothing said but warnings and errors */
} loop;

/* What a frame's camera and sun are made of, as numbers: a frame whose pose equals the last
 * one's is still. */
#define VIEW_POSE_N 18
typedef struct view_pose {
    double v[VIEW_POSE_N];
} view_pose;

static view_pose view_pose_of(const view_state *s)
{
    const atmos_utc_time *t = &s->time;
    const int timed = s->sun_from_time != 0;
    const view_pose p = {{s->pos[0], s->pos[1], s->pos[2], s->yaw_deg, s->pitch_deg, s->fov_deg, s->pinhole_fov_deg,
                          s->sun_el, s->sun_az, timed, s->lat, s->lon, timed ? t->year : 0, timed ? t->month : 0,
                          timed ? t->day : 0, timed ? t->hour : 0, timed ? t->minute : 0, timed ? t->second : 0}};
    return p;
}

/* 1 when the state's camera or sun differs from the pose's (a scripted flight marks them changed
 * every frame; a key that cannot act further changes nothing). */
static int view_moved(const view_pose *last, const view_state *s)
{
    const view_pose now = view_pose_of(s);
    for (int i = 0; i < VIEW_POSE_N; i++)
        if (now.v[i] != last->v[i]) return 1;
    return 0;
}

static void drop_plans(loop *L)
{
    for (int k = 0; k <= ATMOS_RENDERER_LAST; k++) atmos_plan_destroy(L->plan[k]), L->plan[k] = NULL;
    atmos_image_destroy(L->img), L->img = NULL;
}

static atmos_status get_plan(loop *L, const view_state *s, atmos_plan **out)
{
    if (s->spectral != L->spectral) drop_plans(L), L->spectral = s->spectral;
    const int k = (int)s->renderer;
    if (!L->plan[k]) {
        atmos_scene sc = *L->sc;
        sc.renderer = s->renderer;
        sc.wavelengths = s->spectral ? ATMOS_WAVELENGTHS_SPECTRAL : ATMOS_WAVELENGTHS_RGB;
        if (!view_renderer_draws(sc.renderer, sc.camera.type)) { /* the stand-in pinhole of the frames */
            atmos_frame f;
            memset(&f, 0, sizeof f);
            view_state_frame(s, &f);
            sc.camera = f.camera;
        }
        if (sc.renderer == ATMOS_RENDERER_SKY) sc.volume.source[0] = 0; /* the sky alone, the volume left out */
        if (!L->quiet) fprintf(stderr, "atmos view: preparing the %s renderer...\n", atmos_renderer_name(s->renderer));
        cli_shared_progress()->log = L->quiet ? 0 : L->progress_log; /* a plan's making may be long: logged */
        atmos_status st = atmos_plan_create(L->ctx, &sc, sc.renderer == ATMOS_RENDERER_SKY ? NULL : L->vol, NULL, &L->plan[k]);
        cli_shared_progress()->log = 0; /* the frames' renders are not: a frame is short */
        if (st != ATMOS_OK) return st;
        atmos_image_destroy(L->img), L->img = NULL;
    }
    *out = L->plan[k];
    return ATMOS_OK;
}

/* The automatic exposure's scale (atmos_tonemap_scale) of the frame's linear sRGB, from every
 * 4th pixel of every 4th row of a large frame, converted as the display converts them (to
 * linear sRGB, gamut mapped): the log average of a frame changes little, and the serial sum over
 * every pixel of a 1280 x 720 frame took a tenth of its time. */
static double exposure_scale(atmos_context *ctx, const atmos_image *img, const atmos_wavelengths *wl,
                             const atmos_tonemap_desc *td)
{
    const int step = img->width * img->height > 65536 ? 4 : 1, w = (img->width + step - 1) / step,
              h = (img->height + step - 1) / step, C = img->channels;
    atmos_image *sub = NULL, *lin = NULL;
    double scale = 1.0;
    if (atmos_image_create(NULL, w, h, C, &sub) != ATMOS_OK) return scale;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            memcpy(sub->pixels + ((size_t)y * w + x) * C, img->pixels + ((size_t)y * step * img->width + x * step) * C,
                   sizeof(float) * C);
    if (atmos_image_to_srgb(ctx, sub, wl, &lin) == ATMOS_OK && atmos_image_gamut_map(ctx, lin, NULL) == ATMOS_OK)
        scale = atmos_tonemap_scale(lin, td);
    atmos_image_destroy(sub), atmos_image_destroy(lin);
    return scale;
}

/* The tone map of L->img: the scene's curve, the exposure held as a manual EV (so that a saved
 * scene reproduces it); automatic exposure adapts smoothly (a third of the way in log a frame)
 * unless `snap`. */
static atmos_tonemap_desc frame_tonemap(loop *L, const atmos_plan *p, const view_state *s, int snap)
{
    atmos_tonemap_desc td;
    memset(&td, 0, sizeof td);
    td.curve = L->sc->tonemap.curve;
    td.manual_exposure = s->manual_exposure;
    td.exposure_ev = s->ev;
    if (!s->manual_exposure) {
        const double ls = log(fmax(exposure_scale(L->ctx, L->img, atmos_plan_wavelengths(p), &td), 1e-30));
        L->log_scale = (!L->have_scale || snap) ? ls : L->log_scale + (ls - L->log_scale) / 3.0;
        L->have_scale = 1;
        /* manual: scale = 1 / (1.2 2^EV) */
        td.manual_exposure = 1;
        td.exposure_ev = -log2(1.2 * exp(L->log_scale));
    }
    return td;
}

/* A save's images of L->img (L->lin linear sRGB with the render's metadata, L->disp the display
 * values), made anew by the library's steps one after the other. */
static atmos_status display(loop *L, const atmos_plan *p, view_state *s, int snap, double *ev_used)
{
    atmos_image_destroy(L->lin), L->lin = NULL;
    atmos_image_destroy(L->disp), L->disp = NULL;
    const atmos_tonemap_desc td = frame_tonemap(L, p, s, snap);
    *ev_used = td.exposure_ev;
    atmos_status st = atmos_image_to_srgb(L->ctx, L->img, atmos_plan_wavelengths(p), &L->lin);
    if (st == ATMOS_OK) st = atmos_image_gamut_map(L->ctx, L->lin, NULL); /* as atmos render writes it */
    if (st == ATMOS_OK) st = atmos_tonemap(L->ctx, L->lin, &td, &L->disp);
    return st;
}

/* A frame's 8-bit display values in one pass (atmos_image_display_checked: the bytes of the
 * values display's steps give, from the curve's table over the scaled value; a NaN or an
 * infinity in the frame refused in the same pass, the plan not checking it: atmos_frame.no_check),
 * L->rgba: the window's, and a headless run's whether it records or not (the window's work). */
static atmos_status display_frame(loop *L, const atmos_plan *p, view_state *s, int snap)
{
    const int W = L->img->width, H = L->img->height;
    if ((size_t)W * H * 4 > L->rgba_cap) {
        free(L->rgba), L->rgba_cap = 0;
        if (!(L->rgba = malloc((size_t)W * H * 4))) return ATMOS_E_NOMEM;
        L->rgba_cap = (size_t)W * H * 4;
    }
    const atmos_tonemap_desc td = frame_tonemap(L, p, s, snap);
    return atmos_image_display_checked(L->ctx, L->img, atmos_plan_wavelengths(p), &td, NULL, L->rgba);
}

/* A recorded frame's display values (L->disp, for its PNG) from its bytes, after the frame's
 * time is taken: b / 255 (the PNG's rounding gives b back), alpha the frame's clamped to [0, 1]
 * as the display pass takes it (1 for a frame without alpha): the PNG the display values made
 * in the frame gave. */
static atmos_status record_values(loop *L, const atmos_plan *p)
{
    const int W = L->img->width, H = L->img->height, C = L->img->channels;
    const int alpha = C == atmos_plan_wavelengths(p)->count + 1;
    if (!L->disp || L->disp->width != W || L->disp->height != H) {
        atmos_image_destroy(L->disp), L->disp = NULL;
        const atmos_status st = atmos_image_create(L->ctx, W, H, 4, &L->disp);
        if (st != ATMOS_OK) return st;
    }
    for (size_t i = 0; i < (size_t)W * H; i++) {
        float *d = L->disp->pixels + 4 * i;
        const float a = alpha ? L->img->pixels[i * C + C - 1] : 1.0f;
        for (int c = 0; c < 3; c++) d[c] = (float)L->rgba[4 * i + c] / 255.0f;
        d[3] = a > 0 ? (a < 1 ? a : 1.0f) : 0.0f;
    }
    return ATMOS_OK;
}

/* The viewer's frames take the sky behind the volume every VIEW_SKY_STEP pixels and read it
 * between them where it is smooth (atmos_frame.sky_step: within 0.1 % of every pixel's), its
 * values from the sky-view table (atmos_frame.sky_table: within about one level of 255); a save
 * and a preview session's still frame, every pixel evaluated, as atmos render does. */
#define VIEW_SKY_STEP 4

static const char *camera_name(atmos_camera_type t)
{
    return t == ATMOS_CAMERA_FISHEYE ? "fisheye" : t == ATMOS_CAMERA_EQUIRECT ? "equirect" : "pinhole";
}

/* Says once that a renderer shows the scene's camera as a pinhole (view_state_camera). */
static void say_pinhole(loop *L, const view_state *s)
{
    double fov;
    if (L->said_pinhole || view_state_camera(s, &fov) == s->camera) return;
    fprintf(stderr,
            "atmos view: the %s renderer draws pinhole cameras only: the scene's %s camera is shown as a "
            "%.0f-degree pinhole looking the same way (the sky, nishita, harris and path renderers show it as it is)\n",
            atmos_renderer_name(s->renderer), camera_name(s->camera), fov);
    L->said_pinhole = 1;
}

/* The slice renderer's preview while the camera or the sun moves: this many slices at most
 * (the scene's own count when smaller), the eye buffer at half the scene's scale per axis and
 * the light buffer at half the scene's side. */
#define VIEW_PREVIEW_SLICES 48

/* A frame's quality: the preview of a moving view; the full render of a still view in a session
 * that previews (the slice renderer's equal to atmos render's: the sky at every pixel, the
 * diffuse field solved afresh); a scripted frame without --preview (the scene's quality, the
 * sky every VIEW_SKY_STEP pixels, the field warm-started); a save. */
typedef enum { VIEW_PREVIEW, VIEW_STILL, VIEW_SCRIPTED, VIEW_SAVE } view_quality;

/* The slice renderer's frame settings for a quality (f: the scene's frame). */
static void slice_quality(atmos_frame *f, const atmos_scene *sc, view_quality q)
{
    if (q == VIEW_STILL) f->sky_step = 1, f->sky_table = 0, f->warm_field = 0;
    if (q != VIEW_PREVIEW) return;
    f->eye_scale = 0.5 * (f->eye_scale > 0 ? f->eye_scale : 1.0);
    f->light_size = sc->slice.light_size / 2 > 16 ? sc->slice.light_size / 2 : sc->slice.light_size;
    f->no_air_shadows = 1; /* the shadows on the air and ground come back when the view is still */
    f->hold_field = 1;     /* the diffuse field of the sun before the move, solved when still */
    const int scene_slices = f->slices > 0 ? f->slices : sc->slice.slices;
    f->slices = scene_slices > 0 && scene_slices < VIEW_PREVIEW_SLICES ? scene_slices : VIEW_PREVIEW_SLICES;
}

/* Renders the state's frame at a quality. */
static atmos_status render(loop *L, view_state *s, view_quality q, atmos_plan **pp)
{
    const int preview = q == VIEW_PREVIEW, saving = q == VIEW_SAVE;
    atmos_plan *p;
    atmos_status st = get_plan(L, s, &p);
    if (st != ATMOS_OK) return st;
    atmos_frame f;
    if ((st = atmos_frame_from_scene(L->ctx, L->sc, &f)) != ATMOS_OK) return st;
    view_state_frame(s, &f);
    say_pinhole(L, s);
    if (!saving) /* a cloud holding the eye: its near particles in coarser layers (docs/viewer.md) */
        f.sky_step = VIEW_SKY_STEP, f.sky_table = 1, f.impostor_budget = L->impostor_budget, f.screen_layer_px = L->screen_layer_px;
    f.warm_field = !saving; /* a saved frame is the offline render's: its field built afresh */
    /* a moving view's frame is not kept by the plan for an unchanged next one (the copy of a
     * 1280 x 720 frame saved; a still view's frame is kept) */
    f.no_keep = q == VIEW_PREVIEW || q == VIEW_SCRIPTED;
    f.no_check = !saving; /* display_frame's pass checks the frame; a save's, by the plan */
    if (s->renderer == ATMOS_RENDERER_SLICE) slice_quality(&f, L->sc, q);
    /* Harris's preview: the diffuse field of the sun before the move (none yet: the forward
     * shading alone), solved, warm-started, when the view is still (docs/viewer.md) */
    if (s->renderer == ATMOS_RENDERER_HARRIS && preview) f.hold_field = 1;
    if (s->renderer == ATMOS_RENDERER_PATH) {
        const int full = L->sc->path.spp > 0 ? L->sc->path.spp : 64;
        L->spp = preview ? 1 : (L->spp < full ? L->spp + 1 : full);
        f.spp = L->spp;
    }
    if (!L->img && (st = atmos_plan_image_create(p, &f, &L->img)) != ATMOS_OK) return st;
    *pp = p;
    st = atmos_plan_render(p, &f, NULL, L->img, NULL);
    atmos_plan_stats ps;
    atmos_plan_get_stats(p, &ps);
    L->impostor_updates = ps.impostor_updates, L->impostors_coarse = ps.impostors_coarse;
    return st;
}

static int save(loop *L, const view_opts *o, view_state *s, const char *text)
{
    atmos_plan *p;
    const int keep_spp = L->spp;
    L->spp = 1 << 30; /* the scene's full budget */
    double ev;
    atmos_status st = render(L, s, VIEW_SAVE, &p);
    if (st == ATMOS_OK) st = display(L, p, s, 0, &ev);
    L->spp = keep_spp;
    if (st != ATMOS_OK) return cli_runtime_error("view", L->ctx, st);
    view_state saved = *s;
    saved.manual_exposure = 1, saved.ev = ev;
    atmos_scene sc = *L->sc; /* the volume where the plan put it (a default placement follows the
                                camera, which has moved since) */
    double off[3], lo[3], hi[3];
    const atmos_volume *v = atmos_plan_volume(p, off);
    if (v) {
        atmos_volume_bounds(v, lo, hi);
        sc.volume.placed = 1;
        for (int i = 0; i < 3; i++) sc.volume.position_m[i] = off[i] + (i == 1 ? lo[i] : 0.5 * (lo[i] + hi[i]));
    }
    char base[4096];
    snprintf(base, sizeof base, "%s_%03d", o->save_base ? o->save_base : "view", ++L->saves);
    /* its folder made as atmos render makes its outputs' */
    if (cli_output_folder("view", "--save-base", base) != 0) return CLI_EXIT_RUNTIME;
    cli_outputs_defer_signals(1); /* a signal meanwhile acts after the save's files are whole */
    const int rc = view_save(L->ctx, base, text, &sc, &saved, L->lin, L->disp);
    cli_outputs_defer_signals(0);
    return rc;
}

static void overlay(const view_state *s, double ms, char lines[4][160])
{
    snprintf(lines[0], 160, "%s  %.1f ms  %.1f fps", atmos_renderer_name(s->renderer), ms, ms > 0 ? 1000.0 / ms : 0.0);
    if (s->sun_from_time)
        snprintf(lines[1], 160, "sun %.1f / %.1f deg  %04d-%02d-%02d %02d:%02d UTC", s->sun_el, s->sun_az, s->time.year,
                 s->time.month, s->time.day, s->time.hour, s->time.minute);
    else snprintf(lines[1], 160, "sun elevation %.1f azimuth %.1f deg", s->sun_el, s->sun_az);
    double fov;
    const atmos_camera_type t = view_state_camera(s, &fov);
    char cam[64] = ""; /* the scene's type, or the pinhole standing in for it; an equirect has no fov */
    if (s->camera != ATMOS_CAMERA_PINHOLE)
        snprintf(cam, sizeof cam, "  %s%s%s", camera_name(t), t != s->camera ? " for the " : "",
                 t != s->camera ? camera_name(s->camera) : "");
    if (t != ATMOS_CAMERA_EQUIRECT) snprintf(cam + strlen(cam), sizeof cam - strlen(cam), "  fov %.0f", fov);
    snprintf(lines[2], 160, "camera %.0f %.0f %.0f m  heading %.0f pitch %.0f%s%s", s->pos[0], s->pos[1], s->pos[2],
             s->yaw_deg, s->pitch_deg, cam, s->orbit ? "  orbit" : "");
    snprintf(lines[3], 160, "%s  EV %+.1f  H: hide  Esc: quit", s->spectral ? "spectral" : "rgb", s->ev);
}

/* The orbit's centre: the middle of the volume's box where the plan placed it. */
static int volume_centre(const atmos_plan *p, double c[3])
{
    double off[3], lo[3], hi[3];
    const atmos_volume *v = atmos_plan_volume(p, off);
    if (!v) return 0;
    atmos_volume_bounds(v, lo, hi);
    for (int i = 0; i < 3; i++) c[i] = 0.5 * (lo[i] + hi[i]) + off[i];
    return 1;
}

/* A sun or clock move (what: the option or the flight's key that asks for it) where the
 * renderer lights the scene without the sun: said to change nothing, and why. */
static void say_sunless(const char *what, const atmos_scene *sc, atmos_renderer_kind r)
{
    fprintf(stderr, "atmos view: %s: changes nothing: the %s renderer lights this scene without the sun (by its %d lamp%s)\n",
            what, atmos_renderer_name(r), sc->light_count, sc->light_count == 1 ? "" : "s");
}

/* A flight's sun (key frames that set it, sun or clock keys pressed) on such a scene: said
 * once (a pressed key by its key frame). Up to its first renderer key only: after it another
 * renderer lights the scene. */
static void flight_sunless(const view_script *script, const char *path, const atmos_scene *sc, atmos_renderer_kind r)
{
    for (int i = 0; script && i < script->n && cli_lit_without_sun(sc, r); i++) {
        const view_action a = script->k[i].press;
        if (a == VA_RENDERER) return;
        if (script->k[i].has_sun || (a >= VA_SUN_UP && a <= VA_TIME_FORWARD)) {
            char what[ATMOS_SCENE_PATH_MAX + 64];
            if (script->k[i].has_sun) snprintf(what, sizeof what, "--script %s: the flight's sun", path);
            else snprintf(what, sizeof what, "--script %s: /keys/%d/press", path, i);
            say_sunless(what, sc, r);
            return;
        }
    }
}

static int start(loop *L, const view_opts *o, view_state *s, const view_script *script)
{
    atmos_frame f;
    atmos_status st = atmos_frame_from_scene(L->ctx, L->sc, &f);
    view_state_init(s, L->sc, &f, NULL);
    const int rc = view_script_check(script, s, o->script); /* before the plan's work */
    if (rc != CLI_EXIT_OK) return rc;
    flight_sunless(script, o->script, L->sc, s->renderer);
    atmos_plan *p = NULL;
    if (st == ATMOS_OK) st = get_plan(L, s, &p);
    if (st != ATMOS_OK) return cli_runtime_error("view", L->ctx, st);
    double c[3];
    if (volume_centre(p, c)) view_state_init(s, L->sc, &f, c);
    return CLI_EXIT_OK;
}

/* --press's keys: through the window's event queue, as a user's; headless, tapped on the state
 * (view_state_tap: what the window does with a key pressed and released at once). A key that
 * moves the sun or the clock where the renderer lights the scene by its lamps only is said to
 * change nothing, and why, rather than taken in silence: judged by the renderer the keys
 * before it give (in a window they are only queued here). */
static void press(view_window *win, view_state *s, const atmos_scene *sc, const char *keys)
{
    int codes[16];
    const int n = view_key_codes(keys, codes, 16);
    atmos_renderer_kind r = s->renderer;
    for (int k = 0; k < n; k++) {
        const view_action a = view_key_action(codes[k]);
        if (a == VA_RENDERER) r = view_next_renderer(r, s->has_volume);
        if (a >= VA_SUN_UP && a <= VA_TIME_FORWARD && cli_lit_without_sun(sc, r)) {
            char what[64];
            snprintf(what, sizeof what, "--press %s", view_action_name(a));
            say_sunless(what, sc, r);
        }
        if (win) view_window_push_key(win, codes[k]);
        else view_state_tap(s, a);
    }
}

int view_loop(atmos_context *ctx, const view_opts *o, const view_script *script, atmos_scene *sc,
              const atmos_volume *vol, const char *text)
{
    loop L;
    memset(&L, 0, sizeof L);
    L.ctx = ctx, L.sc = sc, L.vol = vol, L.spectral = sc->wavelengths == ATMOS_WAVELENGTHS_SPECTRAL;
    L.impostor_budget = o->impostor_budget, L.screen_layer_px = o->screen_layer_px;
    L.quiet = o->quiet;
    L.progress_log = cli_shared_progress()->log;
    cli_shared_progress()->log = 0;
    view_state s;
    view_recorder rec = {0};
    view_window *win = NULL;
    /* Ctrl-C, SIGTERM: "atmos view: interrupted", the process ended by the signal; a recorded
     * frame or a save being written is finished first (view_record_frame, save). Before the
     * window: SDL then keeps it rather than installing its own. */
    cli_outputs_catch("view");
    /* the window first: without a display the viewer stops at once, before any work */
    int rc = CLI_EXIT_OK;
    if (!o->headless && !(win = view_window_open(o->width, o->height, "atmos view"))) rc = CLI_EXIT_RUNTIME;
    if (rc == CLI_EXIT_OK) rc = view_record_open(&rec, o->record); /* before preparing the renderer */
    if (rc == CLI_EXIT_OK) rc = start(&L, o, &s, script);
    const int scripted = o->frames > 0 || script;
    /* a flight without --frames: until its last key frame (a window closes then too) */
    const int frames = o->frames > 0 ? o->frames : view_script_frames(script);
    const double fps = script ? script->fps : 24;
    double last_ms = 0.0;
    int pressed = 0, unsaved = 0;
    view_pose pose = view_pose_of(&s);
    for (int i = 0; rc == CLI_EXIT_OK && !s.quit && (!frames || i < frames); i++) {
        const double t0 = cli_now_s();
        if (scripted) view_script_step(script, &s, (i - 1) / fps, i / fps, i, frames);
        if (i == 1 && o->press) press(win, &s, sc, o->press), pressed = 1;
        if (win) view_window_events(win, &s, last_ms > 0 ? last_ms / 1000.0 : 1.0 / 30.0);
        const int moving = i > 0 && (s.changes & (VIEW_CHANGED_CAMERA | VIEW_CHANGED_SUN)) && view_moved(&pose, &s);
        s.changes = 0;
        pose = view_pose_of(&s);
        atmos_plan *p = NULL;
        const view_quality q = scripted && !o->preview ? VIEW_SCRIPTED : moving ? VIEW_PREVIEW : VIEW_STILL;
        atmos_status st = render(&L, &s, q, &p);
        if (st == ATMOS_OK) st = display_frame(&L, p, &s, i == 0 || scripted);
        if (st != ATMOS_OK) {
            rc = cli_runtime_error("view", ctx, st);
            break;
        }
        char lines[4][160];
        const char *lp[4] = {lines[0], lines[1], lines[2], lines[3]};
        overlay(&s, last_ms, lines);
        if (win && view_window_present(win, L.rgba, L.img->width, L.img->height, s.overlay ? lp : NULL, 4) != 0) rc = CLI_EXIT_RUNTIME;
        last_ms = 1000.0 * (cli_now_s() - t0);
        if (rc == CLI_EXIT_OK && o->record && (st = record_values(&L, p)) != ATMOS_OK) rc = cli_runtime_error("view", ctx, st);
        if (rc == CLI_EXIT_OK) rc = view_record_frame(&rec, ctx, L.disp, last_ms, atmos_renderer_name(s.renderer), L.impostor_updates,
                                                      L.impostors_coarse, q == VIEW_PREVIEW,
                                                      cli_lit_without_sun(sc, s.renderer), &s);
        /* a save that fails is said (save prints why) and the session goes on; headless, where
         * no one sees the message, the session's exit status then says it (1) */
        if (rc == CLI_EXIT_OK && s.save && save(&L, o, &s, text) != CLI_EXIT_OK) {
            fprintf(stderr, "atmos view: the frame was not saved; the session goes on%s\n",
                    o->headless ? " (its exit status will be 1)" : "");
            unsaved++;
        }
        s.save = 0;
    }
    if (o->headless && unsaved && rc == CLI_EXIT_OK) rc = CLI_EXIT_RUNTIME;
    if (o->press && !pressed && rc == CLI_EXIT_OK) /* the session ended before its second frame */
        fprintf(stderr, "atmos view: --press %s: not pressed: the session ended before its second frame\n", o->press);
    if (view_record_close(&rec) != CLI_EXIT_OK && rc == CLI_EXIT_OK) rc = CLI_EXIT_RUNTIME;
    view_window_close(win);
    drop_plans(&L);
    atmos_image_destroy(L.lin);
    atmos_image_destroy(L.disp);
    free(L.rgba);
    cli_shared_progress()->log = L.progress_log;
    return rc;
}
