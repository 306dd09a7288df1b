/* Vorticity confinement (Steinhoff & Underhill 1994; Fedkiw, Stam & Jensen 2001, Eq. 9-11):
 * f = eps dx |omega| (N x omega), N = grad|omega| / |grad|omega||, which puts back the small
 * swirls the semi-Lagrangian advection's smoothing takes out. Fedkiw et al.'s eps has units of
 * 1/s in SI (their f = eps dx (N x omega)); here it is made dimensionless by the local |omega|,
 * so one value serves every cell size. omega from the cell-centred velocity by
 * central differences; f averaged onto the faces. */
#include "sim/sim_internal.h"

#include <math.h>

#define CONF_CLONES ATMOS_CLONES

/* The rows of a cell's neighbours: j - 1 and j + 1 wrapped, level k - 1 and k + 1 clamped (as
 * offsets from the cell's own row). The loops over a row run i = 1 .. nx - 2 with i - 1 and
 * i + 1 as they are (so that the compiler vectorises them) and the two ends wrapped. */
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
CONF_CLONES static void velocity_centres(atmos_sim *s, int k, float *restrict uc, float *restrict vc, float *restrict wc)
{
    const int nx = s->nx;
    const size_t lev = (size_t)nx * s->ny;
    const float *restrict u = s->u, *restrict v = s->v, *restrict w = s->w;
    for (int j = 0; j < s->ny; j++) {
        const rows o = rows_of(s, j, k);
        for (int i = 0; i < nx; i++) {
            const size_t n = o.r + i;
            vc[n] = 0.5f * (v[n] + v[o.yp + i]);
            wc[n] = 0.5f * (w[n] + w[n + lev]);
        }
        for (int i = 0; i + 1 < nx; i++) uc[o.r + i] = 0.5f * (u[o.r + i] + u[o.r + i + 1]);
        uc[o.r + nx - 1] = 0.5f * (u[o.r + nx - 1] + u[o.r]);
    }
}

/* The vorticity omega at cell n of a row (neighbours along x at xm and xp; zf the vertical
 * difference's factor, one-sided at the ground and the lid). */
typedef struct {
    float x, y, z;
} vec3f;

ATMOS_CLONE_HELPER vec3f vort_at(const rows *o, size_t n, size_t i, size_t xm, size_t xp, float inv2, float zf,
                                 const float *restrict uc, const float *restrict vc, const float *restrict wc)
{
    const size_t yp = o->yp + i, ym = o->ym + i, zp = n + o->zp, zm = n + o->zm;
    vec3f w;
    w.x = (wc[yp] - wc[ym]) * inv2 - (vc[zp] - vc[zm]) * zf;
    w.y = (uc[zp] - uc[zm]) * zf - (wc[xp] - wc[xm]) * inv2;
    w.z = (vc[xp] - vc[xm]) * inv2 - (uc[yp] - uc[ym]) * inv2;
    return w;
}

ATMOS_CLONE_HELPER float len(vec3f w)
{
    return sqrtf(w.x * w.x + w.y * w.y + w.z * w.z);
}

static float vert_factor(const atmos_sim *s, int k)
{
    const float inv2 = (float)(0.5 / s->dx);
    return (k > 0 && k + 1 < s->nz) ? inv2 : 2 * inv2;
}

/* |omega| at the centres of level k into f[6] (omega itself is found again where the force
 * needs it: three fields fewer written and read). */
CONF_CLONES static void vorticity(atmos_sim *s, int k, float *const f[7])
{
    const float *restrict uc = f[0], *restrict vc = f[1], *restrict wc = f[2];
    float *restrict om = f[6];
    const int nx = s->nx;
    const float inv2 = (float)(0.5 / s->dx), zf = vert_factor(s, k);
    for (int j = 0; j < s->ny; j++) {
        const rows o = rows_of(s, j, k);
        const size_t r = o.r, e = (size_t)nx - 1;
        om[r] = len(vort_at(&o, r, 0, r + e, r + 1, inv2, zf, uc, vc, wc));
        for (size_t i = 1; i < e; i++) om[r + i] = len(vort_at(&o, r + i, i, r + i - 1, r + i + 1, inv2, zf, uc, vc, wc));
        om[r + e] = len(vort_at(&o, r + e, e, r + e - 1, r, inv2, zf, uc, vc, wc));
    }
}

/* The force eps dx |omega| (N x omega) at cell n of a row into fx, fy, fz. */
#define FORCE_ARGS                                                                                                   \
    const float *restrict uc, const float *restrict vc, const float *restrict wc, const float *restrict om,           \
        float *restrict fx, float *restrict fy, float *restrict fz
ATMOS_CLONE_HELPER void force_cell(const rows *o, size_t n, size_t i, size_t xm, size_t xp, float a, float inv2, float zf,
                                   FORCE_ARGS)
{
    const vec3f w = vort_at(o, n, i, xm, xp, inv2, zf, uc, vc, wc);
    float gx = om[xp] - om[xm];
    float gy = om[o->yp + i] - om[o->ym + i];
    float gz = om[n + o->zp] - om[n + o->zm];
    const float gl = sqrtf(gx * gx + gy * gy + gz * gz) + 1e-20f;
    gx /= gl, gy /= gl, gz /= gl;
    const float am = a * om[n];
    fx[n] = am * (gy * w.z - gz * w.y);
    fy[n] = am * (gz * w.x - gx * w.z);
    fz[n] = am * (gx * w.y - gy * w.x);
}

/* A row's forces (its two ends wrapped apart, the rest vectorised: a function of its own, so
 * that the compiler takes the fields' restrict at its word). */
ATMOS_CLONES_NOINLINE static void force_row(const rows *o, size_t e, float a, float inv2, float zf, FORCE_ARGS)
{
    const size_t r = o->r;
    force_cell(o, r, 0, r + e, r + 1, a, inv2, zf, uc, vc, wc, om, fx, fy, fz);
    for (size_t i = 1; i < e; i++) force_cell(o, r + i, i, r + i - 1, r + i + 1, a, inv2, zf, uc, vc, wc, om, fx, fy, fz);
    force_cell(o, r + e, e, r + e - 1, r, a, inv2, zf, uc, vc, wc, om, fx, fy, fz);
}

/* The force at the centres of level k (from the centred velocity f[0..2] and |omega| f[6],
 * into f[3..5]), then (the level's forces known) its x and y components averaged onto the u
 * and v faces of the level, times dt (the w faces need the level below: apply_w, after a
 * barrier). */
CONF_CLONES static void force(atmos_sim *s, int k, float a, float dt, float *const f[7])
{
    const int nx = s->nx;
    const size_t e = (size_t)nx - 1;
    const float inv2 = (float)(0.5 / s->dx), zf = vert_factor(s, k);
    for (int j = 0; j < s->ny; j++) {
        const rows o = rows_of(s, j, k);
        force_row(&o, e, a, inv2, zf, f[0], f[1], f[2], f[6], f[3], f[4], f[5]);
    }
    const float *restrict fx = f[3], *restrict fy = f[4];
    float *restrict u = s->u, *restrict v = s->v;
    const float h = 0.5f * dt;
    for (int j = 0; j < s->ny; j++) {
        const rows o = rows_of(s, j, k);
        const size_t r = o.r;
        u[r] += h * (fx[r] + fx[r + e]);
        for (size_t i = 1; i < (size_t)nx; i++) u[r + i] += h * (fx[r + i] + fx[r + i - 1]);
        for (size_t i = 0; i < (size_t)nx; i++) v[r + i] += h * (fy[r + i] + fy[o.ym + i]);
    }
}

/* The force's z component averaged onto the w faces of level k > 0, times dt. */
CONF_CLONES static void apply_w(atmos_sim *s, int k, float dt, const float *restrict fz)
{
    const size_t lev = (size_t)s->nx * s->ny;
    float *restrict w = s->w;
    const float h = 0.5f * dt;
    for (size_t n = k * lev; n < (k + 1) * lev; n++) w[n] += h * (fz[n] + fz[n - lev]);
}

void atmos__sim_confine(atmos_sim *s, double dt)
{
    const double eps = s->env.confinement;
    if (!(eps > 0)) return;
    const int nz = s->nz;
    float *const f[7] = {s->s[0], s->s[1], s->s[2], s->s[3], s->s[4], s->s[5], s->s[6]};
    SIM_FOR
    for (int k = 0; k < nz; k++) velocity_centres(s, k, f[0], f[1], f[2]);
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k < nz; k++) vorticity(s, k, f);
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k < nz; k++) force(s, k, (float)(eps * s->dx), (float)dt, f);
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 1; k < nz; k++) apply_w(s, k, (float)dt, f[5]);
    atmos__sim_sync(s);
}
