/* The volume a scene names ("volume" in a scene file): loading or generating it and
 * placing it in the world. */
#include "core/internal.h"

#include <math.h>
#include <string.h>

atmos_status atmos_scene_load_volume(atmos_context *ctx, const atmos_scene *scene, atmos_volume **out,
                                     double offset_m[3])
{
    if (!scene || !out || !offset_m) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "scene volume: missing argument");
    *out = NULL;
    const atmos_scene_volume *sv = &scene->volume;
    if (!sv->source[0]) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "scene volume: the scene names no volume");
    atmos_status st;
    atmos_volume *vol = NULL;
    if (!strncmp(sv->source, "generate:", 9)) {
        atmos_volume_generate_desc gd;
        memset(&gd, 0, sizeof gd);
        gd.seed = sv->seed;
        gd.voxel_size_m = sv->voxel_size_m;
        gd.scale = sv->scale > 0 ? sv->scale : 1.0;
        st = atmos_volume_generate(ctx, sv->source + 9, &gd, &vol);
    } else {
        atmos_volume_load_desc ld;
        memset(&ld, 0, sizeof ld);
        ld.grids = sv->grids[0] ? sv->grids : NULL;
        ld.field = sv->particle[0] ? sv->particle : NULL;
        ld.time_index = sv->time_index;
        ld.voxel_size_m = sv->voxel_size_m;
        st = atmos_volume_load(ctx, sv->source, &ld, &vol);
    }
    if (st != ATMOS_OK) return st;
    atmos_scene_volume_offset(scene, vol, offset_m);
    *out = vol;
    return ATMOS_OK;
}

void atmos_scene_volume_offset(const atmos_scene *scene, const atmos_volume *volume, double offset_m[3])
{
    const atmos_scene_volume *sv = &scene->volume;
    double lo[3], hi[3];
    atmos_volume_bounds(volume, lo, hi);
    if (sv->placed) {
        /* position_m is where the centre of the box's bottom face goes. */
        offset_m[0] = sv->position_m[0] - 0.5 * (lo[0] + hi[0]);
        offset_m[1] = sv->position_m[1] - lo[1];
        offset_m[2] = sv->position_m[2] - 0.5 * (lo[2] + hi[2]);
    } else {
        /* The box's centre moved horizontally to three of its widths (at least 4 km)
         * in front of the camera, at its own altitude. */
        const atmos_camera_desc *c = &scene->camera;
        double f[3];
        for (int k = 0; k < 3; k++) f[k] = c->look_at[k] - c->position[k];
        double fh = sqrt(f[0] * f[0] + f[2] * f[2]);
        if (!(fh > 1e-9)) f[0] = 0, f[2] = -1, fh = 1; /* looking straight up or down: north */
        double width = fmax(hi[0] - lo[0], hi[2] - lo[2]), dist = fmax(3.0 * width, 4000.0);
        offset_m[0] = c->position[0] + f[0] / fh * dist - 0.5 * (lo[0] + hi[0]);
        offset_m[1] = 0.0;
        offset_m[2] = c->position[2] + f[2] / fh * dist - 0.5 * (lo[2] + hi[2]);
    }
}
