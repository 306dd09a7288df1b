/* What the public questions of an atmosphere (include/atmos/atmosphere.h) refuse: a point or
 * direction that is not finite, a direction that is not a unit vector, an observer under the
 * ground or inside the planet. Those answer NaN; atmos_atmosphere_check_ray says why. */
#ifndef ATMOS_ATMOSPHERE_CHECK_H
#define ATMOS_ATMOSPHERE_CHECK_H

#include <atmos/atmosphere.h>

/* How far |dir| may be from 1, and how far below the ground (m) an observer may be (a point
 * placed on the ground by arithmetic lands a little either side). */
#define ATMOS__ATM_UNIT_TOLERANCE 1e-6
#define ATMOS__ATM_BELOW_TOLERANCE_M 1.0

/* Each returns NULL when its arguments may be answered, else what is wrong with them. */
const char *atmos__atm_unit_fault(const double dir[3]);
/* A view ray: p finite and not below the ground (beyond the tolerance), dir a unit vector. */
const char *atmos__atm_ray_fault(const atmos_atmosphere *atm, const double p[3], const double dir[3]);
/* p and dir finite (the ground's distance: the renderers also ask it along the zero
 * direction of a fisheye's pixel outside its circle). */
const char *atmos__atm_finite_fault(const double p[3], const double dir[3]);
/* The sunlight at p: p finite (a point below the ground counts as on it), sun a unit vector. */
const char *atmos__atm_light_fault(const double p[3], const double sun[3]);

/* p moved onto the ground where it is under it (a planet's: along its radius; its centre to
 * the point of the ground at the origin), else copied: where the renderers ask what the sky
 * sends to a volume whose centre may lie under the ground. */
void atmos__atm_onto_ground(const atmos_atmosphere *atm, const double p[3], double out[3]);

#endif
