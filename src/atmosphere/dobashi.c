/* Dobashi et al. 2002 §5: the sky over a spherical earth from look-up tables.
 * PROVISIONAL: answers by the numeric solver until the tables land. */
#include "atmosphere/planet_solver.h"

const atmos__planet_solver atmos__dobashi_solver = {
    .name = "dobashi",
    .transmittance = atmos__numeric_transmittance,
    .sunlight = atmos__numeric_sunlight,
    .inscatter = atmos__numeric_inscatter,
};
