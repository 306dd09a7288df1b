/* The path tracer's point lights, spotlights, fog and objects (path_lamps.c, docs/path.md
 * "Lights, fog and objects"): the ground truth of the beam renderer. Not part of the API. */
#ifndef ATMOS_RENDER_PATH_LAMPS_H
#define ATMOS_RENDER_PATH_LAMPS_H

#include "light/lamp.h"
#include "render/objects.h"
#include "scene/scene_fog.h"

typedef struct path_lamps {
    int nlamps;
    atmos__lamp *lamp;
    atmos__objects obj;
    double sigma_s, sigma_a;    /* the fog's (0, 0 without one) */
    atmos__fog_optics fog;      /* its phase function (and coefficients) */
} path_lamps;

/* The scene's lights, objects and fog for the wavelength set. */
atmos_status atmos__path_lamps_build(atmos_context *ctx, const atmos_scene *s, const atmos_wavelengths *wl,
                                     path_lamps *L);
void atmos__path_lamps_free(path_lamps *L);

#endif
