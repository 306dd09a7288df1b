/* The production sky's tables' parametrizations and look-ups (spherical.h; what each table
 * holds and how it is built: spherical_tables.c). */
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

/* ------------------------------------------------------------------ mappings */

/* Bruneton's (x_r, x_mu) of (r, mu) and back. */
static void tau_coords(const atmos__sph_model *m, double r, double mu, double *xr, double *xm)
{
    r = atmos__clampd(r, m->R, m->Rt);
    const double rho = sqrt(fmax(r * r - m->R * m->R, 0.0));
    const double disc = r * r * (mu * mu - 1.0) + m->Rt * m->Rt;
    const double d = fmax(0.0, -r * mu + sqrt(fmax(disc, 0.0)));
    const double dmin = m->Rt - r, dmax = rho + m->H;
    *xr = rho / m->H;
    *xm = dmax > dmin ? atmos__clampd((d - dmin) / (dmax - dmin), 0.0, 1.0) : 0.0;
}

void atmos__sph_tau_node(const atmos__sph_model *m, double xr, double xm, double *r, double *mu)
{
    const double rho = m->H * xr;
    *r = sqrt(rho * rho + m->R * m->R);
    const double dmin = m->Rt - *r, dmax = rho + m->H, d = dmin + xm * (dmax - dmin);
    *mu = d <= 0 ? 1.0 : atmos__clampd((m->H * m->H - rho * rho - d * d) / (2.0 * *r * d), -1.0, 1.0);
}

static double mus_to_x(double mus)
{
    return 0.5 * (1.0 + copysign(sqrt(fabs(atmos__clampd(mus, -1, 1))), mus));
}
double atmos__sph_x_to_mus(double x)
{
    const double s = 2.0 * x - 1.0;
    return s * fabs(s);
}
static double alt_to_x(const atmos__sph_model *m, double r)
{
    return sqrt(atmos__clampd((r - m->R) / (m->Rt - m->R), 0.0, 1.0));
}

/* Bilinear look-up in a [n][ny][nx] table at fractional coordinates u (x) and v (y) in [0, 1]. */
static void bilinear(const float *tab, int ny, int nx, double u, double v, int cnt, const int *k, double *out)
{
    const double fx = atmos__clampd(u, 0, 1) * (nx - 1), fy = atmos__clampd(v, 0, 1) * (ny - 1);
    int ix = (int)fx, iy = (int)fy;
    if (ix > nx - 2) ix = nx - 2;
    if (iy > ny - 2) iy = ny - 2;
    const double ax = fx - ix, ay = fy - iy;
    for (int i = 0; i < cnt; i++) {
        const float *t = tab + (size_t)ATMOS__WL(k, i) * nx * ny + (size_t)iy * nx + ix;
        out[i] = (1 - ay) * ((1 - ax) * t[0] + ax * t[1]) + ay * ((1 - ax) * t[nx] + ax * t[nx + 1]);
    }
}

void atmos__sph_tau_top(const atmos__sph_model *m, double r, double mu, int cnt, const int *k, double *out)
{
    double xr, xm;
    tau_coords(m, r, mu, &xr, &xm);
    bilinear(m->tau, TR, TM, xm, xr, cnt, k, out);
}

void atmos__sph_sun_t(const atmos__sph_model *m, double r, double mu_s, int cnt, const int *k, double *out)
{
    if (r < m->R) r = m->R;
    const double q = m->R / r;
    if (mu_s < 0 && mu_s * mu_s >= 1.0 - q * q) { /* the ground hides the sun's centre */
        for (int i = 0; i < cnt; i++) out[i] = 0.0;
        return;
    }
    if (r >= m->Rt) {
        for (int i = 0; i < cnt; i++) out[i] = 1.0;
        return;
    }
    atmos__sph_tau_top(m, r, mu_s, cnt, k, out);
    for (int i = 0; i < cnt; i++) out[i] = exp(-out[i]);
}

void atmos__sph_psi(const atmos__sph_model *m, double r, double mu_s, int cnt, const int *k, double *out)
{
    bilinear(m->psi, MR, MM, mus_to_x(mu_s), alt_to_x(m, r), cnt, k, out);
}

double atmos__sph_fms(const atmos__sph_model *m, double r, double mu_s, int k)
{
    double v;
    bilinear(m->fms, MR, MM, mus_to_x(mu_s), alt_to_x(m, r), 1, &k, &v);
    return v;
}

/* Geometric between the columns where both are positive: with the sun below the horizon
 * the sky's irradiance falls ~3.6 times per degree, and the linear interpolation over the
 * columns' 1.2 degrees there put it up to 25 % high. */
void atmos__sph_esky(const atmos__sph_model *m, double mu_s, int cnt, const int *k, double *out)
{
    const double f = atmos__clampd(mus_to_x(mu_s), 0, 1) * (EM - 1);
    int i = (int)f;
    if (i > EM - 2) i = EM - 2;
    const double a = f - i;
    for (int j = 0; j < cnt; j++) {
        const float *t = m->esky + (size_t)ATMOS__WL(k, j) * 2 * EM + i;
        out[j] = t[0] > 0 && t[1] > 0 ? exp((1 - a) * log(t[0]) + a * log(t[1])) : (1 - a) * t[0] + a * t[1];
    }
}

/* ------------------------------------------------------------------ build */
