/* A warning for a light that an object shuts in (objects.h): a point or spot light inside a
 * closed mesh lights nothing outside it, and the image is black there without a word. */
#include "render/objects.h"
#include "mesh/mesh_enclose.h"

void atmos__objects_warn_enclosed_lights(atmos_context *ctx, const atmos_scene *s, const atmos__objects *ob)
{
    for (int i = 0; i < s->light_count; i++) {
        const double *p = s->lights[i].position_m;
        for (int j = 0; j < ob->n; j++)
            if (atmos__mesh_encloses(ob->mesh[j], p)) {
                atmos__log(ctx, ATMOS_LOG_WARN,
                           "/lights/%d at (%g, %g, %g) m is inside /objects/%d, a closed mesh: none of its light "
                           "leaves it",
                           i, p[0], p[1], p[2], j);
                break;
            }
    }
}
