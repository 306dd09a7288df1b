/* The analytic sky of Riley et al. 2004, §4.1 (Eq. 8-15) and §4.2.4.
 *
 * Flat earth, y = altitude, molecular density eta(h) = eta0 exp(-gamma h) (Eq. 9), so
 * the scattering (= extinction, albedo 1) coefficient is beta(h) = beta_sl exp(-gamma h)
 * (Eq. 10). Along a ray from a point at altitude y in direction p, with
 * beta_eye = beta_sl exp(-gamma y) (Eq. 13) and distance t:
 *
 *   optical depth to the eye  tau_v(t) = beta_eye t g(gamma p_y t),  g(z) = (1 - e^-z)/z
 *   sun's optical depth       tau_s(t) = beta(t) / (gamma l_y)                (Eq. 12)
 *   in-scatter  L = P(theta) E_sun  int_0^K beta(t) exp(-tau_v(t) - tau_s(t)) dt  (Eq. 14)
 *
 * Because d(tau_v + tau_s)/dt = beta(t) (1 - p_y/l_y), the integral is exact:
 *
 *   L = P E_sun tau_v(K) e^{-tau_s(0)} h(D),   D = tau_v(K) (1 - p_y/l_y),  h(D) = (1 - e^-D)/D
 *
 * which equals the paper's Eq. 15 multiplied by exp(-beta_eye / (gamma p_y)): the printed
 * Eq. 15 drops the attenuation between the eye and the start of the segment (see
 * docs/models.md). Written with g and h (both -> 1 at 0, computed with expm1) it has no
 * division by p_y or (p_y - l_y), so horizontal rays and views at the sun's elevation are
 * exact limits rather than 0/0.
 */
#include "atmosphere/atmosphere_internal.h"

#include <math.h>

double atmos__sky_g(double z)
{
    if (fabs(z) < 1e-6) return 1.0 - 0.5 * z + z * z / 6.0;
    return -expm1(-z) / z;
}

/* Wavelength-independent part of tau_v(K)/beta_eye: K g(gamma p_y K), INFINITY if unbounded. */
double atmos__sky_view_depth_factor(double gamma, double py, double K)
{
    if (!(K > 0)) return 0.0;
    if (isinf(K)) return py > 0 ? 1.0 / (gamma * py) : INFINITY;
    double z = gamma * py * K;
    if (z < -700.0) return INFINITY; /* exp overflow: beyond any meaningful optical depth */
    return K * atmos__sky_g(z);
}

static double h_fn(double D) { return atmos__sky_g(D); }

double atmos__sky_inscatter_factor(double gamma, double beta_eye, double G, double ly, double py, double e_end)
{
    /* tau_v(K) e^{-tau_s(0)} h(D) (see the file comment): the in-scattered radiance
     * divided by P(theta) E_sun. G = tau_v(K)/beta_eye (INFINITY for an endless
     * horizontal or downward ray), e_end = exp(-gamma p_y K) = beta(K)/beta_eye. */
    if (!(ly > 0) || !(beta_eye > 0) || !(G > 0)) return 0.0;
    double c = 1.0 - py / ly;
    double ts0 = beta_eye / (gamma * ly);
    if (isinf(G)) {
        /* Endless ray (p_y <= 0 so c >= 1): tau_v -> inf and tau_v h(D) -> 1/c. */
        return exp(-ts0) / c;
    }
    double x = beta_eye * G;
    double D = c * x;
    if (D >= 0) return x * exp(-ts0) * h_fn(D);
    /* D < 0 (view steeper than the sun): e^{-ts0} h(D) = e^{-(ts0 + D)} h(-D), with
     * ts0 + D = tau_v(K) + tau_s(K) >= 0 formed without cancellation. This keeps the
     * sun near the horizon (ts0 huge, e^{-D} huge) from becoming 0 * inf. */
    double tsK = ts0 * e_end;
    return x * exp(-(x + tsK)) * h_fn(-D);
}

/* An eye far above the air (gamma y > ATMOS__RILEY_HIGH_EYE): beta_eye = beta_sl e^{-gamma y}
 * underflows and G = K g(-gamma y) overflows, and their product, the optical depth, becomes
 * 0 * inf. A descending segment's optical depth written from its low end y_end = y + p_y K,
 *   tau_v(K) = beta_sl e^{-gamma y_end} K g(-gamma p_y K),
 * has neither. Returns the wavelength-independent part tau_v / beta_sl (0 if the segment
 * does not descend or is unbounded), used only for such eyes so that the images of any
 * lower eye stay as they were. */
static int high_descent(const atmos_atmosphere *a, double y, double py, double dist, double *depth)
{
    if (!(a->gamma * y > ATMOS__RILEY_HIGH_EYE) || !(py < 0) || !(dist > 0) || isinf(dist)) return 0;
    const double y_end = fmax(y + py * dist, 0.0);
    *depth = exp(-a->gamma * y_end) * dist * atmos__sky_g(-a->gamma * py * dist);
    return 1;
}

void atmos__riley_transmittance(const atmos_atmosphere *a, double y, const double d[3], double dist, int m,
                                const int *k, double *out)
{
    double depth;
    if (high_descent(a, y, d[1], dist, &depth)) {
        for (int i = 0; i < m; i++) out[i] = exp(-a->beta_sl[ATMOS__WL(k, i)] * depth);
        return;
    }
    const double G = atmos__sky_view_depth_factor(a->gamma, d[1], dist);
    const double ey = exp(-a->gamma * y);
    for (int i = 0; i < m; i++) out[i] = isinf(G) ? 0.0 : exp(-a->beta_sl[ATMOS__WL(k, i)] * ey * G);
}

/* Eq. 12: the sun's optical depth from altitude y is beta(y) / (gamma l_y). */
void atmos__riley_sunlight(const atmos_atmosphere *a, double y, const double sun[3], int m, const int *k, double *out)
{
    const double ly = sun[1];
    const double ey = exp(-a->gamma * y);
    for (int i = 0; i < m; i++) {
        const int j = ATMOS__WL(k, i);
        out[i] = ly > 0 ? a->sun_e[j] * exp(-a->beta_sl[j] * ey / (a->gamma * ly)) : 0.0;
    }
}

int atmos__riley_inscatter(const atmos_atmosphere *a, double y, const double d[3], double dist, const double sun[3],
                           int m, const int *k, double *out)
{
    const double py = d[1], ly = sun[1];
    if (!(ly > 0)) { /* a flat earth's air is dark once the sun has set */
        for (int i = 0; i < m; i++) out[i] = 0.0;
        return 0;
    }
    const double P = atmos_phase_rayleigh(d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2]);
    double depth;
    if (high_descent(a, y, py, dist, &depth)) {
        /* p_y < 0 < l_y, so D = (1 - p_y/l_y) tau_v > 0: tau_v e^{-tau_s(0)} h(D). */
        const double c = 1.0 - py / ly, ey = exp(-a->gamma * y);
        for (int i = 0; i < m; i++) {
            const int j = ATMOS__WL(k, i);
            const double x = a->beta_sl[j] * depth, ts0 = a->beta_sl[j] * ey / (a->gamma * ly);
            out[i] = P * a->sun_e[j] * x * exp(-ts0) * atmos__sky_g(c * x);
        }
        return 1;
    }
    const double G = atmos__sky_view_depth_factor(a->gamma, py, dist);
    const double e_end = isinf(dist) ? (py > 0 ? 0.0 : INFINITY) : exp(-a->gamma * py * dist);
    const double ey = exp(-a->gamma * y);
    for (int i = 0; i < m; i++) {
        const int j = ATMOS__WL(k, i);
        out[i] = P * a->sun_e[j] * atmos__sky_inscatter_factor(a->gamma, a->beta_sl[j] * ey, G, ly, py, e_end);
    }
    return 1;
}

/* The point by the optical depth of wavelength h from y, an exponential truncated to
 * [0, tau_h(dist)]; along the ray tau_h(t) = beta_h(y) G(t) with G(t) = t g(gamma p_y t)
 * inverted in closed form. The other wavelengths share the density profile, so
 * sigma_i / sigma_h = beta_sl,i / beta_sl,h and T_i / T_h = exp(-(beta_i - beta_h) G). */
int atmos__riley_scatter_point(const atmos_atmosphere *a, double y, const double d[3], double dist, int m,
                               const int *k, const double *w, atmos__stream *rng, double *t, double *ratio)
{
    int h = -1;
    for (int i = 0; i < m; i++)
        if (w[i] != 0 && (h < 0 || a->beta_sl[ATMOS__WL(k, i)] < a->beta_sl[ATMOS__WL(k, h)])) h = i;
    if (h < 0) return 0;
    const double py = d[1], bsh = a->beta_sl[ATMOS__WL(k, h)];
    const double G = atmos__sky_view_depth_factor(a->gamma, py, dist);
    const double ey = exp(-a->gamma * y);
    const double bh = bsh * ey;
    const double A = isinf(G) ? 1.0 : -expm1(-bh * G);
    if (!(A > 0)) return 0;
    const double Ga = -log1p(-atmos__stream_u(rng) * A) / bh; /* G at the point */
    const double z = a->gamma * py;
    double ta = fabs(z * Ga) < 1e-12 ? Ga : -log1p(-z * Ga) / z;
    if (!(ta >= 0)) return 0;
    if (ta > dist) ta = dist;
    *t = ta;
    for (int i = 0; i < m; i++) {
        const double bk = a->beta_sl[ATMOS__WL(k, i)];
        ratio[i] = bk / bsh * exp(-(bk - bsh) * ey * Ga) * A;
    }
    return 1;
}
