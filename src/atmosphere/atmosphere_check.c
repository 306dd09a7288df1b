/* What the public questions of an atmosphere refuse (atmosphere_check.h), and
 * atmos_atmosphere_check_ray, which names it. */
#include "atmosphere/atmosphere_check.h"
#include "atmosphere/atmosphere_internal.h"
#include "atmosphere/planet.h"

#include <math.h>

static int finite3(const double v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

const char *atmos__atm_unit_fault(const double dir[3])
{
    if (!finite3(dir)) return "is not finite (NaN or infinity)";
    const double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (!(fabs(len - 1.0) <= ATMOS__ATM_UNIT_TOLERANCE)) return "is not a unit vector";
    return NULL;
}

/* The observer's height above the ground (a planet's, or the flat y = 0); INFINITY in a
 * vacuum, which has no ground. */
static double height(const atmos_atmosphere *atm, const double p[3])
{
    if (atm->planet) return atmos__planet_altitude(atm->planet, p);
    if (atm->desc.kind == ATMOS_ATMOSPHERE_VACUUM) return INFINITY;
    return p[1];
}

const char *atmos__atm_ray_fault(const atmos_atmosphere *atm, const double p[3], const double dir[3])
{
    if (!finite3(p)) return "position is not finite (NaN or infinity)";
    if (height(atm, p) < -ATMOS__ATM_BELOW_TOLERANCE_M)
        return atm->planet ? "position is inside the planet (below its ground)" : "position is below the ground (y < 0)";
    return atmos__atm_unit_fault(dir) ? "direction is not a finite unit vector" : NULL;
}

const char *atmos__atm_finite_fault(const double p[3], const double dir[3])
{
    return finite3(p) && finite3(dir) ? NULL : "position or direction is not finite (NaN or infinity)";
}

const char *atmos__atm_light_fault(const double p[3], const double sun[3])
{
    if (!finite3(p)) return "position is not finite (NaN or infinity)";
    return atmos__atm_unit_fault(sun) ? "sun direction is not a finite unit vector" : NULL;
}

void atmos__atm_onto_ground(const atmos_atmosphere *atm, const double p[3], double out[3])
{
    for (int a = 0; a < 3; a++) out[a] = p[a];
    if (!(height(atm, p) < 0)) return;
    if (!atm->planet) {
        out[1] = 0.0;
        return;
    }
    const double R = atm->planet->r_ground, q[3] = {p[0], p[1] + R, p[2]};
    const double r = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    if (!(r > 0)) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    for (int a = 0; a < 3; a++) out[a] = q[a] * (R / r);
    out[1] -= R;
}

atmos_status atmos_atmosphere_check_ray(atmos_context *ctx, const atmos_atmosphere *atm, const double p[3],
                                        const double dir[3], const double sun_dir[3])
{
    if (!atm || !p || !dir) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere check: NULL argument");
    const char *why = atmos__atm_ray_fault(atm, p, dir);
    if (!why && sun_dir && atmos__atm_unit_fault(sun_dir)) why = "sun direction is not a finite unit vector";
    if (why)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere: view ray from (%g, %g, %g) along (%g, %g, %g): %s",
                            p[0], p[1], p[2], dir[0], dir[1], dir[2], why);
    return ATMOS_OK;
}
