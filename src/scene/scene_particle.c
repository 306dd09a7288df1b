/* A particle type by name for a scene: one of its own "particles" (docs/scene-format.md), else
 * a preset (atmos_particle_preset); the lookup every part of a scene that names a particle
 * uses (a volume field's type, the fog's). */
#include "scene/scene_internal.h"

#include <string.h>

atmos_status atmos_scene_particle(atmos_context *ctx, const atmos_scene *scene, const char *name, atmos_particle_desc *out)
{
    if (!scene || !name || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "scene particle: missing argument");
    for (int i = 0; i < scene->particle_count && i < ATMOS_SCENE_MAX_PARTICLES; i++)
        if (!strcmp(scene->particles[i].name, name)) {
            *out = scene->particles[i];
            return ATMOS_OK;
        }
    if (atmos_particle_preset(NULL, name, out) == ATMOS_OK) return ATMOS_OK;
    char list[512] = "";
    for (int i = 0; i < scene->particle_count && i < ATMOS_SCENE_MAX_PARTICLES; i++) {
        strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, scene->particles[i].name, sizeof list - strlen(list) - 1);
    }
    const char *const *names = atmos_particle_preset_names();
    for (int i = 0; names && names[i]; i++) {
        strncat(list, list[0] ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, names[i], sizeof list - strlen(list) - 1);
    }
    return atmos__error(ctx, ATMOS_E_INVALID_ARG, "particle type '%s' is neither in the scene's \"particles\" nor a preset (known: %s)",
                        name, list);
}
