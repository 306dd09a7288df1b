/* Loading a mesh (include/atmos/mesh.h, atmos_mesh_load): a built-in shape
 * (mesh_builtin.c) or a Wavefront OBJ file read through tinyobjloader (mesh_obj.h), checked
 * and finished (mesh.c). */
#include "mesh/mesh_internal.h"
#include "mesh/mesh_obj.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static atmos_status load_obj(atmos_context *ctx, const char *path, int max_triangles, atmos_mesh **out)
{
    float *pos = NULL;
    uint32_t *idx = NULL;
    long nv = 0, nt = 0;
    char msg[512];
    const int rc = atmos__obj_read(path, max_triangles, &pos, &nv, &idx, &nt, msg, sizeof msg);
    if (rc != ATMOS__OBJ_OK) {
        const atmos_status st = rc == ATMOS__OBJ_E_IO       ? ATMOS_E_IO
                                : rc == ATMOS__OBJ_E_NOMEM  ? ATMOS_E_NOMEM
                                : rc == ATMOS__OBJ_E_LIMIT  ? ATMOS_E_LIMIT
                                                            : ATMOS_E_FORMAT;
        return atmos__error(ctx, st, "mesh %s: %s", path, msg);
    }
    if (nt < 1) {
        free(pos), free(idx);
        return atmos__error(ctx, ATMOS_E_FORMAT, "mesh %s: no triangles (no face of three or more vertices)", path);
    }
    atmos_mesh *m = calloc(1, sizeof *m);
    float *nrm = calloc((size_t)nt * 3, sizeof(float));
    if (!m || !nrm) {
        free(m), free(nrm), free(pos), free(idx);
        return atmos__error(ctx, ATMOS_E_NOMEM, "mesh %s: out of memory", path);
    }
    m->positions = pos, m->indices = idx, m->normals = nrm;
    m->vertex_count = (int)nv, m->triangle_count = (int)nt;
    atmos_status st = atmos_mesh_finish(ctx, m);
    if (st != ATMOS_OK) {
        char inner[400];
        snprintf(inner, sizeof inner, "%s", atmos_context_error(ctx));
        atmos_mesh_destroy(m);
        return atmos__error(ctx, st, "%s (%s)", inner, path);
    }
    *out = m;
    return ATMOS_OK;
}

atmos_status atmos_mesh_load(atmos_context *ctx, const char *source, int max_triangles, atmos_mesh **out)
{
    if (!source || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mesh: missing source or output");
    *out = NULL;
    if (max_triangles <= 0 || max_triangles > ATMOS_MESH_MAX_TRIANGLES) max_triangles = ATMOS_MESH_MAX_TRIANGLES;
    if (!strncmp(source, "builtin:", 8)) return atmos__mesh_builtin(ctx, source + 8, out);
    return load_obj(ctx, source, max_triangles, out);
}
