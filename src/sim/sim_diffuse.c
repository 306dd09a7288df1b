/* Horizontal sub-grid mixing (the preset's k_eddy, 0 = none): one explicit step of
 * d f / dt = K (d^2 f / dx^2 + d^2 f / dy^2) for theta, vapour, cloud water and the three
 * velocity components, each on its own staggered points, x and y wrapping. A coarse grid
 * resolves convection only at scales of several cells; without mixing the smallest resolved
 * scale grows fastest and a shallow layer (the stratocumulus preset's mixed layer is 8 cells
 * deep at the default grid) breaks into noise one cell wide. The mixing is horizontal only:
 * the same K across the inversion would mix the warm dry air above into the deck and
 * evaporate it within minutes. K is k_eddy at 100 m cells and grows with the cell as
 * dx^(4/3) (Richardson's law for the eddy diffusivity of eddies of size dx), so that the
 * deck looks alike at the grids from 32 to 64. Stable for K dt / dx^2 <= 1/4 (the
 * coefficient is capped below that); each level's sum is kept up to rounding (every flux
 * leaves one cell for another). */
#include "sim/sim_internal.h"

#include <math.h>

/* Level k of field f into d. */
static void level(const atmos_sim *s, const float *restrict f, float *restrict d, int k, float a)
{
    const int nx = s->nx, ny = s->ny;
    for (int j = 0; j < ny; j++) {
        const size_t r = sim_idx(s, 0, j, k), rm = sim_idx(s, 0, j ? j - 1 : ny - 1, k);
        const size_t rp = sim_idx(s, 0, j + 1 == ny ? 0 : j + 1, k);
        for (int i = 0; i < nx; i++) {
            const int im = i ? i - 1 : nx - 1, ip = i + 1 == nx ? 0 : i + 1;
            const float c = f[r + i];
            d[r + i] = c + a * ((f[r + im] + f[r + ip]) + (f[rm + i] + f[rp + i]) - 4.0f * c);
        }
    }
}

/* The mixed fields into the scratch arrays s[1..6], then swapped in by one thread between
 * barriers (s[0] is the projection's FFT array and is left alone). */
void atmos__sim_diffuse(atmos_sim *s, double dt)
{
    const double K = s->env.k_eddy;
    if (!(K > 0)) return;
    const int nz = s->nz;
    const double a = fmin(K * pow(s->dx / 100.0, 4.0 / 3.0) * dt / (s->dx * s->dx), 0.2);
    float **const src[6] = {&s->th, &s->qv, &s->qc, &s->u, &s->v, &s->w};
    SIM_FOR
    for (int k = 0; k <= nz; k++)
        for (int f = 0; f < 6; f++)
            if (k < nz || f == 5) level(s, *src[f], s->s[1 + f], k, (float)a); /* w: nz + 1 levels of faces */
    atmos__sim_sync(s);
#pragma omp master
    for (int f = 0; f < 6; f++) {
        float *t = *src[f];
        *src[f] = s->s[1 + f], s->s[1 + f] = t;
    }
    atmos__sim_sync(s);
}
