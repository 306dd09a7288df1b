/* The air's single scattering over the cells of a segment (atmosphere_ops.h,
 * atmos__atm_single_cells_sub): what a shadow can take from the air's in-scatter. A
 * planet's models hold every order of scattering in one in-scatter; this is the first order
 * alone, from the planet's description. */
#include "atmosphere/atmosphere_internal.h"
#include "atmosphere/planet.h"
#include "core/vec.h"

#include <math.h>

void atmos__atm_single_cells_sub(const atmos_atmosphere *a, const double p[3], const double d[3], double s0,
                                 double s1, int n, const double sun[3], int m, const int *k, double *out)
{
    const double dt = (s1 - s0) / n, nu = atmos__dot3(d, sun);
    double T[ATMOS_MAX_WAVELENGTHS], E[ATMOS_MAX_WAVELENGTHS], PR[ATMOS_MAX_WAVELENGTHS], PM[ATMOS_MAX_WAVELENGTHS];
    const atmos__planet *pl = a->planet;
    if (pl)
        for (int i = 0; i < m; i++) {
            PR[i] = atmos__planet_rayleigh_phase(pl, ATMOS__WL(k, i), nu);
            PM[i] = atmos__planet_mie_phase(pl, ATMOS__WL(k, i), nu);
        }
    atmos__atm_transmittance_sub(a, p, d, s0, m, k, T);
    for (int c = 0; c < n; c++) {
        const double t = s0 + (c + 0.5) * dt;
        const double x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
        double *o = out + (size_t)c * m;
        atmos__atm_sunlight_sub(a, x, sun, m, k, E);
        if (!pl) { /* the flat kinds: Rayleigh's phase function, the closed-form transmittance */
            double sca[ATMOS_MAX_WAVELENGTHS], Tc[ATMOS_MAX_WAVELENGTHS];
            atmos_atmosphere_scattering(a, x, sca, NULL);
            atmos__atm_transmittance_sub(a, p, d, t, m, k, Tc);
            for (int i = 0; i < m; i++) o[i] = sca[ATMOS__WL(k, i)] * atmos_phase_rayleigh(nu) * E[i] * Tc[i] * dt;
            continue;
        }
        const double h = atmos__planet_altitude(pl, x);
        const int on = h <= pl->r_top - pl->r_ground;
        const double rr = atmos__planet_rho_rayleigh(pl, h), rm = atmos__planet_rho_mie(pl, h);
        for (int i = 0; i < m; i++) {
            const int kk = ATMOS__WL(k, i);
            const double half = exp(-0.5 * atmos__planet_extinction(pl, h, kk) * dt);
            const double sca = on ? pl->rayleigh[kk] * rr * PR[i] + pl->mie_sca[kk] * rm * PM[i] : 0.0;
            o[i] = sca * E[i] * T[i] * half * dt;
            T[i] *= half * half;
        }
    }
}

int atmos__atm_air_span(const atmos_atmosphere *a, const double p[3], const double d[3], double *s0, double *s1)
{
    double t0, t1;
    if (!a->planet) return *s1 > *s0;
    if (!atmos__planet_clip(a->planet, p, d, *s1, &t0, &t1)) return 0;
    *s0 = fmax(*s0, t0), *s1 = fmin(*s1, t1);
    return *s1 > *s0;
}
