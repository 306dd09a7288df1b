/* A warning for a light that lights nothing (objects.h), where the image would be black without a
 * word: a point or spot light inside a closed mesh, or a spot of no angle. */
#include "render/objects.h"
#include "mesh/mesh_enclose.h"

void atmos__objects_warn_dark_lights(atmos_context *ctx, const atmos_scene *s, const atmos__objects *ob)
{
    for (int i = 0; i < s->light_count; i++) {
        const atmos_scene_light *l = &s->lights[i];
        if (l->type == ATMOS_LIGHT_SPOT && l->cone_deg + l->edge_deg <= 0)
            atmos__log(ctx, ATMOS_LOG_WARN, "/lights/%d: a spot of cone_deg 0 and edge_deg 0 lights nothing", i);
        const double *p = l->position_m;
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
