/* The planet's optical description from an atmosphere desc (planet.h): the coefficients
 * of air, aerosols and ozone at each wavelength and the aerosols' phase function.
 * PROVISIONAL values (Rayleigh lambda^-4, an Angstrom law for the aerosols, a Gaussian
 * Chappuis band, a Cornette-Shanks phase function) until the physical ones land. */
#include "atmosphere/planet.h"

#include <math.h>
#include <string.h>

/* Fills the cumulative distribution over the scattering angle of each phase table
 * (trapezoids in theta of P sin theta). */
static void phase_cdf(atmos__planet *pl)
{
    const int N = ATMOS__PLANET_PHASE_N;
    const double dth = ATMOS_PI / (N - 1);
    for (int k = 0; k < pl->n; k++) {
        double acc = 0, prev = 0, g = 0;
        pl->mie_cdf[k][0] = 0;
        for (int j = 1; j < N; j++) {
            const double th = j * dth, f = pl->mie_phase[k][j] * sin(th);
            acc += 0.5 * (prev + f) * dth;
            g += 0.5 * dth * (prev * cos(th - dth) + f * cos(th));
            prev = f;
            pl->mie_cdf[k][j] = (float)acc;
        }
        for (int j = 1; j < N; j++) pl->mie_cdf[k][j] = (float)(pl->mie_cdf[k][j] / acc);
        pl->mie_cdf[k][N - 1] = 1.0f;
        pl->mie_g[k] = g / acc;
    }
}

atmos_status atmos__planet_init(atmos_context *ctx, atmos__planet *pl, const atmos_atmosphere_desc *d,
                                const atmos_wavelengths *wl)
{
    (void)ctx;
    memset(pl, 0, sizeof *pl);
    pl->r_ground = d->planet_radius_m;
    pl->r_top = d->planet_radius_m + d->top_m;
    pl->n = wl->count;
    pl->h_rayleigh = d->rayleigh_scale_height_m;
    pl->h_mie = d->aerosol_scale_height_m;
    pl->ozone_centre = 25e3;
    pl->ozone_half_width = 15e3;
    pl->albedo = d->ground_albedo;
    const double ray550 = 1.16e-5;
    const double aer550 = d->aerosol == ATMOS_AEROSOL_NONE ? 0.0 : fmax(3.912 / (d->visibility_km * 1e3) - ray550, 0.0);
    const double o3 = d->no_ozone ? 0.0 : d->ozone_du * 2.687e20 / pl->ozone_half_width;
    const double dth = ATMOS_PI / (ATMOS__PLANET_PHASE_N - 1);
    for (int k = 0; k < pl->n; k++) {
        const double nm = wl->nm[k];
        pl->rayleigh[k] = ray550 * pow(550.0 / nm, 4.0);
        pl->mie_ext[k] = aer550 * pow(550.0 / nm, 1.3);
        pl->mie_sca[k] = 0.9 * pl->mie_ext[k];
        pl->ozone[k] = o3 * 5e-25 * exp(-((nm - 600.0) / 60.0) * ((nm - 600.0) / 60.0));
        for (int j = 0; j < ATMOS__PLANET_PHASE_N; j++)
            pl->mie_phase[k][j] = (float)atmos_phase_cornette_shanks(cos(j * dth), 0.7);
    }
    phase_cdf(pl);
    return ATMOS_OK;
}
