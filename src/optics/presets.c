/* Particle presets (Riley et al. 2004 §3.1, Table 2). The extinction cross-sections are
 * Table 2's; the size distributions, which Riley et al. do not give, are published
 * typical values (sources and reasoning in docs/optics.md). */
#include "core/internal.h"

#include <string.h>

static const char *const preset_names[] = {"air", "cloud", "rain", "ice", "snow", NULL};

const char *const *atmos_particle_preset_names(void) { return preset_names; }

atmos_status atmos_particle_preset(atmos_context *ctx, const char *name, atmos_particle_desc *out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "particle preset: output is NULL");
    if (!name) name = "(null)";
    atmos_particle_desc d;
    memset(&d, 0, sizeof d);
    if (!strcmp(name, "air")) {
        /* Rayleigh; sigma_ext 0 = per wavelength (Riley Eq. 1, Table 2's air rows) */
        d.kind = ATMOS_PARTICLE_AIR;
    } else if (!strcmp(name, "cloud")) {
        /* Hansen & Travis (1974) Eq. 2.56 standard gamma distribution with effective radius
         * 10 um (Riley's "0.01 mm sphere") and effective variance 0.1, typical of liquid
         * water clouds: n(r) ~ r^7 exp(-r / 1 um), mode 7 um. */
        d.kind = ATMOS_PARTICLE_WATER;
        d.size = (atmos_size_distribution){.kind = ATMOS_SIZE_GAMMA, .r_m = 7e-6, .alpha = 7.0, .gamma = 1.0};
        d.sigma_ext_m2 = 6.28e-10;
    } else if (!strcmp(name, "rain")) {
        /* Lognormal (Feingold & Levin 1986) with median radius 1 mm (Riley: "1 mm sphere")
         * and sigma = 0.3 in ln r; drops above 3 mm radius break up (Pruppacher & Klett
         * 1997 §10.3.6), hence r_max. */
        d.kind = ATMOS_PARTICLE_WATER;
        d.size = (atmos_size_distribution){.kind = ATMOS_SIZE_LOGNORMAL, .r_m = 1e-3, .sigma = 0.3, .r_max = 3e-3};
        d.sigma_ext_m2 = 6.28e-6;
    } else if (!strcmp(name, "ice")) {
        /* hexagonal columns, length / diameter 2; crystal size chosen by the crystal code */
        d.kind = ATMOS_PARTICLE_ICE;
        d.habit = ATMOS_CRYSTAL_COLUMN;
        d.aspect_ratio = 2.0;
        d.sigma_ext_m2 = 1.82e-6;
    } else if (!strcmp(name, "snow")) {
        d.kind = ATMOS_PARTICLE_SNOW;
        d.habit = ATMOS_CRYSTAL_PLATE;
        d.sigma_ext_m2 = 1.41e-5;
    } else {
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "particle preset '%s' unknown; presets: air, cloud, rain, ice, snow",
                            name);
    }
    strncpy(d.name, name, sizeof d.name - 1);
    *out = d;
    return ATMOS_OK;
}
