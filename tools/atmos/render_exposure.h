/* atmos render's automatic exposure over an animation (docs/scene-format.md#animation):
 *  - locked (the default): one exposure for every frame, that of the frame with the highest
 *    sun (known from the frames' times or angles before anything is rendered): the day is
 *    exposed as a photographer exposes it, and the night falls dark. When that frame is not
 *    the first, a small render of it (a quarter of the width and height) chooses the
 *    exposure first;
 *  - per frame: each frame's own automatic exposure;
 *  - either way no brighter than the camera's limit, animation.exposure_limit_ev (EV100 -2:
 *    30 s at f/2.8), so a night sky is not brightened into a dusk;
 *  - a warning, once, when a frame comes out mostly white with the locked exposure. */
#ifndef ATMOS_CLI_RENDER_EXPOSURE_H
#define ATMOS_CLI_RENDER_EXPOSURE_H

#include "atmos/atmos.h"

typedef struct exposure_lock {
    int lock, locked; /* lock: one exposure for all frames; locked: it is chosen (ev) */
    int key;          /* the frame (from 1) whose exposure is locked */
    int by_sun;       /* key is the frame of the highest sun (the sun moves), not the first */
    double ev;        /* the locked exposure as a manual EV100 */
    int limit;        /* an animation: automatic exposures stop at limit_ev */
    double limit_ev;
    int frame, nframes, warned; /* the frame being written; the white frames' warning given */
} exposure_lock;

/* The exposure of an animation of scene (nframes > 1) from plan: per_frame or locked (then
 * the key frame found and, when it is not the first, its exposure chosen from a small render
 * of it). sun_moves: the frames differ by their sun alone (not a time-lapse, the sun lights
 * something). */
atmos_status render_exposure_start(atmos_context *ctx, atmos_plan *plan, const atmos_scene *scene, int nframes,
                                   int per_frame, int sun_moves, exposure_lock *xl);

/* The tone-mapped image of a frame (scene fs, linear sRGB lin), with the exposure the
 * animation keeps; the scale used goes in lin's metadata (atmos:exposure_scale). */
atmos_status render_exposure_tone_map(atmos_context *ctx, atmos_image *lin, const atmos_scene *fs, exposure_lock *xl,
                                      atmos_image **disp);

#endif
