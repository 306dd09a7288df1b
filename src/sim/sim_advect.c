/* Semi-Lagrangian advection (Stam 1999; Staniforth & Cote 1991): every value is what arrives
 * from its departure point, sampled trilinearly (monotone: no new extrema). Scalars share one
 * departure point per cell found with a midpoint (second-order) trace and are then corrected
 * by MacCormack's step (sim_maccormack.c); each velocity component is traced from its own face
 * with the velocity there. Positions are in cell units; x and y
 * wrap, z clamps to the grid. */
#include "sim/sim_internal.h"

#include <math.h>
#include <string.h>

#define ADV_CLONES ATMOS_CLONES
/* The helpers (ATMOS_CLONE_HELPER) are inlined into each clone. The loops over a row run
 * i = 1 .. nx - 2 with i - 1 and i + 1 as they are (so that the compiler vectorises them) and the
 * row's ends wrapped apart. */
/* Level k packed for the scalars' trace (s->pack): the velocity at the cell centres (u, v, w, 0)
 * and the scalars (theta, q_v, q_c, q_r), 4 floats a cell each; and the level's water before
 * the advection: q_v into part[k], q_c + q_r into part[nz + 1 + k]. */
ATMOS_CLONE_HELPER void pack_cell(const atmos_sim *s, size_t n, size_t xp, size_t yp, size_t lev, float *restrict p,
                                  float *restrict q)
{
    p[0] = 0.5f * (s->u[n] + s->u[xp]);
    p[1] = 0.5f * (s->v[n] + s->v[yp]);
    p[2] = 0.5f * (s->w[n] + s->w[n + lev]);
    p[3] = 0;
    q[0] = s->th[n], q[1] = s->qv[n], q[2] = s->qc[n], q[3] = s->qr[n];
}

ADV_CLONES static void centres(atmos_sim *s, int k)
{
    const int nx = s->nx, ny = s->ny;
    const size_t lev = (size_t)nx * ny, e = (size_t)nx - 1;
    float *vel4 = s->pack, *sc4 = s->pack + 4 * s->n;
    for (int j = 0; j < ny; j++) {
        const size_t r = sim_idx(s, 0, j, k), rp = sim_idx(s, 0, j + 1 == ny ? 0 : j + 1, k);
        for (size_t i = 0; i < e; i++) pack_cell(s, r + i, r + i + 1, rp + i, lev, vel4 + 4 * (r + i), sc4 + 4 * (r + i));
        pack_cell(s, r + e, r, rp + e, lev, vel4 + 4 * (r + e), sc4 + 4 * (r + e));
    }
    double vl = 0, tl = 0;
    for (size_t n = k * lev; n < (k + 1) * lev; n++) {
        vl += s->qv[n];
        tl += (double)s->qc[n] + s->qr[n];
    }
    s->part[k] = vl, s->part[s->nz + 1 + k] = tl;
}

/* Level k of the scalars' semi-Lagrangian step, packed into pack[8 n ..], each cell's departure
 * point traced once (midpoint rule on the cell-centred velocity) for all four and kept in
 * s[0..2] for MacCormack's correction (sim_maccormack.c), which writes the fields. */
ADV_CLONES static void scalars(atmos_sim *s, int k, float c)
{
    const int nx = s->nx, ny = s->ny;
    const float *vel4 = s->pack, *sc4 = s->pack + 4 * s->n;
    float *hat4 = s->pack + 8 * s->n;
    float x[ATMOS_SIM_MAX_GRID], y[ATMOS_SIM_MAX_GRID], z[ATMOS_SIM_MAX_GRID];
    float q[4 * ATMOS_SIM_MAX_GRID];
    const float h = 0.5f * c;
    for (int j = 0; j < ny; j++) {
        const size_t r = sim_idx(s, 0, j, k);
        const float fj = (float)j, fk = (float)k;
        for (int i = 0; i < nx; i++) { /* half a step back with the velocity here */
            const float *p = vel4 + 4 * (r + i);
            x[i] = (float)i - h * p[0], y[i] = fj - h * p[1], z[i] = fk - h * p[2];
        }
        atmos__sim_sample4_row(s, vel4, s->nz, x, y, z, q, nx);
        for (int i = 0; i < nx; i++) /* a whole step back with the velocity there */
            x[i] = (float)i - c * q[4 * i], y[i] = fj - c * q[4 * i + 1], z[i] = fk - c * q[4 * i + 2];
        atmos__sim_sample4_row(s, sc4, s->nz, x, y, z, hat4 + 4 * r, nx);
        memcpy(s->s[0] + r, x, nx * sizeof *x); /* the departure points, for the correction */
        memcpy(s->s[1] + r, y, nx * sizeof *y);
        memcpy(s->s[2] + r, z, nx * sizeof *z);
    }
}

/* The departure points of the faces of a row: u's, v's and w's (the velocity's components
 * other than the face's own averaged from its four nearest faces). */
ATMOS_CLONE_HELPER void pos_u(const float *restrict u, const float *restrict v, const float *restrict w, size_t r, size_t rp,
                      size_t lev, int i, int im, float fj, float fk, float c, float *restrict x, float *restrict y,
                              float *restrict z)
{
    const float vu = 0.25f * (v[r + im] + v[r + i] + v[rp + im] + v[rp + i]);
    const float wu = 0.25f * (w[r + im] + w[r + i] + w[r + lev + im] + w[r + lev + i]);
    x[i] = (float)i - c * u[r + i], y[i] = fj - c * vu, z[i] = fk - c * wu;
}

ATMOS_CLONE_HELPER void pos_v(const float *restrict u, const float *restrict v, const float *restrict w, size_t r, size_t rm,
                      size_t lev, int i, int ip, float fj, float fk, float c, float *restrict x, float *restrict y,
                              float *restrict z)
{
    const float uv = 0.25f * (u[rm + i] + u[rm + ip] + u[r + i] + u[r + ip]);
    const float wv = 0.25f * (w[rm + i] + w[r + i] + w[rm + lev + i] + w[r + lev + i]);
    x[i] = (float)i - c * uv, y[i] = fj - c * v[r + i], z[i] = fk - c * wv;
}

ATMOS_CLONE_HELPER void pos_w(const float *restrict u, const float *restrict v, const float *restrict w, size_t r, size_t rp,
                      size_t lev, int i, int ip, float fj, float fk, float c, float *restrict x, float *restrict y,
                              float *restrict z)
{
    const float uw = 0.25f * (u[r - lev + i] + u[r - lev + ip] + u[r + i] + u[r + ip]);
    const float vw = 0.25f * (v[r - lev + i] + v[rp - lev + i] + v[r + i] + v[rp + i]);
    x[i] = (float)i - c * uw, y[i] = fj - c * vw, z[i] = fk - c * w[r + i];
}

/* The departure points of row r's faces of component f (0: u, 1: v, 2: w; rn the row j + 1's
 * offset for u and w, j - 1's for v), each row's end wrapped apart. A function of its own whose
 * restrict-qualified arrays let the compiler vectorise the loops (inlined, with x, y, z as
 * floats like the fields, it needed too many run-time alias checks and stayed scalar). */
ATMOS_CLONES_NOINLINE static void points(int f, const float *restrict u, const float *restrict v,
                                                        const float *restrict w, size_t r, size_t rn, size_t lev,
                                                        int nx, float fj, float fk, float c, float *restrict x,
                                                        float *restrict y, float *restrict z)
{
    const int e = nx - 1;
    if (f == 0) {
        pos_u(u, v, w, r, rn, lev, 0, e, fj, fk, c, x, y, z);
        for (int i = 1; i < nx; i++) pos_u(u, v, w, r, rn, lev, i, i - 1, fj, fk, c, x, y, z);
    } else if (f == 1) {
        for (int i = 0; i < e; i++) pos_v(u, v, w, r, rn, lev, i, i + 1, fj, fk, c, x, y, z);
        pos_v(u, v, w, r, rn, lev, e, 0, fj, fk, c, x, y, z);
    } else {
        for (int i = 0; i < e; i++) pos_w(u, v, w, r, rn, lev, i, i + 1, fj, fk, c, x, y, z);
        pos_w(u, v, w, r, rn, lev, e, 0, fj, fk, c, x, y, z);
    }
}

/* Level k of the new velocity into s[4..6] from the old one (each face traced from itself with
 * its own component and the other two averaged from the four nearest faces; in a field's own
 * index space the departure point is its index minus dt v / dx); k = nz is the lid's w. */
static void velocity(atmos_sim *s, int k, float c)
{
    const int nx = s->nx, ny = s->ny, nz = s->nz;
    const size_t lev = (size_t)nx * ny;
    const float *u = s->u, *v = s->v, *w = s->w;
    float *nu = s->s[4], *nv = s->s[5], *nw = s->s[6];
    float x[ATMOS_SIM_MAX_GRID], y[ATMOS_SIM_MAX_GRID], z[ATMOS_SIM_MAX_GRID];
    const float fk = (float)k;
    for (int j = 0; j < ny; j++) {
        const float fj = (float)j;
        const size_t r = (size_t)k * lev + (size_t)j * nx;
        const size_t rm = (size_t)k * lev + (size_t)(j ? j - 1 : ny - 1) * nx;
        const size_t rp = (size_t)k * lev + (size_t)(j + 1 == ny ? 0 : j + 1) * nx;
        if (k < nz) { /* u on the face x = i - 1/2, v on y = j - 1/2 */
            points(0, u, v, w, r, rp, lev, nx, fj, fk, c, x, y, z);
            atmos__sim_sample_row(s, u, nz, x, y, z, nu + r, nx);
            points(1, u, v, w, r, rm, lev, nx, fj, fk, c, x, y, z);
            atmos__sim_sample_row(s, v, nz, x, y, z, nv + r, nx);
        }
        if (k == 0 || k == nz) {
            for (int i = 0; i < nx; i++) nw[r + i] = 0;
            continue;
        }
        points(2, u, v, w, r, rp, lev, nx, fj, fk, c, x, y, z); /* w on z = k - 1/2 */
        atmos__sim_sample_row(s, w, nz + 1, x, y, z, nw + r, nx);
    }
}

/* The new velocity (in s[4..6]) becomes the velocity: called by one thread while the others
 * do not touch u, v, w, and followed by a barrier before anyone does. */
void atmos__sim_advected_velocity(atmos_sim *s)
{
    float *t;
    t = s->u, s->u = s->s[4], s->s[4] = t;
    t = s->v, s->v = s->s[5], s->s[5] = t;
    t = s->w, s->w = s->s[6], s->s[6] = t;
}

/* Two passes over the levels: the cell-centred velocity and the scalars packed (and the water
 * before), then the new velocity into s[4..6] and the new scalars in place (and the water
 * after). Semi-Lagrangian advection does not conserve mass (by 0.3 % in 1000 steps of a
 * towering cumulus, 1 % in 200 of a stratocumulus's sharp inversion): the water it gained or
 * lost is given back to the vapour in proportion (a global fixer in the manner of Priestley
 * 1993), so the budget closes; the factor is returned (to every thread) for the microphysics
 * to apply (atmos__sim_micro), which saves a pass. The new velocity is swapped in by one thread
 * during the microphysics, which does not use it (atmos__sim_advected_velocity): one barrier
 * fewer. */
double atmos__sim_advect(atmos_sim *s, double dt)
{
    const int nz = s->nz;
    const float c = (float)(dt / s->dx); /* the departure points in single precision (sim_trace.c) */
    SIM_FOR
    for (int k = 0; k < nz; k++) centres(s, k);
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k <= nz; k++) {
        velocity(s, k, c);
        if (k < nz) scalars(s, k, c);
    }
    atmos__sim_sync(s);
    atmos__sim_maccormack(s);
    /* the sums level by level, in order (as one serial pass would add them); every thread */
    double w0 = 0, w1 = 0, v1 = 0;
    const double *p = s->part;
    const size_t m = (size_t)nz + 1;
    for (int k = 0; k < nz; k++) { /* water's mass: each level's by its density (anelastic) */
        const double r = s->rho_c[k];
        w0 += r * (p[m + k] + p[k]);
        w1 += r * (p[3 * m + k] + p[2 * m + k]);
        v1 += r * p[2 * m + k];
    }
    return v1 > 0 ? (double)(float)(1.0 + (w0 - w1) / v1) : 1.0;
}
