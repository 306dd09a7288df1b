/* The planet's optical description from an atmosphere desc (planet.h): the coefficients
 * of air, aerosols and ozone at each wavelength and the aerosols' phase function, from the
 * physics of planet_air.c, planet_aerosol.c and ozone_data.c (docs/sky.md).
 *
 * Air: the column of molecules is the standard sea-level column (planet_optics.h), so the
 * density at the ground is that column over the exponential profile's integral to the top;
 * with the default 7994 m scale height it is 2.687e25 m^-3, air at 273.15 K and 1013.25 hPa.
 * Ozone: the tent profile scaled to the column ozone_du. Aerosols: OPAC mixtures with their
 * ground extinction at 550 nm from the visibility (Koschmieder) or Linke's turbidity.
 * Spectral sets average the air's and the ozone's cross-sections over each sample's bin;
 * rgb takes them at the three wavelengths. */
#include "atmosphere/planet_optics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Fills the cumulative distribution over the scattering angle of each phase table
 * (trapezoids in theta of P sin theta) and scales the table so that it integrates to one
 * over the sphere by the same rule (the Mie tables' forward peak is narrower than the grid
 * for the largest particles). */
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
        for (int j = 0; j < N; j++) pl->mie_phase[k][j] = (float)(pl->mie_phase[k][j] / (2.0 * ATMOS_PI * acc));
    }
}

/* Integral of exp(-h / H) from the ground to the top. */
static double column_length(double H, double top) { return H * -expm1(-top / H); }

static void air_and_ozone(atmos__planet *pl, const atmos_atmosphere_desc *d, const atmos_wavelengths *wl)
{
    const int spectral = wl->mode == ATMOS_WAVELENGTHS_SPECTRAL;
    const double n0 = atmos__air_column() / column_length(pl->h_rayleigh, d->top_m);
    /* the tent's integral is its half width (the top is at least 60 km, above the tent) */
    const double o3 = d->no_ozone ? 0.0 : d->ozone_du * ATMOS__DOBSON_UNIT / pl->ozone_half_width;
    for (int k = 0; k < pl->n; k++) {
        const double nm = wl->nm[k], lo = nm - 0.5 * wl->width_nm[k], hi = nm + 0.5 * wl->width_nm[k];
        const double ray = spectral ? atmos__air_rayleigh_cross_section_mean(lo, hi) : atmos__air_rayleigh_cross_section(nm);
        const double oz = spectral ? atmos__ozone_cross_section_mean(lo, hi) : atmos__ozone_cross_section(nm);
        pl->rayleigh[k] = ray * n0;
        const double rho = atmos__air_depolarization(nm);
        pl->rayleigh_gamma[k] = rho / (2.0 - rho);
        pl->ozone[k] = o3 * oz;
    }
}

/* The aerosols' extinction at the ground at 550 nm (m^-1). */
static double aerosol_550(const atmos__planet *pl, const atmos_atmosphere_desc *d)
{
    if (d->aerosol == ATMOS_AEROSOL_NONE) return 0.0;
    const double n0 = atmos__air_column() / column_length(pl->h_rayleigh, d->top_m);
    const double air = atmos__air_rayleigh_cross_section(550.0) * n0;
    if (d->turbidity > 0) {
        const double tau_air = air * column_length(pl->h_rayleigh, d->top_m);
        return fmax(d->turbidity - 1.0, 0.0) * tau_air / column_length(pl->h_mie, d->top_m);
    }
    return fmax(3.912 / (d->visibility_km * 1e3) - air, 0.0);
}

static atmos_status aerosols(atmos_context *ctx, atmos__planet *pl, const atmos_atmosphere_desc *d,
                             const atmos_wavelengths *wl)
{
    double ext[ATMOS_MAX_WAVELENGTHS], sca[ATMOS_MAX_WAVELENGTHS];
    atmos_status st = atmos__aerosol_optics(ctx, d->aerosol, pl->n, wl->nm, ext, sca, pl->mie_phase, pl->mie_g);
    if (st != ATMOS_OK) return st;
    double ext550 = -1, sca550;
    for (int k = 0; k < pl->n; k++)
        if (wl->nm[k] == 550.0) ext550 = ext[k];
    if (ext550 < 0) {
        const double nm550 = 550.0;
        st = atmos__aerosol_optics(ctx, d->aerosol, 1, &nm550, &ext550, &sca550, NULL, NULL);
        if (st != ATMOS_OK) return st;
    }
    const double scale = ext550 > 0 ? aerosol_550(pl, d) / ext550 : 0.0;
    for (int k = 0; k < pl->n; k++) {
        pl->mie_ext[k] = scale * ext[k];
        pl->mie_sca[k] = scale * sca[k];
    }
    return ATMOS_OK;
}

atmos_status atmos__planet_init(atmos_context *ctx, atmos__planet *pl, const atmos_atmosphere_desc *d,
                                const atmos_wavelengths *wl)
{
    memset(pl, 0, sizeof *pl);
    pl->r_ground = d->planet_radius_m;
    pl->r_top = d->planet_radius_m + d->top_m;
    pl->n = wl->count;
    pl->h_rayleigh = d->rayleigh_scale_height_m;
    pl->h_mie = d->aerosol_scale_height_m;
    pl->ozone_centre = 25e3;
    pl->ozone_half_width = 15e3;
    pl->albedo = d->ground_albedo;
    air_and_ozone(pl, d, wl);
    atmos_status st = aerosols(ctx, pl, d, wl);
    if (st != ATMOS_OK) return st;
    phase_cdf(pl);
    return ATMOS_OK;
}
