/* The volume's shadow on the air along the Nishita renderer's eye rays (nishita_internal.h,
 * atmos__nishita_air_shadow; the slice renderer's counterpart is slice_shadow.c). The sky image
 * lights the air as if the volume were not there; where the air lies in the volume's shadow (the
 * sun ahead: the air between the eye and a cloud, under it) it scatters less. Per span of the
 * eye ray this takes the air's single scattering of the sunlight times 1 - T_vol, T_vol the
 * volume's transmittance from the point toward the sun: the column density of the render voxel
 * where the point's way to the sun enters the box (the sun's columns of nishita_plan.c, the
 * first order's own), times the eye rays' extinction. */
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "render/nishita_internal.h"

#include <math.h>

#define AIR_CELLS 24 /* the span's cells (the air's single scattering at their centres) */

/* The volume's transmittance toward the sun from grid-frame point x, per wavelength, into T. */
static void sun_transmittance(const atmos__nishita_plan *np, const double x[3], const double sun_g[3],
                              const float sig[][ATMOS_MAX_WAVELENGTHS], double *T)
{
    const sgrid *g = &np->g;
    double a, b;
    for (int w = 0; w < np->n; w++) T[w] = 1;
    if (!atmos__ray_box(x, sun_g, g->box_lo, g->box_hi, &a, &b) || !(b > 0)) return;
    if (a < 0) a = 0;
    float col[ATMOS_VOLUME_MAX_FIELDS];
    atmos__nishita_grid_at(g, np->col, np->nf, (x[0] + a * sun_g[0]) * g->sc + g->off[0],
                           (x[1] + a * sun_g[1]) * g->sc + g->off[1], (x[2] + a * sun_g[2]) * g->sc + g->off[2], col);
    for (int w = 0; w < np->n; w++) {
        double tau = 0;
        for (int f = 0; f < np->nf; f++) tau += col[f] * sig[f][w];
        T[w] = exp(-tau);
    }
}

void atmos__nishita_air_shadow(const atmos__nishita_plan *np, const atmos_atmosphere *atm, const double cam[3],
                               const double d[3], const double eye_g[3], const double dg[3], const double sun_w[3],
                               const double sun_g[3], const float sig[][ATMOS_MAX_WAVELENGTHS], double s0, double s1,
                               double *D)
{
    const int n = np->n;
    double S[AIR_CELLS * ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    for (int w = 0; w < n; w++) D[w] = 0;
    if (!(s1 > s0) || !atmos__atm_air_span(atm, cam, d, &s0, &s1)) return;
    atmos__atm_single_cells_sub(atm, cam, d, s0, s1, AIR_CELLS, sun_w, n, NULL, S);
    const double dt = (s1 - s0) / AIR_CELLS;
    for (int c = 0; c < AIR_CELLS; c++) {
        const double t = s0 + (c + 0.5) * dt, x[3] = {eye_g[0] + t * dg[0], eye_g[1] + t * dg[1], eye_g[2] + t * dg[2]};
        sun_transmittance(np, x, sun_g, sig, T);
        for (int w = 0; w < n; w++) D[w] += S[(size_t)c * n + w] * (1 - T[w]);
    }
}
