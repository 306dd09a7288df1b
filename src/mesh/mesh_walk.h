/* A walk over a finished mesh's bounding volume hierarchy, nearest boxes first (mesh_bvh.c),
 * for callers that cull its nodes themselves (the beam renderer's primary raster). Not part of
 * the API. */
#ifndef ATMOS_MESH_WALK_H
#define ATMOS_MESH_WALK_H

#include "atmos/mesh.h"

/* enter(user, lo, hi): 1 to look inside a node's box, 0 to skip it and all below. */
typedef int (*atmos__mesh_enter_fn)(void *user, const float lo[3], const float hi[3]);
/* leaf(user, tri, n): the n triangles (indices into the mesh) of a leaf entered. */
typedef void (*atmos__mesh_leaf_fn)(void *user, const int *tri, int n);

/* Depth first from the root, of a node's two children the one whose box's centre is nearer to
 * eye first, so a caller drawing the leaves sees near surfaces before those behind them. */
void atmos__mesh_walk(const atmos_mesh *m, const double eye[3], atmos__mesh_enter_fn enter, atmos__mesh_leaf_fn leaf,
                      void *user);

#endif
