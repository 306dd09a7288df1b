/* Compiled-in spectral tables (generated: src/core/spectral_data.c). */
#ifndef ATMOS_SPECTRAL_DATA_H
#define ATMOS_SPECTRAL_DATA_H

#define ATMOS__SPECTRAL_DATA_LO_NM 360
#define ATMOS__SPECTRAL_DATA_HI_NM 830
#define ATMOS__SPECTRAL_DATA_COUNT (ATMOS__SPECTRAL_DATA_HI_NM - ATMOS__SPECTRAL_DATA_LO_NM + 1)

extern const double atmos__cie_xyz[ATMOS__SPECTRAL_DATA_COUNT][3];
extern const double atmos__solar_etr[ATMOS__SPECTRAL_DATA_COUNT];

#endif
