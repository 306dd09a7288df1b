/* The atmosphere object (include/atmos/atmosphere.h): its settings, creation, and what every
 * kind shares (the wavelengths' coefficients, the sun, the flat ground). The questions are
 * asked in atmosphere_ask.c. */
#include "atmosphere/atmosphere_check.h"
#include "atmosphere/atmosphere_internal.h"
#include "atmosphere/planet_solver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Riley et al. 2004, Table 3: sea-level scattering coefficients, m^-1. */
static const double table3_nm[3] = {680.0, 550.0, 440.0};
static const double table3_beta[3] = {5.8e-6, 1.35e-5, 3.31e-5};

void atmos_atmosphere_defaults(atmos_atmosphere_desc *d)
{
    memset(d, 0, sizeof *d);
    d->beta_sl_550 = ATMOS_SKY_BETA_SL_550;
    d->scale_height_m = 8000.0;
    d->ground_albedo = 0.1;
    d->sun_diameter_deg = 0.5;
    d->sun_scale = 1.0;
    d->kind = ATMOS_ATMOSPHERE_RILEY;
    d->thickness_m = 8000.0;
    d->planet_radius_m = 6360e3;
    d->top_m = 100e3;
    d->rayleigh_scale_height_m = 7994.0;
    d->aerosol = ATMOS_AEROSOL_CONTINENTAL;
    d->aerosol_scale_height_m = 1200.0;
    d->visibility_km = 40.0;
    d->ozone_du = 300.0;
}

static int planet_kind(atmos_atmosphere_kind k)
{
    return k == ATMOS_ATMOSPHERE_DOBASHI || k == ATMOS_ATMOSPHERE_SPHERICAL;
}

/* Zero means default for every field except ground_albedo (and the vacuum's radiance). */
static void resolve(const atmos_atmosphere_desc *in, atmos_atmosphere_desc *d)
{
    atmos_atmosphere_defaults(d);
    if (!in) return;
    *d = *in;
    if (d->beta_sl_550 == 0) d->beta_sl_550 = ATMOS_SKY_BETA_SL_550;
    if (d->scale_height_m == 0) d->scale_height_m = 8000.0;
    if (d->sun_diameter_deg == 0) d->sun_diameter_deg = 0.5;
    if (d->sun_scale == 0) d->sun_scale = 1.0;
    if (d->thickness_m == 0) d->thickness_m = 8000.0;
    if (d->planet_radius_m == 0) d->planet_radius_m = 6360e3;
    if (d->top_m == 0) d->top_m = 100e3;
    if (d->rayleigh_scale_height_m == 0) d->rayleigh_scale_height_m = 7994.0;
    if (d->aerosol_scale_height_m == 0) d->aerosol_scale_height_m = 1200.0;
    if (d->visibility_km == 0) d->visibility_km = 40.0;
    if (d->ozone_du == 0) d->ozone_du = 300.0;
}

/* The spherical kinds' settings. */
static atmos_status check_planet(atmos_context *ctx, const atmos_atmosphere_desc *d)
{
    if (!(d->planet_radius_m >= 1e3 && d->planet_radius_m <= 1e8))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/planet_radius_m: must be in [1e3, 1e8], got %g",
                            d->planet_radius_m);
    if (!(d->top_m >= 60e3 && d->top_m <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/top_m: must be in [60e3, 1e6], got %g", d->top_m);
    if (!(d->rayleigh_scale_height_m >= 100 && d->rayleigh_scale_height_m <= 100000))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmosphere/rayleigh_scale_height_m: must be in [100, 100000], got %g",
                            d->rayleigh_scale_height_m);
    if (!(d->aerosol_scale_height_m >= 100 && d->aerosol_scale_height_m <= 100000))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmosphere/aerosol_scale_height_m: must be in [100, 100000], got %g",
                            d->aerosol_scale_height_m);
    if ((int)d->aerosol < 0 || d->aerosol > ATMOS_AEROSOL_NONE)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/aerosol: unknown type %d", (int)d->aerosol);
    if (!(d->visibility_km >= 0.5 && d->visibility_km <= 1000))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/visibility_km: must be in [0.5, 1000], got %g",
                            d->visibility_km);
    if (!(d->turbidity == 0 || (d->turbidity >= 1 && d->turbidity <= 50)))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/turbidity: must be 0 (unset) or in [1, 50], got %g",
                            d->turbidity);
    if (!(d->ozone_du >= 0 && d->ozone_du <= 1000))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/ozone_du: must be in [0, 1000], got %g", d->ozone_du);
    if (!(d->dobashi_ambient >= 0 && d->dobashi_ambient <= 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/dobashi_ambient: must be in [0, 1], got %g",
                            d->dobashi_ambient);
    if (!(fabs(d->latitude_deg) <= 90 && fabs(d->longitude_deg) <= 360))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmosphere/latitude_deg, longitude_deg: must be in [-90, 90] and [-360, 360], got %g, %g",
                            d->latitude_deg, d->longitude_deg);
    if (!(d->night_radiance >= 0 && d->night_radiance <= 1e3))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/night_radiance: must be in [0, 1e3], got %g",
                            d->night_radiance);
    return ATMOS_OK;
}

static atmos_status check(atmos_context *ctx, const atmos_atmosphere_desc *d, const atmos_wavelengths *wl)
{
    if (d->kind != ATMOS_ATMOSPHERE_RILEY && d->kind != ATMOS_ATMOSPHERE_VACUUM &&
        d->kind != ATMOS_ATMOSPHERE_HOMOGENEOUS && !planet_kind(d->kind))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/kind: unknown kind %d", (int)d->kind);
    if (!(d->beta_sl_550 > 0 && d->beta_sl_550 <= 0.01))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/beta_sl_550_per_m: must be in (0, 0.01], got %g",
                            d->beta_sl_550);
    if (!(d->scale_height_m >= 100 && d->scale_height_m <= 100000))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/scale_height_m: must be in [100, 100000], got %g",
                            d->scale_height_m);
    if (!(d->ground_albedo >= 0 && d->ground_albedo <= 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/ground_albedo: must be in [0, 1], got %g",
                            d->ground_albedo);
    if (!(d->sun_diameter_deg > 0 && d->sun_diameter_deg <= 20))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/sun_diameter_deg: must be in (0, 20], got %g",
                            d->sun_diameter_deg);
    if (!(d->sun_scale >= 0 && d->sun_scale <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/sun_scale: must be in [0, 1e6], got %g", d->sun_scale);
    if (!(d->background_radiance >= 0 && d->background_radiance <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/background_radiance: must be in [0, 1e6], got %g",
                            d->background_radiance);
    if (!(d->thickness_m >= 1 && d->thickness_m <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/thickness_m: must be in [1, 1e6], got %g",
                            d->thickness_m);
    if (wl->count < 1 || wl->count > ATMOS_MAX_WAVELENGTHS)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere: wavelength set has %d samples (allowed 1..%d)",
                            wl->count, ATMOS_MAX_WAVELENGTHS);
    return planet_kind(d->kind) ? check_planet(ctx, d) : ATMOS_OK;
}

/* The planet and its solver's tables for the spherical kinds. */
static atmos_status create_planet(atmos_context *ctx, atmos_atmosphere *a)
{
    a->planet = calloc(1, sizeof *a->planet);
    if (!a->planet) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory");
    atmos_status st = atmos__planet_init(ctx, a->planet, &a->desc, &a->wl);
    if (st == ATMOS_OK) st = atmos__planet_surface_create(ctx, a->planet, &a->desc, &a->wl);
    if (st == ATMOS_OK && a->desc.clouds.image) atmos__clouds_resolve(&a->desc.clouds);
    if (st == ATMOS_OK) st = atmos__planet_clouds_create(ctx, a->planet, &a->desc);
    /* the planet keeps its own copies: the caller's images may go */
    a->desc.ground_map = a->desc.night_map = a->desc.clouds.image = NULL;
    if (st != ATMOS_OK) return st;
    a->solver = a->desc.kind == ATMOS_ATMOSPHERE_DOBASHI ? &atmos__dobashi_solver : &atmos__spherical_solver;
    return a->solver->create ? a->solver->create(ctx, a) : ATMOS_OK;
}

atmos_status atmos_atmosphere_create(atmos_context *ctx, const atmos_atmosphere_desc *desc,
                                     const atmos_wavelengths *wl, atmos_atmosphere **out)
{
    if (!out || !wl) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere: missing argument");
    *out = NULL;
    atmos_atmosphere_desc d;
    resolve(desc, &d);
    atmos_status st = check(ctx, &d, wl);
    if (st != ATMOS_OK) return st;
    atmos_atmosphere *a = calloc(1, sizeof *a);
    if (!a) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory");
    a->desc = d;
    a->wl = *wl;
    a->gamma = 1.0 / d.scale_height_m;
    const double scale = d.beta_sl_550 / ATMOS_SKY_BETA_SL_550;
    for (int i = 0; i < wl->count; i++) {
        double b = ATMOS_SKY_BETA_SL_550 * pow(550.0 / wl->nm[i], 4.0);
        if (wl->mode == ATMOS_WAVELENGTHS_RGB) {
            /* The paper's own channel values where the wavelength is one of Table 3's. */
            for (int k = 0; k < 3; k++)
                if (fabs(wl->nm[i] - table3_nm[k]) < 1e-9) b = table3_beta[k];
        }
        a->beta_sl[i] = d.kind == ATMOS_ATMOSPHERE_VACUUM ? 0.0 : b * scale;
        a->sun_e[i] = wl->sun_irradiance[i] * d.sun_scale;
    }
    const double r = 0.5 * d.sun_diameter_deg * ATMOS_DEG2RAD;
    a->cos_sun_radius = cos(r);
    /* 2 pi (1 - cos r), which cancels to 0 for a disk below ~1e-8 rad (a valid
     * sun_diameter_deg of 1e-6) and is then divided by; 4 pi sin^2(r/2) is the same
     * solid angle without the cancellation. The first form is kept for r >= 1e-3 rad,
     * where it is exact to ~1e-10, so that the images of such suns stay as they were. */
    a->sun_solid_angle = r < 1e-3 ? 4.0 * ATMOS_PI * sin(0.5 * r) * sin(0.5 * r) : 2.0 * ATMOS_PI * (1.0 - cos(r));
    if (planet_kind(d.kind) && (st = create_planet(ctx, a)) != ATMOS_OK) {
        atmos_atmosphere_destroy(a);
        return st;
    }
    if (!atmos__flat_skylight_build(a)) {
        atmos_atmosphere_destroy(a);
        return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory");
    }
    *out = a;
    return ATMOS_OK;
}

void atmos_atmosphere_destroy(atmos_atmosphere *atm)
{
    if (!atm) return;
    if (atm->solver && atm->solver->destroy && atm->model) atm->solver->destroy(atm->model);
    atmos__planet_surface_release(atm->planet);
    atmos__planet_clouds_release(atm->planet);
    free(atm->planet);
    free(atm->sky_ground);
    free(atm);
}
atmos_atmosphere_kind atmos_atmosphere_get_kind(const atmos_atmosphere *atm) { return atm->desc.kind; }
const atmos_wavelengths *atmos_atmosphere_wavelengths(const atmos_atmosphere *atm) { return &atm->wl; }
const atmos_atmosphere_desc *atmos_atmosphere_get_desc(const atmos_atmosphere *atm) { return &atm->desc; }
double atmos_atmosphere_sun_solid_angle(const atmos_atmosphere *atm) { return atm->sun_solid_angle; }
const double *atmos__atm_sun_irradiance(const atmos_atmosphere *a) { return a->sun_e; }
double atmos__atm_cos_sun_radius(const atmos_atmosphere *a) { return a->cos_sun_radius; }

double atmos__atm_background(const atmos_atmosphere *a)
{
    return a->desc.kind == ATMOS_ATMOSPHERE_VACUUM ? a->desc.background_radiance : 0.0;
}

double atmos_atmosphere_ground_albedo(const atmos_atmosphere *atm)
{
    return atm->desc.kind == ATMOS_ATMOSPHERE_VACUUM ? 0.0 : atm->desc.ground_albedo;
}

/* The ground is the plane y = 0 of a flat earth; a point on or below it looking down is on it. */
double atmos_atmosphere_ground_distance(const atmos_atmosphere *atm, const double p[3], const double dir[3])
{
    if (atmos__atm_finite_fault(p, dir)) return NAN; /* p and dir finite */
    if (atm->desc.kind == ATMOS_ATMOSPHERE_VACUUM) return INFINITY;
    if (atm->planet) return atmos__planet_ground_distance(atm->planet, p, dir);
    const double y = p[1];
    if (y <= 0) return dir[1] < 0 ? 0.0 : (y < 0 ? 0.0 : INFINITY);
    if (dir[1] >= 0) return INFINITY;
    return y / -dir[1];
}

void atmos__atm_ground_hit(const atmos_atmosphere *a, double p[3], double n[3])
{
    if (a->planet) {
        atmos__planet_ground_point(a->planet, p, n);
        return;
    }
    p[1] = 0; /* the flat ground y = 0 */
    n[0] = 0, n[1] = 1, n[2] = 0;
}

int atmos_atmosphere_sun_disk_visible(const atmos_atmosphere *atm, const double sun_dir[3])
{
    /* a spherical kind's disk is hidden ray by ray where the planet is in the way */
    if (atm->planet) return !atm->desc.hide_sun_disk;
    return atm->desc.kind != ATMOS_ATMOSPHERE_VACUUM && !atm->desc.hide_sun_disk && sun_dir[1] > 0;
}
