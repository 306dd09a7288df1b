/* MacCormack's correction of the scalars' semi-Lagrangian advection (Selle, Fedkiw, Kim, Liu &
 * Rossignac 2008, "An unconditionally stable MacCormack method"): the forward step's result
 * phi^ is carried back along the flow to phi~, and half the difference between the old field
 * and phi~ (the forward step's error, to first order) is added, phi^ + (phi - phi~) / 2,
 * limited to the range of the eight old values the forward sample interpolated between, so that
 * no new extremum appears. Second order in space where the field is smooth: the trilinear
 * interpolation's smoothing, which the semi-Lagrangian step applies every step, mostly goes,
 * and with it the grid-scale blur of the clouds' edges. */
#include "sim/sim_internal.h"

#include <string.h>

#define MAC_CLONES ATMOS_CLONES

typedef float v4f __attribute__((vector_size(16)));
typedef int v4i __attribute__((vector_size(16)));
typedef float v8f __attribute__((vector_size(32)));
typedef int v8i __attribute__((vector_size(32)));

static inline v4f ld4(const float *p)
{
    v4f v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* Vectors of two cells' four fields (8 floats) pass through macros, not functions: a function
 * taking or returning one has a different calling convention in the AVX2 build. PAIR: the
 * cell at p and the one d floats on (its neighbour along x); PICK8: the lanes of a where m is
 * set, else b's (bitwise, so that NaN-free fields give exactly their least and greatest). */
#define PAIR(v, p, d)                                                                                              \
    do {                                                                                                           \
        if ((d) == 4) {                                                                                            \
            memcpy(&(v), (p), 8 * sizeof(float));                                                                  \
        } else {                                                                                                   \
            memcpy(&(v), (p), 4 * sizeof(float));                                                                  \
            memcpy((float *)&(v) + 4, (p) + (d), 4 * sizeof(float));                                               \
        }                                                                                                          \
    } while (0)
#define PICK8(m, a, b) ((v8f)(((v8i)(m) & (v8i)(a)) | (~(v8i)(m) & (v8i)(b))))
#define MIN8(a, b) PICK8((a) < (b), a, b)
#define MAX8(a, b) PICK8((a) > (b), a, b)

static inline v4f pick4(v4i m, v4f a, v4f b)
{
    return (v4f)((m & (v4i)a) | (~m & (v4i)b));
}

/* The four packed fields' old values at the eight cells whose corner the departure point
 * (x, y, z) interpolated from: their least and greatest (pairs of cells along x loaded
 * together, reduced as a tree). */
static inline void range(const atmos_sim *s, const float *sc4, float x, float y, float z, v4f *lo, v4f *hi)
{
    const int nx = s->nx, ny = s->ny;
    const float top = (float)(s->nz - 1);
    z = z < 0 ? 0 : z > top ? top : z;
    const int i0 = sim_wrap(sim_ifloor(x), nx), j0 = sim_wrap(sim_ifloor(y), ny), k0 = sim_ifloor(z);
    const size_t di = 4 * (size_t)(i0 + 1 == nx ? -i0 : 1);
    const size_t r00 = 4 * (((size_t)k0 * ny + j0) * nx + i0);
    const size_t dj = 4 * (size_t)nx * (size_t)(j0 + 1 == ny ? -j0 : 1);
    const size_t dk = k0 + 1 < s->nz ? 4 * (size_t)nx * ny : 0;
    v8f q0, q1, q2, q3;
    PAIR(q0, sc4 + r00, di);
    PAIR(q1, sc4 + r00 + dj, di);
    PAIR(q2, sc4 + r00 + dk, di);
    PAIR(q3, sc4 + r00 + dj + dk, di);
    const v8f m01 = MIN8(q0, q1), m23 = MIN8(q2, q3), n01 = MAX8(q0, q1), n23 = MAX8(q2, q3);
    const v8f a = MIN8(m01, m23), b = MAX8(n01, n23);
    const v4f al = {a[0], a[1], a[2], a[3]}, ah = {a[4], a[5], a[6], a[7]};
    const v4f bl = {b[0], b[1], b[2], b[3]}, bh = {b[4], b[5], b[6], b[7]};
    *lo = pick4(al < ah, al, ah), *hi = pick4(bl > bh, bl, bh);
}

/* Level k: carried back along the flow (the midpoint rule forward from each cell), corrected,
 * limited, into the fields. */
MAC_CLONES static void level(atmos_sim *s, int k)
{
    const int nx = s->nx, ny = s->ny;
    const size_t lev = (size_t)nx * ny;
    float *dst[4] = {s->th, s->qv, s->qc, s->qr};
    const float *sc4 = s->pack + 4 * s->n, *hat4 = s->pack + 8 * s->n;
    float x[ATMOS_SIM_MAX_GRID], y[ATMOS_SIM_MAX_GRID], z[ATMOS_SIM_MAX_GRID];
    float q[4 * ATMOS_SIM_MAX_GRID];
    const float fk = (float)k;
    for (int j = 0; j < ny; j++) {
        const size_t r = sim_idx(s, 0, j, k);
        const float fj = (float)j;
        const float *xd = s->s[0] + r, *yd = s->s[1] + r, *zd = s->s[2] + r;
        for (int i = 0; i < nx; i++) /* as far forward as the departure point lies back */
            x[i] = 2.0f * (float)i - xd[i], y[i] = 2.0f * fj - yd[i], z[i] = 2.0f * fk - zd[i];
        atmos__sim_sample4_row(s, hat4, s->nz, x, y, z, q, nx);
        for (int i = 0; i < nx; i++) {
            v4f lo, hi;
            range(s, sc4, xd[i], yd[i], zd[i], &lo, &hi);
            v4f v = ld4(hat4 + 4 * (r + i)) + 0.5f * (ld4(sc4 + 4 * (r + i)) - ld4(q + 4 * i));
            v = pick4(v < lo, lo, v);
            v = pick4(v > hi, hi, v);
            for (int f = 0; f < 4; f++) dst[f][r + i] = v[f];
        }
    }
    double vl = 0, tl = 0;
    for (size_t n = k * lev; n < (k + 1) * lev; n++) {
        vl += dst[1][n];
        tl += (double)dst[2][n] + dst[3][n];
    }
    s->part[2 * (s->nz + 1) + k] = vl, s->part[3 * (s->nz + 1) + k] = tl;
}

void atmos__sim_maccormack(atmos_sim *s)
{
    SIM_FOR
    for (int k = 0; k < s->nz; k++) level(s, k);
    atmos__sim_sync(s);
}
