/* The Earth's atmosphere over a spherical planet: one description (densities, coefficients,
 * phase functions, geometry) shared by its solvers (Dobashi's tables, the production sky,
 * the Monte Carlo reference). Internal to src/atmosphere/.
 *
 * Frame: the planet's centre is at (0, -r_ground, 0); y is the altitude above the point of
 * the ground under the origin. Altitudes and distances in metres, coefficients in m^-1,
 * per-wavelength arrays indexed like the atmosphere's wavelength set. */
#ifndef ATMOS_PLANET_H
#define ATMOS_PLANET_H

#include "core/fastmath.h"
#include "core/internal.h"
#include "core/rng.h"

#include <math.h>

/* Cosine grid of the tabulated aerosol phase function: uniform in the scattering angle. */
#define ATMOS__PLANET_PHASE_N 721

typedef struct atmos__planet {
    double r_ground, r_top;               /* radii of the ground and the top of the air */
    int n;                                /* wavelengths */
    double rayleigh[ATMOS_MAX_WAVELENGTHS]; /* air molecules' scattering at the ground */
    double rayleigh_gamma[ATMOS_MAX_WAVELENGTHS]; /* their phase function's depolarization
                                          term gamma = rho / (2 - rho) (0: pure Rayleigh) */
    double h_rayleigh;                    /* their scale height */
    double mie_sca[ATMOS_MAX_WAVELENGTHS];  /* aerosols' scattering at the ground */
    double mie_ext[ATMOS_MAX_WAVELENGTHS];  /* aerosols' extinction at the ground */
    double h_mie;
    double ozone[ATMOS_MAX_WAVELENGTHS];  /* ozone absorption at the peak of its profile */
    double ozone_centre, ozone_half_width; /* tent profile: 1 at centre, 0 beyond +- half width */
    double albedo;                        /* the ground's Lambertian reflectance */
    /* the aerosols' phase function per wavelength, sr^-1, at scattering angles
     * theta_j = j * 180 / (N - 1) degrees, and its cumulative distribution over theta for
     * sampling (cdf[k][0] = 0, cdf[k][N-1] = 1) */
    float mie_phase[ATMOS_MAX_WAVELENGTHS][ATMOS__PLANET_PHASE_N];
    float mie_cdf[ATMOS_MAX_WAVELENGTHS][ATMOS__PLANET_PHASE_N];
    double mie_g[ATMOS_MAX_WAVELENGTHS];  /* asymmetry parameter */
    /* The members above are the air's description, the spherical sky's cache key
     * (spherical.c, whose asserts pin the tail); what follows does not enter its tables. */
    /* the geographic frame (planet_surface.c): the Earth-centred axes (x to latitude 0,
     * longitude 0; y to longitude 90 E; z north) of the world's x (east at the origin),
     * y (up there) and -z (north there) */
    double geo_east[3], geo_up[3], geo_north[3];
    struct atmos__surface *surface;       /* the ground's maps; NULL: uniform, no lights */
    struct atmos__clouds *clouds;         /* the cloud spheres (planet_clouds.c); NULL: none */
} atmos__planet;

/* Fills the description from a resolved atmosphere desc (planet.c, planet_optics.c). */
atmos_status atmos__planet_init(atmos_context *ctx, atmos__planet *pl, const atmos_atmosphere_desc *d,
                                const atmos_wavelengths *wl);

/* ------------------------------------------------------------------ profiles */
static inline double atmos__planet_rho_rayleigh(const atmos__planet *pl, double h)
{
    return exp(-(h > 0 ? h : 0) / pl->h_rayleigh);
}
static inline double atmos__planet_rho_mie(const atmos__planet *pl, double h)
{
    return exp(-(h > 0 ? h : 0) / pl->h_mie);
}
static inline double atmos__planet_rho_ozone(const atmos__planet *pl, double h)
{
    const double x = 1.0 - fabs(h - pl->ozone_centre) / pl->ozone_half_width;
    return x > 0 ? x : 0.0;
}
/* Extinction at altitude h for wavelength k (above the top: 0). */
static inline double atmos__planet_extinction(const atmos__planet *pl, double h, int k)
{
    if (h > pl->r_top - pl->r_ground) return 0.0;
    return pl->rayleigh[k] * atmos__planet_rho_rayleigh(pl, h) + pl->mie_ext[k] * atmos__planet_rho_mie(pl, h) +
           pl->ozone[k] * atmos__planet_rho_ozone(pl, h);
}

/* ------------------------------------------------------------------ phase functions */
/* The air molecules' phase function with depolarization (Chandrasekhar 1950 §18):
 * 3 / (16 pi) (1 + 3 gamma + (1 - gamma) cos^2) / (1 + 2 gamma), sr^-1. */
static inline double atmos__planet_rayleigh_phase(const atmos__planet *pl, int k, double cos_theta)
{
    const double g = pl->rayleigh_gamma[k];
    return 3.0 / (16.0 * ATMOS_PI) * (1.0 + 3.0 * g + (1.0 - g) * cos_theta * cos_theta) / (1.0 + 2.0 * g);
}
/* The same as kr (a + b cos^2), kr = 3 / (16 pi): the coefficients a and b of wavelength k
 * (for loops that apply it to many rays). */
static inline void atmos__planet_rayleigh_ab(const atmos__planet *pl, int k, float *a, float *b)
{
    const double g = pl->rayleigh_gamma[k];
    *a = (float)((1.0 + 3.0 * g) / (1.0 + 2.0 * g));
    *b = (float)((1.0 - g) / (1.0 + 2.0 * g));
}
/* The aerosols' phase function (sr^-1) at cos_theta for wavelength k: P sin(theta)
 * interpolated linearly in theta between the table's angles, over sin(theta); it integrates
 * to one over the sphere. */
double atmos__planet_mie_phase(const atmos__planet *pl, int k, double cos_theta);
/* That phase function tabulated for look-ups: out[k * steps + j] at sin(theta / 2) =
 * j / (steps - 1), for the n wavelengths (steps >= 2). */
void atmos__planet_mie_phase_table(const atmos__planet *pl, int n, int steps, float *out);
/* A cos_theta drawn from exactly that density with the uniform number u (pdf = eval). */
double atmos__planet_mie_sample(const atmos__planet *pl, int k, double u);
/* The mixture at altitude h: (rayleigh_sca * P_R + mie_sca * P_M) / (rayleigh_sca + mie_sca). */
double atmos__planet_phase(const atmos__planet *pl, double h, int k, double cos_theta);

/* ------------------------------------------------------------------ geometry */
/* Distance from the centre, altitude, and the cosine of the zenith angle of d at p. */
double atmos__planet_radius(const atmos__planet *pl, const double p[3]);
double atmos__planet_altitude(const atmos__planet *pl, const double p[3]);
double atmos__planet_mu(const atmos__planet *pl, const double p[3], const double d[3]);
/* The nearest t >= 0 where p + t d meets the sphere of radius r about the centre, or
 * INFINITY. From inside the sphere this is the exit. */
double atmos__planet_sphere_hit(const atmos__planet *pl, const double p[3], const double d[3], double r);
/* Distance to the ground along d (INFINITY if missed); a point at or below the ground
 * looking down is on it (0). */
double atmos__planet_ground_distance(const atmos__planet *pl, const double p[3], const double d[3]);
/* The part [*t0, *t1] of the segment [0, dist] inside the atmosphere (below r_top and
 * above the ground); 0 if none. */
int atmos__planet_clip(const atmos__planet *pl, const double p[3], const double d[3], double dist, double *t0,
                       double *t1);
/* The local frame at q (a position from the planet's centre): up, e1 horizontal toward the
 * sun (any horizontal axis with the sun at the zenith or nadir), e2 = up x e1; returns the
 * sun's zenith cosine there. The per-eye tables of the solvers are laid out in it. */
double atmos__planet_sun_frame(const double q[3], const double sun[3], double up[3], double e1[3], double e2[3]);
/* Moves p onto the ground along the local vertical; n: the outward normal there. */
void atmos__planet_ground_point(const atmos__planet *pl, double p[3], double n[3]);
/* Distance to the ground and to the top along the direction of cosine mu from altitude h:
 * the standard (r, mu) parametrization of the spherical kinds' tables. */
double atmos__planet_dist_top(const atmos__planet *pl, double r, double mu);
double atmos__planet_dist_ground(const atmos__planet *pl, double r, double mu); /* INFINITY: misses */

/* ------------------------------------------------------------------ the ground */
/* The ground's Lambertian reflectance at the ground point g for wavelength k (uniform, or
 * from a map) and the radiance its night map gives there at full night, W m^-2 sr^-1 nm^-1
 * (planet_surface.c); every solver and the reference draw the lights through
 * atmos__planet_ground_lights, which fades them by the sun's elevation. */
double atmos__planet_ground_albedo(const atmos__planet *pl, const double g[3], int k);
double atmos__planet_ground_emission(const atmos__planet *pl, const double g[3], int k);
/* The night lights at g as the sun (direction sun) sees them: the emission times the night
 * factor, 1 where the sun is 12 degrees or more below g's horizon, 0 where it is above it,
 * smooth between (twilight). The solvers' radiance uses this one. */
double atmos__planet_ground_lights(const atmos__planet *pl, const double g[3], const double sun[3], int k);
/* Latitude and longitude (degrees; longitude in [-180, 180]) of the direction of x from the
 * planet's centre. */
void atmos__planet_latlon(const atmos__planet *pl, const double x[3], double *lat_deg, double *lon_deg);
/* The same for texture look-ups (the cloud image), without the library's asin and atan2:
 * within 1.2e-6 degrees of atmos__planet_latlon (test_earth's test_latlon_fast). */
static inline void atmos__planet_latlon_fast(const atmos__planet *pl, const double x[3], double *lat_deg,
                                             double *lon_deg)
{
    const double v[3] = {x[0], x[1] + pl->r_ground, -x[2]};
    double q[3];
    for (int i = 0; i < 3; i++) q[i] = v[0] * pl->geo_east[i] + v[1] * pl->geo_up[i] + v[2] * pl->geo_north[i];
    *lat_deg = atmos__atan2_fast(q[2], sqrt(q[0] * q[0] + q[1] * q[1])) * ATMOS_RAD2DEG;
    *lon_deg = atmos__atan2_fast(q[1], q[0]) * ATMOS_RAD2DEG;
}
/* Builds the geographic frame and the maps of d (planet_surface.c) and the cloud spheres
 * (planet_clouds.c) into pl; the release functions free them (NULL-safe). */
atmos_status atmos__planet_surface_create(atmos_context *ctx, atmos__planet *pl, const atmos_atmosphere_desc *d,
                                          const atmos_wavelengths *wl);
void atmos__planet_surface_release(atmos__planet *pl);
atmos_status atmos__planet_clouds_create(atmos_context *ctx, atmos__planet *pl, const atmos_atmosphere_desc *d);
void atmos__planet_clouds_release(atmos__planet *pl);
/* Fills the cloud settings' defaults (zero means default; planet_clouds.c). */
void atmos__clouds_resolve(atmos_cloud_desc *c);

/* ------------------------------------------------------------------ numerics */
/* Optical depth per wavelength (subset k[0..m-1], k NULL: all) of the segment p + t d,
 * t in [0, dist] (dist may be INFINITY), by quadrature fine enough for a reference (the
 * solvers' tables are built with it; planet.c documents the accuracy). */
void atmos__planet_optical_depth(const atmos__planet *pl, const double p[3], const double d[3], double dist, int m,
                                 const int *k, double *out);
/* Transmittance of the sunlight (direction sun) reaching p: exp(-depth to the top), 0 where
 * the planet hides the sun's centre. */
void atmos__planet_sun_transmittance(const atmos__planet *pl, const double p[3], const double sun[3], int m,
                                     const int *k, double *out);
/* Single scattering (per unit solar irradiance) of the segment p + t d, t in [0, dist]:
 * the integral of sigma_s P T(p, x) T_sun(x) by brute-force quadrature, with the planet's
 * shadow. A slow second method for tests and the tables. */
void atmos__planet_single_scatter(const atmos__planet *pl, const double p[3], const double d[3], double dist,
                                  const double sun[3], int m, const int *k, double *out);

#endif
