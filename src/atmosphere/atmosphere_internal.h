/* The atmosphere object and its kinds' functions (src/atmosphere/). Renderers never
 * include this: they use include/atmos/atmosphere.h and atmosphere/atmosphere_ops.h. */
#ifndef ATMOS_ATMOSPHERE_INTERNAL_H
#define ATMOS_ATMOSPHERE_INTERNAL_H

#include "atmosphere/atmosphere_ops.h"

/* Riley et al. 2004, Table 3, 550 nm. */
#define ATMOS_SKY_BETA_SL_550 1.35e-5

struct atmos_atmosphere {
    atmos_atmosphere_desc desc;              /* resolved */
    atmos_wavelengths wl;
    double beta_sl[ATMOS_MAX_WAVELENGTHS];   /* sea-level scattering coefficient, m^-1 (RILEY,
                                                HOMOGENEOUS: the whole layer) */
    double sun_e[ATMOS_MAX_WAVELENGTHS];     /* extraterrestrial irradiance, W m^-2 nm^-1 */
    double cos_sun_radius;
    double sun_solid_angle;
    double gamma;                            /* RILEY: 1 / scale height, m^-1 */
    /* DOBASHI, SPHERICAL (NULL otherwise): the planet, its solver and the solver's tables */
    struct atmos__planet *planet;
    const struct atmos__planet_solver *solver;
    void *model;
    /* RILEY, HOMOGENEOUS with a ground albedo: the sky's irradiance on the ground at
     * ATMOS__SKYLIGHT_NODES sun heights l_y = j / (nodes - 1), per wavelength (flat_skylight.c) */
    double *sky_ground;
};

#define ATMOS__SKYLIGHT_NODES 33
/* flat_skylight.c: builds a->sky_ground (0: out of memory); the irradiance for the sun at
 * height l_y (0 when there is no table or the sun is down). */
int atmos__flat_skylight_build(atmos_atmosphere *a);
void atmos__flat_skylight(const atmos_atmosphere *a, double ly, double *out);

/* Wavelength i of a subset: k[i], or i itself when k is NULL (the whole set). */
#define ATMOS__WL(k, i) ((k) ? (k)[i] : (i))

/* Riley et al. 2004 §4.1 (riley.c). y is the altitude of the point (>= 0). */
/* gamma y above which an eye's descending rays are evaluated from their low end (riley.c) and
 * the renderers' float batch hands Riley's sky to the double-precision functions: at 50 scale
 * heights beta_eye ~ 1e-27 m^-1 is still a normal float, e^{gamma y} ~ 5e21 far from overflow. */
#define ATMOS__RILEY_HIGH_EYE 50.0
/* (1 - e^-z)/z, exact limit 1 at z = 0. */
double atmos__sky_g(double z);
/* tau_v(K) / beta_eye = K g(gamma p_y K); INFINITY for unbounded depth. */
double atmos__sky_view_depth_factor(double gamma, double py, double K);
/* In-scatter along a segment divided by P(theta) E_sun (see riley.c). */
double atmos__sky_inscatter_factor(double gamma, double beta_eye, double G, double ly, double py, double e_end);
void atmos__riley_transmittance(const atmos_atmosphere *a, double y, const double d[3], double dist, int m,
                                const int *k, double *out);
void atmos__riley_sunlight(const atmos_atmosphere *a, double y, const double sun[3], int m, const int *k, double *out);
int atmos__riley_inscatter(const atmos_atmosphere *a, double y, const double d[3], double dist, const double sun[3],
                           int m, const int *k, double *out);
int atmos__riley_scatter_point(const atmos_atmosphere *a, double y, const double d[3], double dist, int m,
                               const int *k, const double *w, atmos__stream *rng, double *t,
                               double *ratio);

/* The homogeneous layer (homogeneous.c); same conventions. */
void atmos__homog_transmittance(const atmos_atmosphere *a, double y, const double d[3], double dist, int m,
                                const int *k, double *out);
void atmos__homog_sunlight(const atmos_atmosphere *a, double y, const double sun[3], int m, const int *k, double *out);
int atmos__homog_inscatter(const atmos_atmosphere *a, double y, const double d[3], double dist, const double sun[3],
                           int m, const int *k, double *out);
int atmos__homog_scatter_point(const atmos_atmosphere *a, double y, const double d[3], double dist, int m,
                               const int *k, const double *w, atmos__stream *rng, double *t,
                               double *ratio);

#endif
