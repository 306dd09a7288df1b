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
 * volume. The air is the scene's atmosphere (atmosphere.h): the medium around and inside
 * the volume's box, its in-scatter shadowed by the volume (light shafts), and the light
 * arriving from everywhere a path escapes to; the ground is Lambertian, lit by the sun
 * (shadowed by the volume) and by the paths that leave it. In a vacuum (a black or uniform
 * background) the volume floats in empty space.
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

#include "atmos/base.h"
#include "atmos/render.h"
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_PATH_MAX_SPP 1000000

/* Work done and time spent by a render. */
typedef struct atmos_path_stats {
    int spp;                   /* samples per pixel taken (the lowest count of the pixels) */
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
    /* The noise of the volume's pixels (those where some sample scattered in the volume): the
     * relative standard error of the pixel's mean luminance, its mean, median and 90th
     * percentile over them (pixels with a nonzero mean and 2 or more samples). */
    long long volume_pixels;
    double volume_rel_error_mean, volume_rel_error_median, volume_rel_error_p90;
    long long cut_paths;       /* paths stopped by the default depth limit (scene max_depth 0:
                                  10000 scattering events; their further light is lost) */
    long long walks_ended;     /* free flights and shadow rays that took more than 4096 steps
                                  and ended at the Russian roulette that bounds their cost */
    int budget_cut;            /* the time budget stopped the render inside a pass (a pass it
                                  cut is discarded; the first pass's samples are kept) */
    long long empty_pixels;    /* pixels without a sample (a budget spent in the first pass) */
} atmos_path_stats;

/* What atmos_render_path needs beyond the scene; zero means default for every field. The
 * tracer's own settings (samples, time budget, seed, depth, truncation, the estimators) are
 * the scene's "path" section (scene.h, atmos_renderer_settings) and the density scale is the
 * scene's volume's. */
typedef struct atmos_path_settings {
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
} atmos_path_settings;

ATMOS_API void atmos_path_defaults(atmos_path_settings *s);

/* Renders the scene (camera of any type, sun, atmosphere, wavelengths, "path" settings) with
 * the volume (may be NULL: the atmosphere and the ground alone) by path tracing: a plan made
 * and destroyed in one call (include/atmos/plan.h keeps one, and adds samples progressively). *out has the layout of
 * atmos_render_sky: spectral radiance per wavelength (W m^-2 sr^-1 nm^-1), then coverage
 * alpha. settings and info may be NULL. Reports progress through ctx ("render path", from
 * the calling thread, about four times a second) and honours cancellation and the time
 * budget before every sample. */
ATMOS_API atmos_status atmos_render_path(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                         const atmos_path_settings *settings, atmos_image **out,
                                         atmos_render_info *info);

#ifdef __cplusplus
}
#endif
#endif
