/* The production sky's node of the aerial-perspective volume (planet_solver.h's `aerial`,
 * atmosphere_aerial.c): the march's running sums along one view ray at every slice distance,
 * from one pass (atmos__sph_march_cumulative). */
#include "atmosphere/spherical.h"

#include <math.h>
#include <stdlib.h>

/* Steps of the march per slice. */
#define SPH_AERIAL_STEPS 1

void atmos__sph_aerial(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3], int nd,
                       const double *t, float *out)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count;
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    double ta = 0, tb = 0;
    double *sums = malloc(sizeof(double) * (size_t)nd * n * 4);
    const int inside = sums && atmos__planet_clip(pl, p, d, t[nd - 1], &ta, &tb);
    if (inside) atmos__sph_march_cumulative(pl, a->model, q, d, ta, tb, nd, t, sun, SPH_AERIAL_STEPS, 1, n, NULL, sums);
    for (int j = 0; j < nd; j++) {
        float *o = out + (size_t)j * n * 4;
        const double *s = sums + (size_t)j * n * 4;
        for (int k = 0; k < n; k++) {
            const double T = inside ? s[4 * k + 3] : 1.0, tau = T > 1.8e-35 ? -log(T) : 80.0;
            o[4 * k] = inside ? (float)(s[4 * k] * a->sun_e[k]) : 0.0f;
            o[4 * k + 1] = inside ? (float)(s[4 * k + 1] * a->sun_e[k]) : 0.0f;
            o[4 * k + 2] = inside ? (float)(s[4 * k + 2] * a->sun_e[k]) : 0.0f;
            o[4 * k + 3] = (float)(tau < 80.0 ? tau : 80.0);
        }
    }
    free(sums);
}
