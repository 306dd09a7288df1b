/* Fast float evaluation of Riley's sky for many view rays at once (the renderers'
 * inner loop, through atmosphere_ops.h). Same model and closed form as riley.c, arranged
 * so that everything depending only on the eye and the sun is computed once and
 * the per-ray work is a few vectorisable exponentials per wavelength. */
#ifndef ATMOS_SKY_BATCH_H
#define ATMOS_SKY_BATCH_H

#include "atmos/atmos.h"

typedef struct atmos__sky_batch {
    int n;                 /* wavelengths */
    int sun_up;            /* l_y > 0: otherwise the flat-earth sky is black */
    int high;              /* gamma eye_y > ATMOS__RILEY_HIGH_EYE: beta_eye and e^{gamma eye_y}
                              leave float's range; the caller evaluates in double instead */
    float gamma, eye_y, ly;
    float sun[3];
    float beta_eye[ATMOS_MAX_WAVELENGTHS];    /* Eq. 13 */
    float ts0[ATMOS_MAX_WAVELENGTHS];         /* sun's optical depth at the eye */
    float e_ts0[ATMOS_MAX_WAVELENGTHS];       /* exp(-ts0) */
    float sun_e[ATMOS_MAX_WAVELENGTHS];       /* extraterrestrial irradiance */
    float ground[ATMOS_MAX_WAVELENGTHS];      /* albedo/pi * (l_y * sunlight + sky light) at y = 0 */
} atmos__sky_batch;

void atmos__sky_batch_init(atmos__sky_batch *b, const atmos_atmosphere *sky, double eye_y, const double sun[3]);

/* Per-ray scratch the evaluator needs: 6 floats per ray. */
#define ATMOS__SKY_BATCH_SCRATCH 6

/* Radiance (no sun disk) for count rays (b->high must be 0) with unit directions (dx, dy, dz), added
 * wavelength-major: out[k*count + i] += weight[i] * L_k(ray i).
 * scratch: count*ATMOS__SKY_BATCH_SCRATCH floats. */
void atmos__sky_batch_eval(const atmos__sky_batch *b, int count, const float *dx, const float *dy, const float *dz,
                           const float *weight, float *out, float *scratch);

#endif
