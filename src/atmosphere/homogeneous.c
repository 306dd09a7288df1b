/* A layer of air of uniform density from the ground (y = 0) to the height H
 * (desc.thickness_m) over a flat earth: the scattering coefficient is beta_sl (Riley's
 * sea-level values) inside and 0 above, albedo 1, the Rayleigh phase function, collimated
 * sunlight. Every answer is closed form:
 *
 *   a segment p + t d meets the layer in one interval [ta, tb] (the layer is convex);
 *   transmittance  T = exp(-beta (tb - ta))
 *   sunlight at altitude y < H:  E = E_sun exp(-beta (H - y) / l_y)
 *   in-scatter     L = P(theta) E_sun beta e^{-beta (H - y_a)/l_y} S g(beta c S),
 *                  S = tb - ta, c = 1 - p_y / l_y, y_a the altitude at ta, g(z) = (1 - e^-z)/z
 *
 * because along the segment the optical depth to the eye plus the sun's grows linearly,
 * at the rate beta c. The test cases use it to check that renderers know nothing of a
 * kind's insides; a scene may use it as a fog layer. */
#include "atmosphere/atmosphere_internal.h"

#include <math.h>

/* The part [*ta, *tb] of p + t d, t in [0, dist], inside 0 <= y <= H (y0 >= 0 is p's
 * altitude); 0 if none. */
static int layer_interval(double H, double y0, double py, double dist, double *ta, double *tb)
{
    double a = 0.0, b = dist;
    if (py > 0) {
        if (y0 >= H) return 0;
        b = fmin(b, (H - y0) / py);
    } else if (py < 0) {
        if (y0 > H) a = (H - y0) / py;
        b = fmin(b, y0 / -py);
    } else if (y0 > H) {
        return 0;
    }
    if (!(a < b)) return 0;
    *ta = a, *tb = b;
    return 1;
}

void atmos__homog_transmittance(const atmos_atmosphere *a, double y, const double d[3], double dist, int m,
                                const int *k, double *out)
{
    double ta, tb;
    const int in = layer_interval(a->desc.thickness_m, y, d[1], dist, &ta, &tb);
    for (int i = 0; i < m; i++) out[i] = in ? exp(-a->beta_sl[ATMOS__WL(k, i)] * (tb - ta)) : 1.0;
}

void atmos__homog_sunlight(const atmos_atmosphere *a, double y, const double sun[3], int m, const int *k, double *out)
{
    const double ly = sun[1], depth = fmax(a->desc.thickness_m - y, 0.0);
    for (int i = 0; i < m; i++) {
        const int j = ATMOS__WL(k, i);
        out[i] = ly > 0 ? a->sun_e[j] * exp(-a->beta_sl[j] * depth / ly) : 0.0;
    }
}

int atmos__homog_inscatter(const atmos_atmosphere *a, double y, const double d[3], double dist, const double sun[3],
                           int m, const int *k, double *out)
{
    const double ly = sun[1];
    double ta, tb;
    for (int i = 0; i < m; i++) out[i] = 0.0;
    if (!(ly > 0)) return 0;
    if (!layer_interval(a->desc.thickness_m, y, d[1], dist, &ta, &tb)) return 1;
    const double S = tb - ta, c = 1.0 - d[1] / ly;
    const double ya = fmin(y + ta * d[1], a->desc.thickness_m);
    const double P = atmos_phase_rayleigh(d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2]);
    for (int i = 0; i < m; i++) {
        const int j = ATMOS__WL(k, i);
        const double b = a->beta_sl[j];
        const double es = b * (a->desc.thickness_m - ya) / ly; /* sun's optical depth at the segment's start */
        if (c < 0 && -b * c * S > 700.0) {
            /* A view much steeper than a low sun: the start's e^{-es} underflows while
             * the integral's e^{-b c S} overflows (0 * inf). Written from the segment's end,
             * where the integrand peaks: e^{-(es + b c S)} S g(-b c S). */
            out[i] = P * a->sun_e[j] * b * exp(-(es + b * c * S)) * S * atmos__sky_g(-b * c * S);
            continue;
        }
        /* S g(b c S) = integral of e^{-b c s} over [0, S]; S infinite only for a level ray (c = 1) */
        const double integral = isinf(S) ? 1.0 / (b * c) : S * atmos__sky_g(b * c * S);
        out[i] = P * a->sun_e[j] * b * exp(-es) * integral;
    }
    return 1;
}

/* s = t - ta exponential with rate beta_h truncated to [0, S]; ratio_i = (b_i / b_h)
 * e^{-(b_i - b_h) s} A with A = 1 - e^{-b_h S}. */
int atmos__homog_scatter_point(const atmos_atmosphere *a, double y, const double d[3], double dist, int m,
                               const int *k, const double *w, atmos__stream *rng, double *t, double *ratio)
{
    double ta, tb;
    int h = -1;
    for (int i = 0; i < m; i++)
        if (w[i] != 0 && (h < 0 || a->beta_sl[ATMOS__WL(k, i)] < a->beta_sl[ATMOS__WL(k, h)])) h = i;
    if (h < 0 || !layer_interval(a->desc.thickness_m, y, d[1], dist, &ta, &tb)) return 0;
    const double bh = a->beta_sl[ATMOS__WL(k, h)], S = tb - ta;
    const double A = isinf(S) ? 1.0 : -expm1(-bh * S);
    if (!(A > 0)) return 0;
    double s = -log1p(-atmos__stream_u(rng) * A) / bh;
    if (!(s >= 0)) return 0;
    if (s > S) s = S;
    *t = ta + s;
    for (int i = 0; i < m; i++) {
        const double bk = a->beta_sl[ATMOS__WL(k, i)];
        ratio[i] = bk / bh * exp(-(bk - bh) * s) * A;
    }
    return 1;
}
