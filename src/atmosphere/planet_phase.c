/* The planet's phase functions (planet.h): the aerosols' tabulated phase function,
 * interpolated in the scattering angle and sampled through its cumulative distribution,
 * and the mixture with the air molecules' Rayleigh phase function at an altitude. */
#include "atmosphere/planet.h"

#include <math.h>

#define NP ATMOS__PLANET_PHASE_N
#define DTH (ATMOS_PI / (NP - 1))

double atmos__planet_mie_phase(const atmos__planet *pl, int k, double cos_theta)
{
    const double c = cos_theta > 1 ? 1 : (cos_theta < -1 ? -1 : cos_theta);
    const double x = acos(c) / DTH;
    int j = (int)x;
    if (j >= NP - 1) j = NP - 2;
    const double f = x - j;
    return (1.0 - f) * pl->mie_phase[k][j] + f * pl->mie_phase[k][j + 1];
}

double atmos__planet_mie_sample(const atmos__planet *pl, int k, double u)
{
    const float *cdf = pl->mie_cdf[k];
    int lo = 0, hi = NP - 1;
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (cdf[mid] <= u) lo = mid;
        else hi = mid;
    }
    const double span = cdf[hi] - cdf[lo], f = span > 0 ? (u - cdf[lo]) / span : 0.5;
    return cos((lo + f) * DTH);
}

double atmos__planet_phase(const atmos__planet *pl, double h, int k, double cos_theta)
{
    const double r = pl->rayleigh[k] * atmos__planet_rho_rayleigh(pl, h);
    const double m = pl->mie_sca[k] * atmos__planet_rho_mie(pl, h);
    if (!(r + m > 0)) return atmos_phase_rayleigh(cos_theta);
    return (r * atmos_phase_rayleigh(cos_theta) + m * atmos__planet_mie_phase(pl, k, cos_theta)) / (r + m);
}
