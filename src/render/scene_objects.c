/* The scene's objects as meshes (plan_internal.h, atmos__scene_objects_load): each loaded,
 * placed by its transform, its albedo per wavelength. The renderers that draw objects (the
 * beam renderer, Harris's particle renderer) share it. */
#include "render/plan_internal.h"

#include <stdlib.h>
#include <string.h>

atmos_status atmos__scene_objects_load(atmos_plan *p, atmos_mesh ***mesh, double (**albedo)[ATMOS_MAX_WAVELENGTHS],
                                       int *n)
{
    const atmos_scene *s = &p->scene;
    *n = 0;
    *mesh = calloc((size_t)(s->object_count ? s->object_count : 1), sizeof **mesh);
    *albedo = calloc((size_t)(s->object_count ? s->object_count : 1), sizeof **albedo);
    if (!*mesh || !*albedo) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render: out of memory for the objects");
    for (int i = 0; i < s->object_count; i++) {
        const atmos_scene_object *o = &s->objects[i];
        atmos_status st = atmos_mesh_load(p->ctx, o->mesh, 0, &(*mesh)[i]);
        if (st != ATMOS_OK) return st;
        *n = i + 1;
        atmos_mesh_transform t;
        memcpy(t.position_m, o->position_m, sizeof t.position_m);
        memcpy(t.scale, o->scale, sizeof t.scale);
        memcpy(t.rotation_deg, o->rotation_deg, sizeof t.rotation_deg);
        if ((st = atmos_mesh_apply_transform(p->ctx, (*mesh)[i], &t)) != ATMOS_OK) return st;
        for (int k = 0; k < p->wl.count; k++)
            (*albedo)[i][k] = p->wl.mode == ATMOS_WAVELENGTHS_RGB ? o->albedo[k < 3 ? k : 2]
                                                                 : (o->albedo[0] + o->albedo[1] + o->albedo[2]) / 3;
    }
    return ATMOS_OK;
}
