/* atmos render's time-lapse of a simulated volume (render_timelapse.h). */
#include "render_timelapse.h"

#include <string.h>

int render_timelapse_wanted(const atmos_scene *scene)
{
    return scene->animation.frames > 1 && scene->animation.minutes_end_set;
}

atmos_status render_timelapse_volume(atmos_context *ctx, render_timelapse *tl, const atmos_scene *fs,
                                     atmos_volume **out)
{
    const atmos_scene_volume *sv = &fs->volume;
    if (!tl->sim) {
        const atmos_sim_desc d = {sv->source + 9, 0, sv->sim_grid, sv->seed, sv->sim_refine, sv->sim_detail, sv->sim_ice};
        atmos_status st = atmos_sim_create(ctx, &d, &tl->sim);
        if (st != ATMOS_OK) return st;
    }
    return atmos_sim_volume_at(ctx, tl->sim, sv->sim_minutes, out);
}

void render_timelapse_free(render_timelapse *tl)
{
    atmos_sim_destroy(tl->sim);
    tl->sim = NULL;
}
