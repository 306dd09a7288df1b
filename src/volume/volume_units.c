/* What a volume file's values and lengths are: the density units of atmos_volume_load_desc
 * (number density, water content, a 0..1 fraction) turned into the factor that gives
 * particles per m^3, and the mean particle masses a water content needs. */
#include "volume/volume_units.h"
#include "core/internal.h"

#include <math.h>
#include <string.h>

static double sphere_mass(double radius_m, double rho) { return 4.0 / 3.0 * ATMOS_PI * pow(radius_m, 3) * rho; }

/* The same assumptions as the NetCDF reader's mixing-ratio conversion (docs/volumes.md). */
double atmos_particle_mean_mass(const char *particle)
{
    if (!particle) return 0.0;
    if (!strcmp(particle, "cloud")) return sphere_mass(10e-6, 1000.0); /* droplet, r = 10 um */
    if (!strcmp(particle, "rain")) return sphere_mass(1e-3, 1000.0);   /* raindrop, r = 1 mm */
    if (!strcmp(particle, "ice")) return sphere_mass(50e-6, 917.0);    /* cloud ice, r = 50 um */
    if (!strcmp(particle, "snow")) return 0.069 * 2e-3 * 2e-3;         /* m = 0.069 D^2, D = 2 mm */
    if (!strcmp(particle, "graupel")) return sphere_mass(1e-3, 500.0); /* r = 1 mm, 500 kg/m^3 */
    return 0.0;
}

atmos_status atmos__volume_unit_factor(atmos_context *ctx, const char *path, atmos_density_unit unit,
                                       atmos_density_unit format_default, const char *particle, double *factor)
{
    if (unit == ATMOS_DENSITY_AUTO) unit = format_default;
    switch (unit) {
    case ATMOS_DENSITY_PER_M3: *factor = 1.0; return ATMOS_OK;
    case ATMOS_DENSITY_FRACTION: *factor = ATMOS_DENSITY_FRACTION_PER_M3; return ATMOS_OK;
    case ATMOS_DENSITY_G_M3: {
        const char *p = particle && particle[0] ? particle : "cloud";
        double m = atmos_particle_mean_mass(p);
        if (!(m > 0))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "%s: density unit g_m3 needs a particle type with a known mean mass "
                                "(cloud, rain, ice, snow, graupel), not \"%s\"",
                                path, p);
        *factor = 1e-3 / m; /* g/m^3 -> kg/m^3 -> particles/m^3 */
        return ATMOS_OK;
    }
    default: break;
    }
    return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: unknown density unit %d", path, (int)unit);
}

const char *atmos__density_unit_name(atmos_density_unit unit)
{
    switch (unit) {
    case ATMOS_DENSITY_PER_M3: return "per_m3";
    case ATMOS_DENSITY_G_M3: return "g_m3";
    case ATMOS_DENSITY_FRACTION: return "fraction";
    default: return "auto";
    }
}
