/* Forces and sources of one step: buoyancy from the potential temperature and vapour
 * excesses and the water loading, B = g (theta'/theta0 + 0.61 q_v' - q_c - q_r) (the
 * Boussinesq form, kept in the anelastic model; e.g. Klemp & Wilhelmson 1978, Eq. 2.1),
 * averaged onto the w faces; a Rayleigh sponge under
 * the lid; the surface heat and moisture fluxes with seeded noise; cloud-top radiative cooling. */
#include "sim/sim_internal.h"
#include "core/rng.h"

#include <math.h>

static double hash01(uint64_t seed, uint64_t a, uint64_t b)
{
    return atmos__u01(atmos__mix64(atmos__mix64(seed ^ 0x2545f491ULL) + a * 0x9e3779b97f4a7c15ULL + b));
}

/* Buoyancy on the w faces of row j from the cell centres' (b into s[7] at the row's cells). */
static void buoyancy(atmos_sim *s, double dt, int j)
{
    const int nx = s->nx;
    const size_t lev = (size_t)nx * s->ny;
    float *b = s->s[7];
    for (int k = 0; k < s->nz; k++) {
        const float th0 = (float)s->th0[k], qv0 = (float)s->qv0[k], g = (float)SIM_G;
        const size_t r = sim_idx(s, 0, j, k);
        for (size_t n = r; n < r + nx; n++)
            b[n] = g * ((s->th[n] - th0) / th0 + 0.61f * (s->qv[n] - qv0) - s->qc[n] - s->qr[n]);
    }
    const float h = (float)(0.5 * dt);
    for (int k = 1; k < s->nz; k++) {
        const size_t r = sim_idx(s, 0, j, k);
        for (size_t n = r; n < r + nx; n++) s->w[n] += h * (b[n] + b[n - lev]);
    }
}

/* Rayleigh damping towards the environment in the top quarter (at most 3 km) of the domain,
 * rate sin^2 rising to 1/(100 s) at the lid; implicit, so any step is stable. Row j. */
static void sponge(atmos_sim *s, double dt, int j)
{
    const double top = s->nz * s->dx, depth = fmin(0.25 * top, 3000.0), zs = top - depth;
    const int nx = s->nx;
    for (int k = 0; k <= s->nz; k++) {
        const double zf = k * s->dx, zc = (k + 0.5) * s->dx;
        if (zf <= zs && zc <= zs) continue; /* both factors are 1 */
        const double sf = sin(0.5 * ATMOS_PI * fmax(0.0, (zf - zs) / depth));
        const double sc = sin(0.5 * ATMOS_PI * fmin(1.0, fmax(0.0, (zc - zs) / depth)));
        const float df = (float)(1.0 / (1.0 + dt * sf * sf / 100.0)), dc = (float)(1.0 / (1.0 + dt * sc * sc / 100.0));
        const size_t r = sim_idx(s, 0, j, k);
        if (df < 1.0f)
            for (size_t n = r; n < r + nx; n++) s->w[n] *= df;
        if (k < s->nz && dc < 1.0f) {
            const float th0 = (float)s->th0[k], ue = (float)s->ue[k];
            for (size_t n = r; n < r + nx; n++) {
                s->th[n] = th0 + (s->th[n] - th0) * dc;
                s->u[n] = ue + (s->u[n] - ue) * dc;
                s->v[n] *= dc;
            }
        }
    }
}

/* Surface fluxes into the lowest cells of row j, each cell's times 1 + noise (seeded by step
 * and cell); returns the water added (for the budget), cell by cell. */
static double surface(atmos_sim *s, double dt, int j)
{
    const sim_env *e = &s->env;
    if (e->shf == 0 && e->lhf == 0) return 0.0;
    const double f = dt / s->dx;
    double added = 0;
    for (int i = 0; i < s->nx; i++) {
        const size_t n = sim_idx(s, i, j, 0);
        const double p = 1.0 + e->flux_noise * (2.0 * hash01(s->seed, (uint64_t)s->steps, n) - 1.0);
        s->th[n] += (float)(e->shf * p * f);
        const float dq = (float)(e->lhf * p * f);
        s->qv[n] += dq;
        added += dq;
    }
    return added;
}

/* Radiative cooling F / (rho c_p dx) of the cloudy cells under clear air (cloud top), row j. */
static void top_cooling(atmos_sim *s, double dt, int j)
{
    if (!(s->env.top_cooling > 0)) return;
    const size_t lev = (size_t)s->nx * s->ny;
    for (int k = 0; k < s->nz - 1; k++) {
        const float d = (float)(dt * s->env.top_cooling / (s->rho0[k] * SIM_CP * s->dx) / s->pi0[k]);
        const size_t r = sim_idx(s, 0, j, k);
        for (size_t n = r; n < r + s->nx; n++)
            if (s->qc[n] > 1e-5f && s->qc[n + lev] <= 1e-5f) s->th[n] -= d;
    }
}

double atmos__sim_forces_row(atmos_sim *s, double dt, int j)
{
    const double added = surface(s, dt, j);
    top_cooling(s, dt, j);
    buoyancy(s, dt, j);
    sponge(s, dt, j);
    return added;
}
