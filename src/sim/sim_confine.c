/* Vorticity confinement (Steinhoff & Underhill 1994; Fedkiw, Stam & Jensen 2001, Eq. 9-11):
 * f = eps dx |omega| (N x omega), N = grad|omega| / |grad|omega||, which puts back the small
 * swirls the semi-Lagrangian advection's smoothing takes out. Fedkiw et al.'s eps has units of
 * 1/s in SI (their f = eps dx (N x omega)); here it is made dimensionless by the local |omega|,
 * so one value serves every cell size. omega from the cell-centred velocity by
 * central differences; f averaged onto the faces. */
#include "sim/sim_internal.h"

#include <math.h>

/* The rows of a cell's neighbours: j - 1 and j + 1 wrapped, level k - 1 and k + 1 clamped (as
 * offsets from the cell's own row), and i - 1 / i + 1 wrapped. */
typedef struct {
    size_t r, ym, yp;
    ptrdiff_t zm, zp;
} rows;

static rows rows_of(const atmos_sim *s, int j, int k)
{
    const int ny = s->ny, nz = s->nz;
    const ptrdiff_t lev = (ptrdiff_t)s->nx * ny;
    rows o;
    o.r = sim_idx(s, 0, j, k);
    o.ym = sim_idx(s, 0, j ? j - 1 : ny - 1, k);
    o.yp = sim_idx(s, 0, j + 1 == ny ? 0 : j + 1, k);
    o.zm = k > 0 ? -lev : 0;
    o.zp = k + 1 < nz ? lev : 0;
    return o;
}

/* The velocity at the cell centres of level k. */
static void centres(atmos_sim *s, int k, float *uc, float *vc, float *wc)
{
    const int nx = s->nx;
    const size_t lev = (size_t)nx * s->ny;
    for (int j = 0; j < s->ny; j++) {
        const rows o = rows_of(s, j, k);
        for (int i = 0; i < nx; i++) {
            const size_t n = o.r + i;
            uc[n] = 0.5f * (s->u[n] + s->u[o.r + (i + 1 == nx ? 0 : i + 1)]);
            vc[n] = 0.5f * (s->v[n] + s->v[o.yp + i]);
            wc[n] = 0.5f * (s->w[n] + s->w[n + lev]);
        }
    }
}

/* The vorticity omega and its length at the centres of level k (central differences, one-sided
 * at the ground and the lid). */
static void vorticity(atmos_sim *s, int k, float *const f[7])
{
    const float *uc = f[0], *vc = f[1], *wc = f[2];
    float *ox = f[3], *oy = f[4], *oz = f[5], *om = f[6];
    const int nx = s->nx, nz = s->nz;
    const float inv2 = (float)(0.5 / s->dx), zf = (k > 0 && k + 1 < nz) ? inv2 : 2 * inv2;
    for (int j = 0; j < s->ny; j++) {
        const rows o = rows_of(s, j, k);
        for (int i = 0; i < nx; i++) {
            const size_t n = o.r + i;
            const size_t xp = o.r + (i + 1 == nx ? 0 : i + 1), xm = o.r + (i ? i - 1 : nx - 1);
            const size_t yp = o.yp + i, ym = o.ym + i, zp = n + o.zp, zm = n + o.zm;
            ox[n] = (wc[yp] - wc[ym]) * inv2 - (vc[zp] - vc[zm]) * zf;
            oy[n] = (uc[zp] - uc[zm]) * zf - (wc[xp] - wc[xm]) * inv2;
            oz[n] = (vc[xp] - vc[xm]) * inv2 - (uc[yp] - uc[ym]) * inv2;
            om[n] = sqrtf(ox[n] * ox[n] + oy[n] * oy[n] + oz[n] * oz[n]);
        }
    }
}

/* The force eps dx |omega| (N x omega) at the centres of level k into f[0..2]. */
static void force(atmos_sim *s, int k, float a, float *const f[7])
{
    float *fx = f[0], *fy = f[1], *fz = f[2];
    const float *ox = f[3], *oy = f[4], *oz = f[5], *om = f[6];
    const int nx = s->nx;
    for (int j = 0; j < s->ny; j++) {
        const rows o = rows_of(s, j, k);
        for (int i = 0; i < nx; i++) {
            const size_t n = o.r + i;
            float gx = om[o.r + (i + 1 == nx ? 0 : i + 1)] - om[o.r + (i ? i - 1 : nx - 1)];
            float gy = om[o.yp + i] - om[o.ym + i];
            float gz = om[n + o.zp] - om[n + o.zm];
            const float gl = sqrtf(gx * gx + gy * gy + gz * gz) + 1e-20f;
            gx /= gl, gy /= gl, gz /= gl;
            const float am = a * om[n];
            fx[n] = am * (gy * oz[n] - gz * oy[n]);
            fy[n] = am * (gz * ox[n] - gx * oz[n]);
            fz[n] = am * (gx * oy[n] - gy * ox[n]);
        }
    }
}

/* The centred force averaged onto the faces of level k, times dt. */
static void apply(atmos_sim *s, int k, float dt, float *const f[7])
{
    const float *fx = f[0], *fy = f[1], *fz = f[2];
    const int nx = s->nx;
    const size_t lev = (size_t)nx * s->ny;
    const float h = 0.5f * dt;
    for (int j = 0; j < s->ny; j++) {
        const rows o = rows_of(s, j, k);
        for (int i = 0; i < nx; i++) {
            const size_t n = o.r + i;
            s->u[n] += h * (fx[n] + fx[o.r + (i ? i - 1 : nx - 1)]);
            s->v[n] += h * (fy[n] + fy[o.ym + i]);
            if (k > 0) s->w[n] += h * (fz[n] + fz[n - lev]);
        }
    }
}

void atmos__sim_confine(atmos_sim *s, double dt)
{
    const double eps = s->env.confinement;
    if (!(eps > 0)) return;
    const int nz = s->nz;
    float *const f[7] = {s->s[0], s->s[1], s->s[2], s->s[3], s->s[4], s->s[5], s->s[6]};
    SIM_FOR
    for (int k = 0; k < nz; k++) centres(s, k, f[0], f[1], f[2]);
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k < nz; k++) vorticity(s, k, f);
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k < nz; k++) force(s, k, (float)(eps * s->dx), f);
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k < nz; k++) apply(s, k, (float)dt, f);
    atmos__sim_sync(s);
}
