/* atmos render's automatic exposure over an animation (render_exposure.h). */
#include "render_exposure.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The manual EV100 whose scale (1 / (1.2 * 2^EV), atmos_tonemap_scale) is scale. */
static double ev_of_scale(double scale) { return log2(1.0 / (1.2 * scale)); }

/* The scale of the automatic exposure of lin under scene fs's tone map, at most the
 * animation's limit; *limited: the limit held it. */
static double auto_scale(const atmos_image *lin, const atmos_scene *fs, const exposure_lock *xl, int *limited)
{
    atmos_tonemap_desc td = fs->tonemap;
    double scale = atmos_tonemap_scale(lin, &td);
    *limited = 0;
    if (xl->limit) {
        td.manual_exposure = 1, td.exposure_ev = xl->limit_ev;
        const double cap = atmos_tonemap_scale(lin, &td);
        if (!(scale <= cap)) scale = cap, *limited = 1;
    }
    return scale;
}

/* *key: the frame (from 1) whose sun stands highest; the first of equals; *moves: the sun's
 * elevation is not the same in every frame. fs: room for a frame's scene. */
static atmos_status highest_sun(atmos_context *ctx, const atmos_scene *scene, int nframes, atmos_scene *fs, int *key,
                                int *moves)
{
    double best = -INFINITY, low = INFINITY;
    *key = 1;
    for (int i = 0; i < nframes; i++) {
        double dir[3], el = 0, az = 0;
        atmos_status st = atmos_scene_animation_frame(ctx, scene, i, fs);
        if (st == ATMOS_OK) st = atmos_scene_sun_direction(ctx, fs, dir, &el, &az);
        if (st != ATMOS_OK) return st;
        if (el > best) best = el, *key = i + 1;
        low = el < low ? el : low;
    }
    *moves = best > low;
    return ATMOS_OK;
}

/* The key frame's exposure from a render of it at a quarter of the width and height (fs:
 * room for its scene); none to lock on (a black frame): the first frame's, as without a
 * moving sun. */
static atmos_status key_exposure(atmos_context *ctx, atmos_plan *plan, const atmos_scene *scene, exposure_lock *xl,
                                 atmos_scene *fs)
{
    atmos_frame f;
    atmos_image *spec = NULL, *lin = NULL;
    atmos_status st = atmos_scene_animation_frame(ctx, scene, xl->key - 1, fs);
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, fs, &f);
    if (st == ATMOS_OK) {
        f.width = f.width / 4 > 8 ? f.width / 4 : (f.width < 8 ? f.width : 8);
        f.height = f.height / 4 > 8 ? f.height / 4 : (f.height < 8 ? f.height : 8);
        st = atmos_plan_image_create(plan, &f, &spec);
    }
    if (st == ATMOS_OK) st = atmos_plan_render(plan, &f, NULL, spec, NULL);
    if (st == ATMOS_OK) st = atmos_image_to_srgb(ctx, spec, atmos_plan_wavelengths(plan), &lin);
    if (st == ATMOS_OK) {
        int limited = 0;
        const double scale = auto_scale(lin, fs, xl, &limited);
        if (scale > 0 && isfinite(scale)) xl->ev = ev_of_scale(scale), xl->locked = 1;
        else xl->key = 1, xl->by_sun = 0; /* nothing to lock on: the first frame's, when it comes */
    }
    atmos_image_destroy(lin);
    atmos_image_destroy(spec);
    return st;
}

atmos_status render_exposure_start(atmos_context *ctx, atmos_plan *plan, const atmos_scene *scene, int nframes,
                                   int per_frame, int sun_moves, exposure_lock *xl)
{
    memset(xl, 0, sizeof *xl);
    xl->key = 1, xl->nframes = nframes;
    if (nframes < 2 || scene->tonemap.manual_exposure) return ATMOS_OK;
    xl->limit = 1, xl->limit_ev = scene->animation.exposure_limit_ev;
    xl->lock = !per_frame;
    if (!xl->lock || !sun_moves) return ATMOS_OK;
    atmos_scene *fs = malloc(sizeof *fs); /* large: not on the stack */
    if (!fs) return fprintf(stderr, "atmos render: out of memory\n"), ATMOS_E_NOMEM;
    atmos_status st = highest_sun(ctx, scene, nframes, fs, &xl->key, &xl->by_sun);
    if (st == ATMOS_OK && xl->key > 1) st = key_exposure(ctx, plan, scene, xl, fs);
    free(fs);
    return st;
}

/* The share of pixels of a display image whose three channels are all at least 250/255. */
static double white_share(const atmos_image *disp)
{
    const size_t n = (size_t)disp->width * disp->height;
    size_t white = 0;
    for (size_t i = 0; i < n; i++) {
        const float *p = disp->pixels + i * (size_t)disp->channels;
        white += p[0] >= 250.f / 255 && p[1] >= 250.f / 255 && p[2] >= 250.f / 255;
    }
    return n ? (double)white / n : 0;
}

atmos_status render_exposure_tone_map(atmos_context *ctx, atmos_image *lin, const atmos_scene *fs, exposure_lock *xl,
                                      atmos_image **disp)
{
    atmos_tonemap_desc td = fs->tonemap;
    int limited = 0;
    if (xl->locked && !td.manual_exposure) td.manual_exposure = 1, td.exposure_ev = xl->ev;
    if (!td.manual_exposure) {
        const double s = auto_scale(lin, fs, xl, &limited);
        if (limited && s > 0) td.manual_exposure = 1, td.exposure_ev = xl->limit_ev;
    }
    const double scale = atmos_tonemap_scale(lin, &td);
    char buf[96];
    snprintf(buf, sizeof buf, "%.6g", scale);
    atmos_image_set_meta(lin, "atmos:exposure_scale", buf);
    if (xl->lock && !xl->locked && !fs->tonemap.manual_exposure && scale > 0 && isfinite(scale))
        xl->ev = ev_of_scale(scale), xl->locked = 1; /* the key frame is the first */
    if (xl->locked && !fs->tonemap.manual_exposure) {
        snprintf(buf, sizeof buf, "locked at frame %d's%s", xl->key, xl->by_sun ? " (the highest sun)" : "");
        atmos_image_set_meta(lin, "atmos:exposure", buf);
    } else if (limited) {
        snprintf(buf, sizeof buf, "automatic, held at the limit EV %g", xl->limit_ev);
        atmos_image_set_meta(lin, "atmos:exposure", buf);
    }
    atmos_status st = atmos_tonemap(ctx, lin, &td, disp);
    if (st == ATMOS_OK && xl->locked && !fs->tonemap.manual_exposure && !xl->warned) {
        const double w = white_share(*disp);
        if (w > 0.25) {
            fprintf(stderr, "atmos render: warning: frame %d/%d: %.0f %% of the pixels are white with the exposure "
                            "locked at frame %d's; --exposure-per-frame exposes each frame for itself\n",
                    xl->frame, xl->nframes, 100 * w, xl->key);
            xl->warned = 1;
        }
    }
    return st;
}
