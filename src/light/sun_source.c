/* The source of the diffuse field: the sunlight a forward-lobe model drops (lfield.h,
 * atmos__lfield_sun_source).
 *
 * Riley et al. 2004's light buffer keeps, of the light scattered in a slab, the share F_{n+1}
 * that goes into the forward hemisphere (Eq. 24/25: I <- I (T + (1 - T) alpha F)); per unit
 * length the beam loses sig_t - sig_s F, of which sig_a I is absorbed and sig_s (1 - F) I is
 * scattered sideways and back. That light does not leave a conservative cloud: it is the
 * source of the diffuse field. The beam is marched here on the field's own grid, from each
 * cell's centre back toward the sun in steps of h/2 (the cell of each step's midpoint), then
 * integrated forward so that the scattering count n grows from where the light entered.
 * The dropped light goes back (the forward model keeps the forward hemisphere): its first
 * moment, Q times the mean cosine of the dropped part along the beam, tells the diffusion so. */
#include "light/lfield.h"

#include <math.h>
#include <stdlib.h>

#define SRC_STEP 0.5 /* march step, cells */

/* The cells of the steps from cell (i, j, k)'s centre back toward the sun (direction -lt)
 * until the beam leaves the grid through a non-periodic face, nearest first; at most cap.
 * Returns the count. */
static int beam_cells(const atmos__lmedium *m, const double lt[3], int i, int j, int k, size_t *out, int cap)
{
    const double p0[3] = {i + 0.5, j + 0.5, k + 0.5};
    int cnt = 0;
    for (int s = 0; s < cap; s++) {
        const double t = (s + 0.5) * SRC_STEP;
        int idx[3];
        int inside = 1;
        for (int a = 0; a < 3 && inside; a++) {
            double x = p0[a] - t * lt[a];
            int ix = (int)floor(x);
            if (m->periodic[a]) {
                ix %= m->c[a];
                if (ix < 0) ix += m->c[a];
            } else if (ix < 0 || ix >= m->c[a]) {
                inside = 0;
            }
            idx[a] = ix;
        }
        if (!inside) break;
        out[cnt++] = ((size_t)idx[2] * m->c[1] + idx[1]) * m->c[0] + idx[0];
    }
    return cnt;
}

void atmos__lfield_sun_source(const atmos__lmedium *m, const double lt[3], const double *sun, atmos__lkeep_fn keep,
                              const void *user, float *Q, float *Q1, float *Ibeam, int threads)
{
    const int n = m->n;
    const size_t cells = atmos__lmedium_cells(m);
    /* a beam never needs more steps than twice the grid's diagonal in cells (periodic axes:
     * a few times around) */
    const int cap = (int)(4.0 * (m->c[0] + m->c[1] + m->c[2]) / SRC_STEP) + 8;
    const double ds = SRC_STEP * m->h;
#pragma omp parallel num_threads(threads)
    {
        size_t *path = malloc(sizeof(size_t) * (size_t)cap);
#pragma omp for schedule(dynamic, 64)
        for (long long ci = 0; ci < (long long)cells; ci++) {
            const size_t cell = (size_t)ci;
            const int i = (int)(cell % (size_t)m->c[0]), j = (int)(cell / (size_t)m->c[0] % (size_t)m->c[1]),
                      k = (int)(cell / ((size_t)m->c[0] * m->c[1]));
            const int cnt = path ? beam_cells(m, lt, i, j, k, path, cap) : 0;
            double I[ATMOS_MAX_WAVELENGTHS], nsc = 0;
            for (int w = 0; w < n; w++) I[w] = 1.0;
            /* from the entry to the cell's centre (step s covers s..s + 1 steps behind it) */
            for (int s = cnt - 1; s >= 0; s--) {
                const size_t q = path[s];
                const double len = ds;
                double dn = 0;
                for (int w = 0; w < n; w++) {
                    const double st = m->sig_t[q * n + w], ss = m->sig_s[q * n + w];
                    float mu;
                    const double F = ss > 0 ? keep(user, q, w, (float)nsc + 1.0f, &mu) : 0.0;
                    I[w] *= exp(-(st - ss * F) * len);
                    dn += ss * len;
                }
                nsc += dn / n;
            }
            for (int w = 0; w < n; w++) {
                const double ss = m->sig_s[cell * n + w];
                float mu = 0.0f;
                const double F = ss > 0 ? keep(user, cell, w, (float)nsc + 1.0f, &mu) : 0.0;
                const double q = ss * (1.0 - F) * I[w] * sun[w];
                Q[cell * n + w] = (float)q;
                if (Q1)
                    for (int a = 0; a < 3; a++) Q1[(cell * n + w) * 3 + a] = (float)(q * mu * lt[a]);
                if (Ibeam) Ibeam[cell * n + w] = (float)(I[w] * sun[w]);
            }
        }
        free(path);
    }
}

