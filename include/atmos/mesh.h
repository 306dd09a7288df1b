/* Triangle meshes: the opaque objects of a scene that cast shadows into the air and reflect
 * light (docs/beams.md). Positions are float metres; a mesh is built once (loaded from a
 * Wavefront OBJ file or made by a built-in generator), transformed, and then queried by rays
 * through a bounding volume hierarchy. A finished mesh is read-only: any number of threads
 * may intersect it at once.
 */
#ifndef ATMOS_MESH_H
#define ATMOS_MESH_H

#include "atmos/base.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The most triangles a mesh may have. Measured on a 980 000-triangle OBJ file: 180 MB at the
 * peak of the load (the reader's own arrays and the hierarchy's build, about 190 bytes a
 * triangle), 91 MB resident after; so 4 million triangles take about 0.75 GB while loading.
 * Larger inputs are ATMOS_E_LIMIT, counted before the file is read into memory. */
#define ATMOS_MESH_MAX_TRIANGLES 4000000

typedef struct atmos__mesh_bvh atmos__mesh_bvh;

typedef struct atmos_mesh {
    int vertex_count, triangle_count;
    float *positions;        /* 3 per vertex, metres */
    uint32_t *indices;       /* 3 per triangle, counter-clockwise seen from the front */
    float *normals;          /* unit; 3 per vertex when vertex_normals, else 3 per triangle */
    int vertex_normals;
    float lo[3], hi[3];      /* bounds of the positions */
    atmos__mesh_bvh *bvh;    /* built by atmos_mesh_finish; NULL before */
} atmos_mesh;

/* Where a mesh goes in the world: scaled per axis about its origin, rotated about x, then y,
 * then z (degrees, right-handed), then moved to position_m. */
typedef struct atmos_mesh_transform {
    double position_m[3];
    double scale[3];
    double rotation_deg[3];
} atmos_mesh_transform;

/* The identity transform. */
ATMOS_API void atmos_mesh_transform_identity(atmos_mesh_transform *t);

/* The names "builtin:NAME" accepts, NULL-terminated: "sphere" (radius 1, per-vertex normals),
 * "box" (the cube [-1, 1]^3), "plane" (the square [-1, 1] x {0} x [-1, 1], facing +y) and
 * "aircraft" (a fuselage along z from -1 to 1, nose toward -z, wings, tailplane and fin; the
 * wings span 1.6). */
ATMOS_API const char *const *atmos_mesh_builtin_names(void);

/* A mesh from source: "builtin:NAME" or an OBJ file's path (faces of more than three
 * vertices are fanned into triangles; the file's normals, materials and texture coordinates
 * are ignored: normals are the triangles' own). Missing, unreadable or malformed files, no
 * triangles, non-finite vertices, indices out of range and more than max_triangles (0: the
 * ATMOS_MESH_MAX_TRIANGLES bound) are errors naming the file and the problem. The mesh is
 * finished (its hierarchy built). */
ATMOS_API atmos_status atmos_mesh_load(atmos_context *ctx, const char *source, int max_triangles, atmos_mesh **out);

/* Terrain: a height map turned into a grid of triangles (docs/beams.md#terrain). The grid's
 * columns run along +x, its rows along +z, heights along +y; it is centred on the origin in x
 * and z, size_m wide along x (square cells: the depth along z follows the raster's shape).
 * source: a raster file read through GDAL (16-bit PNG, GeoTIFF, anything GDAL reads; band 1;
 * no-data pixels take the lowest valid height) or a generated map, deterministic by seed,
 * samples x samples points: "generate:ridges" (a ridged fractal) or "generate:city" (blocks
 * of buildings of random heights between streets, 12 samples a block). Heights: with height_m > 0 the
 * lowest value becomes 0 and the highest height_m; otherwise value * height_scale (0: 1, the
 * raster holds metres). Every stride-th row and column is kept (stride 0: the least stride
 * that keeps 2 (nx - 1)(nz - 1) within max_triangles, 0: 1 000 000). Missing, unreadable and
 * non-raster files, rasters under 2 x 2 or over ATMOS_TERRAIN_MAX_SIDE a side, non-finite
 * values, a flat normalised map and an unknown generator are errors naming the source; a
 * build without GDAL answers ATMOS_E_UNSUPPORTED for files (the generator still works). */
#define ATMOS_TERRAIN_MAX_SIDE 65536
typedef struct atmos_terrain_desc {
    const char *source;
    double size_m;       /* (0, 1e7] */
    double height_m;     /* > 0: normalised to [0, height_m] */
    double height_scale; /* with height_m 0: metres per raster unit (0: 1) */
    int stride;          /* 0: automatic */
    int max_triangles;   /* 0: 1 000 000; at most ATMOS_MESH_MAX_TRIANGLES */
    int samples;         /* generate: points a side, [2, 4097]; 0: 257 */
    uint64_t seed;       /* generate */
} atmos_terrain_desc;

ATMOS_API atmos_status atmos_mesh_terrain(atmos_context *ctx, const atmos_terrain_desc *desc, atmos_mesh **out);

/* Applies t to the positions and normals and rebuilds the hierarchy. A scale of zero on any
 * axis, or a non-finite value, is ATMOS_E_INVALID_ARG. */
ATMOS_API atmos_status atmos_mesh_apply_transform(atmos_context *ctx, atmos_mesh *mesh, const atmos_mesh_transform *t);

/* Builds (again) the bounds and the bounding volume hierarchy. */
ATMOS_API atmos_status atmos_mesh_finish(atmos_context *ctx, atmos_mesh *mesh);

ATMOS_API void atmos_mesh_destroy(atmos_mesh *mesh);

/* The first hit of the ray o + t d (d need not be unit) with t in (tmin, tmax). */
typedef struct atmos_mesh_hit {
    double t;
    int triangle;
    double normal[3];        /* unit, interpolated with per-vertex normals, facing against d */
} atmos_mesh_hit;

/* 1 and *hit (may be NULL) if the ray hits a triangle of a finished mesh, else 0. */
ATMOS_API int atmos_mesh_intersect(const atmos_mesh *mesh, const double o[3], const double d[3], double tmin,
                                   double tmax, atmos_mesh_hit *hit);

/* The same test against the one triangle tri of the mesh (0 <= tri < triangle_count): 1 and *hit
 * if the ray meets it with t in (tmin, tmax), with the t and normal atmos_mesh_intersect gives
 * when that triangle is the first hit. */
ATMOS_API int atmos_mesh_intersect_triangle(const atmos_mesh *mesh, int tri, const double o[3], const double d[3],
                                            double tmin, double tmax, atmos_mesh_hit *hit);

#ifdef __cplusplus
}
#endif
#endif
