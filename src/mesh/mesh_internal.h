/* The mesh module's parts (mesh.c, mesh_builtin.c, mesh_bvh.c). Not part of the API. */
#ifndef ATMOS_MESH_INTERNAL_H
#define ATMOS_MESH_INTERNAL_H

#include "core/internal.h"

/* A mesh with room for nv vertices and nt triangles (contents zero), normals per vertex when
 * vertex_normals, else per triangle. */
atmos_status atmos__mesh_alloc(atmos_context *ctx, long nv, long nt, int vertex_normals, atmos_mesh **out);

/* The built-in mesh called name (without "builtin:"), finished. */
atmos_status atmos__mesh_builtin(atmos_context *ctx, const char *name, atmos_mesh **out);

/* The bounding volume hierarchy of a mesh's triangles (mesh_bvh.c). */
atmos_status atmos__mesh_bvh_build(atmos_context *ctx, atmos_mesh *mesh);
void atmos__mesh_bvh_destroy(atmos__mesh_bvh *bvh);

#endif
