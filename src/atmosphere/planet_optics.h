/* The physics behind the spherical planet's coefficients (planet_optics.c assembles them):
 * Rayleigh scattering by dry air (planet_air.c), ozone's absorption cross-section
 * (ozone_data.c) and the aerosol types' Mie optics (planet_aerosol.c). Wavelengths in nm,
 * cross-sections in m^2, columns in m^-2. Internal to src/atmosphere/; docs/sky.md gives the
 * formulas and their sources. */
#ifndef ATMOS_PLANET_OPTICS_H
#define ATMOS_PLANET_OPTICS_H

#include "atmosphere/planet.h"

/* ------------------------------------------------------------------ air (Bodhaine et al. 1999) */
/* Refractive index minus one of dry air with 360 ppm CO2 at 288.15 K and 1013.25 hPa
 * (Peck & Reeder 1972 with Bodhaine et al.'s CO2 scaling, their Eq. 4 and 19). */
double atmos__air_refractivity(double nm);
/* King correction factor of air, (6 + 3 rho) / (6 - 7 rho) (Bates 1984 for N2 and O2,
 * Ar 1.00, CO2 1.15, weighted by volume as Bodhaine et al. 1999 Eq. 23). */
double atmos__air_king_factor(double nm);
/* The depolarization factor rho of air from its King factor. */
double atmos__air_depolarization(double nm);
/* Rayleigh scattering cross-section per molecule of air (Bodhaine et al. Eq. 2). */
double atmos__air_rayleigh_cross_section(double nm);
/* Its mean over [lo, hi] nm (Simpson's rule on 8 intervals). */
double atmos__air_rayleigh_cross_section_mean(double lo, double hi);
/* Molecules of air in a vertical column over the sea at 1013.25 hPa and 45 degrees latitude
 * (P A / (m_a g), Bodhaine et al. Eq. 24-25): about 2.15e29 m^-2. */
double atmos__air_column(void);

/* ------------------------------------------------------------------ ozone */
/* Absorption cross-section of ozone (m^2), linearly interpolated in the table of
 * ozone_data.c (clamped at its ends), and its mean over [lo, hi] nm. */
double atmos__ozone_cross_section(double nm);
double atmos__ozone_cross_section_mean(double lo, double hi);
/* Molecules per m^2 in one Dobson unit. */
#define ATMOS__DOBSON_UNIT 2.6867e20

/* ------------------------------------------------------------------ aerosols */
/* Optics of one aerosol type per unit of its mixture (the mixture's number densities as
 * published, per cm^3; only ratios matter): extinction and scattering cross-sections (m^2)
 * at each of n wavelengths, its phase function on the planet's grid (theta_j = j * 180 /
 * (ATMOS__PLANET_PHASE_N - 1) degrees, sr^-1, as computed by Mie theory before any
 * normalisation on the grid; NULL: not computed) and its asymmetry parameter (NULL: not
 * wanted). ATMOS_AEROSOL_NONE gives zeros. Built through the disk cache. */
atmos_status atmos__aerosol_optics(atmos_context *ctx, atmos_aerosol_type type, int n, const double *nm, double *ext,
                                   double *sca, float (*phase)[ATMOS__PLANET_PHASE_N], double *g);

#endif
