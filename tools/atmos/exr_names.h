/* Names of EXR channels that hold one wavelength each (the path tracer's variance, the sky
 * models' tables): one spelling for every file atmos writes (exr_names.c). */
#ifndef ATMOS_CLI_EXR_NAMES_H
#define ATMOS_CLI_EXR_NAMES_H

#include <stddef.h>

/* "<layer>.<nm>nm" into buf: the wavelength as it is (%.6g: "440", "386,25"), with a comma
 * for the decimal point as OpenEXR's spectral layout (Fichet et al. 2021) writes it, since
 * OpenEXR takes everything before a name's last dot for its layer ("variance.386.25nm" would be
 * channel "25nm" of layer "variance.386"). */
void cli_exr_wavelength_name(char *buf, size_t cap, const char *layer, double nm);

#endif
