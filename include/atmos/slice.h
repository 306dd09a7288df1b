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

#ifdef __cplusplus
extern "C" {
#endif

/* Light-buffer update rule (Riley §4.2.2). */
typedef enum {
    ATMOS_SLICE_EQ25 = 0, /* the paper's worst-case approximation (default) */
    ATMOS_SLICE_EQ24 = 1  /* the exact product of F_i, at fractional n (atmos_msphase_log_forward_sum) */
} atmos_slice_update;

/* Time spent in each stage of the last render (seconds) and the work done. */
typedef struct atmos_slice_timing {
    double prepare;       /* resampling the volume, tables, per-frame set-up (see setup) */
    double light;         /* light-buffer passes (Eq. 21, 25/24) */
    double eye;           /* eye-buffer passes (Eq. 26) */
    double sky;           /* the sky image and the front/back composite (§5) */
    double total;
    long long eye_samples;   /* eye samples evaluated (non-empty occupancy blocks) */
    long long light_samples; /* light samples evaluated */
    int grid_dims[3];        /* the resampled render grid */
    double setup;            /* per-frame set-up (part of prepare): per-pixel rays, light texels,
                                the per-slice spans of pixels and texels to visit */
    int eye_dims[2];         /* the eye buffer (width, height) */
} atmos_slice_timing;

/* Settings; zero means default for every field (atmos_slice_defaults shows them). */
typedef struct atmos_slice_settings {
    int slices;            /* sampling planes across the volume; default 256, 1..8192 */
    int light_size;        /* light buffer texels per side; default 256, 8..8192 */
    double xi;             /* Riley's back-scatter term xi added to Ams (Eq. 26), sr^-1;
                              0 = default 0.1/(4 pi); negative = no back-scatter term */
    atmos_slice_update update;
    int low_albedo;        /* nonzero: single scattering with the plain phase function,
                              light attenuated by T only (Riley Fig. 13) */
    int grid_max_dim;      /* the volume is box-filtered onto a dense grid of at most this
                              many voxels per axis; default 256, 8..2048 */
    int max_order;         /* Ams orders tabulated (higher n use the last); default 64, 1..1000 */
    double density_scale;  /* multiplies the volume's densities; 0 = 1 */
    double offset_m[3];    /* added to the volume's world position (placement in a scene) */
    const atmos_volume_optics *optics; /* NULL = atmos_volume_optics_build inside the render */
    atmos_slice_timing *timing;       /* optional output */
    int reference;         /* nonzero: the plain scalar passes with libm's exp (slow; the fast
                              default differs from it by < 1e-5 relative, docs/slice.md) */
    double eye_scale;      /* eye buffer resolution relative to the image, per axis, in (0, 1];
                              0 = 1 (the image is the eye buffer). Below 1 the eye passes run on
                              round(scale * width) x round(scale * height) rays and the volume's
                              radiance and transparency are upsampled bilinearly before the §5
                              composite with the full-resolution sky (docs/slice.md) */
} atmos_slice_settings;

/* Fills *s with the resolved defaults. */
ATMOS_API void atmos_slice_defaults(atmos_slice_settings *s);

/* Renders the scene (camera, sun, atmosphere, wavelengths) with the volume by
 * half-angle slicing. *out has the layout of atmos_render_sky: the spectral radiance
 * at each wavelength, then coverage alpha. Pinhole cameras only
 * (ATMOS_E_UNSUPPORTED otherwise). settings may be NULL (defaults); info may be NULL.
 * Reports progress through ctx ("render slice") and honours cancellation. */
ATMOS_API atmos_status atmos_render_slice(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                          const atmos_slice_settings *settings, atmos_image **out,
                                          atmos_render_info *info);

#ifdef __cplusplus
}
#endif
#endif
