/* Wavelength sets and colour: the paper's three channels ("rgb") or N spectral
 * samples ("spectral"), with conversion to CIE 1931 XYZ and linear sRGB.
 *
 * A wavelength set is a small value type; copy it freely. Thread-safe (read-only).
 */
#ifndef ATMOS_SPECTRUM_H
#define ATMOS_SPECTRUM_H

#include "atmos/base.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_MAX_WAVELENGTHS 128
#define ATMOS_SPECTRAL_DEFAULT 16
#define ATMOS_SPECTRAL_MIN_NM 380.0
#define ATMOS_SPECTRAL_MAX_NM 780.0

typedef enum {
    /* Riley et al. 2004's three channels: 680, 550, 440 nm (Table 3). Values are
     * spectral radiances at those wavelengths; colour is obtained by scaling each
     * channel by (sRGB of the solar spectrum) / (solar irradiance at that
     * wavelength), so that unattenuated sunlight maps to its true colour. */
    ATMOS_WAVELENGTHS_RGB = 0,
    /* N samples at bin centres of N equal bins spanning 380-780 nm; XYZ by the CIE
     * 1931 2° observer integrated over each bin. */
    ATMOS_WAVELENGTHS_SPECTRAL = 1
} atmos_wavelength_mode;

typedef struct atmos_wavelengths {
    atmos_wavelength_mode mode;
    int count;                              /* 3 for rgb, N for spectral */
    double nm[ATMOS_MAX_WAVELENGTHS];       /* sample wavelengths, nm, decreasing for rgb (R,G,B) */
    double width_nm[ATMOS_MAX_WAVELENGTHS]; /* bin widths, nm (rgb: nominal band widths) */
    /* Linear weights: colour[c] = sum_i w[i][c] * radiance[i]. to_xyz gives CIE XYZ
     * with Y in cd m^-2 when radiance is W m^-2 sr^-1 nm^-1 (683 lm/W included);
     * to_srgb gives linear sRGB (Rec. 709 primaries, D65) in the same scale. */
    double to_xyz[ATMOS_MAX_WAVELENGTHS][3];
    double to_srgb[ATMOS_MAX_WAVELENGTHS][3];
    /* Extraterrestrial solar spectral irradiance at each sample, W m^-2 nm^-1
     * (ASTM G173-03, averaged over the sample's bin). */
    double sun_irradiance[ATMOS_MAX_WAVELENGTHS];
} atmos_wavelengths;

/* The paper's three channels. Never fails. */
ATMOS_API void atmos_wavelengths_rgb(atmos_wavelengths *out);
/* N spectral samples in 380-780 nm, 1 <= N <= ATMOS_MAX_WAVELENGTHS. Returns
 * ATMOS_E_INVALID_ARG (out untouched) for other N. */
ATMOS_API atmos_status atmos_wavelengths_spectral(int n, atmos_wavelengths *out);

/* CIE 1931 2° colour-matching functions at a wavelength (nm), linearly
 * interpolated from the 1 nm table; zero outside 360-830 nm. */
ATMOS_API void atmos_cie_xyz_cmf(double nm, double xyz[3]);
/* ASTM G173-03 extraterrestrial spectral irradiance (W m^-2 nm^-1) at nm,
 * linearly interpolated; defined over 280-4000 nm of the table we ship (360-830 nm). */
ATMOS_API double atmos_solar_irradiance(double nm);
/* Mean of the above over [lo, hi] nm. */
ATMOS_API double atmos_solar_irradiance_mean(double lo_nm, double hi_nm);

/* XYZ -> linear sRGB (IEC 61966-2-1 matrix, D65 white). */
ATMOS_API void atmos_xyz_to_srgb(const double xyz[3], double rgb[3]);
ATMOS_API void atmos_srgb_to_xyz(const double rgb[3], double xyz[3]);

#ifdef __cplusplus
}
#endif
#endif
