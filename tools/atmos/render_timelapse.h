/* atmos render's time-lapse of a simulated volume ("animation": {"minutes_end": M}): one
 * simulation carried from frame to frame, each frame's volume taken from it at the frame's
 * minutes (atmos_sim_volume_at: the same as a run of its own to that time). */
#ifndef ATMOS_CLI_RENDER_TIMELAPSE_H
#define ATMOS_CLI_RENDER_TIMELAPSE_H

#include "atmos/atmos.h"

typedef struct render_timelapse {
    atmos_sim *sim; /* made at the first frame asked for */
} render_timelapse;

/* Whether the scene's animation is a time-lapse. */
int render_timelapse_wanted(const atmos_scene *scene);
/* The volume of frame scene fs (atmos_scene_animation_frame's; a plan made with it places it
 * as the scene says); frames asked in increasing order. */
atmos_status render_timelapse_volume(atmos_context *ctx, render_timelapse *tl, const atmos_scene *fs,
                                     atmos_volume **out);
void render_timelapse_free(render_timelapse *tl);

#endif
