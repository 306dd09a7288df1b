/* The single scattering of the air over the part of a segment that a volume can shadow, by
 * quadrature (path_trace.h, air_single): what the volume's shadow can take from the air's
 * in-scatter over a planet, whose models hold every order of scattering in one in-scatter.
 * Only the sun's single scattering is shadowed there: the higher orders come from the whole
 * sky, which a cloud mostly does not hide, and stay (docs/path.md, "What is computed"). */
#include "atmosphere/atmosphere_ops.h"
#include "render/path_trace.h"

#include <math.h>

/* Where an endless span is cut (m) if the air left it endless (a planet's is clipped to its top). */
#define AIR_SINGLE_FAR 1.0e6

void atmos__path_air_single(const path_run *R, const double p[3], const double d[3], double s0, double s1,
                            air_single *S)
{
    const int m = R->b->m;
    if (!atmos__atm_air_span(R->J->atm, p, d, &s0, &s1)) { /* no air in the span: nothing to shadow */
        S->s0 = s0, S->dt = 0;
        for (int i = 0; i < m; i++) S->sum[i] = 0;
        for (int c = 0; c < AIR_SINGLE_N; c++)
            for (int i = 0; i < m; i++) S->g[c][i] = 0;
        return;
    }
    if (!isfinite(s1)) s1 = s0 + AIR_SINGLE_FAR; /* a ray along the shadow's axis, away from the sun */
    S->s0 = s0, S->dt = (s1 - s0) / AIR_SINGLE_N;
    double g[AIR_SINGLE_N * PATH_B]; /* cell c, wavelength i at c * m + i */
    atmos__atm_single_cells_sub(R->J->atm, p, d, s0, s1, AIR_SINGLE_N, R->J->sun, m, R->b->k, g);
    for (int i = 0; i < m; i++) {
        S->sum[i] = 0;
        for (int c = 0; c < AIR_SINGLE_N; c++) S->sum[i] += S->g[c][i] = g[c * m + i];
    }
}

int atmos__path_air_single_point(const path_run *R, const air_single *S, const double *w, double *t, double *ratio)
{
    const int m = R->b->m;
    double q[AIR_SINGLE_N], tot = 0;
    for (int c = 0; c < AIR_SINGLE_N; c++) {
        q[c] = 0;
        for (int i = 0; i < m; i++)
            if (w[i] != 0 && S->sum[i] > 0) q[c] += S->g[c][i] / S->sum[i];
        tot += q[c];
    }
    if (!(tot > 0)) return 0;
    double u = atmos__stream_u(R->r) * tot;
    int c = 0;
    while (c < AIR_SINGLE_N - 1 && (u >= q[c] || q[c] == 0)) u -= q[c++];
    if (!(q[c] > 0)) return 0;
    *t = S->s0 + (c + atmos__stream_u(R->r)) * S->dt;
    for (int i = 0; i < m; i++) ratio[i] = S->g[c][i] * tot / q[c];
    return 1;
}
