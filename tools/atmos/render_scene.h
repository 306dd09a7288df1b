/* atmos render's scene from its options (render_scene.c). */
#ifndef ATMOS_CLI_RENDER_SCENE_H
#define ATMOS_CLI_RENDER_SCENE_H

#include "render_opts.h"

/* The scene: the file (a volume file there is refused with a hint to --volume) or the
 * default, the options applied, validated. A volume file with no camera in the scene or
 * the options is loaded into *volume (else NULL; the caller destroys it), placed, and the
 * camera framed on it. Returns CLI_EXIT_OK or the exit status of the failure (message
 * printed). */
int render_scene_make(atmos_context *ctx, const render_opts *o, atmos_scene *scene, atmos_volume **volume);

#endif
