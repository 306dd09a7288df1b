/* The Riley et al. 2004 volume renderer (§4.2-§5): half-angle slicing (Kniss et al.)
 * with a light buffer carrying the intensity I and the expected scattering count n
 * (Eq. 21-22) updated slice by slice (Eq. 25, or the exact product of Eq. 24), an eye
 * buffer accumulating Eq. 26 with the multiple-scattering phase functions Ams_{n+1}
 * plus the back-scatter term xi, and the analytic sky in front of and behind the
 * volume's halfway plane (§5) with the direct sun through the volume (§4.2.4).
 * docs/slice.md describes the algorithm as implemented and its departures.
 *
 * Thread safety: a render reads the volume and the optics tables only; any number of
 * renders may share them. Results do not depend on the thread count.
 */
#ifndef ATMOS_SLICE_H
#define ATMOS_SLICE_H

#include "atmos/base.h"
#include "atmos/render.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Time spent in each stage of a frame (seconds) and the work done. */
typedef struct atmos_slice_timing {
    double prepare;       /* building the plan's render grid and tables (once per plan; not part
                             of the frame's total) */
    double light;         /* light-buffer passes (Eq. 21, 25/24) */
    double eye;           /* eye-buffer passes (Eq. 26) */
    double sky;           /* the sky image and the front/back composite (§5) */
    double total;         /* the frame, end to end */
    long long eye_samples;   /* eye samples evaluated (non-empty occupancy blocks) */
    long long light_samples; /* light samples evaluated */
    int grid_dims[3];        /* the resampled render grid */
    double setup;            /* per-frame set-up: per-pixel rays, light texels, the per-slice spans
                                of pixels and texels to visit (and, when the sun moved, the light
                                frame) */
    int eye_dims[2];         /* the eye buffer (width, height) */
    double aerial;           /* the air in front of the volume (aerial perspective) in the
                                composite, its per-frame table included; part of sky */
    double sunlight;         /* the sunlight entering the light buffer, when the sun moved;
                                part of setup */
    double field;            /* the diffuse light field ("diffuse"), when the sun moved: its source
                                and its diffusion solve; part of setup */
    int field_sweeps;        /* that solve's sweeps (0: kept from the last frame) */
    double air_shadow;       /* the volume's shadow on the air ("air_shadows"): its shadow map when
                                the sun moved, its per-frame table and the per-pixel march; part of
                                sky */
} atmos_slice_timing;

/* What atmos_render_slice needs beyond the scene; zero means default for every field. The
 * renderer's own settings (slices, light buffer, xi, update rule, low albedo, grid size,
 * eye-buffer scale, Ams orders) are the scene's "slice" section (scene.h,
 * atmos_renderer_settings) and the density scale is the scene's volume's. */
typedef struct atmos_slice_settings {
    double offset_m[3];    /* added to the volume's world position (placement in a scene) */
    const atmos_volume_optics *optics; /* NULL = built from the scene inside the render */
    atmos_slice_timing *timing;       /* optional output */
    int reference;         /* nonzero: the plain scalar passes with libm's exp (slow; the fast
                              default differs from it by < 1e-5 relative, docs/slice.md), and
                              the air in front of the volume asked of the atmosphere per pixel
                              instead of the aerial-perspective volume (the spherical kinds) */
} atmos_slice_settings;

/* Fills *s with the defaults (all zero). */
ATMOS_API void atmos_slice_defaults(atmos_slice_settings *s);

/* Renders the scene (camera, sun, atmosphere, wavelengths, "slice" settings, the volume's
 * density scale) with the volume by half-angle slicing: a plan made and destroyed in one call
 * (include/atmos/plan.h keeps one for many frames). *out has the layout of atmos_render_sky:
 * the spectral radiance at each wavelength, then coverage alpha. Pinhole cameras only
 * (ATMOS_E_UNSUPPORTED otherwise). settings may be NULL (defaults); info may be NULL.
 * Reports progress through ctx ("render slice") and honours cancellation. */
ATMOS_API atmos_status atmos_render_slice(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                          const atmos_slice_settings *settings, atmos_image **out,
                                          atmos_render_info *info);

#ifdef __cplusplus
}
#endif
#endif
