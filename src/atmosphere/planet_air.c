/* Rayleigh scattering by dry air after Bodhaine, Wood, Dutton & Slusser 1999 ("On Rayleigh
 * optical depth calculations", J. Atmos. Oceanic Technol. 16, 1854-1861):
 *
 *   sigma(lambda) = 24 pi^3 (n^2 - 1)^2 / (lambda^4 N_s^2 (n^2 + 2)^2) F_air(lambda)
 *
 * with n the refractive index of standard air (Peck & Reeder 1972, 288.15 K, 1013.25 hPa,
 * scaled to 360 ppm CO2), N_s = 2.546899e25 m^-3 the number density at the same state (so
 * that sigma does not depend on it) and F_air the King factor (Bates 1984). */
#include "atmosphere/planet_optics.h"

#include <math.h>

#define CO2_PPV 360e-6      /* carbon dioxide, parts per volume (Bodhaine et al.'s choice) */
#define N_STD 2.546899e25   /* molecules m^-3 at 288.15 K and 1013.25 hPa */

double atmos__air_refractivity(double nm)
{
    const double s2 = 1e6 / (nm * nm); /* (1 / lambda)^2 in um^-2 */
    /* Peck & Reeder 1972 for 300 ppm CO2 (Bodhaine et al. Eq. 4, lambda > 0.23 um) */
    const double n300 = 1e-8 * (8060.51 + 2480990.0 / (132.274 - s2) + 17455.7 / (39.32957 - s2));
    return n300 * (1.0 + 0.54 * (CO2_PPV - 0.0003)); /* Bodhaine et al. Eq. 19 */
}

double atmos__air_king_factor(double nm)
{
    const double s2 = 1e6 / (nm * nm);
    const double f_n2 = 1.034 + 3.17e-4 * s2;                       /* Bates 1984 */
    const double f_o2 = 1.096 + 1.385e-3 * s2 + 1.448e-4 * s2 * s2; /* Bates 1984 */
    const double c = CO2_PPV * 100.0;                              /* percent by volume */
    return (78.084 * f_n2 + 20.946 * f_o2 + 0.934 * 1.00 + c * 1.15) / (78.084 + 20.946 + 0.934 + c);
}

double atmos__air_depolarization(double nm)
{
    /* F = (6 + 3 rho) / (6 - 7 rho)  =>  rho = 6 (F - 1) / (3 + 7 F) */
    const double f = atmos__air_king_factor(nm);
    return 6.0 * (f - 1.0) / (3.0 + 7.0 * f);
}

double atmos__air_rayleigh_cross_section(double nm)
{
    const double n = 1.0 + atmos__air_refractivity(nm), n2 = n * n;
    const double lam = nm * 1e-9, l4 = lam * lam * lam * lam;
    const double a = (n2 - 1.0) / (n2 + 2.0);
    return 24.0 * ATMOS_PI * ATMOS_PI * ATMOS_PI * a * a / (l4 * N_STD * N_STD) * atmos__air_king_factor(nm);
}

double atmos__air_rayleigh_cross_section_mean(double lo, double hi)
{
    if (!(hi > lo)) return atmos__air_rayleigh_cross_section(lo);
    const int m = 8;
    const double h = (hi - lo) / m;
    double s = 0;
    for (int i = 0; i <= m; i++) {
        const double w = (i == 0 || i == m) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        s += w * atmos__air_rayleigh_cross_section(lo + i * h);
    }
    return s * h / 3.0 / (hi - lo);
}

double atmos__air_column(void)
{
    /* Bodhaine et al. Eq. 24-25: N = P A / (m_a g) with the mean molecular weight of dry
     * air m_a = 15.0556 CO2 + 28.9595 g/mol and g at sea level and 45 degrees latitude
     * (Eq. 11: 980.6160 cm s^-2, List 1968) */
    const double P = 101325.0, A = 6.0221367e23;
    const double m_a = (15.0556 * CO2_PPV + 28.9595) * 1e-3;
    const double g = 9.806160;
    return P * A / (m_a * g);
}
