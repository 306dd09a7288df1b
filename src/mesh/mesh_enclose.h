/* Whether a point is shut inside a mesh (mesh_enclose.c): the renderers warn of a light that
 * a closed mesh keeps from the scene. Not part of the API. */
#ifndef ATMOS_MESH_ENCLOSE_H
#define ATMOS_MESH_ENCLOSE_H

#include "atmos/mesh.h"

/* 1 if p lies within the mesh's bounds and rays from p in six directions (three axes, each
 * both ways, tilted off the grid's planes) each cross the surface an odd number of times: p is
 * inside a closed surface, which every path out of it crosses. An open surface (a plane, a
 * terrain) lets at least one of the rays out without a crossing, so 0; a ray that grazes an
 * edge and counts it twice can give 0 for a point inside, never 1 for one outside a closed
 * mesh. */
int atmos__mesh_encloses(const atmos_mesh *m, const double p[3]);

#endif
