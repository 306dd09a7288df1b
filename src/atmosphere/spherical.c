/* The production sky over a spherical earth with all orders of scattering.
 * PROVISIONAL: answers by the numeric solver (single scattering) until the tables land. */
#include "atmosphere/planet_solver.h"

const atmos__planet_solver atmos__spherical_solver = {
    .name = "spherical",
    .transmittance = atmos__numeric_transmittance,
    .sunlight = atmos__numeric_sunlight,
    .inscatter = atmos__numeric_inscatter,
};
