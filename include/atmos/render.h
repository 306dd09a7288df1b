/* Rendering a scene to an HDR image, and colour conversion of the result.
 * Renderers do no I/O. Results do not depend on the thread count.
 */
#ifndef ATMOS_RENDER_H
#define ATMOS_RENDER_H

#include "atmos/base.h"
#include "atmos/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct atmos_render_info {
    double seconds;          /* wall time of the render */
    double sun_elevation_deg, sun_azimuth_deg;
} atmos_render_info;

/* Renders the sky of a scene (Riley §4.1 + §4.2.4). *out gets an image with
 * count+1 channels: the spectral radiance (W m^-2 sr^-1 nm^-1) at each wavelength of
 * the scene's set, then coverage alpha (0 outside a fisheye's circle). Reports
 * progress through ctx and honours cancellation. info may be NULL. */
ATMOS_API atmos_status atmos_render_sky(atmos_context *ctx, const atmos_scene *scene,
                                        atmos_image **out, atmos_render_info *info);

/* The optical depth of the volume (moved by offset_m) along the ray through each pixel
 * centre of the scene's camera, with extinction cross-sections sigma_ext[field] (m^2,
 * densities already scaled): a 1-channel image, for error analyses by depth. */
ATMOS_API atmos_status atmos_render_optical_depth(atmos_context *ctx, const atmos_scene *scene,
                                                  const atmos_volume *volume, const double *sigma_ext,
                                                  const double offset_m[3], atmos_image **out);

#ifdef __cplusplus
}
#endif
#endif
