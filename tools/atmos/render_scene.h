/* atmos render's scene from its options (render_scene.c). */
#ifndef ATMOS_CLI_RENDER_SCENE_H
#define ATMOS_CLI_RENDER_SCENE_H

#include "render_opts.h"

#include <stddef.h>

/* The scene: the file (a volume file there is refused with a hint to --volume) or the
 * default, the options applied, validated. A volume file with no camera in the scene or
 * the options is loaded into *volume (else NULL; the caller destroys it), placed, and the
 * camera framed on it. Returns CLI_EXIT_OK or the exit status of the failure (message
 * printed). */
int render_scene_make(atmos_context *ctx, const render_opts *o, atmos_scene *scene, atmos_volume **volume);

/* The -D (its whole text) whose key is, or holds, the JSON pointer that follows the scene file's
 * name in the error msg ("scene.json: /objects/0/terrain: ..."), or NULL: the error is the
 * define's, not the file's. */
const char *render_scene_define_in(const render_opts *o, const char *msg);

/* The name of the default output (NAME.png when no output is given): the scene file's name
 * without its folder and extension (as pbrt and Mitsuba do), or the scene's "name" for the
 * default scene and a scene from standard input. Returns buf or scene->name. */
const char *render_scene_output_name(const render_opts *o, const atmos_scene *scene, char *buf, size_t cap);

/* The scene file's text for the outputs' metadata (atmos:scene_json): NULL for the default
 * scene, standard input, a file over 1 MiB or one that cannot be read (the scene's own
 * reading reports that). The caller frees it. */
char *render_scene_text(const char *path);

#endif
