/* The production sky's node of the aerial-perspective volume (planet_solver.h's `aerial`,
 * atmosphere_aerial.c): the march's running sums along one view ray at every slice distance,
 * from one pass (atmos__sph_march_cumulative), after the air in front of the first slice
 * (atmos__sph_march over that segment, as the one-ray answer). Over [0, t_j] = over [0, t_0]
 * + T(0, t_0) x over [t_0, t_j]: every sum of the march is an integral of the transmittance
 * from the segment's start times a source. */
#include "atmosphere/spherical.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
    /* the air in front of the first slice: one segment, as the one-ray answer marches it */
    atmos__sph_sums near;
    memset(&near, 0, sizeof near);
    for (int k = 0; k < n; k++) near.t[k] = 1.0;
    if (inside && t[0] > ta) atmos__sph_march(pl, a->model, q, d, ta, fmin(t[0], tb), sun, ATMOS__SPH_STEPS, 1, n, NULL, &near);
    if (inside)
        atmos__sph_march_cumulative(pl, a->model, q, d, fmax(ta, t[0]), tb, nd, t, sun, SPH_AERIAL_STEPS, 1, n, NULL,
                                    sums);
    for (int j = 0; j < nd; j++) {
        float *o = out + (size_t)j * n * 4;
        const double *s = sums + (size_t)j * n * 4;
        for (int k = 0; k < n; k++) {
            const double Tn = near.t[k];
            const double T = inside ? Tn * s[4 * k + 3] : 1.0, tau = T > 1.8e-35 ? -log(T) : 80.0;
            o[4 * k] = inside ? (float)((near.sr[k] + Tn * s[4 * k]) * a->sun_e[k]) : 0.0f;
            o[4 * k + 1] = inside ? (float)((near.sm[k] + Tn * s[4 * k + 1]) * a->sun_e[k]) : 0.0f;
            o[4 * k + 2] = inside ? (float)((near.ms[k] + Tn * s[4 * k + 2]) * a->sun_e[k]) : 0.0f;
            o[4 * k + 3] = (float)(tau < 80.0 ? tau : 80.0);
        }
    }
    free(sums);
}
