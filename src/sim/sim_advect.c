/* Semi-Lagrangian advection (Stam 1999; Staniforth & Cote 1991): every value is what arrives
 * from its departure point, sampled trilinearly (monotone: no new extrema). Scalars share one
 * departure point per cell found with a midpoint (second-order) trace; each velocity component
 * is traced from its own face with the velocity there. Positions are in cell units; x and y
 * wrap, z clamps to the grid. */
#include "sim/sim_internal.h"

#include <math.h>

/* Trilinear sample of a field of nz_f levels at (x, y, z) in its own index space. */
static inline float sample(const atmos_sim *s, const float *f, int nz_f, double x, double y, double z)
{
    const int nx = s->nx, ny = s->ny;
    if (z < 0) z = 0;
    if (z > nz_f - 1) z = nz_f - 1;
    const double fx0 = floor(x), fy0 = floor(y), fz0 = floor(z);
    const float ax = (float)(x - fx0), ay = (float)(y - fy0), az = (float)(z - fz0);
    int i0 = (int)fx0 % nx, j0 = (int)fy0 % ny, k0 = (int)fz0;
    if (i0 < 0) i0 += nx;
    if (j0 < 0) j0 += ny;
    const int i1 = i0 + 1 == nx ? 0 : i0 + 1, j1 = j0 + 1 == ny ? 0 : j0 + 1, k1 = k0 + 1 < nz_f ? k0 + 1 : k0;
    const size_t l0 = (size_t)k0 * nx * ny, l1 = (size_t)k1 * nx * ny, r0 = (size_t)j0 * nx, r1 = (size_t)j1 * nx;
    const float c00 = f[l0 + r0 + i0] + ax * (f[l0 + r0 + i1] - f[l0 + r0 + i0]);
    const float c01 = f[l0 + r1 + i0] + ax * (f[l0 + r1 + i1] - f[l0 + r1 + i0]);
    const float c10 = f[l1 + r0 + i0] + ax * (f[l1 + r0 + i1] - f[l1 + r0 + i0]);
    const float c11 = f[l1 + r1 + i0] + ax * (f[l1 + r1 + i1] - f[l1 + r1 + i0]);
    const float c0 = c00 + ay * (c01 - c00), c1 = c10 + ay * (c11 - c10);
    return c0 + az * (c1 - c0);
}

/* The velocity (cells per second times dx) at a point given in cell-centre index space. */
static inline void velocity(const atmos_sim *s, double x, double y, double z, double v[3])
{
    v[0] = sample(s, s->u, s->nz, x + 0.5, y, z);
    v[1] = sample(s, s->v, s->nz, x, y + 0.5, z);
    v[2] = sample(s, s->w, s->nz + 1, x, y, z + 0.5);
}

static void advect_scalars(atmos_sim *s, double dt)
{
    const int nx = s->nx, ny = s->ny;
    const double c = dt / s->dx;
    const float *src[4] = {s->th, s->qv, s->qc, s->qr};
    float *dst[4] = {s->s[0], s->s[1], s->s[2], s->s[3]};
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (int k = 0; k < s->nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const size_t n = sim_idx(s, i, j, k);
                const double uc = 0.5 * (s->u[n] + s->u[sim_idx(s, i + 1 == nx ? 0 : i + 1, j, k)]);
                const double vc = 0.5 * (s->v[n] + s->v[sim_idx(s, i, j + 1 == ny ? 0 : j + 1, k)]);
                const double wc = 0.5 * (s->w[n] + s->w[n + (size_t)nx * ny]);
                double v[3];
                velocity(s, i - 0.5 * c * uc, j - 0.5 * c * vc, k - 0.5 * c * wc, v);
                const double x = i - c * v[0], y = j - c * v[1], z = k - c * v[2];
                for (int f = 0; f < 4; f++) dst[f][n] = sample(s, src[f], s->nz, x, y, z);
            }
    float *t;
    t = s->th, s->th = s->s[0], s->s[0] = t;
    t = s->qv, s->qv = s->s[1], s->s[1] = t;
    t = s->qc, s->qc = s->s[2], s->s[2] = t;
    t = s->qr, s->qr = s->s[3], s->s[3] = t;
}

/* The new velocity into s[4..6] from the old one (each face traced from itself: in a field's
 * own index space the departure point is its index minus dt v / dx). */
static void advect_velocity(atmos_sim *s, double dt)
{
    const int nx = s->nx, ny = s->ny, nz = s->nz;
    const double c = dt / s->dx;
    float *nu = s->s[4], *nv = s->s[5], *nw = s->s[6];
#pragma omp parallel for schedule(static) num_threads(s->threads)
    for (int k = 0; k <= nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const size_t n = sim_idx(s, i, j, k);
                double v[3];
                if (k < nz) { /* u on the face x = i - 1/2, v on y = j - 1/2 */
                    velocity(s, i - 0.5, j, k, v);
                    nu[n] = sample(s, s->u, nz, i - c * s->u[n], j - c * v[1], k - c * v[2]);
                    velocity(s, i, j - 0.5, k, v);
                    nv[n] = sample(s, s->v, nz, i - c * v[0], j - c * s->v[n], k - c * v[2]);
                }
                if (k == 0 || k == nz) {
                    nw[n] = 0;
                } else { /* w on the face z = k - 1/2 */
                    velocity(s, i, j, k - 0.5, v);
                    nw[n] = sample(s, s->w, nz + 1, i - c * v[0], j - c * v[1], k - c * s->w[n]);
                }
            }
}

/* Sum of q_v + q_c + q_r (and of q_v alone), level by level in order: the same for any
 * thread count. */
static double total_water(const atmos_sim *s, double *vapour)
{
    const size_t lev = (size_t)s->nx * s->ny;
    double t = 0, v = 0;
    for (int k = 0; k < s->nz; k++) {
        double tl = 0, vl = 0;
        for (size_t n = k * lev; n < (k + 1) * lev; n++) {
            vl += s->qv[n];
            tl += (double)s->qc[n] + s->qr[n];
        }
        t += tl + vl, v += vl;
    }
    *vapour = v;
    return t;
}

void atmos__sim_advect(atmos_sim *s, double dt)
{
    double v0, v1;
    const double w0 = total_water(s, &v0);
    advect_velocity(s, dt);
    advect_scalars(s, dt); /* with the old velocity, still in s->u, s->v, s->w */
    /* Semi-Lagrangian advection does not conserve mass (by 0.3 % in 1000 steps of a
     * towering cumulus, 1 % in 200 of a stratocumulus's sharp inversion): the water it
     * gained or lost is given back to the vapour in proportion (a global fixer in the manner
     * of Priestley 1993), so the budget closes. */
    const double w1 = total_water(s, &v1);
    if (v1 > 0) {
        const float f = (float)(1.0 + (w0 - w1) / v1);
        const size_t n = s->n;
        float *q = s->qv;
#pragma omp parallel for schedule(static) num_threads(s->threads)
        for (size_t m = 0; m < n; m++) q[m] *= f;
    }
    float *t;
    t = s->u, s->u = s->s[4], s->s[4] = t;
    t = s->v, s->v = s->s[5], s->s[5] = t;
    t = s->w, s->w = s->s[6], s->s[6] = t;
}
