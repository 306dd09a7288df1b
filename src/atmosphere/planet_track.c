/* Free flights and transmittances through the spherical planet's air (planet_track.h).
 *
 * Along a ray p + t d the distance from the planet's centre is r(t) = sqrt(b_p^2 + (b + t)^2)
 * (b = q.d with q = p - centre, b_p the impact parameter): the altitude h(t) = r(t) - R is a
 * convex function of t, falling until the perigee t* = -b and rising after it. A convex
 * function lies above each of its tangent lines, so with the tangent line L(t) at a point the
 * exponential profiles obey sigma_c exp(-h(t)/H_c) <= sigma_c exp(-L(t)/H_c): a majorant
 * that is itself an exponential in t, whose free flights invert in closed form
 * (t = ln(1 + k E / A) / k for the rate A e^{k t}, no flight when 1 + k E / A <= 0). The
 * sum of the components' majorants (air molecules, aerosols, and for ozone's tent profile
 * its largest value over the segment) is sampled as a superposition of Poisson processes:
 * the first of the components' flights.
 *
 * The ray is cut into segments: rising, the tangent is taken at the segment's start (the
 * current point, exact there) and the segment ends where the ray has risen by max(2 km, h)
 * (this only tightens the ozone majorant); falling, it is taken at the segment's lowest
 * point, its end, and the segment ends where the ray has fallen by max(1 km, 0.3 h) or at
 * the perigee, so that the majorant exceeds the profile by at most e^{drop / H} at the
 * segment's start. After every tentative collision and at every segment end the tracking
 * starts again from there with a fresh majorant; this is valid because the tentative
 * collisions are a Poisson process: what follows a stopping time depends only on the
 * majorant chosen then (the standard restart argument of delta tracking with piecewise
 * majorants). The estimators are therefore exact, whatever the segmentation: it affects
 * only the cost (the number of tentative collisions, about the majorant's optical depth)
 * and, for ratio tracking, the variance. Ratio tracking plays a Russian roulette once its
 * estimate falls below 0.01 (kept with probability T / 0.01, then 0.01): a shadow ray through
 * an optically thick path stops after a few optical depths instead of running to the end. */
#include "atmosphere/planet_track.h"

#include "core/vec.h"

#include <math.h>

#define RISE_MIN 2000.0
#define DROP_MIN 1000.0
#define DROP_FRAC 0.3
/* Transmittance below which ratio tracking plays a Russian roulette (survivors take it). */
#define RATIO_RR 0.01
/* Tentative collisions per call beyond which a flight or a shadow ray is abandoned (never
 * reached by the Earth's air: a vertical ray meets ~2, a horizontal one from the ground at
 * 400 nm ~40). */
#define GUARD 1000000

double atmos__planet_exit_top(const atmos__planet *pl, const double p[3], const double d[3])
{
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double b = atmos__dot3(q, d), c = atmos__dot3(q, q) - pl->r_top * pl->r_top;
    const double disc = b * b - c;
    if (disc < 0) return 0.0;
    const double s = sqrt(disc), t = b > 0 ? -c / (b + s) : s - b;
    return t > 0 ? t : 0.0;
}

double atmos__planet_hit_ground(const atmos__planet *pl, const double p[3], const double d[3])
{
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double b = atmos__dot3(q, d);
    if (b >= 0) return INFINITY;
    const double c = atmos__dot3(q, q) - pl->r_ground * pl->r_ground;
    if (c <= 0) return 0.0;
    const double disc = b * b - c;
    if (disc < 0) return INFINITY;
    return c / (sqrt(disc) - b);
}

/* The majorant of one segment [t, te] of the ray: the tangent line's value L0 at t and its
 * slope, and the ozone's constant part. */
typedef struct {
    double te, L0, slope, ozone;
} segment;

static void make_segment(const atmos__planet *pl, double pp, double b, double t, double tmax, int k, segment *s)
{
    const double R = pl->r_ground, rc = sqrt(pp + (b + t) * (b + t)), hc = rc - R;
    double hlo, hhi;
    if (b + t < 0) {
        const double rr = rc - fmax(DROP_MIN, DROP_FRAC * hc);
        double te = rr * rr > pp ? -b - sqrt(rr * rr - pp) : -b;
        if (!(te > t)) te = -b;
        if (te > tmax) te = tmax;
        const double re = sqrt(pp + (b + te) * (b + te)), se = re > 0 ? (b + te) / re : 0.0;
        s->te = te;
        s->slope = se;
        s->L0 = (re - R) + se * (t - te);
        hlo = re - R, hhi = hc;
    } else {
        const double rr = rc + fmax(RISE_MIN, hc);
        const double te = fmin(tmax, -b + sqrt(fmax(rr * rr - pp, 0.0)));
        s->te = te > t ? te : tmax;
        s->slope = rc > 0 ? (b + t) / rc : 1.0;
        s->L0 = hc;
        hlo = hc, hhi = sqrt(pp + (b + s->te) * (b + s->te)) - R;
    }
    s->ozone = 0;
    if (pl->ozone[k] > 0) {
        const double c = pl->ozone_centre;
        const double m = c >= hlo && c <= hhi ? 1.0
                                              : fmax(atmos__planet_rho_ozone(pl, hlo), atmos__planet_rho_ozone(pl, hhi));
        s->ozone = pl->ozone[k] * m;
    }
}

/* The distance to the first arrival of the Poisson process of rate A e^{kk u}, u >= 0. */
static double arrival(double A, double kk, double u01)
{
    if (!(A > 0)) return INFINITY;
    const double E = -log1p(-u01);
    if (kk == 0) return E / A;
    const double x = kk * E / A;
    return x > -1 ? log1p(x) / kk : INFINITY;
}

/* Tracking along p + t d, t in [0, tmax]: delta tracking (ratio == 0; returns the first real
 * collision or tmax) or ratio tracking (returns the transmittance estimate). */
static double track(const atmos__planet *pl, const double p[3], const double d[3], double tmax, int k,
                    atmos__stream *r, int ratio)
{
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double b = atmos__dot3(q, d), pp = fmax(atmos__dot3(q, q) - b * b, 0.0);
    const double sR = pl->rayleigh[k], sM = pl->mie_ext[k], HR = pl->h_rayleigh, HM = pl->h_mie;
    double t = 0, T = 1;
    if (!(tmax > 0)) return ratio ? 1.0 : 0.0;
    for (int guard = 0; t < tmax && guard < GUARD; guard++) {
        segment s;
        make_segment(pl, pp, b, t, tmax, k, &s);
        const double L0 = s.L0;
        const double AR = sR * exp(-L0 / HR), AM = sM * exp(-L0 / HM);
        double u = arrival(AR, -s.slope / HR, atmos__stream_u(r));
        u = fmin(u, arrival(AM, -s.slope / HM, atmos__stream_u(r)));
        if (s.ozone > 0) u = fmin(u, -log1p(-atmos__stream_u(r)) / s.ozone);
        if (!(t + u < s.te)) {
            t = s.te;
            continue;
        }
        t += u;
        const double h = sqrt(pp + (b + t) * (b + t)) - pl->r_ground;
        const double Lt = L0 + s.slope * u;
        const double maj = sR * exp(-Lt / HR) + sM * exp(-Lt / HM) + s.ozone;
        const double ext = atmos__planet_extinction(pl, h, k);
        const double f = maj > 0 ? ext / maj : 0.0;
        if (ratio) {
            T *= f < 1 ? 1.0 - f : 0.0;
            if (!(T > 0)) return 0.0;
            if (T < RATIO_RR) {
                /* Russian roulette: deep shadow rays stop early, unbiased */
                if (atmos__stream_u(r) * RATIO_RR >= T) return 0.0;
                T = RATIO_RR;
            }
        } else if (atmos__stream_u(r) < f) {
            return t;
        }
    }
    return ratio ? T : tmax;
}

double atmos__planet_free_flight(const atmos__planet *pl, const double p[3], const double d[3], double tmax, int k,
                                 atmos__stream *r)
{
    return track(pl, p, d, tmax, k, r, 0);
}

double atmos__planet_ratio_track(const atmos__planet *pl, const double p[3], const double d[3], double tmax, int k,
                                 atmos__stream *r)
{
    return track(pl, p, d, tmax, k, r, 1);
}

double atmos__planet_sun_track(const atmos__planet *pl, const double p[3], const double sun[3], int k,
                               atmos__stream *r)
{
    if (atmos__planet_hit_ground(pl, p, sun) < INFINITY) return 0.0;
    return atmos__planet_ratio_track(pl, p, sun, atmos__planet_exit_top(pl, p, sun), k, r);
}
