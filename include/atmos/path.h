/* Spectral Monte Carlo volumetric path tracing over a multi-field volume: the reference
 * renderer the fast models are measured against. docs/path.md describes the estimator.
 *
 * Transport inside the volume is unbiased (unless truncate_deg is set: the forward-peak
 * truncation, an approximation, off by default): free flights by delta tracking against the
 * volume's majorant grid (spectral tracking: one flight serves every wavelength a path
 * carries), transmittance of shadow rays by ratio tracking on the residual above a
 * per-cell minorant, directions from the tabulated phase functions by their inverse CDF
 * (atmos_phase_table_sample) of one hero wavelength per path (multiple importance sampling
 * over the carried wavelengths), any number of scattering events ended by Russian roulette,
 * the sun's disk and the sky found at every scattering event both by next-event estimation
 * and by the phase-sampled continuation, combined by multiple importance sampling, and a
 * camera ray's single scattering estimated at a point forced into its crossing of the
 * volume. The air is the analytic sky (sky.h): the medium around and inside the volume's
 * box, its in-scatter shadowed by the volume (light shafts), and the light arriving from
 * everywhere a path escapes to; the ground is Lambertian, lit by the sun (shadowed by the
 * volume) and by the paths that leave it. With a black or uniform background the volume
 * floats in vacuum.
 *
 * Determinism: every (pixel, sample) has its own random stream derived from the seed,
 * so the image is the same bit for bit for any thread count. With a time budget the
 * number of samples depends on the machine; with a sample count it does not.
 *
 * Thread safety: a render reads the volume and the optics only; any number of renders
 * may share them.
 */
#ifndef ATMOS_PATH_H
#define ATMOS_PATH_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_PATH_MAX_SPP 1000000

/* Work done and time spent by a render. */
typedef struct atmos_path_stats {
    int spp;                   /* samples per pixel taken (whole passes) */
    long long paths;           /* camera paths traced */
    long long events;          /* real scattering events (volume and ground) */
    long long tentative;       /* tentative collisions of free-flight sampling (real + null) */
    long long shadow_rays;     /* next-event transmittance estimates */
    double prepare_s;          /* building the tables and the acceleration grid */
    double trace_s;            /* tracing */
    double total_s;
    double mean_rel_error;     /* mean over pixels with a nonzero mean of the relative standard
                                  error of the pixel's mean (luminance-weighted over channels) */
    double truncate_deg;       /* the forward-peak cut used (a grid angle); 0: none */
    double truncated_min, truncated_max; /* the fraction f of the scattering removed by it, over
                                            the fields and wavelengths */
} atmos_path_stats;

/* Settings; zero means "the scene's path section" (scene->path) for spp, time_budget_s,
 * seed and max_depth, and the stated default otherwise. atmos_path_defaults shows them. */
typedef struct atmos_path_settings {
    int spp;               /* samples per pixel, 1..ATMOS_PATH_MAX_SPP (default scene, 64) */
    double time_budget_s;  /* > 0: stop after the pass during which this much time has passed
                              (spp is then the upper limit) */
    uint64_t seed;         /* 0 = the scene's (default 1) */
    int max_depth;         /* scattering events per path; 0 = the scene's (0 = unlimited) */
    double density_scale;  /* multiplies the volume's densities; 0 = 1 */
    double truncate_deg;   /* forward-peak truncation (docs/path.md): the part of every phase
                              function above its value at theta_c inside the cone theta < theta_c
                              counts as not scattered. Degrees, (0, 20]; 0 = the scene's (default
                              0: none, exact); < 0: none whatever the scene says. An
                              approximation: changes radiances within ~theta_c of the forward
                              direction (the sun's aureole), removes the droplets' fireflies. */
    double offset_m[3];    /* added to the volume's world position (as atmos_slice_settings) */
    const atmos_volume_optics *optics; /* NULL: built inside the render (only the phase tables
                                         are read; the Ams tables are not needed) */
    atmos_image **variance; /* optional output: per pixel the variance of the pixel's mean
                               radiance at each wavelength ((W m^-2 sr^-1 nm^-1)^2), then, in
                               the place of alpha, the variance of the mean luminance Y
                               ((cd m^-2)^2, covariances between wavelengths included) */
    atmos_image **order;    /* optional output: per pixel (1 channel) the mean number of volume
                               scattering events of the light reaching the pixel, weighted by
                               each contribution's luminance (sum of order x Y over sum of Y;
                               0 where the pixel's mean luminance is 0). Light from the air or
                               the ground counts the volume events before it only. */
    atmos_path_stats *stats; /* optional output */
    int no_sky_nee;         /* 1: no next-event estimation toward the sky (the sky is then found
                               by the phase-sampled continuations alone; same mean, more noise) */
    int no_forced;          /* 1: camera rays find their single scattering only where their free
                               flight collides (no forced single scattering; same mean, more noise
                               in thin media) */
    int no_aureole;         /* 1: no aureole estimate (docs/path.md, "Fireflies of droplet clouds";
                               used where a phase function's forward peak exceeds 100 sr^-1; same
                               mean, more fireflies) */
} atmos_path_settings;

ATMOS_API void atmos_path_defaults(atmos_path_settings *s);

/* Renders the scene (camera of any type, sun, background, wavelengths) with the volume
 * (may be NULL: the sky and the ground alone) by path tracing. *out has the layout of
 * atmos_render_sky: spectral radiance per wavelength (W m^-2 sr^-1 nm^-1), then coverage
 * alpha. settings and info may be NULL. Reports progress through ctx ("render path")
 * and honours cancellation between passes. */
ATMOS_API atmos_status atmos_render_path(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                         const atmos_path_settings *settings, atmos_image **out,
                                         atmos_render_info *info);

#ifdef __cplusplus
}
#endif
#endif
