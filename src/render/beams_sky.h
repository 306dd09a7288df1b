/* The sky's light on the beam renderer's surfaces (docs/beams.md#the-skys-light): the
 * irradiance a Lambertian surface receives from the sky model's upper hemisphere, tabulated
 * once per frame over the surface's normal. Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_SKY_H
#define ATMOS_RENDER_BEAMS_SKY_H

#include "core/internal.h"
#include "atmos/atmosphere.h"

/* Normals of the table: BEAMS_SKY_NY values of n_y over [-1, 1] by BEAMS_SKY_NA azimuths. */
#define BEAMS_SKY_NY 17
#define BEAMS_SKY_NA 32

typedef struct atmos__beams_sky {
    int nw;   /* wavelengths; 0: no sky (a vacuum) */
    float *E; /* [(iy * BEAMS_SKY_NA + ia) * nw + k]: W m^-2 nm^-1 */
} atmos__beams_sky;

/* The table for the sun at sun_dir, the sky as seen from p (the ground under the eye): the
 * radiance of the atmosphere (atmos_atmosphere_radiance, without the sun's disk) over the
 * upper hemisphere on a grid of directions of equal solid angle, times max(0, n . w). */
atmos_status atmos__beams_sky_build(atmos_context *ctx, const atmos_atmosphere *atm, const double p[3],
                                    const double sun_dir[3], int nw, atmos__beams_sky *s);
/* The sky's irradiance on a surface of unit normal n (bilinear in the table) into E[nw]. */
void atmos__beams_sky_irradiance(const atmos__beams_sky *s, const double n[3], double *E);
void atmos__beams_sky_free(atmos__beams_sky *s);

#endif
