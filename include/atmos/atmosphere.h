/* The atmosphere: what surrounds the volumes and lights them. One small interface with
 * several kinds; every renderer asks it the same questions and reads no kind's fields:
 *
 *   transmittance along a segment           atmos_atmosphere_transmittance
 *   sunlight reaching a point               atmos_atmosphere_sunlight
 *   in-scattered light along a segment      atmos_atmosphere_inscatter   (aerial perspective)
 *   what a view ray sees                    atmos_atmosphere_radiance    (air, ground, sun's disk)
 *   where a ray meets the ground            atmos_atmosphere_ground_distance, _ground_albedo
 *   the air's coefficients and phase        atmos_atmosphere_scattering, _phase
 *
 * Kinds:
 *  - ATMOS_ATMOSPHERE_RILEY: Riley et al. 2004 §4.1 and §4.2.4: a flat earth (y = altitude, the
 *    ground is y = 0), air of density exp(-y / H) scattering by Rayleigh's law (albedo 1),
 *    single scattering of collimated sunlight in closed form (Eq. 8-15, Eq. 15 corrected:
 *    docs/models.md), a Lambertian ground and the sun's disk.
 *  - ATMOS_ATMOSPHERE_VACUUM: no air and no ground; radiance background_radiance from every
 *    direction (0: black), the sun unattenuated and its disk not drawn.
 *  - ATMOS_ATMOSPHERE_HOMOGENEOUS: a layer of air of uniform density from the ground (y = 0)
 *    to thickness_m, with Riley's coefficients at sea level and the Rayleigh phase function,
 *    over the same Lambertian ground: every answer in closed form (a test case, and fog).
 *  - ATMOS_ATMOSPHERE_DOBASHI, ATMOS_ATMOSPHERE_SPHERICAL: the Earth's atmosphere over a
 *    spherical planet (docs/sky.md): air molecules (Rayleigh with the refractive index's
 *    dispersion and the King factor), aerosols (Mie over a size distribution), ozone
 *    absorption, a Lambertian ground. The planet's centre is at (0, -planet_radius_m, 0), so
 *    the ground under the origin is y = 0 and y is the altitude there. DOBASHI is Dobashi et
 *    al. 2002 §5's look-up tables (single scattering and an ambient term); SPHERICAL is the
 *    production sky with all orders of scattering.
 *
 * Units: positions in metres (world frame, y up), directions unit vectors, radiance in
 * W m^-2 sr^-1 nm^-1, irradiance in W m^-2 nm^-1, coefficients in m^-1. Every per-wavelength
 * output has atmos_atmosphere_wavelengths(atm)->count values. An atmosphere is immutable after
 * creation: any number of threads may query it.
 */
#ifndef ATMOS_ATMOSPHERE_H
#define ATMOS_ATMOSPHERE_H

#include "atmos/base.h"
#include "atmos/spectrum.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    ATMOS_ATMOSPHERE_RILEY = 0,
    ATMOS_ATMOSPHERE_VACUUM = 1,
    ATMOS_ATMOSPHERE_HOMOGENEOUS = 2,
    ATMOS_ATMOSPHERE_DOBASHI = 3,
    ATMOS_ATMOSPHERE_SPHERICAL = 4
} atmos_atmosphere_kind;

/* Aerosol types of the spherical kinds (docs/sky.md gives their size distributions,
 * refractive indices and sources). */
typedef enum {
    ATMOS_AEROSOL_CONTINENTAL = 0,
    ATMOS_AEROSOL_MARITIME = 1,
    ATMOS_AEROSOL_URBAN = 2,
    ATMOS_AEROSOL_DESERT = 3,
    ATMOS_AEROSOL_NONE = 4
} atmos_aerosol_type;

struct atmos_image;

/* Clouds of the spherical kinds from a satellite image (Dobashi et al. 2002 §5.4; docs/sky.md,
 * "The Earth from space"): a layer between base_m and top_m of uniform density along the
 * vertical, drawn as `spheres` concentric cloud spheres; the column's optical depth comes from
 * the image's brightness. */
typedef struct atmos_cloud_desc {
    const struct atmos_image *image; /* NULL: no clouds. Brightness, sRGB-encoded in [0,1] (grey,
                                         or the mean of R, G, B); equirectangular over the extent
                                         below, north up */
    double lon_west_deg, lon_east_deg;  /* the image's outer pixel edges; all four 0: the whole */
    double lat_south_deg, lat_north_deg; /* globe (-180..180, -90..90) */
    double base_m, top_m;       /* heights of the layer, m; default 2000 and 8000 */
    int spheres;                /* cloud spheres, 1..64; default 5 */
    double threshold;           /* linear brightness of cloud-free pixels (no cloud at or below
                                   it); default 0.04 */
    double max_optical_depth;   /* cap of the column's optical depth; default 100 */
    double g;                   /* Henyey-Greenstein asymmetry of the clouds' single scattering;
                                   default 0 */
    int single_scattering;      /* nonzero: the sunlight scattered once only (Dobashi's model);
                                   0: also the diffuse source mu_s E (1 - G) / pi (docs/sky.md) */
} atmos_cloud_desc;

/* Atmosphere settings. atmos_atmosphere_defaults() fills the paper's values; in a
 * zero-initialised desc, zero means default for every field except ground_albedo. */
typedef struct atmos_atmosphere_desc {
    double beta_sl_550;       /* sea-level scattering coefficient at 550 nm, m^-1; default 1.35e-5
                                 (Riley Table 3); other wavelengths: rgb mode uses Table 3
                                 scaled by beta_sl_550/1.35e-5, spectral mode the lambda^-4 law */
    double scale_height_m;    /* RILEY: 1/gamma, default 8000 m (Riley Eq. 9-10) */
    double ground_albedo;     /* Lambertian ground reflectance in [0, 1]; zero is black ground */
    double sun_diameter_deg;  /* apparent diameter of the sun's disk, default 0.5 (Riley §4.2.4) */
    double sun_scale;         /* multiplies the extraterrestrial solar spectrum; default 1 */
    int hide_sun_disk;        /* nonzero: do not draw the disk (its light still scatters) */
    atmos_atmosphere_kind kind; /* default RILEY */
    double background_radiance; /* VACUUM: radiance from every direction, >= 0 */
    double thickness_m;       /* HOMOGENEOUS: height of the layer's top, m; default 8000 */
    /* DOBASHI and SPHERICAL (ground_albedo, sun_* as above): */
    double planet_radius_m;   /* default 6360e3 */
    double top_m;             /* height of the top of the atmosphere, m; default 100e3 (>= 60e3) */
    double rayleigh_scale_height_m; /* default 7994 (Dobashi et al. 2002 Appendix A.1) */
    atmos_aerosol_type aerosol;     /* default CONTINENTAL */
    double aerosol_scale_height_m;  /* default 1200 (Dobashi et al. 2002 Appendix A.1) */
    double visibility_km;     /* meteorological range at the ground (Koschmieder, 2 % contrast,
                                 550 nm): sets the aerosol amount; default 40 */
    double turbidity;         /* if > 0, replaces visibility_km: Linke's turbidity at 550 nm,
                                 (tau_air + tau_aerosol) / tau_air over the vertical */
    double ozone_du;          /* ozone column in Dobson units; default 300 */
    int no_ozone;             /* nonzero: no ozone (ozone_du ignored) */
    double dobashi_ambient;   /* DOBASHI: the ambient term I_a standing for multiple scattering
                                 (Dobashi et al. 2002 §3): an isotropic radiance per unit
                                 extraterrestrial irradiance, sr^-1, that the air along a view
                                 ray adds as I_a E_sun (1 - T_view); default 0 (single
                                 scattering only), in [0, 1] */
    /* DOBASHI and SPHERICAL: the Earth's surface and clouds from maps (docs/sky.md, "The Earth
     * from space"). The maps are equirectangular: longitude -180..180 left to right, latitude
     * 90..-90 top to bottom, values sRGB-encoded in [0,1]. The atmosphere keeps compact copies
     * (8 bits per channel): the images may be destroyed after atmos_atmosphere_create. */
    double latitude_deg, longitude_deg; /* where the ground under the origin is; there x points
                                           east, y up, z south (atmos_direction_from_angles) */
    const struct atmos_image *ground_map; /* the ground's reflectance (1 or 3 channels); NULL:
                                             the uniform ground_albedo */
    const struct atmos_image *night_map;  /* lights on the night side (1 or 3 channels); NULL: none */
    double night_radiance;    /* radiance of a white night_map pixel, W m^-2 sr^-1 nm^-1;
                                 default 5e-6 (a bright city in VIIRS's day/night band) */
    atmos_cloud_desc clouds;
} atmos_atmosphere_desc;

ATMOS_API void atmos_atmosphere_defaults(atmos_atmosphere_desc *desc);

typedef struct atmos_atmosphere atmos_atmosphere;

/* Builds an atmosphere for a wavelength set. Errors name the offending field. */
ATMOS_API atmos_status atmos_atmosphere_create(atmos_context *ctx, const atmos_atmosphere_desc *desc,
                                               const atmos_wavelengths *wl, atmos_atmosphere **out);
ATMOS_API void atmos_atmosphere_destroy(atmos_atmosphere *atm);
ATMOS_API atmos_atmosphere_kind atmos_atmosphere_get_kind(const atmos_atmosphere *atm);
ATMOS_API const atmos_wavelengths *atmos_atmosphere_wavelengths(const atmos_atmosphere *atm);
ATMOS_API const atmos_atmosphere_desc *atmos_atmosphere_get_desc(const atmos_atmosphere *atm);

/* The questions below that take a point p and directions (dir, sun_dir) answer NaN (every
 * wavelength of out; an atmos_atmosphere_hit's distance_m NaN, its flags 0) instead of
 * reading out of their tables when
 *  - p, dir or sun_dir is not finite, or dir or sun_dir is not a unit vector (|v| within
 *    1e-6 of 1: normalise first);
 *  - for a view ray (radiance, transmittance, inscatter) the observer p is more than 1 m below
 *    the ground (y < 0 over a flat earth) or inside the planet of a spherical kind;
 *  - for transmittance and inscatter, the distance is NaN.
 * They return void because the renderers call them in their inner loops with checked
 * input; atmos_atmosphere_check_ray answers ATMOS_E_INVALID_ARG with the reason for the same
 * rules (sun_dir may be NULL: not checked), for a caller whose input comes from outside. */
ATMOS_API atmos_status atmos_atmosphere_check_ray(atmos_context *ctx, const atmos_atmosphere *atm, const double p[3],
                                                  const double dir[3], const double sun_dir[3]);

/* Distance (m) from p along dir to the ground, or INFINITY if the ray never reaches it
 * (always INFINITY in a vacuum); NaN when p or dir is not finite. */
ATMOS_API double atmos_atmosphere_ground_distance(const atmos_atmosphere *atm, const double p[3],
                                                  const double dir[3]);
/* Reflectance of the (Lambertian) ground; 0 where there is none. */
ATMOS_API double atmos_atmosphere_ground_albedo(const atmos_atmosphere *atm);

/* Transmittance of the air from p along dir over distance metres (may be INFINITY). */
ATMOS_API void atmos_atmosphere_transmittance(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                                              double distance, double *out);
/* Solar spectral irradiance on a surface facing the sun at p, attenuated by the air (a point
 * below the ground or inside the planet counts as on it); zero when the sun is on or below the horizon of a flat
 * earth. */
ATMOS_API void atmos_atmosphere_sunlight(const atmos_atmosphere *atm, const double p[3], const double sun_dir[3],
                                         double *out);
/* Radiance the air scatters toward p from the segment p -> p + distance*dir (distance may be
 * INFINITY): single scattering for riley, homogeneous and dobashi (plus its ambient term when
 * set), every order for spherical (docs/sky.md). */
ATMOS_API void atmos_atmosphere_inscatter(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                                          double distance, const double sun_dir[3], double *out);

/* What a view ray sees: the in-scatter to the ground or to space, the lit ground attenuated
 * by the air, the background beyond, and the sun's disk (attenuated) if dir falls inside it. */
typedef struct atmos_atmosphere_hit {
    double distance_m;   /* length of the air path (INFINITY when it leaves the atmosphere) */
    int hits_ground;
    int in_sun_disk;
} atmos_atmosphere_hit;
ATMOS_API void atmos_atmosphere_radiance(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                                         const double sun_dir[3], double *out, atmos_atmosphere_hit *info);

/* Radiance of the sun's disk (uniform) seen from p: attenuated irradiance over the disk's
 * solid angle. */
ATMOS_API void atmos_atmosphere_sun_radiance(const atmos_atmosphere *atm, const double p[3], const double sun_dir[3],
                                             double *out);
/* Solid angle of the sun's disk, sr. */
ATMOS_API double atmos_atmosphere_sun_solid_angle(const atmos_atmosphere *atm);
/* 1 if the sun's disk is drawn for this sun direction (not hidden, above the horizon of a
 * flat earth, not in a vacuum). */
ATMOS_API int atmos_atmosphere_sun_disk_visible(const atmos_atmosphere *atm, const double sun_dir[3]);

/* The air's scattering and extinction coefficients (m^-1) at p (either may be NULL). */
ATMOS_API void atmos_atmosphere_scattering(const atmos_atmosphere *atm, const double p[3], double *scattering,
                                           double *extinction);
/* The clouds' extinction (m^-1, grey) at p: a spherical kind's cloud layer at uniform density
 * along the vertical, its column optical depth from the cloud image (docs/sky.md); 0 outside
 * the layer, outside the image, and for an atmosphere without clouds. What the cloud spheres
 * draw, as a field that a volume can sample (atmos_scene_cloud_volume). */
ATMOS_API double atmos_atmosphere_cloud_extinction(const atmos_atmosphere *atm, const double p[3]);
/* The air's phase function at p, sr^-1 (Rayleigh's for the kinds here). */
ATMOS_API double atmos_atmosphere_phase(const atmos_atmosphere *atm, const double p[3], double cos_theta);

/* The look-up tables of a spherical kind, to print or plot: names (NULL-terminated; an empty
 * list for kinds without tables) and one table as an image with one channel per wavelength
 * of the set, its metadata "atmos:table" (the name), "atmos:axes" (what x and y are) and
 * "atmos:units" (what a value is and its units: "1: the transmittance to the top of the air").
 * SPHERICAL: "transmittance", "multiple_scattering", "f_ms", "sky_irradiance",
 * "higher_orders_air", "higher_orders_aerosols"; DOBASHI: "sun_attenuation", "plane_rayleigh",
 * "plane_mie", "plane_attenuation" (docs/sky.md). atmos_atmosphere_kind_table_names gives a
 * kind's names without creating an atmosphere (an empty list for kinds without tables or an
 * unknown kind). ATMOS_E_INVALID_ARG for an unknown name, listing the known ones. */
ATMOS_API const char *const *atmos_atmosphere_table_names(const atmos_atmosphere *atm);
ATMOS_API const char *const *atmos_atmosphere_kind_table_names(atmos_atmosphere_kind kind);
ATMOS_API atmos_status atmos_atmosphere_table(atmos_context *ctx, const atmos_atmosphere *atm, const char *name,
                                              struct atmos_image **out);

/* Ground truth for the spherical kinds (DOBASHI and SPHERICAL describe the same air; the
 * reference ignores their tables): what the view ray sees without the sun's disk, by Monte
 * Carlo random walks through the air with every order of scattering, the ozone's
 * absorption and the ground's reflections; `paths` walks per wavelength, the same result for
 * the same seed on any thread count. max_order > 0 keeps only the light scattered at most
 * that many times (1: single scattering), 0 keeps all. std_error (may be NULL) receives each
 * wavelength's standard error. ATMOS_E_INVALID_ARG for another kind. */
ATMOS_API atmos_status atmos_atmosphere_reference_radiance(const atmos_atmosphere *atm, const double p[3],
                                                           const double dir[3], const double sun_dir[3], long paths,
                                                           unsigned long long seed, int max_order, double *out,
                                                           double *std_error);

#ifdef __cplusplus
}
#endif
#endif
