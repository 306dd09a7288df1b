/* Semi-Lagrangian advection (Stam 1999; Staniforth & Cote 1991): every value is what arrives
 * from its departure point, sampled trilinearly (monotone: no new extrema). Scalars share one
 * departure point per cell found with a midpoint (second-order) trace; each velocity component
 * is traced from its own face with the velocity there. Positions are in cell units; x and y
 * wrap, z clamps to the grid. */
#include "sim/sim_internal.h"

#include <math.h>
#include <string.h>

/* The eight corners and weights of a trilinear sample at (x, y, z) in the index space of a
 * field of nz_f levels: set up once, evaluated for any field on that grid. */
typedef struct {
    size_t c[4];      /* offsets of the corners (i0, j, k) of rows j0/j1 at levels k0/k1 */
    int i0, i1;
    float ax, ay, az;
} tri;

static inline int wrap(int i, int n)
{
    if ((unsigned)i >= (unsigned)n) {
        i %= n;
        if (i < 0) i += n;
    }
    return i;
}

/* floor() without the library call (the baseline x86-64 target has no rounding instruction);
 * positions stay far inside int's range. */
static inline int ifloor(double x)
{
    const int i = (int)x;
    return i - (x < i);
}

static inline void tri_setup(const atmos_sim *s, int nz_f, double x, double y, double z, tri *t)
{
    const int nx = s->nx, ny = s->ny;
    if (z < 0) z = 0;
    if (z > nz_f - 1) z = nz_f - 1;
    const int fx0 = ifloor(x), fy0 = ifloor(y), fz0 = ifloor(z);
    t->ax = (float)(x - fx0), t->ay = (float)(y - fy0), t->az = (float)(z - fz0);
    const int i0 = wrap(fx0, nx), j0 = wrap(fy0, ny), k0 = fz0;
    const int j1 = j0 + 1 == ny ? 0 : j0 + 1, k1 = k0 + 1 < nz_f ? k0 + 1 : k0;
    t->i0 = i0, t->i1 = i0 + 1 == nx ? 0 : i0 + 1;
    const size_t l0 = (size_t)k0 * nx * ny, l1 = (size_t)k1 * nx * ny;
    t->c[0] = l0 + (size_t)j0 * nx, t->c[1] = l0 + (size_t)j1 * nx;
    t->c[2] = l1 + (size_t)j0 * nx, t->c[3] = l1 + (size_t)j1 * nx;
}

static inline float tri_eval(const float *f, const tri *t)
{
    const int i0 = t->i0, i1 = t->i1;
    const float c00 = f[t->c[0] + i0] + t->ax * (f[t->c[0] + i1] - f[t->c[0] + i0]);
    const float c01 = f[t->c[1] + i0] + t->ax * (f[t->c[1] + i1] - f[t->c[1] + i0]);
    const float c10 = f[t->c[2] + i0] + t->ax * (f[t->c[2] + i1] - f[t->c[2] + i0]);
    const float c11 = f[t->c[3] + i0] + t->ax * (f[t->c[3] + i1] - f[t->c[3] + i0]);
    const float c0 = c00 + t->ay * (c01 - c00), c1 = c10 + t->ay * (c11 - c10);
    return c0 + t->az * (c1 - c0);
}

/* Four fields packed per cell (AoS, 16 bytes a cell) sampled at once: the same arithmetic as
 * tri_eval on each lane, one 4-wide load per corner. */
typedef float v4f __attribute__((vector_size(16)));

static inline v4f ld4(const float *p)
{
    v4f v;
    memcpy(&v, p, sizeof v);
    return v;
}

static inline v4f tri_eval4(const float *f4, const tri *t)
{
    const size_t i0 = 4 * (size_t)t->i0, i1 = 4 * (size_t)t->i1;
    v4f c[4];
    for (int r = 0; r < 4; r++) {
        const v4f a = ld4(f4 + 4 * t->c[r] + i0), b = ld4(f4 + 4 * t->c[r] + i1);
        c[r] = a + t->ax * (b - a);
    }
    const v4f c0 = c[0] + t->ay * (c[1] - c[0]), c1 = c[2] + t->ay * (c[3] - c[2]);
    return c0 + t->az * (c1 - c0);
}

static inline float sample(const atmos_sim *s, const float *f, int nz_f, double x, double y, double z)
{
    tri t;
    tri_setup(s, nz_f, x, y, z, &t);
    return tri_eval(f, &t);
}

/* Level k packed for the scalars' trace (s->pack): the velocity at the cell centres (u, v, w, 0)
 * and the scalars (theta, q_v, q_c, q_r), 4 floats a cell each; and the level's water before
 * the advection: q_v into part[k], q_c + q_r into part[nz + 1 + k]. */
static void centres(atmos_sim *s, int k)
{
    const int nx = s->nx, ny = s->ny;
    const size_t lev = (size_t)nx * ny;
    float *vel4 = s->pack, *sc4 = s->pack + 4 * s->n;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            const size_t n = sim_idx(s, i, j, k);
            float *p = vel4 + 4 * n, *q = sc4 + 4 * n;
            p[0] = 0.5f * (s->u[n] + s->u[sim_idx(s, i + 1 == nx ? 0 : i + 1, j, k)]);
            p[1] = 0.5f * (s->v[n] + s->v[sim_idx(s, i, j + 1 == ny ? 0 : j + 1, k)]);
            p[2] = 0.5f * (s->w[n] + s->w[n + lev]);
            p[3] = 0;
            q[0] = s->th[n], q[1] = s->qv[n], q[2] = s->qc[n], q[3] = s->qr[n];
        }
    double vl = 0, tl = 0;
    for (size_t n = k * lev; n < (k + 1) * lev; n++) {
        vl += s->qv[n];
        tl += (double)s->qc[n] + s->qr[n];
    }
    s->part[k] = vl, s->part[s->nz + 1 + k] = tl;
}

/* Level k of the scalars into s[0..3], each cell's departure point traced once (midpoint rule
 * on the cell-centred velocity) for all four; the level's new water into part[2 (nz + 1) + k]
 * (vapour) and part[3 (nz + 1) + k] (the rest). */
static void scalars(atmos_sim *s, int k, double c)
{
    const int nx = s->nx, ny = s->ny;
    const size_t lev = (size_t)nx * ny;
    float *dst[4] = {s->th, s->qv, s->qc, s->qr}; /* in place: the sources are the packed copies */
    const float *vel4 = s->pack, *sc4 = s->pack + 4 * s->n;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            const size_t n = sim_idx(s, i, j, k);
            const float *p = vel4 + 4 * n;
            tri t;
            tri_setup(s, s->nz, i - 0.5 * c * p[0], j - 0.5 * c * p[1], k - 0.5 * c * p[2], &t);
            const v4f vm = tri_eval4(vel4, &t);
            tri_setup(s, s->nz, i - c * (double)vm[0], j - c * (double)vm[1], k - c * (double)vm[2], &t);
            const v4f q = tri_eval4(sc4, &t);
            dst[0][n] = q[0], dst[1][n] = q[1], dst[2][n] = q[2], dst[3][n] = q[3];
        }
    double vl = 0, tl = 0;
    for (size_t n = k * lev; n < (k + 1) * lev; n++) {
        vl += dst[1][n];
        tl += (double)dst[2][n] + dst[3][n];
    }
    s->part[2 * (s->nz + 1) + k] = vl, s->part[3 * (s->nz + 1) + k] = tl;
}

/* Level k of the new velocity into s[4..6] from the old one (each face traced from itself with
 * its own component and the other two averaged from the four nearest faces; in a field's own
 * index space the departure point is its index minus dt v / dx); k = nz is the lid's w. */
static void velocity(atmos_sim *s, int k, double c)
{
    const int nx = s->nx, ny = s->ny, nz = s->nz;
    const size_t lev = (size_t)nx * ny;
    const float *u = s->u, *v = s->v, *w = s->w;
    float *nu = s->s[4], *nv = s->s[5], *nw = s->s[6];
    for (int j = 0; j < ny; j++) {
        const size_t r = (size_t)k * lev + (size_t)j * nx;
        const size_t rm = (size_t)k * lev + (size_t)(j ? j - 1 : ny - 1) * nx;
        const size_t rp = (size_t)k * lev + (size_t)(j + 1 == ny ? 0 : j + 1) * nx;
        for (int i = 0; i < nx; i++) {
            const int im = i ? i - 1 : nx - 1, ip = i + 1 == nx ? 0 : i + 1;
            if (k < nz) { /* u on the face x = i - 1/2, v on y = j - 1/2 */
                const double vu = 0.25 * (v[r + im] + v[r + i] + v[rp + im] + v[rp + i]);
                const double wu = 0.25 * (w[r + im] + w[r + i] + w[r + lev + im] + w[r + lev + i]);
                nu[r + i] = sample(s, u, nz, i - c * u[r + i], j - c * vu, k - c * wu);
                const double uv = 0.25 * (u[rm + i] + u[rm + ip] + u[r + i] + u[r + ip]);
                const double wv = 0.25 * (w[rm + i] + w[r + i] + w[rm + lev + i] + w[r + lev + i]);
                nv[r + i] = sample(s, v, nz, i - c * uv, j - c * v[r + i], k - c * wv);
            }
            if (k == 0 || k == nz) {
                nw[r + i] = 0;
            } else { /* w on the face z = k - 1/2 */
                const double uw = 0.25 * (u[r - lev + i] + u[r - lev + ip] + u[r + i] + u[r + ip]);
                const double vw = 0.25 * (v[r - lev + i] + v[rp - lev + i] + v[r + i] + v[rp + i]);
                nw[r + i] = sample(s, w, nz + 1, i - c * uw, j - c * vw, k - c * w[r + i]);
            }
        }
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
    const double c = dt / s->dx;
    SIM_FOR
    for (int k = 0; k < nz; k++) centres(s, k);
    atmos__sim_sync(s);
    SIM_FOR
    for (int k = 0; k <= nz; k++) {
        velocity(s, k, c);
        if (k < nz) scalars(s, k, c);
    }
    atmos__sim_sync(s);
    /* the sums level by level, in order (as one serial pass would add them); every thread */
    double w0 = 0, w1 = 0, v1 = 0;
    const double *p = s->part;
    const size_t m = (size_t)nz + 1;
    for (int k = 0; k < nz; k++) {
        w0 += p[m + k] + p[k];
        w1 += p[3 * m + k] + p[2 * m + k];
        v1 += p[2 * m + k];
    }
    return v1 > 0 ? (double)(float)(1.0 + (w0 - w1) / v1) : 1.0;
}
