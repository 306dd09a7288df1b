/* Ground truth for the spherical kinds (atmos_atmosphere_reference_radiance).
 * PROVISIONAL: single scattering by quadrature (max_order is ignored, std_error 0) until
 * the Monte Carlo walk lands. */
#include "atmosphere/planet_solver.h"

#include <string.h>

atmos_status atmos_atmosphere_reference_radiance(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                                                 const double sun_dir[3], long paths, unsigned long long seed,
                                                 int max_order, double *out, double *std_error)
{
    (void)paths, (void)seed, (void)max_order;
    if (!atm || !atm->planet) return ATMOS_E_INVALID_ARG;
    atmos_atmosphere a = *atm;
    a.solver = &atmos__numeric_solver;
    atmos__planet_radiance_generic(&a, p, dir, sun_dir, out, NULL);
    if (std_error) memset(std_error, 0, sizeof(double) * (size_t)atm->wl.count);
    return ATMOS_OK;
}
