/* The mesh module's parts (mesh.c, mesh_builtin.c, mesh_bvh.c). Not part of the API. */
#ifndef ATMOS_MESH_INTERNAL_H
#define ATMOS_MESH_INTERNAL_H

#include "core/internal.h"
#include "core/module.h"

/* A mesh with room for nv vertices and nt triangles (contents zero), normals per vertex when
 * vertex_normals, else per triangle. */
atmos_status atmos__mesh_alloc(atmos_context *ctx, long nv, long nt, int vertex_normals, atmos_mesh **out);

/* The built-in mesh called name (without "builtin:"), finished. */
atmos_status atmos__mesh_builtin(atmos_context *ctx, const char *name, atmos_mesh **out);

/* The bounding volume hierarchy of a mesh's triangles (mesh_bvh.c). */
atmos_status atmos__mesh_bvh_build(atmos_context *ctx, atmos_mesh *mesh);
void atmos__mesh_bvh_destroy(atmos__mesh_bvh *bvh);

/* A height map's kept samples (mesh_terrain.c, mesh_gdal.c): nx x nz values, row by row. */
typedef struct atmos__heights {
    int nx, nz;
    double *h;
} atmos__heights;

/* Band 1 of a raster file through GDAL, every stride-th row and column (stride 0: the least
 * that keeps 2 (nx - 1)(nz - 1) triangles within max_triangles), no-data pixels set to the
 * lowest valid value (mesh_gdal.c). ATMOS_E_UNSUPPORTED without GDAL or its module. */
atmos_status atmos__terrain_read(atmos_context *ctx, const char *path, int stride, long max_triangles,
                                 atmos__heights *out);

/* The GDAL module (terrain_gdal.c, libatmos_gdal.so), its stamp (core/module.h) and its entry:
 * atmos__terrain_read's work on a file that opens, the message of a failure in msg (cap bytes). */
#define ATMOS__GDAL_MODULE "libatmos_gdal.so"
#define ATMOS__GDAL_MODULE_ENTRY "atmos_gdal_module_v1"
#define ATMOS__GDAL_MODULE_STAMP {ATMOS_VERSION_STRING, ATMOS__MODULE_ABI, {sizeof(atmos__heights), 0, 0}}
typedef atmos_status (*atmos__gdal_module_entry)(const char *path, int stride, long max_triangles,
                                                 atmos__heights *out, char *msg, size_t cap);

#endif
