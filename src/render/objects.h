/* The scene's objects ("objects": opaque Lambertian meshes) loaded and placed, for the
 * renderers that draw them (the beam renderer, the path tracer). Not part of the API. */
#ifndef ATMOS_RENDER_OBJECTS_H
#define ATMOS_RENDER_OBJECTS_H

#include "core/internal.h"
#include "atmos/mesh.h"
#include "atmos/scene.h"

typedef struct atmos__objects {
    int n;
    atmos_mesh **mesh;
    double (*albedo)[ATMOS_MAX_WAVELENGTHS]; /* per mesh and wavelength */
} atmos__objects;

/* Every object of the scene loaded, transformed, with its albedo per wavelength of wl (rgb:
 * the channel's; spectral: the mean of the three). */
atmos_status atmos__objects_load(atmos_context *ctx, const atmos_scene *s, const atmos_wavelengths *wl,
                                 atmos__objects *o);
void atmos__objects_free(atmos__objects *o);
/* Warns of each of the scene's lights that lights nothing: inside a closed mesh, or a spot of no
 * angle (objects_lights.c); called by the renderers that draw the scene's lights. */
void atmos__objects_warn_dark_lights(atmos_context *ctx, const atmos_scene *s, const atmos__objects *o);

/* The nearest hit of the ray o + t d, t in (tmin, tmax), over all the meshes: 1 and *hit,
 * *which (the mesh) if any; with hit NULL, 1 at the first hit found (a shadow ray). */
int atmos__objects_hit(const atmos__objects *ob, const double o[3], const double d[3], double tmin, double tmax,
                       atmos_mesh_hit *hit, int *which);

#endif
