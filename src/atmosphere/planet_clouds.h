/* The cloud spheres of the spherical kinds (planet_clouds.c, planet_clouds_render.c):
 * internal to src/atmosphere/. */
#ifndef ATMOS_PLANET_CLOUDS_H
#define ATMOS_PLANET_CLOUDS_H

#include "atmosphere/planet_solver.h"

#define ATMOS__CLOUDS_MAX 64

typedef struct atmos__clouds {
    int m;                       /* spheres */
    double base, top, dh;        /* the layer's heights and one shell's thickness, m */
    double r[ATMOS__CLOUDS_MAX]; /* radii of the spheres, lowest first */
    double mu_min[ATMOS__CLOUDS_MAX];
    double sigma_per_tau;        /* the layer's extinction per unit column optical depth, m^-1 */
    int w, h, global;            /* the optical depth image and whether it spans 360 degrees */
    double lon_w, lon_e, lat_s, lat_n;
    float *tau;                  /* column optical depth per pixel, row 0 north */
    double g;                    /* Henyey-Greenstein asymmetry of single scattering */
    int single;                  /* nonzero: no diffuse source */
} atmos__clouds;

/* Column optical depth of a pixel of linear brightness b (planet_clouds.c's mapping). */
double atmos__clouds_tau_from_brightness(double b, double threshold, double max_tau);
/* Column optical depth at (lat, lon), bilinear; 0 outside the image. */
double atmos__clouds_column_tau(const atmos__clouds *cl, double lat, double lon);
/* Optical depth of shell i crossed at cosine mu to the vertical where the column's is tau:
 * tau / m / max(|mu|, the shell's grazing limit). */
double atmos__clouds_shell_tau(const atmos__clouds *cl, int i, double tau, double mu);
/* Optical depth of shell i crossed at x (on sphere i) in direction d. */
double atmos__clouds_crossing_tau(const atmos__planet *pl, int i, const double x[3], const double d[3]);
/* G: the transmittance of the cloud spheres above sphere `below` (-1: all of them, for the
 * ground) to the sunlight reaching x; the attenuation texture of sphere i is
 * G(x on sphere i, sun, i). */
double atmos__clouds_sun_attenuation(const atmos__planet *pl, const double x[3], const double sun[3], int below);
/* Tabulates G_i over an equirectangular w x h grid of sphere i's points (row 0 north,
 * longitudes -180..180) for one sun direction: the attenuation texture. */
void atmos__clouds_attenuation_texture(const atmos__planet *pl, int i, const double sun[3], int w, int h,
                                       float *out);

/* The attenuation textures of one sun direction (planet_clouds_sun.c): G of every sphere
 * below the top one and of the ground tabulated over a latitude/longitude grid at a quarter
 * of the cloud image's pitch, filled tile by tile as look-ups need them (any thread; the
 * values do not depend on which). NULL without clouds or memory. */
typedef struct atmos__clouds_sun atmos__clouds_sun;
atmos__clouds_sun *atmos__clouds_sun_create(const atmos__planet *pl, const double sun[3]);
void atmos__clouds_sun_destroy(atmos__clouds_sun *s);
/* Nonzero when s was made for exactly this sun. */
int atmos__clouds_sun_same(const atmos__clouds_sun *s, const double sun[3]);
/* G at x (on sphere `below`, or the ground for -1) of latitude and longitude lat, lon
 * (degrees, atmos__planet_latlon_fast's), interpolated bilinearly; outside the grid's box
 * atmos__clouds_sun_attenuation itself. */
double atmos__clouds_sun_lookup(atmos__clouds_sun *s, const double x[3], int below, double lat, double lon);
/* The world-frame point at radius r from the planet's centre over lat, lon (degrees). */
void atmos__clouds_geo_point(const atmos__planet *pl, double r, double lat_deg, double lon_deg, double x[3]);

/* The clouds' transmittance along p + t d, t in [0, dist] (the sun's disk behind them). */
double atmos__clouds_view_transmittance(const atmos__planet *pl, const double p[3], const double d[3], double dist);

/* A view ray through the air and the cloud spheres (planet_clouds_render.c): the solver's
 * in-scatter and transmittance on the segments between the eye, the spheres and the
 * ground; each crossing scatters the sunlight reaching it (times G) and attenuates what
 * lies behind it; the ground is shadowed by G of all spheres. Without the sun's disk. */
void atmos__planet_radiance_clouds(const atmos_atmosphere *a, const double p[3], const double d[3],
                                   const double sun[3], double *out, atmos_atmosphere_hit *info);

/* The same ray from an eye above the cloud layer that meets the ground, the air's part given:
 * Lc[j n + k], Tc[j n + k] the air's in-scatter (phase functions applied) and transmittance
 * from p to stop j, the crossing of sphere m - 1 - j for j < m, the ground for j = m (a
 * per-eye table's, spherical_space.c). The clouds' light and the ground's are composited
 * as atmos__planet_radiance_clouds does, with G from sun's textures (NULL: evaluated at each
 * crossing). Returns 0 (out untouched) when the ray does not
 * cross each sphere once, top to bottom, before the ground. */
int atmos__clouds_radiance_stops(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                                 const double *Lc, const double *Tc, atmos__clouds_sun *gs, double *out);

#endif
