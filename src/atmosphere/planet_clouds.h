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
    double inv_r[ATMOS__CLOUDS_MAX]; /* 1 / r */
    double inv_m;                /* 1 / m */
    double sigma_per_tau;        /* the layer's extinction per unit column optical depth, m^-1 */
    int w, h, global;            /* the optical depth image and whether it spans 360 degrees */
    double lon_w, lon_e, lat_s, lat_n;
    double u_per_deg, v_per_deg; /* the image's pixels a degree of longitude and of latitude */
    float *tau;                  /* column optical depth per pixel, row 0 north */
    double g;                    /* Henyey-Greenstein asymmetry of single scattering */
    int single;                  /* nonzero: no diffuse source */
} atmos__clouds;

/* Column optical depth of a pixel of linear brightness b (planet_clouds.c's mapping). */
double atmos__clouds_tau_from_brightness(double b, double threshold, double max_tau);
/* The column optical depth bilinear at the image's pixel coordinates (u, v) (pixel centres
 * at integers; clamped to the image). */
static inline double atmos__clouds_bilinear(const atmos__clouds *cl, double u, double v)
{
    u = u > 0.0 ? u : 0.0, u = u < cl->w - 1.0 ? u : cl->w - 1.0; /* selects, not library calls */
    v = v > 0.0 ? v : 0.0, v = v < cl->h - 1.0 ? v : cl->h - 1.0;
    const int x0 = (int)u, y0 = (int)v;
    const int x1 = x0 + 1 < cl->w ? x0 + 1 : x0, y1 = y0 + 1 < cl->h ? y0 + 1 : y0;
    const double au = u - x0, av = v - y0;
    const float *t = cl->tau;
    const size_t W = (size_t)cl->w;
    return (1 - av) * ((1 - au) * t[y0 * W + x0] + au * t[y0 * W + x1]) +
           av * ((1 - au) * t[y1 * W + x0] + au * t[y1 * W + x1]);
}
/* A regional image's column (planet_clouds.c): 0 outside it, faded over its margin. */
double atmos__clouds_column_tau_edge(const atmos__clouds *cl, double lat, double lon);
/* Column optical depth at (lat, lon), bilinear; 0 outside the image. */
static inline double atmos__clouds_column_tau(const atmos__clouds *cl, double lat, double lon)
{
    if (!cl->global) return atmos__clouds_column_tau_edge(cl, lat, lon);
    if (lat < cl->lat_s || lat > cl->lat_n) return 0.0;
    /* lon in [-180, 180] and the image's west edge in [-360, 360]: one turn at most */
    lon = lon < cl->lon_w ? lon + 360.0 : lon;
    lon = lon >= cl->lon_w + 360.0 ? lon - 360.0 : lon;
    return atmos__clouds_bilinear(cl, (lon - cl->lon_w) * cl->u_per_deg - 0.5, (cl->lat_n - lat) * cl->v_per_deg - 0.5);
}
/* Optical depth of shell i crossed at cosine mu to the vertical where the column's is tau:
 * tau / m / max(|mu|, the shell's grazing limit). */
static inline double atmos__clouds_shell_tau(const atmos__clouds *cl, int i, double tau, double mu)
{
    const double a = fabs(mu);
    return tau * cl->inv_m / (a > cl->mu_min[i] ? a : cl->mu_min[i]);
}
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
 * (degrees, atmos__planet_latlon_fast's), interpolated bilinearly; where the four texels
 * differ by more than 0.05 (a sharp edge between them) one step down from the sphere above
 * at x itself; outside the grid's box atmos__clouds_sun_attenuation itself. */
double atmos__clouds_sun_lookup(atmos__clouds_sun *s, const double x[3], int below, double lat, double lon);
/* The same for a point seen through clouds that pass `through` of its light (in (0, 1]): an
 * error e of G reaches the eye as through e, so the look-up (and its steps down) interpolates
 * over four texels that differ by up to 0.05 / through before it steps down. */
double atmos__clouds_sun_lookup_through(atmos__clouds_sun *s, const double x[3], int below, double lat, double lon,
                                        double through);
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
/* The same with the air of each segment from air->segment (x + t d, t in [0, len]; between:
 * the segment runs from one crossing to the next): its light S (as the solver's in-scatter)
 * and transmittance T, per wavelength. */
typedef struct atmos__clouds_air {
    void (*segment)(const void *ctx, const double x[3], const double d[3], double len, int between, double *S,
                    double *T);
    const void *ctx;
} atmos__clouds_air;
void atmos__planet_radiance_clouds_air(const atmos_atmosphere *a, const double p[3], const double d[3],
                                       const double sun[3], const atmos__clouds_air *air, double *out);

/* The sunlight through the air at the radius of each cloud sphere and of the ground over the
 * sun's cosine there: e[(j n + k) ne + i] for sphere j (j = m: the ground), wavelength k and
 * cosine -1 + 2 i / (ne - 1), looked up linearly. */
typedef struct atmos__sunlight_table {
    const float *e;
    int ne;
} atmos__sunlight_table;
/* Fills out[(m + 1) n ne] with the solver's sunlight at those nodes. */
void atmos__clouds_sunlight_fill(const atmos_atmosphere *a, int ne, float *out);

/* The same ray from an eye above the cloud layer that meets the ground, the air's part given:
 * Lc[j n + k], Tc[j n + k] the air's in-scatter (phase functions applied) and transmittance
 * from p to stop j, the crossing of sphere m - 1 - j for j < m, the ground for j = m (a
 * per-eye table's, spherical_space.c). The clouds' light and the ground's are composited
 * as atmos__planet_radiance_clouds does, with G from sun's textures (NULL: evaluated at each
 * crossing) and the sunlight from e's table (NULL: the solver's at each crossing). Returns 0
 * (out untouched) when the ray does not cross each sphere once, top to bottom, before the
 * ground. */
int atmos__clouds_radiance_stops(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                                 const double *Lc, const double *Tc, atmos__clouds_sun *gs,
                                 const atmos__sunlight_table *e, double *out);

#endif
