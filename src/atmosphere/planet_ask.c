/* What the spherical kinds answer alike (planet_solver.h): the radiance of a view ray from
 * a solver's in-scatter, transmittance and sunlight when it has no faster way. */
#include "atmosphere/planet_solver.h"

#include "core/vec.h"

void atmos__planet_radiance_generic(const atmos_atmosphere *a, const double p[3], const double d[3],
                                    const double sun[3], double *out, atmos_atmosphere_hit *info)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count;
    const double K = atmos__planet_ground_distance(pl, p, d);
    const int ground = K < INFINITY;
    if (!a->solver->inscatter(a, p, d, K, sun, n, NULL, out))
        for (int i = 0; i < n; i++) out[i] = 0.0;
    if (ground) {
        double g[3] = {p[0] + K * d[0], p[1] + K * d[1], p[2] + K * d[2]}, nrm[3];
        atmos__planet_ground_point(pl, g, nrm);
        const double cs = fmax(atmos__dot3(nrm, sun), 0.0);
        double E[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
        a->solver->transmittance(a, p, d, K, n, NULL, T);
        if (cs > 0) a->solver->sunlight(a, g, sun, n, NULL, E);
        for (int i = 0; i < n; i++) {
            const double lit = cs > 0 ? atmos__planet_ground_albedo(pl, g, i) / ATMOS_PI * cs * E[i] : 0.0;
            out[i] += (lit + atmos__planet_ground_lights(pl, g, sun, i)) * T[i];
        }
    }
    if (info) {
        info->distance_m = K;
        info->hits_ground = ground;
        info->in_sun_disk = 0;
    }
}
