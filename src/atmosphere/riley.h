/* Internals of the analytic sky shared with the renderers. */
#ifndef ATMOS_SKY_INTERNAL_H
#define ATMOS_SKY_INTERNAL_H

#include "atmos/atmos.h"

/* Riley et al. 2004, Table 3, 550 nm. */
#define ATMOS_SKY_BETA_SL_550 1.35e-5

struct atmos_sky {
    atmos_atmosphere_desc desc;
    atmos_wavelengths wl;
    double gamma;                            /* 1 / scale height, m^-1 */
    double beta_sl[ATMOS_MAX_WAVELENGTHS];   /* sea-level scattering coefficient, m^-1 */
    double sun_e[ATMOS_MAX_WAVELENGTHS];     /* extraterrestrial irradiance, W m^-2 nm^-1 */
    double cos_sun_radius;
    double sun_solid_angle;
};

/* (1 - e^-z)/z, exact limit 1 at z = 0. */
double atmos__sky_g(double z);
/* tau_v(K) / beta_eye = K g(gamma p_y K); INFINITY for unbounded depth. */
double atmos__sky_view_depth_factor(double gamma, double py, double K);
/* In-scatter along a segment divided by P(theta) E_sun (see sky.c). */
double atmos__sky_inscatter_factor(double gamma, double beta_eye, double G, double ly, double py, double e_end);

#endif
