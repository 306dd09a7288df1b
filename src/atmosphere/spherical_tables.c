/* The production sky's tables (spherical.h): their parametrizations, look-ups and build.
 *
 * tau(r, mu): optical depth to the top of the atmosphere along rays that miss the ground,
 *   on Bruneton's 2017 mapping ("Precomputed Atmospheric Scattering: a New Implementation",
 *   §transmittance): x_r = rho / H with rho = sqrt(r^2 - R^2), H = sqrt(Rt^2 - R^2), and
 *   x_mu = (d - d_min) / (d_max - d_min), d the distance to the top, d_min = Rt - r,
 *   d_max = rho + H. Depth (not T) is stored: it is smooth where T underflows.
 * Psi_ms(r, mu_s): Hillaire 2020 §5.5-5.6: at each point, light of the second order
 *   L_2nd = int_sphere L'(x, -w) p_u dw (p_u = 1 / 4 pi) with L' the sunlight scattered once
 *   along the ray plus the sunlit Lambertian ground at its end, and
 *   f_ms = int_sphere L_f(x, -w) p_u dw with L_f = int sigma_s T dt; all higher orders
 *   follow as the geometric series Psi_ms = L_2nd / (1 - f_ms). Unlike Hillaire, L' uses
 *   the real phase functions (Rayleigh, the aerosols' table) at the angle to the sun: the
 *   isotropic one put 20-55 % too much higher-order light in the zenith (docs/sky.md).
 *   Rows in x = sqrt(h / top), columns in mu_s = x' |x'|, x' in [-1, 1] (dense near the
 *   horizon, where twilight lives).
 * E_sky(mu_s): the irradiance of the ground by the sky (single scattering with the real
 *   phase functions plus Psi_ms), mu_s mapped like Psi's. */
#include "atmosphere/spherical.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TR ATMOS__SPH_T_R
#define TM ATMOS__SPH_T_MU
#define MR ATMOS__SPH_M_R
#define MM ATMOS__SPH_M_MU
#define EM ATMOS__SPH_E_MU

/* Optical depth from (0, r, 0) along (sqrt(1 - mu^2), mu, 0) to the top (a ray that misses
 * the ground): composite 4-point Gauss-Legendre in s over each monotone piece, t = t_low
 * +- L s^2 (points crowd where the ray is lowest and the air densest). */
static void depth_to_top(const atmos__planet *pl, double r, double mu, double *out)
{
    static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
    static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
    enum { P = 12 };
    const double dist = atmos__planet_dist_top(pl, r, mu), tc = atmos__clampd(-r * mu, 0.0, dist);
    const double len[2] = {tc, dist - tc};
    for (int i = 0; i < pl->n; i++) out[i] = 0.0;
    for (int side = 0; side < 2; side++) {
        const double L = len[side], sg = side ? 1.0 : -1.0;
        if (!(L > 0)) continue;
        for (int p = 0; p < P; p++)
            for (int g = 0; g < 4; g++) {
                const double s = (p + 0.5 + 0.5 * gx[g]) / P, w = gw[g] * 0.5 / P * 2.0 * L * s;
                const double t = tc + sg * L * s * s;
                const double h = sqrt(r * r + t * t + 2.0 * r * mu * t) - pl->r_ground;
                for (int i = 0; i < pl->n; i++) out[i] += w * atmos__planet_extinction(pl, h, i);
            }
    }
}

static void build_tau(const atmos__planet *pl, atmos__sph_model *m)
{
#pragma omp parallel for schedule(dynamic)
    for (int j = 0; j < TR; j++) {
        double tau[ATMOS_MAX_WAVELENGTHS];
        for (int i = 0; i < TM; i++) {
            double r, mu;
            atmos__sph_tau_node(m, (double)j / (TR - 1), (double)i / (TM - 1), &r, &mu);
            depth_to_top(pl, r, mu, tau);
            for (int k = 0; k < m->n; k++) m->tau[((size_t)k * TR + j) * TM + i] = (float)tau[k];
        }
    }
}

/* Psi_ms and f_ms at one (r, mu_s): the sphere of directions by Gauss-Legendre on each
 * side of the horizon (in s, mu = mu_h +- span s^2) times midpoints in azimuth over [0, pi] (the light is
 * symmetric about the sun's vertical plane). */
#define NMU 8
#define NPHI 8
static void psi_entry(const atmos__planet *pl, const atmos__sph_model *m, double r, double mus, const double *albedo,
                      double *psi, double *fms)
{
    static const double gx[NMU] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                   -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                   0.7966664774136267,  0.9602898564975363};
    static const double gw[NMU] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                                   0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    const int n = m->n;
    const double q[3] = {0, r, 0}, sun[3] = {sqrt(fmax(0.0, 1 - mus * mus)), mus, 0};
    const double rr = m->R / r, muh = r > m->R ? -sqrt(fmax(0.0, 1 - rr * rr)) : 0.0;
    const double pu = 1.0 / (4.0 * ATMOS_PI);
    double L2[ATMOS_MAX_WAVELENGTHS] = {0}, F[ATMOS_MAX_WAVELENGTHS] = {0};
    for (int side = 0; side < 2; side++) {
        /* mu = mu_h +- span s^2: nodes crowd at the horizon, where T to the boundary is steep */
        const double span = side ? 1.0 - muh : 1.0 + muh, sg = side ? 1.0 : -1.0;
        for (int a = 0; a < NMU; a++) {
            const double sa = 0.5 + 0.5 * gx[a], mu = muh + sg * span * sa * sa;
            const double wmu = 0.5 * gw[a] * 2.0 * span * sa * 2.0 * ATMOS_PI / NPHI, sn = sqrt(fmax(0.0, 1 - mu * mu));
            for (int b = 0; b < NPHI; b++) {
                const double phi = (b + 0.5) * ATMOS_PI / NPHI;
                const double d[3] = {sn * cos(phi), mu, sn * sin(phi)};
                const double dg = atmos__planet_dist_ground(pl, r, mu);
                const int ground = side == 0 && dg < INFINITY;
                const double t1 = ground ? dg : atmos__planet_dist_top(pl, r, mu);
                atmos__sph_sums s;
                atmos__sph_march(pl, m, q, d, 0.0, t1, sun, ATMOS__SPH_STEPS_TABLE, 0, n, NULL, &s);
                double lo_g[ATMOS_MAX_WAVELENGTHS] = {0};
                if (ground) {
                    double g[3] = {q[0] + t1 * d[0], q[1] + t1 * d[1], q[2] + t1 * d[2]};
                    const double gr = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
                    const double cs = (g[0] * sun[0] + g[1] * sun[1] + g[2] * sun[2]) / gr;
                    if (cs > 0) {
                        atmos__sph_sun_t(m, m->R, cs, n, NULL, lo_g);
                        for (int k = 0; k < n; k++) lo_g[k] *= albedo[k] / ATMOS_PI * cs;
                    }
                }
                const double nu = d[0] * sun[0] + d[1] * sun[1];
                for (int k = 0; k < n; k++) {
                    const double first = atmos__planet_rayleigh_phase(pl, k, nu) * s.sr[k] + atmos__planet_mie_phase(pl, k, nu) * s.sm[k];
                    L2[k] += wmu * pu * (first + s.t[k] * lo_g[k]);
                    F[k] += wmu * pu * s.f[k];
                }
            }
        }
    }
    for (int k = 0; k < n; k++) {
        fms[k] = F[k];
        psi[k] = L2[k] / (1.0 - fmin(F[k], 0.999));
    }
}

static void build_psi(const atmos__planet *pl, atmos__sph_model *m, const double *albedo)
{
#pragma omp parallel for schedule(dynamic)
    for (int e = 0; e < MR * MM; e++) {
        const int j = e / MM, i = e % MM;
        const double x = (double)j / (MR - 1);
        const double r = m->R + (m->Rt - m->R) * x * x, mus = atmos__sph_x_to_mus((double)i / (MM - 1));
        double psi[ATMOS_MAX_WAVELENGTHS], f[ATMOS_MAX_WAVELENGTHS];
        psi_entry(pl, m, r, mus, albedo, psi, f);
        for (int k = 0; k < m->n; k++) {
            m->psi[((size_t)k * MR + j) * MM + i] = (float)psi[k];
            m->fms[((size_t)k * MR + j) * MM + i] = (float)f[k];
        }
    }
}

/* E_sky at one mu_s: the upper hemisphere by Gauss-Legendre in u = sqrt(mu) (two panels;
 * nodes crowd at the horizon, where the twilight sky's light is: 8 points in mu put E_sky
 * 25 % above the integral of the sky's own radiance with the sun 6 degrees below) times
 * azimuth midpoints over [0, pi], radiance (with the real phase functions) times mu. */
#define EMU 8
#define EPHI 16
static void esky_entry(const atmos__planet *pl, const atmos__sph_model *m, double mus, double *out)
{
    static const double gx[EMU] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                   -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                   0.7966664774136267,  0.9602898564975363};
    static const double gw[EMU] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                                   0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    const int n = m->n;
    const double q[3] = {0, m->R, 0}, sun[3] = {sqrt(fmax(0.0, 1 - mus * mus)), mus, 0};
    for (int k = 0; k < n; k++) out[k] = 0.0;
    for (int a = 0; a < 2 * EMU; a++) { /* two panels in u, mu = u^2 (the horizon, twilight's light) */
        const double u = 0.5 * (0.5 * (1.0 + gx[a % EMU]) + a / EMU), mu = u * u;
        const double w = 0.25 * gw[a % EMU] * 2.0 * u * 2.0 * ATMOS_PI / EPHI * mu;
        const double sn = sqrt(fmax(0.0, 1 - mu * mu));
        for (int b = 0; b < EPHI; b++) {
            const double phi = (b + 0.5) * ATMOS_PI / EPHI;
            const double d[3] = {sn * cos(phi), mu, sn * sin(phi)};
            const double nu = d[0] * sun[0] + d[1] * sun[1];
            atmos__sph_sums s;
            atmos__sph_march(pl, m, q, d, 0.0, atmos__planet_dist_top(pl, m->R, mu), sun, ATMOS__SPH_STEPS_SKYVIEW,
                             1, n, NULL, &s);
            for (int k = 0; k < n; k++)
                out[k] += w * (atmos__planet_rayleigh_phase(pl, k, nu) * s.sr[k] + atmos__planet_mie_phase(pl, k, nu) * s.sm[k] + s.ms[k]);
        }
    }
}

static void build_esky(const atmos__planet *pl, atmos__sph_model *m)
{
#pragma omp parallel for schedule(dynamic)
    for (int i = 0; i < EM; i++) {
        double e[ATMOS_MAX_WAVELENGTHS];
        esky_entry(pl, m, atmos__sph_x_to_mus((double)i / (EM - 1)), e);
        for (int k = 0; k < m->n; k++) {
            m->esky[(size_t)k * 2 * EM + i] = (float)e[k];
            m->esky[(size_t)k * 2 * EM + EM + i] = (float)e[k];
        }
    }
}

atmos_status atmos__sph_build(atmos_context *ctx, const atmos__planet *pl, atmos__sph_model *m)
{
    const double t0 = atmos__now();
    /* the multiple-scattering table sees a uniform ground: the albedo under the origin */
    const double g0[3] = {0, 0, 0};
    double albedo[ATMOS_MAX_WAVELENGTHS];
    for (int k = 0; k < m->n; k++) albedo[k] = atmos__planet_ground_albedo(pl, g0, k);
    const double steps = 3.0 + ATMOS__SPH_J_ITER;
    atmos__progress(ctx, "sky tables", 0.0);
    build_tau(pl, m);
    build_psi(pl, m, albedo);
    build_esky(pl, m);
    atmos__progress(ctx, "sky tables", 3.0 / steps);
    /* the higher orders with their angular dependence: fixed-point iterations from Psi_ms,
     * the sky's irradiance of the ground renewed after each (spherical_ms.c) */
    for (int it = 0; it < ATMOS__SPH_J_ITER; it++) {
        const atmos_status st = atmos__sph_build_j(pl, m, albedo);
        if (st != ATMOS_OK) return atmos__error(ctx, st, "atmosphere: out of memory");
        build_esky(pl, m);
        atmos__progress(ctx, "sky tables", (4.0 + it) / steps);
    }
    m->build_seconds = atmos__now() - t0;
    return ATMOS_OK;
}
