/* Kessler warm rain in the form of Klemp & Wilhelmson (1978, J. Atmos. Sci. 35, 1070,
 * Eq. 2.13-2.15), cell by cell:
 *   autoconversion  A = k1 (q_c - a)+,  k1 = 1e-3 s^-1, a = 1e-3 kg/kg (Kessler 1969)
 *   accretion       C = 2.2 q_c q_r^0.875 s^-1
 *   rain evaporation E = (1 - q_v/q_s) C' (rho q_r)^0.525 / (rho (5.4e5 + 2.55e6 / (p q_s)))
 *                   with C' = 1.6 + 124.9 (rho q_r)^0.2046, rho in g cm^-3, p in mb
 *   fall speed      V = 36.34 (rho q_r)^0.1346 (rho / rho_ground)^-1/2 m/s, rho in g cm^-3
 * with ice below 0 C (docs/clouds.md, *The anvil*): the cloud's and the precipitation's ice
 * fraction that of the IFS's mixed phase (atmos__sim_ice_fraction), the ice's autoconversion
 * slower and its precipitation (snow) falling slower, after Lin, Farley & Orville (1983,
 * J. Clim. Appl. Meteor. 22, 1065, Eq. 21 and the snow's fall speed), the cloud's ice falling
 * slowly (Heymsfield & Donner 1990); then the saturation adjustment over water and ice with
 * latent heat (atmos__sim_adjust). Every transfer moves water between q_v, q_c and q_r, so
 * their sum changes only through what falls out (counted in rain_out). */
#include "sim/sim_internal.h"

#include <math.h>

/* A vapour below which every cell of level k is clear, dry air (q_v < 0.9 q_s(T)): 0.9 q_s at
 * the level's coldest theta, less 1e-6 of it (q_s rises with T, and its rounding is far below
 * that margin, so a cell below the bound passes the exact test too: the bound only saves the
 * exponential); 0 if a theta is NaN. */
static double dry_below(const atmos_sim *s, int k, double p, double pi)
{
    const size_t lev = (size_t)s->nx * s->ny;
    const float *th = s->th + k * lev;
    float m = th[0];
    int nan = 0;
    for (size_t n = 0; n < lev; n++) {
        m = th[n] < m ? th[n] : m;
        nan |= th[n] != th[n];
    }
    return nan ? 0.0 : 0.9 * atmos__sim_qsat_cond(m * pi, p) * (1.0 - 1e-6);
}

static inline int plus_zero(float f)
{
    return f == 0 && !signbit(f);
}

#define MICRO_CLONES ATMOS_CLONES

/* A row's vapour times the fixer factor, and which of its cells are not clear, dry air (the
 * cell loop's first test, for the whole row at once: vectorised). */
MICRO_CLONES static void scale_row(float *restrict qv, const float *restrict qc, const float *restrict qr, float fix,
                                   double dry, int m, unsigned char *restrict busy)
{
    for (int i = 0; i < m; i++) {
        const float v = qv[i] * fix;
        qv[i] = v;
        busy[i] = !((qc[i] <= 0) & (qr[i] <= 0) & ((double)v < dry));
    }
}

/* Kessler and the adjustment (with phase changes) of cell n at level pressure p, Exner pi,
 * density rho (g cm^-3); dry as dry_below's. */
static void cell(atmos_sim *s, size_t n, double dt, double p, double pi, double rho, double dry)
{
    double th = s->th[n], qv = s->qv[n], qc = s->qc[n], qr = s->qr[n];
    if (qc <= 0 && qr <= 0) {
        if (qv < dry) return; /* clear, dry air */
        const double qs = atmos__sim_qsat_cond(th * pi, p);
        if (qv < 0.9 * qs) return;
        /* unsaturated and no condensate (both +0): every rate below is 0 and the adjustment
         * returns at once, the cell is left as it is */
        if (qv <= qs && plus_zero(s->qc[n]) && plus_zero(s->qr[n])) return;
    }
    if (qc < 0) qc = 0;
    if (qr < 0) qr = 0;
    /* rain (or snow) from cloud water (ice): the autoconversion's rate for the ice part of
     * Lin et al. (1983), 1e-3 exp(0.025 (T - T_0)) s^-1 */
    const double fi = atmos__sim_ice_fraction(th * pi);
    const double k_auto = 1e-3 * (fi > 0 ? 1 - fi + fi * exp(0.025 * (th * pi - 273.16)) : 1.0);
    const double rate = k_auto * fmax(qc - 1e-3, 0.0) + 2.2 * qc * pow(qr, 0.875);
    const double dr = fmin(qc, rate * dt);
    qc -= dr, qr += dr;
    /* rain evaporating into unsaturated air */
    const double qs = atmos__sim_qsat(th * pi, p);
    if (qr > 0 && qv < qs) {
        const double rq = rho * qr;
        const double e = (1.6 + 124.9 * pow(rq, 0.2046)) * pow(rq, 0.525) / (2.55e8 / (p * qs) + 5.4e5) * (qs - qv) /
                         (rho * qs);
        const double de = fmin(fmin(e * dt, qr), qs - qv);
        qr -= de, qv += de;
        th -= SIM_LV / SIM_CP * de / pi;
    }
    atmos__sim_adjust(&th, &qv, &qc, p, pi);
    s->th[n] = (float)th, s->qv[n] = (float)qv, s->qc[n] = (float)qc, s->qr[n] = (float)qr;
}

/* Each cell's vapour times the advection's fixer factor (always), then Kessler and the
 * adjustment (with phase changes) where the air is not clear and dry, row by row. */
void atmos__sim_micro(atmos_sim *s, double dt, float fix)
{
    const int micro = s->env.micro, nx = s->nx;
    SIM_FOR
    for (int k = 0; k < s->nz; k++) {
        const double p = s->p0[k], pi = s->pi0[k], rho = 1e-3 * s->rho0[k];
        const double dry = micro ? dry_below(s, k, p, pi) : 0;
        unsigned char busy[ATMOS_SIM_MAX_GRID];
        for (int j = 0; j < s->ny; j++) {
            const size_t r = sim_idx(s, 0, j, k);
            scale_row(s->qv + r, s->qc + r, s->qr + r, fix, dry, nx, busy);
            if (micro)
                for (int i = 0; i < nx; i++)
                    if (busy[i]) cell(s, r + i, dt, p, pi, rho, dry);
        }
    }
    atmos__sim_sync(s);
}

/* Whether a cell of row j holds more than 1e-9 of q. */
static int any_in_row(const atmos_sim *s, const float *qf, int j)
{
    const size_t lev = (size_t)s->nx * s->ny;
    for (int k = 0; k < s->nz; k++) {
        const float *q = qf + k * lev + (size_t)j * s->nx;
        int any = 0;
        for (int i = 0; i < s->nx; i++) any |= q[i] > 1e-9;
        if (any) return 1;
    }
    return 0;
}

/* The fall speed (m/s) of precipitation of rho q kg m^-3 at density ratio rho_ground / rho, a
 * fraction fi of it snow: Kessler's rain (header) and Lin et al. (1983)'s snow, mass-weighted
 * over their exponential size distribution (V = 11.72 D^0.41 m/s, D in m; n_0 = 3e6 m^-4,
 * density 100 kg m^-3): 11.72 Gamma(4.41) / 6 (pi 100 n_0)^-0.1025 (rho q)^0.1025 =
 * 2.416 (rho q)^0.1025, about a quarter of the rain's. */
static double fall_speed(double rq, double ratio, double fi)
{
    const double rain = 36.34 * pow(1e-3 * rq, 0.1346);
    const double snow = fi > 0 ? 2.416 * pow(rq, 0.1025) : 0.0;
    return ((1 - fi) * rain + fi * snow) * sqrt(ratio);
}

/* q of column c falls with vel[k] (m/s) by first-order upwind fluxes, sub-stepped so that
 * V dt_sub < dx; returns what left the lowest cell (q times rho0 / rho_ref). */
static double fall_column(const atmos_sim *s, float *qf, size_t c, const double *vel, double vmax, double dt)
{
    const size_t lev = (size_t)s->nx * s->ny;
    double fell = 0;
    if (!(vmax > 0)) return fell;
    const int sub = (int)ceil(vmax * dt / (0.9 * s->dx));
    const double h = dt / sub / s->dx;
    for (int m = 0; m < sub; m++) {
        double from_above = 0; /* flux into cell k from k + 1: q times rho0 / rho_ref */
        for (int k = s->nz - 1; k >= 0; k--) {
            float *q = &qf[c + k * lev];
            const double leave = fmin((double)*q, h * vel[k] * *q);
            *q = (float)(*q - leave + from_above / s->rho_c[k]);
            from_above = leave * s->rho_c[k]; /* the mass that falls (rho_c[0] = 1) */
        }
        fell += from_above;
    }
    return fell;
}

/* Rain (and snow) falls at fall_speed, and the cloud's ice at Heymsfield & Donner's (1990,
 * J. Atmos. Sci. 47, 1865) V = 3.29 (rho q_i)^0.16 m/s (rho q_i in kg m^-3; 0.75 m/s at
 * 1e-4), times the cell's ice fraction. What leaves the lowest cell is precipitation on the
 * ground. The columns of row j, one at a time; returns the row's water out, added column by
 * column. */
double atmos__sim_fall_row(atmos_sim *s, double dt, int j)
{
    if (!s->env.micro) return 0.0;
    const int nx = s->nx, nz = s->nz;
    const size_t lev = (size_t)nx * s->ny;
    double row = 0;
    const int rain = any_in_row(s, s->qr, j), ice = any_in_row(s, s->qc, j);
    if (!rain && !ice) return row; /* each column's water out would be 0 */
    for (int i = 0; i < nx; i++) {
        const size_t c = (size_t)j * nx + i;
        double fell = 0, vel[2 * ATMOS_SIM_MAX_GRID];
        for (int pass = 0; pass < 2; pass++) {
            if (!(pass ? ice : rain)) continue;
            float *qf = pass ? s->qc : s->qr;
            double vmax = 0;
            for (int k = 0; k < nz; k++) {
                const double q = qf[c + k * lev], fi = atmos__sim_ice_fraction(s->th[c + k * lev] * s->pi0[k]);
                vel[k] = q <= 1e-9 ? 0.0
                         : pass    ? fi * 3.29 * pow(s->rho0[k] * q, 0.16)
                                   : fall_speed(s->rho0[k] * q, s->rho0[0] / s->rho0[k], fi);
                vmax = fmax(vmax, vel[k]);
            }
            fell += fall_column(s, qf, c, vel, vmax, dt);
        }
        row += (float)fell;
    }
    return row;
}
