/* What the parts of the path tracer share (path.c: integrator and render loop;
 * path_medium.h, path_phase.h, path_env.h): the wavelength bundle a path carries.
 * Not part of the API. */
#ifndef ATMOS_RENDER_PATH_COMMON_H
#define ATMOS_RENDER_PATH_COMMON_H

#include "core/internal.h"
#include "core/rng.h"
#include "volume/volume_grid.h"

#include <math.h>
#include <stdint.h>

#define PATH_B 4 /* wavelengths carried by one path (all of them when the set has <= 4) */
#define PATH_F ATMOS_VOLUME_MAX_FIELDS

/* ------------------------------------------------------------------ wavelength bundle */

typedef struct {
    int m;             /* wavelengths carried: min(count, PATH_B) */
    int k[PATH_B];     /* their indices in the scene's set */
} path_bundle;

#endif
