/* Moist thermodynamics of the cloud simulation: saturation (Bolton 1980), the saturation
 * adjustment with latent heat, and the base state from a sounding (docs/clouds.md). */
#include "sim/sim_internal.h"

#include <math.h>

/* Bolton (1980), Mon. Wea. Rev. 108, 1046, Eq. 10: e_s = 6.112 exp(17.67 T / (T + 243.5)) hPa,
 * T in degrees Celsius; within 0.1 % of the Wexler values for -30 .. 35 C. */
double atmos__sim_esat(double t_k)
{
    const double tc = t_k - 273.15;
    return 611.2 * exp(17.67 * tc / (tc + 243.5));
}

/* The mixing ratio at vapour pressure e. */
static double mixing_ratio(double e, double p_pa)
{
    if (e > 0.5 * p_pa) e = 0.5 * p_pa; /* never at atmospheric temperatures; keeps q finite */
    return SIM_EPS * e / (p_pa - e);
}

double atmos__sim_qsat(double t_k, double p_pa)
{
    return mixing_ratio(atmos__sim_esat(t_k), p_pa);
}

double atmos__sim_dewpoint(double qv, double p_pa)
{
    const double e = qv * p_pa / (SIM_EPS + qv);
    const double l = log(e / 611.2);
    return 273.15 + 243.5 * l / (17.67 - l);
}

/* Alduchov & Eskridge (1996), J. Appl. Meteor. 35, 601 (AERKi): saturation vapour pressure
 * over ice, e_i = 6.1121 exp(22.587 T / (T + 273.86)) hPa, T in degrees Celsius. */
double atmos__sim_esat_ice(double t_k)
{
    const double tc = t_k - 273.15;
    return 611.21 * exp(22.587 * tc / (tc + 273.86));
}

/* The fraction of condensate that is ice at temperature t (K): 1 - alpha, alpha = ((t - t_ice) /
 * (t_0 - t_ice))^2 the liquid fraction of ECMWF's IFS (IFS Documentation Cy47r1, Part IV:
 * Physical processes, the mixed phase), t_0 = 273.16 K, t_ice = 250.16 K; its derivative in t
 * into *df. */
static double ice_fraction_d(double t, double *df)
{
    const double t0 = 273.16, ti = 250.16;
    *df = 0;
    if (t >= t0) return 0;
    if (t <= ti) return 1;
    const double a = (t - ti) / (t0 - ti);
    *df = -2.0 * a / (t0 - ti);
    return 1 - a * a;
}

double atmos__sim_ice_fraction(double t)
{
    double df;
    return ice_fraction_d(t, &df);
}

/* The saturation mixing ratio of the condensate at t: over water at 0 C and above, blended
 * by the ice fraction f towards that over ice below, (1 - f) q_sw + f q_si (the mixed phase's
 * saturation, as in the IFS); its derivative in t into *dq (analytic: Newton's step). */
static double qsat_cond_d(double t_k, double p_pa, double *dq)
{
    const double tc = t_k - 273.15, qw = atmos__sim_qsat(t_k, p_pa);
    const double dw = qw * 17.67 * 243.5 / ((tc + 243.5) * (tc + 243.5)) * (1.0 + qw / SIM_EPS);
    double df;
    const double f = ice_fraction_d(t_k, &df);
    if (f <= 0) {
        *dq = dw;
        return qw;
    }
    const double qi = mixing_ratio(atmos__sim_esat_ice(t_k), p_pa);
    const double di = qi * 22.587 * 273.86 / ((tc + 273.86) * (tc + 273.86)) * (1.0 + qi / SIM_EPS);
    *dq = (1 - f) * dw + f * di + df * (qi - qw);
    return (1 - f) * qw + f * qi;
}

double atmos__sim_qsat_cond(double t_k, double p_pa)
{
    double d;
    return qsat_cond_d(t_k, p_pa, &d);
}

double atmos__sim_latent(double t_k)
{
    return SIM_LV + SIM_LF * atmos__sim_ice_fraction(t_k);
}

void atmos__sim_adjust(double *th, double *qv, double *qc, double p_pa, double pi)
{
    double t = *th * pi, v = *qv, c = *qc;
    if (v <= atmos__sim_qsat_cond(t, p_pa) && c <= 0) return;
    const double lcp = atmos__sim_latent(t) / SIM_CP;
    /* Newton on f(d) = v - d - q_s(T + L d / c_p): d condensed (negative: evaporated). */
    double d = 0;
    for (int it = 0; it < 8; it++) {
        double dqs;
        const double qs = qsat_cond_d(t + lcp * d, p_pa, &dqs);
        const double step = (v - d - qs) / (1.0 + lcp * dqs);
        d += step;
        if (fabs(step) < 1e-12) break;
    }
    if (d < -c) d = -c; /* all the cloud water evaporates and the air stays unsaturated */
    *qv = v - d;
    *qc = c + d;
    if (*qc < 0) *qc = 0;
    *th += lcp * d / pi;
}

/* Potential temperature and vapour of the layered sounding at height z. */
static void layered(const sim_env *e, double z, double *th, double *qv)
{
    const double zt = e->zi + e->inv_depth;
    if (z < e->zi) {
        *th = e->theta_s;
        *qv = e->qv_bl;
        return;
    }
    if (z < zt) {
        const double f = e->inv_depth > 0 ? (z - e->zi) / e->inv_depth : 1.0;
        *th = e->theta_s + f * e->dtheta_inv;
        *qv = e->qv_bl + f * (e->qv_ft - e->qv_bl);
        return;
    }
    *th = e->theta_s + e->dtheta_inv + e->gamma_ft * (fmin(z, e->z_tp) - zt) + e->gamma_strat * fmax(0.0, z - e->z_tp);
    *qv = e->qv_ft * exp(-(z - zt) / e->hq);
}

/* Weisman & Klemp (1982), Mon. Wea. Rev. 110, 504, Eq. 1-2: theta and relative humidity. */
static double wk82_theta(const sim_env *e, double z, double *rh)
{
    if (z <= e->z_tp) {
        const double f = pow(z / e->z_tp, 1.25);
        *rh = 1.0 - 0.75 * f;
        return e->theta_s + (e->theta_tr - e->theta_s) * f;
    }
    *rh = 0.25;
    return e->theta_tr * exp(SIM_G * (z - e->z_tp) / (SIM_CP * e->t_tr));
}

void atmos__sim_sounding(atmos_sim *sim)
{
    const sim_env *e = &sim->env;
    const double kappa = SIM_RD / SIM_CP;
    double pi = 1.0, z = 0.0; /* the ground at 1000 hPa */
    const int sub = 8;
    for (int k = 0; k < sim->nz; k++) {
        const double zc = (k + 0.5) * sim->dx;
        /* hydrostatic Exner function, d pi / dz = -g / (c_p theta), by the midpoint rule */
        while (z < zc - 1e-9) {
            const double h = fmin(sim->dx / sub, zc - z), zm = z + 0.5 * h;
            double th, q, rh;
            if (e->kind == SIM_SOUNDING_WK82) th = wk82_theta(e, zm, &rh);
            else layered(e, zm, &th, &q);
            pi -= SIM_G / (SIM_CP * th) * h;
            z += h;
        }
        double th, qv, rh = 1;
        if (e->kind == SIM_SOUNDING_WK82) th = wk82_theta(e, zc, &rh);
        else layered(e, zc, &th, &qv);
        const double p = SIM_P00 * pow(pi, 1.0 / kappa), t = th * pi;
        if (e->kind == SIM_SOUNDING_WK82) qv = fmin(e->qv_bl, rh * atmos__sim_qsat(t, p));
        sim->th0[k] = th;
        sim->qv0[k] = qv;
        sim->pi0[k] = pi;
        sim->p0[k] = p;
        sim->rho0[k] = p / (SIM_RD * t * (1.0 + 0.61 * qv));
        sim->ue[k] = e->u_s * (e->z_shear > 0 ? tanh(zc / e->z_shear) : 1.0) - e->u_move;
    }
    sim->rho_ref = sim->rho0[0];
    for (int k = 0; k < sim->nz; k++) sim->rho_c[k] = sim->rho0[k] / sim->rho_ref;
    for (int k = 1; k < sim->nz; k++) sim->rho_f[k] = 0.5 * (sim->rho_c[k - 1] + sim->rho_c[k]);
    sim->rho_f[0] = sim->rho_f[sim->nz] = 0; /* w = 0 there: no flux */
}
