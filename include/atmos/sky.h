/* The analytic sky and aerial perspective of Riley et al. 2004, §4.1 and §4.2.4:
 * a flat earth, an exponential single-scattering Rayleigh atmosphere, collimated
 * sunlight, a Lambertian ground and the sun's disk.
 *
 * These functions are also the aerial-perspective API the volume renderers use:
 * transmittance along a segment (Eq. 11), sunlight at a point (Eq. 12) and
 * in-scattered radiance along a segment (Eq. 13-15, corrected: see docs/models.md).
 *
 * Units: positions in metres (y = altitude), directions unit vectors, radiance in
 * W m^-2 sr^-1 nm^-1, irradiance in W m^-2 nm^-1. Every per-wavelength output is an
 * array of atmos_sky_wavelengths(sky)->count values. A sky is immutable after
 * creation: any number of threads may query it.
 */
#ifndef ATMOS_SKY_H
#define ATMOS_SKY_H

#ifdef __cplusplus
extern "C" {
#endif

/* Atmosphere settings. atmos_atmosphere_defaults() fills the paper's values; in a
 * zero-initialised desc, zero means default for every field except ground_albedo. */
typedef struct atmos_atmosphere_desc {
    double beta_sl_550;       /* sea-level scattering coefficient at 550 nm, m^-1; default 1.35e-5
                                 (Riley Table 3); other wavelengths: rgb mode uses Table 3
                                 scaled by beta_sl_550/1.35e-5, spectral mode the lambda^-4 law */
    double scale_height_m;    /* 1/gamma, default 8000 m (Riley Eq. 9-10) */
    double ground_albedo;     /* Lambertian ground reflectance in [0, 1]; zero is black ground */
    double sun_diameter_deg;  /* apparent diameter of the sun's disk, default 0.5 (Riley §4.2.4) */
    double sun_scale;         /* multiplies the extraterrestrial solar spectrum; default 1 */
    int hide_sun_disk;        /* nonzero: do not draw the disk (its light still scatters) */
} atmos_atmosphere_desc;

ATMOS_API void atmos_atmosphere_defaults(atmos_atmosphere_desc *desc);

typedef struct atmos_sky atmos_sky;

/* Builds a sky for a wavelength set. Errors name the offending field. */
ATMOS_API atmos_status atmos_sky_create(atmos_context *ctx, const atmos_atmosphere_desc *desc,
                                        const atmos_wavelengths *wl, atmos_sky **out);
ATMOS_API void atmos_sky_destroy(atmos_sky *sky);
ATMOS_API const atmos_wavelengths *atmos_sky_wavelengths(const atmos_sky *sky);
ATMOS_API const atmos_atmosphere_desc *atmos_sky_desc(const atmos_sky *sky);
/* Sea-level scattering coefficient beta_sl (m^-1) per wavelength. */
ATMOS_API const double *atmos_sky_beta_sea_level(const atmos_sky *sky);

/* Distance (m) from a point at altitude y along dir to the ground (y = 0), or
 * INFINITY if the ray never reaches it. */
ATMOS_API double atmos_sky_ground_distance(double y, const double dir[3]);

/* Eq. 11: transmittance from a point at altitude y along dir over distance metres
 * (distance may be INFINITY). */
ATMOS_API void atmos_sky_transmittance(const atmos_sky *sky, double y, const double dir[3],
                                       double distance, double *out);

/* Eq. 12: solar spectral irradiance (on a surface facing the sun) at altitude y,
 * attenuated by the atmosphere; zero when the sun is on or below the horizon
 * (flat earth). */
ATMOS_API void atmos_sky_sunlight(const atmos_sky *sky, double y, const double sun_dir[3], double *out);

/* Eq. 13-15 (corrected): single-scattered radiance arriving at eye from the
 * segment eye -> eye + distance*dir (distance may be INFINITY). */
ATMOS_API void atmos_sky_inscatter(const atmos_sky *sky, const double eye[3], const double dir[3],
                                   double distance, const double sun_dir[3], double *out);

/* What a view ray sees: the in-scatter to the ground or to space, the lit ground
 * attenuated by the air, and the sun's disk (attenuated) if dir falls inside it. */
typedef struct atmos_sky_sample {
    double distance_m;   /* length of the air path (INFINITY when it reaches space) */
    int hits_ground;
    int in_sun_disk;
} atmos_sky_sample;
ATMOS_API void atmos_sky_radiance(const atmos_sky *sky, const double eye[3], const double dir[3],
                                  const double sun_dir[3], double *out, atmos_sky_sample *info);

/* Radiance of the sun's disk (uniform disk) seen from altitude y: attenuated
 * irradiance divided by the disk's solid angle. */
ATMOS_API void atmos_sky_sun_radiance(const atmos_sky *sky, double y, const double sun_dir[3], double *out);
/* Solid angle of the sun's disk, sr. */
ATMOS_API double atmos_sky_sun_solid_angle(const atmos_sky *sky);

#ifdef __cplusplus
}
#endif
#endif
