/* A scene that names a volume file and no camera, framed as `atmos render` frames it
 * (include/atmos/scene.h, atmos_scene_frame_volume_file): the one place the CLI and the
 * bindings take this rule from. */
#include "atmos/atmos.h"

#include <math.h>
#include <string.h>

atmos_status atmos_scene_frame_volume_file(atmos_context *ctx, atmos_scene *scene, double view_elevation_deg,
                                           atmos_volume **out)
{
    *out = NULL;
    const int file = scene->volume.source[0] && strncmp(scene->volume.source, "generate:", 9) != 0 &&
                     strncmp(scene->volume.source, "simulate:", 9) != 0;
    if (!file || scene->renderer == ATMOS_RENDERER_SKY || scene->camera_given || scene->camera.type != ATMOS_CAMERA_PINHOLE)
        return ATMOS_OK;
    double off[3], lo[3], hi[3];
    atmos_status st = atmos_scene_load_volume(ctx, scene, out, off);
    if (st != ATMOS_OK) return st;
    atmos_volume_bounds(*out, lo, hi);
    /* Not placed by the scene: the box's centre over the origin at its own heights (the camera
     * is framed around it, so nothing needs it in front of a camera). Three widths away, a
     * model domain hundreds of km wide lay where a round planet's ground is tens of km under
     * y = 0 (a 300 km domain 900 km away: 64 km), its clouds that far above the ground. */
    if (!scene->volume.placed) off[0] = -0.5 * (lo[0] + hi[0]), off[2] = -0.5 * (lo[2] + hi[2]);
    /* The placement made explicit, so that a plan puts the volume where it was framed. */
    scene->volume.placed = 1;
    scene->volume.position_m[0] = off[0] + 0.5 * (lo[0] + hi[0]);
    scene->volume.position_m[1] = off[1] + lo[1];
    scene->volume.position_m[2] = off[2] + 0.5 * (lo[2] + hi[2]);
    /* A model domain is wide and flat: seen from above; a cloud from its own height. */
    const int model = !strcmp(atmos_volume_source_format(*out), "netcdf");
    const double el = !isnan(view_elevation_deg) ? view_elevation_deg : model ? -30.0 : 0.0;
    atmos_scene_frame_volume(scene, *out, off, el);
    scene->camera_given = 1;
    return ATMOS_OK;
}
