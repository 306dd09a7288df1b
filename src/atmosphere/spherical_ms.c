/* The production sky's scattering density of the higher orders with its angular dependence
 * (spherical.h): J_ms(r, mu_s, gamma, psi), the light of orders >= 2 scattered at a point
 * toward the eye, per unit scattering coefficient of each kind of particle and per unit
 * solar irradiance, so that the march adds sigma_R j_R + sigma_M j_M per step (docs/sky.md,
 * "The production sky").
 *
 * The density is the phase-weighted gather of the light arriving at the point,
 *   j_type(x, w) = int_sphere p_type(w . w') L(x, w') dw',
 * where L(x, w') is everything seen from x along w' but the sun's disk: the single
 * scattering along the ray, the higher orders along it, the lit ground at its end (a
 * Lambertian ground of the tables' uniform albedo lit by the sun and by E_sky). Summed over
 * the orders this is the fixed point J = G(L(J)) (Bruneton & Neyret 2008, Bruneton 2017's
 * scattering density, summed over orders instead of order by order). It is reached by
 * iteration from Hillaire's isotropic Psi_ms: iteration 1 gathers the field marched with
 * Psi_ms (the second order and the last scattering of every order exact in angle, the
 * orders >= 3 arriving as Psi makes them), iteration n the field marched with J of
 * iteration n - 1; each iteration shrinks the error of the incoming higher orders by the
 * share of light scattered again (f_ms, <= 0.3 here).
 *
 * Parametrization (sun-centred; J is smooth away from the sun and peaked toward it):
 *   rows   x_r = sqrt(h / top) (dense near the ground, where the aerosols are);
 *   mu_s   the sun's elevation e = (pi / 2) u |u|, the columns uniform in u from
 *          mu_s = -0.3 (17.5 degrees down: the sun is below the horizon of every point of
 *          the air) to the zenith, 40 of them: dense near the horizon (twilight; 0.1 to 1.6
 *          degrees apart within 6 degrees of it, 2.8 at the lowest) and 6.5 at the zenith.
 *          (The columns were 32, y|y| = mu_s uniform in y: 25.5 degrees apart at the zenith,
 *          so with a high sun a view node near the horizon, fixed in angle from the sun, saw
 *          the sky in one column and the ground in the next: J 8-17 % off between them there,
 *          tests/unit/test_sky_jsun.c.) Below the lowest column, that column times
 *          e^(-60 (-0.3 - mu_s)), a steep fade standing for the night's darkening;
 *   gamma  the angle between the view and the sun, gamma = pi (a x + b x^2 + c x^3) with
 *          the slope a = 0.3 at both ends (24 nodes 2.3 degrees apart at the sun and at the
 *          anti-sun, 10.6 between: with a low sun the anti-sun is at the horizon, where the
 *          gathered light jumps from the sky's to the ground's; 20 nodes in the quadratic
 *          mapping pi (a x + (1 - a) x^2), 16 degrees apart there, left the anti-solar horizon
 *          3 % too dark; 20 in the cubic one, 12.8 degrees apart between, made J's kinks
 *          between the aerial-perspective volume's node rays too large in twilight);
 *   psi    the azimuth of the view about the sun's direction, 0 on the zenith's side,
 *          x = (1 - cos psi) / 2 (the light is symmetric about the sun's vertical plane).
 * The gather integrates over the same sun-centred frame: gamma' = pi (a s + (1 - a) s^2), by
 * three 8-point Gauss-Legendre panels in s (the aureole of the incoming single scattering is
 * resolved, and a view's phase lobe far from the sun still meets nodes 9 degrees apart), psi'
 * by 16 midpoints over [0, pi], folded (the light is symmetric in psi'); a node whose cell
 * straddles the horizon takes the light beyond it at that part's centre, weighted by its
 * share of the cell (horizon_cell). The phase weights of each view node,
 * normalised so that a uniform field gathers exactly (energy), depend only on the two
 * grids and are computed once per build. The table holds the logarithm, interpolated
 * quadrilinearly (ATMOS__SPH_J_FLOOR; the look-up and the mappings are in
 * spherical_jlookup.c). Threads over (r, mu_s) nodes: the result does not depend on their
 * number. */
#include "atmosphere/spherical.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define JR ATMOS__SPH_J_R
#define JS ATMOS__SPH_J_MUS
#define JG ATMOS__SPH_J_G
#define JP ATMOS__SPH_J_P
#define GA ATMOS__SPH_J_GA
#define QG 24  /* the gather's gamma' nodes */
#define QP 16  /* its psi' nodes over [0, pi] */
#define QN (QG * QP)
#define JV (JG * JP)
#define JFLOOR ATMOS__SPH_J_FLOOR

/* ------------------------------------------------------------------ the gather's frame */
/* The direction of (gamma, psi) about the sun sun = (ss, ms, 0) at a point on the y axis:
 * cos g sun + sin g (cos psi a + sin psi b), a = (-ms, ss, 0) toward the zenith, b = z. */
static void sun_dir(double ss, double ms, double g, double psi, double d[3])
{
    const double cg = cos(g), sg = sin(g), cp = cos(psi), sp = sin(psi);
    d[0] = cg * ss - sg * cp * ms;
    d[1] = cg * ms + sg * cp * ss;
    d[2] = sg * sp;
}

/* ------------------------------------------------------------------ build */
/* The gather's nodes (gamma', psi', solid angle) and the normalised phase weights
 * w[k][type][v][q] of view node v and incoming node q (psi' folded with -psi'). */
typedef struct j_quad {
    double g[QN], p[QN], dw[QN], gh[QN]; /* gh: half the node's cell in gamma' */
    float *w; /* [n][2][JV][QN] */
} j_quad;

static void quad_nodes(j_quad *qd)
{
    static const double gx[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                 -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                 0.7966664774136267,  0.9602898564975363};
    static const double gw[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                                 0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    for (int a = 0; a < QG; a++) { /* QG / 8 panels of 8 points in s over [0, 1] */
        const double s = (0.5 * (1 + gx[a % 8]) + a / 8) / (QG / 8), ws = 0.5 * gw[a % 8] / (QG / 8);
        const double g = ATMOS_PI * (GA * s + (1.0 - GA) * s * s), dg = ATMOS_PI * (GA + 2.0 * (1.0 - GA) * s) * ws;
        for (int b = 0; b < QP; b++) {
            const int q = a * QP + b;
            qd->g[q] = g, qd->p[q] = (b + 0.5) * ATMOS_PI / QP;
            qd->dw[q] = sin(g) * dg * ATMOS_PI / QP, qd->gh[q] = 0.5 * dg;
        }
    }
}

static void quad_weights(const atmos__planet *pl, j_quad *qd)
{
    const int n = pl->n;
    for (int v = 0; v < JV; v++) {
        const double gv = atmos__sph_j_x_to_gamma((double)(v / JP) / (JG - 1));
        const double cpv = 1.0 - 2.0 * (double)(v % JP) / (JP - 1), spv = sqrt(fmax(0.0, 1.0 - cpv * cpv));
        const double dv[3] = {cos(gv), sin(gv) * cpv, sin(gv) * spv}; /* in (sun, a, b) */
        for (int k = 0; k < n; k++) {
            double sum[2] = {0, 0};
            float *wr = qd->w + (((size_t)k * 2 + 0) * JV + v) * QN, *wm = wr + (size_t)JV * QN;
            for (int q = 0; q < QN; q++) {
                const double cg = cos(qd->g[q]), sg = sin(qd->g[q]), cp = cos(qd->p[q]), sp = sin(qd->p[q]);
                const double c1 = dv[0] * cg + dv[1] * sg * cp + dv[2] * sg * sp;
                const double c2 = dv[0] * cg + dv[1] * sg * cp - dv[2] * sg * sp;
                const double pr = atmos__planet_rayleigh_phase(pl, k, c1) + atmos__planet_rayleigh_phase(pl, k, c2);
                const double pm = atmos__planet_mie_phase(pl, k, c1) + atmos__planet_mie_phase(pl, k, c2);
                wr[q] = (float)(pr * qd->dw[q]), wm[q] = (float)(pm * qd->dw[q]);
                sum[0] += wr[q], sum[1] += wm[q];
            }
            for (int q = 0; q < QN; q++) {
                wr[q] = (float)(wr[q] / sum[0]);
                wm[q] = (float)(wm[q] / sum[1]);
            }
        }
    }
}

/* The light seen from (0, r, 0) along d without the sun's disk, per unit irradiance. */
static void incoming(const atmos__planet *pl, const atmos__sph_model *m, double r, const double d[3],
                     const double sun[3], const double *albedo, double *L)
{
    const int n = m->n;
    const double q[3] = {0, r, 0}, mu = d[1];
    const double dg = atmos__planet_dist_ground(pl, r, mu);
    const double t1 = dg < INFINITY ? dg : atmos__planet_dist_top(pl, r, mu);
    atmos__sph_sums s;
    atmos__sph_march(pl, m, q, d, 0.0, t1, sun, ATMOS__SPH_STEPS_TABLE, 1, n, NULL, &s);
    const double nu = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
    double G[ATMOS_MAX_WAVELENGTHS] = {0};
    if (dg < INFINITY) {
        const double g[3] = {t1 * d[0], r + t1 * d[1], t1 * d[2]};
        const double cs = (g[0] * sun[0] + g[1] * sun[1]) / sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        double ts[ATMOS_MAX_WAVELENGTHS], es[ATMOS_MAX_WAVELENGTHS];
        atmos__sph_sun_t(m, m->R, cs, n, NULL, ts);
        atmos__sph_esky(m, cs, n, NULL, es);
        for (int k = 0; k < n; k++) G[k] = albedo[k] / ATMOS_PI * ((cs > 0 ? cs * ts[k] : 0.0) + es[k]);
    }
    for (int k = 0; k < n; k++)
        L[k] = atmos__planet_rayleigh_phase(pl, k, nu) * s.sr[k] + atmos__planet_mie_phase(pl, k, nu) * s.sm[k] +
               s.ms[k] + s.t[k] * G[k];
}

/* The node q's cell split at the horizon mu_h: the share f of the cell on the other side of
 * the horizon from its centre (mu, linear over the cell, on a 8 x 8 grid) and the centre of
 * that part (g, p); 0 when the cell lies on one side. */
#define HS 8
static double cell_split(const j_quad *qd, int q, double ss, double ms, double muh, double *g, double *p,
                         int *below)
{
    const double g0 = qd->g[q], p0 = qd->p[q], gh = qd->gh[q], ph = 0.5 * ATMOS_PI / QP;
    const double cg = cos(g0), sg = sin(g0), cp = cos(p0), sp = sin(p0);
    const double mu = cg * ms + sg * cp * ss;
    const double dmg = -sg * ms + cg * cp * ss, dmp = -sg * sp * ss;
    if (fabs(mu - muh) >= fabs(dmg) * gh + fabs(dmp) * ph) return 0.0;
    *below = mu < muh;
    int cnt = 0;
    double sgs = 0.0, sps = 0.0;
    for (int i = 0; i < HS; i++)
        for (int j = 0; j < HS; j++) {
            const double a = gh * ((2.0 * i + 1.0) / HS - 1.0), b = ph * ((2.0 * j + 1.0) / HS - 1.0);
            if ((mu + dmg * a + dmp * b < muh) != *below) cnt++, sgs += a, sps += b;
        }
    if (!cnt) return 0.0;
    *g = g0 + sgs / cnt, *p = p0 + sps / cnt;
    return (double)cnt / (HS * HS);
}

/* The incoming light of node q over its cell (L: [n][QN]): where the cell straddles the
 * horizon, the light from beyond it (the sky's or the ground's) at its part's centre,
 * weighted by that part's share. The light jumps there, and a view near the horizon
 * gathers it through the aerosols' narrow forward lobe from few nodes. */
static void horizon_cell(const atmos__planet *pl, const atmos__sph_model *m, const j_quad *qd, int q, double r,
                         const double sun[3], const double *albedo, float *L)
{
    const int n = m->n;
    const double rr = m->R / r, muh = -sqrt(fmax(0.0, 1.0 - rr * rr));
    double g, p, d[3], l[ATMOS_MAX_WAVELENGTHS];
    int below;
    const double f = cell_split(qd, q, sun[0], sun[1], muh, &g, &p, &below);
    if (f <= 0.0) return;
    sun_dir(sun[0], sun[1], g, p, d);
    if ((d[1] < muh) == below) return; /* the linear mu's part is not beyond the horizon */
    incoming(pl, m, r, d, sun, albedo, l);
    for (int k = 0; k < n; k++) L[(size_t)k * QN + q] = (float)((1.0 - f) * L[(size_t)k * QN + q] + f * l[k]);
}

/* The gather at radius r with the sun at cosine ms: log(j + floor) of every view node, in
 * the table's layout of one (r, mu_s) node ([JG][JP][n][2]). */
static int j_gather(const atmos__planet *pl, const atmos__sph_model *m, const j_quad *qd, double r, double ms,
                    const double *albedo, float *out)
{
    const int n = m->n;
    const double ss = sqrt(fmax(0.0, 1.0 - ms * ms));
    const double sun[3] = {ss, ms, 0};
    double l[ATMOS_MAX_WAVELENGTHS];
    float *L = malloc(sizeof(float) * QN * (size_t)n); /* [n][QN]: each wavelength's run contiguous */
    if (!L) return 1;
    for (int q = 0; q < QN; q++) {
        double d[3];
        sun_dir(ss, ms, qd->g[q], qd->p[q], d);
        incoming(pl, m, r, d, sun, albedo, l);
        for (int k = 0; k < n; k++) L[(size_t)k * QN + q] = (float)l[k];
    }
    for (int q = 0; q < QN; q++) horizon_cell(pl, m, qd, q, r, sun, albedo, L);
    for (int v = 0; v < JV; v++)
        for (int k = 0; k < n; k++) {
            const float *wr = qd->w + (((size_t)k * 2 + 0) * JV + v) * QN, *wm = wr + (size_t)JV * QN;
            const float *lk = L + (size_t)k * QN;
            float a = 0.0f, b = 0.0f;
#pragma omp simd reduction(+ : a, b)
            for (int q = 0; q < QN; q++) a += wr[q] * lk[q], b += wm[q] * lk[q];
            out[((size_t)v * n + k) * 2] = (float)log(a + JFLOOR);
            out[((size_t)v * n + k) * 2 + 1] = (float)log(b + JFLOOR);
        }
    free(L);
    return 0;
}

static int j_node(const atmos__planet *pl, const atmos__sph_model *m, const j_quad *qd, int ir, int is,
                  const double *albedo, float *out)
{
    const double x = (double)ir / (JR - 1), r = m->R + (m->Rt - m->R) * x * x;
    return j_gather(pl, m, qd, r, atmos__sph_j_x_mus((double)is / (JS - 1)), albedo, out);
}

/* The quadrature's nodes and phase weights (qd->w allocated; NULL when out of memory). */
static int j_quad_init(const atmos__planet *pl, j_quad *qd)
{
    quad_nodes(qd);
    qd->w = malloc(sizeof(float) * (size_t)pl->n * 2 * JV * QN);
    if (!qd->w) return 1;
    quad_weights(pl, qd);
    return 0;
}

atmos_status atmos__sph_j_direct(const atmos__planet *pl, const atmos__sph_model *m, double r, double mus,
                                 const double *albedo, float *out)
{
    j_quad qd;
    if (j_quad_init(pl, &qd)) return ATMOS_E_NOMEM;
    const int fail = j_gather(pl, m, &qd, r, atmos__clampd(mus, -1.0, 1.0), albedo, out);
    free(qd.w);
    return fail ? ATMOS_E_NOMEM : ATMOS_OK;
}

atmos_status atmos__sph_build_j(const atmos__planet *pl, atmos__sph_model *m, const double *albedo)
{
    const int n = m->n;
    const size_t per = (size_t)JV * 2 * n, total = (size_t)JR * JS * per;
    j_quad qd;
    if (j_quad_init(pl, &qd)) return ATMOS_E_NOMEM;
    float *next = malloc(sizeof(float) * total);
    if (!next) {
        free(qd.w);
        return ATMOS_E_NOMEM;
    }
    int fail = 0;
#pragma omp parallel for schedule(dynamic) reduction(| : fail)
    for (int e = 0; e < JR * JS; e++) fail |= j_node(pl, m, &qd, e / JS, e % JS, albedo, next + (size_t)e * per);
    if (!fail) memcpy(m->jms, next, sizeof(float) * total);
    m->use_j = !fail;
    free(qd.w), free(next);
    return fail ? ATMOS_E_NOMEM : ATMOS_OK;
}
