/* The brute-force solver of the spherical kinds: every answer by quadrature over the
 * planet description (planet.c), single scattering only (atmos__planet_single_scatter).
 * Slow; the reference the tables' solvers are checked against for single scattering, and
 * their fallback. */
#include "atmosphere/planet_solver.h"

#include "core/vec.h"

/* Midpoint rule over SSN steps with the view transmittance accumulated step by step. */
#define SSN 512
void atmos__planet_single_scatter(const atmos__planet *pl, const double p[3], const double d[3], double dist,
                                  const double sun[3], int m, const int *k, double *out)
{
    for (int i = 0; i < m; i++) out[i] = 0.0;
    double t0, t1;
    if (!atmos__planet_clip(pl, p, d, dist, &t0, &t1)) return;
    double tau[ATMOS_MAX_WAVELENGTHS], Ts[ATMOS_MAX_WAVELENGTHS];
    atmos__planet_optical_depth(pl, p, d, t0, m, k, tau);
    const double dt = (t1 - t0) / SSN, nu = atmos__dot3(d, sun);
    for (int s = 0; s < SSN; s++) {
        const double t = t0 + (s + 0.5) * dt;
        const double x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
        const double h = atmos__planet_altitude(pl, x);
        atmos__planet_sun_transmittance(pl, x, sun, m, k, Ts);
        for (int i = 0; i < m; i++) {
            const int kk = k ? k[i] : i;
            const double pr = atmos__planet_rayleigh_phase(pl, kk, nu);
            const double ext = atmos__planet_extinction(pl, h, kk) * dt;
            const double Tv = exp(-(tau[i] + 0.5 * ext));
            const double sca = pl->rayleigh[kk] * atmos__planet_rho_rayleigh(pl, h) * pr +
                               pl->mie_sca[kk] * atmos__planet_rho_mie(pl, h) * atmos__planet_mie_phase(pl, kk, nu);
            out[i] += sca * Tv * Ts[i] * dt;
            tau[i] += ext;
        }
    }
}

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
