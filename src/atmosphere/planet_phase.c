/* The planet's phase functions (planet.h): the aerosols' tabulated phase function,
 * interpolated in the scattering angle and sampled exactly through its cumulative
 * distribution, and the mixture with the air molecules' Rayleigh phase function (with
 * depolarization, planet.h) at an altitude. */
#include "atmosphere/planet.h"

#include <math.h>

#define NP ATMOS__PLANET_PHASE_N
#define DTH (ATMOS_PI / (NP - 1))

/* The table defines f(theta) = P(theta) sin(theta) piecewise linear in theta between grid
 * angles (f = 0 at both poles); the phase function is f / sin(theta), so that it
 * integrates over the sphere exactly as the trapezoid rule that normalised the table and
 * built its cumulative distribution (planet_optics.c), and sampling below draws exactly
 * this density: pdf = eval. Near the poles f / sin is taken as its finite limit. */
static double f_at(const float *P, int j) { return P[j] * sin(j * DTH); }

double atmos__planet_mie_phase(const atmos__planet *pl, int k, double cos_theta)
{
    const float *P = pl->mie_phase[k];
    const double c = cos_theta > 1 ? 1 : (cos_theta < -1 ? -1 : cos_theta);
    const double th = acos(c), x = th / DTH;
    int j = (int)x;
    if (j >= NP - 1) j = NP - 2;
    const double t = x - j;
    if (j == 0) /* f = t f_1: f / sin = f_1 / DTH * theta / sin(theta) */
        return f_at(P, 1) / DTH * (th > 1e-8 ? th / sin(th) : 1.0);
    if (j == NP - 2) { /* f = (1 - t) f_{N-2} */
        const double r = ATMOS_PI - th;
        return f_at(P, NP - 2) / DTH * (r > 1e-8 ? r / sin(r) : 1.0);
    }
    return ((1.0 - t) * f_at(P, j) + t * f_at(P, j + 1)) / sin(th);
}

double atmos__planet_mie_sample(const atmos__planet *pl, int k, double u)
{
    const float *cdf = pl->mie_cdf[k];
    const float *P = pl->mie_phase[k];
    u = u < 0 ? 0 : (u > 1 ? 1 : u);
    int lo = 0, hi = NP - 1;
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (cdf[mid] <= u) lo = mid;
        else hi = mid;
    }
    /* inside [lo, hi] the cumulative is a f_lo t + (f_hi - f_lo) t^2 / 2 (times a constant):
     * solve for the fraction r of the interval's mass, stably for a -> 0 and b -> a */
    const double span = cdf[hi] - cdf[lo], r = span > 0 ? (u - cdf[lo]) / span : 0.5;
    const double a = lo == 0 ? 0.0 : f_at(P, lo), b = hi == NP - 1 ? 0.0 : f_at(P, hi);
    const double q = r * 0.5 * (a + b), disc = a * a + 2.0 * (b - a) * q;
    double t = a + b > 0 ? 2.0 * q / (a + sqrt(disc > 0 ? disc : 0.0)) : r;
    if (!(t >= 0)) t = 0;
    if (t > 1) t = 1;
    return cos((lo + t) * DTH);
}

double atmos__planet_phase(const atmos__planet *pl, double h, int k, double cos_theta)
{
    const double r = pl->rayleigh[k] * atmos__planet_rho_rayleigh(pl, h);
    const double m = pl->mie_sca[k] * atmos__planet_rho_mie(pl, h);
    const double pr = atmos__planet_rayleigh_phase(pl, k, cos_theta);
    if (!(r + m > 0)) return pr;
    return (r * pr + m * atmos__planet_mie_phase(pl, k, cos_theta)) / (r + m);
}

void atmos__planet_mie_phase_table(const atmos__planet *pl, int n, int steps, float *out)
{
    for (int k = 0; k < n; k++)
        for (int j = 0; j < steps; j++) {
            const double x = (double)j / (steps - 1);
            out[(size_t)k * steps + j] = (float)atmos__planet_mie_phase(pl, k, 1.0 - 2.0 * x * x);
        }
}
