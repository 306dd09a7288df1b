/* The brute-force solver of the spherical kinds: every answer by quadrature over the
 * planet description (planet.c), single scattering only. Slow; the reference the tables'
 * solvers are checked against for single scattering, and their fallback. */
#include "atmosphere/planet_solver.h"

void atmos__numeric_transmittance(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                                  int m, const int *k, double *out)
{
    atmos__planet_optical_depth(a->planet, p, d, dist, m, k, out);
    for (int i = 0; i < m; i++) out[i] = exp(-out[i]);
}

void atmos__numeric_sunlight(const atmos_atmosphere *a, const double p[3], const double sun[3], int m, const int *k,
                             double *out)
{
    atmos__planet_sun_transmittance(a->planet, p, sun, m, k, out);
    for (int i = 0; i < m; i++) out[i] *= a->sun_e[ATMOS__WL(k, i)];
}

int atmos__numeric_inscatter(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                             const double sun[3], int m, const int *k, double *out)
{
    atmos__planet_single_scatter(a->planet, p, d, dist, sun, m, k, out);
    int any = 0;
    for (int i = 0; i < m; i++) {
        out[i] *= a->sun_e[ATMOS__WL(k, i)];
        any |= out[i] > 0;
    }
    return any;
}

const atmos__planet_solver atmos__numeric_solver = {
    .name = "numeric",
    .transmittance = atmos__numeric_transmittance,
    .sunlight = atmos__numeric_sunlight,
    .inscatter = atmos__numeric_inscatter,
};
