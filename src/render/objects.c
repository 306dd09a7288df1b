/* The scene's objects for the renderers (objects.h). */
#include "render/objects.h"
#include "scene/scene_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A terrain object's mesh from its height map (a file through GDAL, or generated). */
static atmos_status load_terrain(atmos_context *ctx, const atmos_scene_object *o, atmos_mesh **out)
{
    atmos_terrain_desc d;
    memset(&d, 0, sizeof d);
    d.source = o->terrain, d.size_m = o->size_m, d.height_m = o->height_m, d.height_scale = o->height_scale;
    d.stride = o->stride, d.samples = o->samples, d.max_triangles = o->max_triangles, d.seed = o->seed;
    return atmos_mesh_terrain(ctx, &d, out);
}

/* A failed mesh or terrain's message with the scene file and its key in front, and for a
 * relative path where it was looked for, as a light's image says (lamp.c); placed: the mesh was
 * read and failed once placed (a vertex beyond 1e8 m after position and scale), which the
 * message says with the file's name. */
static atmos_status name_key(atmos_context *ctx, atmos_status st, const atmos_scene *s, int i, int placed)
{
    const atmos_scene_object *o = &s->objects[i];
    const char *path = o->terrain[0] ? o->terrain : o->mesh;
    if (placed) {
        char why[1024];
        snprintf(why, sizeof why, "%s", atmos_context_error(ctx));
        atmos__error(ctx, st, "%s after position and scale (%s)", why, path);
    }
    char key[48];
    snprintf(key, sizeof key, "/objects/%d/%s", i, o->terrain[0] ? "terrain" : "mesh");
    return atmos__scene_file_error(ctx, st, s, path, key, st == ATMOS_E_IO);
}

atmos_status atmos__objects_load(atmos_context *ctx, const atmos_scene *s, const atmos_wavelengths *wl,
                                 atmos__objects *ob)
{
    memset(ob, 0, sizeof *ob);
    const size_t n = (size_t)(s->object_count ? s->object_count : 1);
    ob->mesh = calloc(n, sizeof *ob->mesh);
    ob->albedo = calloc(n, sizeof *ob->albedo);
    if (!ob->mesh || !ob->albedo) return atmos__error(ctx, ATMOS_E_NOMEM, "render: out of memory for the objects");
    for (int i = 0; i < s->object_count; i++) {
        const atmos_scene_object *o = &s->objects[i];
        atmos_status st = o->terrain[0] ? load_terrain(ctx, o, &ob->mesh[i]) : atmos_mesh_load(ctx, o->mesh, 0, &ob->mesh[i]);
        if (st != ATMOS_OK) return name_key(ctx, st, s, i, 0);
        ob->n = i + 1;
        atmos_mesh_transform t;
        memcpy(t.position_m, o->position_m, sizeof t.position_m);
        memcpy(t.scale, o->scale, sizeof t.scale);
        memcpy(t.rotation_deg, o->rotation_deg, sizeof t.rotation_deg);
        if ((st = atmos_mesh_apply_transform(ctx, ob->mesh[i], &t)) != ATMOS_OK) return name_key(ctx, st, s, i, 1);
        for (int k = 0; k < wl->count; k++)
            ob->albedo[i][k] = wl->mode == ATMOS_WAVELENGTHS_RGB ? o->albedo[k < 3 ? k : 2]
                                                               : (o->albedo[0] + o->albedo[1] + o->albedo[2]) / 3;
    }
    return ATMOS_OK;
}

void atmos__objects_free(atmos__objects *ob)
{
    if (!ob) return;
    for (int i = 0; i < ob->n; i++) atmos_mesh_destroy(ob->mesh[i]);
    free(ob->mesh);
    free(ob->albedo);
    memset(ob, 0, sizeof *ob);
}

int atmos__objects_hit(const atmos__objects *ob, const double o[3], const double d[3], double tmin, double tmax,
                       atmos_mesh_hit *hit, int *which)
{
    int any = 0;
    for (int m = 0; m < ob->n; m++) {
        atmos_mesh_hit h = {0, 0, {0, 0, 0}};
        if (atmos_mesh_intersect(ob->mesh[m], o, d, tmin, tmax, hit ? &h : NULL)) {
            if (!hit) return 1;
            *hit = h, *which = m, tmax = h.t, any = 1;
        }
    }
    return any;
}
