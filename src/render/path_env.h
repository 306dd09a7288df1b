/* The sky as a light for the path tracer (path_env.c): a direction distribution for
 * next-event estimation toward the sky. Not part of the API. */
#ifndef ATMOS_RENDER_PATH_ENV_H
#define ATMOS_RENDER_PATH_ENV_H

#include "render/path_common.h"

/* A sampling distribution of directions for next-event estimation of the sky's light: a
 * table over (cos of the angle from +y, azimuth), cells of equal solid angle, each holding
 * the luminance of the analytic sky's single scattering seen from a reference altitude,
 * mixed with a uniform distribution over the sphere (so that no direction has density 0).
 * Only the density matters: the radiance itself is always evaluated exactly. */
#define PATH_ENV_NMU 32
#define PATH_ENV_NPHI 64
typedef struct {
    double cdf[PATH_ENV_NMU * PATH_ENV_NPHI + 1]; /* cumulative over cells, cdf[0] = 0, last 1 */
    double pdf_cell[PATH_ENV_NMU * PATH_ENV_NPHI]; /* density (sr^-1) of the table part */
    double uniform;                                 /* weight of the uniform part */
} path_env;

/* Builds the table for the sky seen from the point ref (weights Y[] per wavelength).
 * Returns 0 when the sky is dark (sun below the horizon): no next-event estimation. */
int atmos__path_env_build(const atmos_atmosphere *atm, const double sun[3], const double ref[3], const double *Y,
                          path_env *e);
/* A direction drawn from the distribution; returns its density (sr^-1). */
double atmos__path_env_sample(const path_env *e, double u0, double u1, double u2, double d[3]);
/* Density (sr^-1) of unit direction d. */
double atmos__path_env_pdf(const path_env *e, const double d[3]);

#endif
