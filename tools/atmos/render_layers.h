/* atmos render --exr-layers: extra layers in the --exr file beside R, G, B, A, so a
 * compositor gets one file (render_layers.c). */
#ifndef ATMOS_CLI_RENDER_LAYERS_H
#define ATMOS_CLI_RENDER_LAYERS_H

#include <atmos/atmos.h>

enum {
    RENDER_LAYER_TAU = 1,           /* tau.Y: the volume's optical depth along the pixel's ray */
    RENDER_LAYER_TRANSMITTANCE = 2, /* transmittance.Y = exp(-tau) */
    RENDER_LAYER_ORDER = 4,         /* order.Y: path tracer, mean scattering order of the light */
    RENDER_LAYER_VARIANCE = 8       /* variance.<nm>nm ... variance.Y: path tracer, of each channel's mean */
};

/* Parses "tau,transmittance,order,variance" (any subset) into *mask; 0 and a message on
 * stderr for an unknown name. */
int render_layers_parse(const char *list, int *mask);

/* lin (R, G, B, A) with the layers of mask appended, named in *names (R, G, B, A, then
 * "tau.Y", ...; valid until the next call). The order and variance layers need the path
 * tracer (ATMOS_E_INVALID_ARG otherwise, with a message in ctx). */
atmos_status render_layers_build(atmos_context *ctx, const atmos_plan *plan, const atmos_scene *scene,
                                 const atmos_image *lin, int mask, atmos_image **out, const char *const **names);

/* The names of the path tracer's variance image's channels (atmos_plan_path_variance: one a
 * wavelength, then the luminance's), the same in the --variance file and the layers:
 * "variance.<nm>nm" (exr_names.h: "variance.440nm", "variance.386,25nm"), then "variance.Y";
 * written into buf[0..channels-1], names[k] = buf[k]. */
/* Their units (atmos:units of the --variance file; after "variance.*: " in the layered file's). */
#define RENDER_VARIANCE_UNITS                                                                           \
    "variance of the mean of each channel: variance.<nm>nm in (W m^-2 sr^-1 nm^-1)^2 (spectral radiance), " \
    "variance.Y in (cd/m^2)^2"
void render_layers_variance_names(const atmos_wavelengths *wl, int channels, char (*buf)[40], const char **names);

/* The volume's optical depth along each pixel's ray at the middle wavelength of the set
 * (a 1-channel image). */
atmos_status render_layers_tau(atmos_context *ctx, const atmos_scene *scene, const atmos_plan *plan, atmos_image **out);

#endif
