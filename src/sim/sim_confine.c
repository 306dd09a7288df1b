/* Vorticity confinement (Steinhoff & Underhill 1994; Fedkiw, Stam & Jensen 2001, Eq. 9-11):
 * f = eps dx |omega| (N x omega), N = grad|omega| / |grad|omega||, which puts back the small
 * swirls the semi-Lagrangian advection's smoothing takes out. Fedkiw et al.'s eps has units of
 * 1/s in SI (their f = eps dx (N x omega)); here it is made dimensionless by the local |omega|,
 * so one value serves every cell size. omega from the cell-centred velocity by
 * central differences; f averaged onto the faces. */
#include "sim/sim_internal.h"

#include <math.h>

void atmos__sim_confine(atmos_sim *s, double dt)
{
    const double eps = s->env.confinement;
    if (!(eps > 0)) return;
    const int nx = s->nx, ny = s->ny, nz = s->nz;
    const size_t lev = (size_t)nx * ny;
    float *uc = s->s[0], *vc = s->s[1], *wc = s->s[2], *ox = s->s[3], *oy = s->s[4], *oz = s->s[5], *om = s->s[6];
    SIM_FOR
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const size_t n = sim_idx(s, i, j, k);
                uc[n] = 0.5f * (s->u[n] + s->u[sim_idx(s, (i + 1) % nx, j, k)]);
                vc[n] = 0.5f * (s->v[n] + s->v[sim_idx(s, i, (j + 1) % ny, k)]);
                wc[n] = 0.5f * (s->w[n] + s->w[n + lev]);
            }
    atmos__sim_sync(s);
    const float inv2 = (float)(0.5 / s->dx);
    SIM_FOR
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const size_t n = sim_idx(s, i, j, k);
                const size_t xp = sim_idx(s, (i + 1) % nx, j, k), xm = sim_idx(s, (i + nx - 1) % nx, j, k);
                const size_t yp = sim_idx(s, i, (j + 1) % ny, k), ym = sim_idx(s, i, (j + ny - 1) % ny, k);
                const size_t zp = k + 1 < nz ? n + lev : n, zm = k > 0 ? n - lev : n;
                const float zf = (k > 0 && k + 1 < nz) ? inv2 : 2 * inv2;
                ox[n] = (wc[yp] - wc[ym]) * inv2 - (vc[zp] - vc[zm]) * zf;
                oy[n] = (uc[zp] - uc[zm]) * zf - (wc[xp] - wc[xm]) * inv2;
                oz[n] = (vc[xp] - vc[xm]) * inv2 - (uc[yp] - uc[ym]) * inv2;
                om[n] = sqrtf(ox[n] * ox[n] + oy[n] * oy[n] + oz[n] * oz[n]);
            }
    atmos__sim_sync(s);
    /* the force at the centres into uc, vc, wc */
    const float a = (float)(eps * s->dx);
    SIM_FOR
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const size_t n = sim_idx(s, i, j, k);
                const size_t zp = k + 1 < nz ? n + lev : n, zm = k > 0 ? n - lev : n;
                float gx = om[sim_idx(s, (i + 1) % nx, j, k)] - om[sim_idx(s, (i + nx - 1) % nx, j, k)];
                float gy = om[sim_idx(s, i, (j + 1) % ny, k)] - om[sim_idx(s, i, (j + ny - 1) % ny, k)];
                float gz = om[zp] - om[zm];
                const float gl = sqrtf(gx * gx + gy * gy + gz * gz) + 1e-20f;
                gx /= gl, gy /= gl, gz /= gl;
                const float am = a * om[n];
                uc[n] = am * (gy * oz[n] - gz * oy[n]);
                vc[n] = am * (gz * ox[n] - gx * oz[n]);
                wc[n] = am * (gx * oy[n] - gy * ox[n]);
            }
    atmos__sim_sync(s);
    const float h = (float)(0.5 * dt);
    SIM_FOR
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const size_t n = sim_idx(s, i, j, k);
                s->u[n] += h * (uc[n] + uc[sim_idx(s, (i + nx - 1) % nx, j, k)]);
                s->v[n] += h * (vc[n] + vc[sim_idx(s, i, (j + ny - 1) % ny, k)]);
                if (k > 0) s->w[n] += h * (wc[n] + wc[n - lev]);
            }
    atmos__sim_sync(s);
}
