/* The beam renderer's primary visibility by rasterisation: the meshes drawn from a pinhole
 * camera into a buffer of the nearest triangle per pixel centre, so that a pixel's ray meets
 * one known triangle instead of searching the meshes' hierarchies. Where the raster could
 * disagree with a traced ray (a pixel centre within EDGE of a triangle's edge as drawn, two
 * surfaces within a relative depth of 1e-6 of each other, a triangle seen edge-on) the pixel
 * is marked and traced as before; elsewhere the ray is intersected with the raster's triangle
 * alone, exactly as the hierarchy's search would (atmos_mesh_intersect_triangle), so the hit,
 * its depth and normal are the traced ones. Surfaces nearer to the eye's plane than 1 mm are
 * clipped away (a traced ray would see them). Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_PRIMARY_H
#define ATMOS_RENDER_BEAMS_PRIMARY_H

#include "render/objects.h"
#include "render/view.h"
#include "render/beams_kept.h"
#include "atmos/camera.h"

/* A pixel's entry: the mesh and triangle nearest along its centre's ray, NONE when it sees no
 * mesh, TRACE when the raster cannot tell. */
#define ATMOS__BEAMS_PRIMARY_NONE (-1)
#define ATMOS__BEAMS_PRIMARY_TRACE (-2)

typedef struct atmos__beams_primary {
    atmos__rect r;  /* the pixels covered */
    int *mesh;      /* per pixel of r, row by row: the mesh, or NONE / TRACE */
    int *tri;       /* the triangle of that mesh */
    long traced;    /* pixels marked TRACE */
    int owned;      /* mesh and tri are the buffer's own (else kept buffers') */
} atmos__beams_primary;

/* The buffer over the pixels r of cam's image (a pinhole camera; other cameras: every pixel
 * TRACE). Tiles of the image go to the threads; the buffer does not depend on their number. */
atmos_status atmos__beams_primary_build(atmos_context *ctx, const atmos__objects *ob, const atmos_camera *cam,
                                        const atmos__rect *r, atmos__beams_primary *P);
/* The same in keep[0] and keep[1] (the mesh and triangle arrays, kept by the caller; freed by
 * atmos__beams_kept_free, not by atmos__beams_primary_free). */
atmos_status atmos__beams_primary_build_kept(atmos_context *ctx, const atmos__objects *ob, const atmos_camera *cam,
                                             const atmos__rect *r, atmos__beams_kept keep[2], atmos__beams_primary *P);
void atmos__beams_primary_free(atmos__beams_primary *P);

/* As atmos__objects_hit(ob, eye, d, 0, INFINITY, hit, which) for the ray d through the centre of
 * pixel (x, y) of r: the raster's triangle intersected alone, or the traced search. */
int atmos__beams_primary_hit(const atmos__beams_primary *P, const atmos__objects *ob, int x, int y, const double eye[3],
                             const double d[3], atmos_mesh_hit *hit, int *which);

#endif
