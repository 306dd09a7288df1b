/* The first order of two populations in a delta-M scaled medium (docs/accuracy.md, "The cumulus in
 * front: where the RMSE is"). The full phase times the whole delta-M beam counts the forward
 * peak's light twice: delta-M keeps it in the beam and the phase's forward lobe sends it toward
 * the eye again. The share exp(-share_dm n) of the beam the peak has not turned (share_dm:
 * delta-M's part of the scattering, the 3-degree cut's left out; n the scattering depth from the
 * sun) scatters with the full phase, the rest with delta-M's scaled phase p* of degree 3 times
 * sigma_s* / sigma_s. The slice renderer's do field tabulates p* beside its Ams rows
 * (slice_do.c), the Nishita renderer evaluates it at each eye ray's angle (nishita_render.c). */
#include "render/dm_two_pop.h"

#include <math.h>

double atmos__dm_cut_share(const stables *t, int f, int w, int n)
{
    const double *g = t->grid[f];
    const float *A = t->ams[f];
    const size_t st = (size_t)t->no * n;
    double pc = 0, cut = 0, all = 0;
    for (int a = 0; a + 1 < t->ng[f]; a++)
        if (g[a] <= ATMOS_DM_CUT_DEG && g[a + 1] > ATMOS_DM_CUT_DEG) pc = A[a * st + w];
    for (int a = 0; a + 1 < t->ng[f]; a++) {
        const double p0 = A[a * st + w], p1 = A[(a + 1) * st + w];
        const double dm = cos(g[a] * ATMOS_DEG2RAD) - cos(g[a + 1] * ATMOS_DEG2RAD);
        all += 2 * ATMOS_PI * 0.5 * (p0 + p1) * dm;
        if (g[a + 1] <= ATMOS_DM_CUT_DEG) cut += 2 * ATMOS_PI * 0.5 * (p0 + p1 - 2 * pc) * dm;
    }
    return all > 0 && cut > 0 ? cut / all : 0;
}

/* The Legendre polynomials P_0..P_3 at mu. */
static void legendre3(double mu, double P[4])
{
    P[0] = 1, P[1] = mu, P[2] = 0.5 * (3 * mu * mu - 1), P[3] = 0.5 * (5 * mu * mu - 3) * mu;
}

void atmos__dm_moments3(const stables *t, int f, int w, int n, double chi[4])
{
    const int no = t->no, ng = t->ng[f];
    const double *g = t->grid[f];
    double P0[4], P1[4];
    for (int l = 0; l < 4; l++) chi[l] = 0;
    for (int a = 0; a + 1 < ng; a++) {
        const double m0 = cos(g[a] * ATMOS_DEG2RAD), m1 = cos(g[a + 1] * ATMOS_DEG2RAD);
        const double p0 = t->ams[f][(size_t)a * no * n + w], p1 = t->ams[f][(size_t)(a + 1) * no * n + w];
        legendre3(m0, P0), legendre3(m1, P1);
        for (int l = 0; l < 4; l++) chi[l] += 2 * ATMOS_PI * 0.5 * (p0 * P0[l] + p1 * P1[l]) * (m0 - m1);
    }
    for (int l = 3; l >= 0; l--) chi[l] = chi[0] > 0 ? chi[l] / chi[0] : l == 0;
}

double atmos__dm_phase3(const double chi[4], double sh, double mu)
{
    double P[4], v = 0;
    legendre3(mu, P);
    for (int l = 0; l < 4; l++) v += (2 * l + 1) / (4 * ATMOS_PI) * (chi[l] - sh) * P[l];
    return v > 0 ? v : 0;
}
