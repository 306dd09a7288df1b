/* The particles' phase functions Ams_n tabulated on the cosine of the scattering angle for the
 * eye pass (psplat.c): a splat's colour needs Ams_{n+1} at each light's angle (the sun and the
 * sky lights) for every particle of every impostor remake; atmos__msphase_eval_all finds the angle with acos and a search
 * of the msphase grid. The table reads it from sqrt(1 - |cos|) (sin(theta/2) sqrt 2 forward, cos
 * (theta/2) sqrt 2 backward: nodes nearly uniform in theta at both ends, no acos), linearly
 * between nodes and orders. Made once a plan (harris_plan.c). Error against the exact
 * atmos_msphase_eval: tests/unit/test_pphase.c, docs/viewer.md. */
#ifndef ATMOS_PARTICLES_PPHASE_H
#define ATMOS_PARTICLES_PPHASE_H

#include "atmos/atmos.h"

#include <math.h>

#define ATMOS__PPHASE_NODES 4096 /* intervals a half (forward, backward) */

typedef struct atmos__pphase {
    int nw, orders; /* orders: Ams_1 .. Ams_orders, the last isotropic (max_order + 1) */
    float *v;       /* [order - 1][half][node 0..NODES][k] */
} atmos__pphase;

#define ATMOS__PPHASE_MAX_BYTES ((size_t)64 << 20) /* a plan's cap per particle type (docs/viewer.md) */

/* The bytes of m's table for nw wavelengths: orders x 2 (NODES + 1) x nw floats. */
size_t atmos__pphase_bytes(const atmos_msphase *m, int nw);
/* The table of m for its first nw wavelengths; NULL when it would take more than max_bytes
 * or when out of memory (the caller then evaluates m exactly, as psplat.c does). */
atmos__pphase *atmos__pphase_make(const atmos_msphase *m, int nw, size_t max_bytes);
void atmos__pphase_free(const atmos__pphase *t);

/* Ams_n(cos_theta) for every wavelength into out[0..nw), n >= 1 (below 1: 1), as
 * atmos__msphase_eval_all answers it within the table's error. */
static inline void atmos__pphase_eval(const atmos__pphase *t, double n, double cos_theta, double *out)
{
    enum { ROW = 2 * (ATMOS__PPHASE_NODES + 1) };
    const double c = cos_theta < 1 ? (cos_theta > -1 ? cos_theta : -1) : 1;
    const double x = sqrt(1.0 - fabs(c)) * ATMOS__PPHASE_NODES;
    const int i = x < ATMOS__PPHASE_NODES - 1 ? (int)x : ATMOS__PPHASE_NODES - 1;
    const double f = x - i;
    if (!(n >= 1)) n = 1;
    if (n > t->orders) n = t->orders;
    const int n0 = (int)n, n1 = n0 < t->orders ? n0 + 1 : n0;
    const double w = n - n0;
    const int nw = t->nw, at = i + (c < 0 ? ATMOS__PPHASE_NODES + 1 : 0);
    const float *a = t->v + ((size_t)(n0 - 1) * ROW + at) * nw, *b = t->v + ((size_t)(n1 - 1) * ROW + at) * nw;
    for (int k = 0; k < nw; k++) {
        const double va = a[k] + f * (a[nw + k] - a[k]), vb = b[k] + f * (b[nw + k] - b[k]);
        out[k] = va + w * (vb - va);
    }
}

#endif
