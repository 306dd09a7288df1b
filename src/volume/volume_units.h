/* Density units of volume files (volume_units.c). */
#ifndef ATMOS_VOLUME_UNITS_H
#define ATMOS_VOLUME_UNITS_H

#include "atmos/atmos.h"

/* The factor that turns a file's values in `unit` (AUTO: format_default) into particles
 * per m^3 of `particle` (NULL or "": cloud); ATMOS_E_INVALID_ARG naming path if the unit
 * cannot apply. */
atmos_status atmos__volume_unit_factor(atmos_context *ctx, const char *path, atmos_density_unit unit,
                                       atmos_density_unit format_default, const char *particle, double *factor);
/* "per_m3", "g_m3", "fraction" or "auto": the names of the scene file and the CLI. */
const char *atmos__density_unit_name(atmos_density_unit unit);

#endif
