/* atmos view: the interactive viewer. A scene becomes a plan per renderer; every frame the
 * viewer's state (camera, sun, exposure, renderer) becomes an atmos_frame rendered from the
 * kept plan, and the image is shown in an SDL2 window (or, headless, only recorded).
 *
 * The state and what the keys do to it (view_state.c, view_keys.c) know nothing of SDL, so
 * that the tests can drive them; the window (view_window.c), the flight script
 * (view_script.c), the recording and the saved views (view_record.c) and the loop
 * (view_cmd.c) are the rest. */
#ifndef ATMOS_VIEW_H
#define ATMOS_VIEW_H

#include "cli.h"

#include <stdio.h>

/* What a key or a script does to the state. */
typedef enum {
    VA_NONE = 0,
    VA_FORWARD, VA_BACK, VA_LEFT, VA_RIGHT, VA_UP, VA_DOWN,         /* flight (held) */
    VA_LOOK_LEFT, VA_LOOK_RIGHT, VA_LOOK_UP, VA_LOOK_DOWN,          /* turning (held) */
    VA_SUN_UP, VA_SUN_DOWN, VA_SUN_LEFT, VA_SUN_RIGHT,              /* the sun (held) */
    VA_TIME_BACK, VA_TIME_FORWARD,                                  /* date and time (pressed) */
    VA_ZOOM_IN, VA_ZOOM_OUT, VA_EXPOSURE_UP, VA_EXPOSURE_DOWN,      /* pressed */
    VA_ORBIT, VA_RENDERER, VA_SPECTRAL, VA_OVERLAY, VA_SAVE, VA_QUIT, /* pressed */
    VA_COUNT
} view_action;

/* The viewer's state: what a frame is made of. */
typedef struct view_state {
    double pos[3];          /* the camera, m (world frame, y up) */
    double yaw_deg;         /* the view's azimuth, clockwise from north (-z) */
    double pitch_deg;       /* the view's elevation, [-89, 89] (fisheye, equirect: [-90, 90]) */
    double fov_deg;         /* the scene camera's field of view: pinhole [5, 120], fisheye [5, 360] */
    atmos_camera_type camera; /* the scene's camera type, kept where the renderer draws it */
    double pinhole_fov_deg; /* a fisheye's or equirect's stand-in pinhole (renderers that draw
                               pinholes only), [5, 120] */
    double speed;           /* flight speed, m/s (scaled by the scene's size) */
    int orbit;              /* 1: moving turns the camera about target at its distance */
    double target[3];       /* the orbit's centre: the volume's centre, or the point looked at */
    double sun_el, sun_az;  /* degrees */
    int sun_from_time;      /* the sun follows the date and time (NOAA) */
    atmos_utc_time time;
    double lat, lon;
    double ev;              /* exposure compensation (automatic) or EV100 (manual), stops */
    int manual_exposure;
    atmos_renderer_kind renderer;
    int has_volume;
    int spectral;           /* nonzero: the scene's spectral samples, else rgb */
    int overlay;            /* the on-screen text shown */
    int quit, save;         /* requests for the loop */
    unsigned changes;       /* VIEW_CHANGED_* since the loop last cleared them */
} view_state;

enum { VIEW_CHANGED_CAMERA = 1, VIEW_CHANGED_SUN = 2, VIEW_CHANGED_PLAN = 4, VIEW_CHANGED_LOOK = 8 };

/* ---- view_state.c */
/* The state of a scene's own frame (f from atmos_frame_from_scene; target: the orbit's
 * centre, NULL for the point the camera looks at). */
void view_state_init(view_state *s, const atmos_scene *sc, const atmos_frame *f, const double *target);
/* One action over dt seconds (held actions) or once (pressed ones); fast / slow: the
 * speed modifiers (x10, x0.1). */
void view_state_apply(view_state *s, view_action a, double dt, int fast, int slow);
/* A tap of a key: a held action for VIEW_TAP_S seconds, a pressed one once (what a key pressed
 * and released at once does in the window; headless --press acts so on the state). */
#define VIEW_TAP_S (1.0 / 30.0)
void view_state_tap(view_state *s, view_action a);
/* The renderer key R gives after r: slice -> harris -> nishita -> path -> sky -> slice with a
 * volume; without one, sky after path and r unchanged otherwise. */
atmos_renderer_kind view_next_renderer(atmos_renderer_kind r, int has_volume);
/* Mouse motion of (dx, dy) pixels: turns the view (or, orbiting, moves about the target). */
void view_state_look(view_state *s, double dx, double dy);
/* Scroll: the field of view narrows (clicks > 0) or widens. */
void view_state_zoom(view_state *s, double clicks);
/* The frame of the state: camera, sun, exposure (f holds the rest: size, budgets). The camera
 * is the scene's type where the state's renderer draws it, else (view_state_camera) a pinhole
 * looking the same way. */
void view_state_frame(const view_state *s, atmos_frame *f);
/* 1 when the renderer draws cameras of type t (the slice, Harris and beams renderers draw
 * pinholes only; the sky, Nishita and path renderers every type). */
int view_renderer_draws(atmos_renderer_kind r, atmos_camera_type t);
/* The camera type the state's frame uses and its field of view (fov may be NULL). */
atmos_camera_type view_state_camera(const view_state *s, double *fov_deg);
/* The largest |pitch| of the state's camera: 89 for a pinhole scene, 90 for a fisheye's or an
 * equirect's (looking straight up is their usual view). */
double view_state_pitch_limit(const view_state *s);
/* The view direction of the state (unit) and the image's up (unit, perpendicular to it: the
 * world's up made perpendicular, or at pitch +-90 the heading's way down/up the image). */
void view_state_forward(const view_state *s, double d[3]);
void view_state_up(const view_state *s, double u[3]);
/* The sun's direction from its angles or (sun_from_time) from the date, time and place. */
void view_state_sun(view_state *s);

/* ---- view_keys.c: the key table (SDL key codes, no SDL here) */
typedef struct view_key {
    int sym;                /* SDL_Keycode */
    view_action action;
    const char *key, *what; /* for --help */
} view_key;
/* The table, ending with sym 0. */
const view_key *view_keys(void);
/* The action of an SDL key code (VA_NONE if none). */
view_action view_key_action(int sym);
/* 1 for the actions that act while their key is held. */
int view_action_held(view_action a);
/* Prints the keys and the mouse to f (the help's "Keys" section). */
void view_keys_help(FILE *f);
/* An action by its name in a script ("forward", "sun_up", ...; VA_NONE if unknown). */
view_action view_action_named(const char *name);
/* The script name of an action ("none" for VA_NONE). */
const char *view_action_name(view_action a);

/* ---- view_script.c: a flight (keyframes of camera and sun), or an orbit */
typedef struct view_key_frame {
    double t;               /* seconds */
    double pos[3], look_at[3];
    int has_sun;
    double sun_el, sun_az;
    view_action press;      /* a key pressed at t (VA_NONE: none) */
} view_key_frame;
typedef struct view_script {
    int n;
    view_key_frame *k;
    double fps;             /* frames per second of the flight's clock; 24 */
} view_script;
/* Reads a flight file: {"fps": 24, "keys": [{"t": 0, "position_m": [..], "look_at_m": [..],
 * "sun": {"elevation_deg": e, "azimuth_deg": a}, "press": "sun_up"}, ...]}, checked as strictly
 * as a scene file (unknown and duplicate keys refused; the file read and its JSON checked by
 * the scene reader, whose messages give the system's reason and a syntax error's line and
 * column). A flight presses any key but the camera's (the key frames place the camera), and,
 * when its key frames set the sun, the sun's and the time's. Returns 0 or an exit status with
 * a message. */
int view_script_load(atmos_context *ctx, const char *path, view_script *out);
/* The most frames a session plays (--frames's cap; frame names are frame_NNNNN.png, wider
 * past 99999). */
#define VIEW_FRAMES_MAX 10000000
/* The frames a flight plays without --frames: frame i is at t = i / fps, so the last one is
 * the first at or after its last key frame (t = T: T fps + 1 frames when T fps is whole);
 * VIEW_FRAMES_MAX + 1 for a flight longer than VIEW_FRAMES_MAX frames. */
int view_script_frames(const view_script *s);
/* What a flight presses that the scene cannot act on (the time's keys without a date, time and
 * place): 0 or a usage error with a message (path: the flight file). */
int view_script_check(const view_script *s, const view_state *st, const char *path);
void view_script_free(view_script *s);
/* The state at time t of the script (camera and sun interpolated between keyframes; keys
 * pressed in (t_prev, t] applied); an empty script orbits the target once in `frames`. */
void view_script_step(const view_script *s, view_state *st, double t_prev, double t, int frame, int frames);

/* ---- view_record.c */
typedef struct view_recorder {
    const char *dir;        /* NULL: no recording */
    FILE *csv;              /* made with the first frame: a start that fails leaves none */
    int frames;
} view_recorder;
/* Makes the folder DIR (if missing). */
int view_record_open(view_recorder *r, const char *dir);
/* Writes frame i: DIR/frame_NNNNN.png (disp: display sRGB) and its row of frames.csv (the
 * file and its header made with the first frame; preview: 1 for a moving view's preview;
 * sunless: 1 when the renderer lights the scene by its lamps only, the sun's columns empty). */
int view_record_frame(view_recorder *r, atmos_context *ctx, const atmos_image *disp, double ms,
                      const char *renderer, int impostor_updates, int impostors_coarse, int preview,
                      int sunless, const view_state *s);
int view_record_close(view_recorder *r);
/* Saves the current view: BASE.exr (linear sRGB), BASE.png (what is shown), BASE.json (the
 * scene that renders the same image with `atmos render BASE.json`). scene_json: the text of
 * the scene file the viewer opened ("{}" for none). */
int view_save(atmos_context *ctx, const char *base, const char *scene_json, const atmos_scene *sc,
              const view_state *s, const atmos_image *lin, const atmos_image *disp);
/* The scene of the state as JSON (a new string; NULL when out of memory): the scene file's
 * text with the camera, sun, size, renderer and exposure of the state. */
char *view_scene_json(const char *scene_json, const atmos_scene *sc, const view_state *s);

/* ---- view_window.c (SDL2) */
typedef struct view_window view_window;
/* Opens a window of w x h; NULL with a message when no display can be opened, or when SDL2
 * could only fall back on a video driver that shows nothing ("offscreen", "dummy") that
 * SDL_VIDEODRIVER did not ask for. */
view_window *view_window_open(int w, int h, const char *title);
void view_window_close(view_window *win);
/* Shows a w x h frame of 8-bit display-sRGB RGBA (atmos_image_display_into's bytes) scaled to
 * the window, with the overlay's lines on top (NULL: none). Returns 0 or -1. */
int view_window_present(view_window *win, const unsigned char *rgba, int w, int h, const char *const *lines,
                        int nlines);
/* Polls the window's events into the state (held keys act over dt). */
void view_window_events(view_window *win, view_state *s, double dt);
/* Pushes a key press and release of the SDL key code sym into the window's queue (the tests'
 * and the scripts' keys go through the same path as a user's). */
void view_window_push_key(view_window *win, int sym);

/* ---- view_cmd.c, view_loop.c */
typedef struct view_opts {
    int width, height, frames, headless;
    int impostor_budget; /* Harris's impostors made again a frame at most (0: all stale ones) */
    int preview;         /* --preview: scripted frames previewed while the camera or the sun moves
                            and refined when still, as an interactive session's are */
    double screen_layer_px; /* Harris's cloud holding the eye: atmos_frame.screen_layer_px (0: off) */
    const char *script, *record, *save_base;
    const char *press;   /* --press: keys pressed at the second frame (window: through its event
                            queue; headless: view_state_tap) */
    int quiet;           /* -q (atmos render's): no "preparing" lines nor progress, warnings kept */
    int passed;          /* arguments left for atmos render's parser */
    char **pass;
} view_opts;
/* The SDL key codes of comma-separated key names or script names (as --help prints them, any
 * case; a script name gives its action's first key) into codes; returns the count, or -1 for
 * an unknown name or more than cap (view_keys.c). */
int view_key_codes(const char *list, int *codes, int cap);
/* Opens the window (unless headless) and runs frames until quit or o->frames (with a flight and
 * no --frames: view_script_frames); script: the flight (o->script's, read), NULL for none;
 * text: the scene file's JSON ("{}" for none). Returns an exit status. */
int view_loop(atmos_context *ctx, const view_opts *o, const view_script *script, atmos_scene *sc,
              const atmos_volume *vol, const char *text);


#endif
