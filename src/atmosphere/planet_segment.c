/* The sunlight scattered once along a flight segment of the Monte Carlo reference
 * (planet_track.h): one point t of the segment p + t d, t in [0, tmax], drawn from a density
 * q fitted to the integrand sigma_s(t) P(t) T(p, t) T_sun(t), gives
 * sigma_s P T(p, t) T_sun(t) / q(t): an unbiased estimate of the segment's single scattering
 * whatever q is, as long as q > 0 wherever the integrand is. Both transmittances are computed
 * by quadrature (atmos__planet_depth1: Gauss-Legendre on pieces cut by altitude; its error,
 * below 1e-6 of the optical depth, is the estimator's only bias), not by ratio tracking: ratio tracking under a tight majorant
 * has a relative variance of e^{tau r} - 1 (r = sigma / majorant), and the sun's and the
 * view's paths near the horizon reach tau = 3-15 (a relative standard deviation of 5 per
 * shadow ray along 50 km of a horizontal ray at 440 nm).
 *
 * q is a mixture: 80 % a piecewise log-linear density over SEG_N equal cells fitted to the
 * integrand at the cells' ends — sigma_s P, the view's transmittance by the trapezoid rule,
 * the planet's shadow exactly, the sun's transmittance from an approximate Chapman function —
 * so that the steep decay of the air along a horizontal ray is followed within a cell; 20 %
 * uniform over the segment (a defence where the fit is poor). Unlike next-event
 * estimation at the walk's collisions, every segment contributes — in thin air most flights
 * cross without a collision — and at twilight the points go to the lit air high up, not to
 * the dense air in the planet's shadow where the collisions fall. */
#include "atmosphere/planet_track.h"

#include "core/vec.h"

#include <math.h>

#define SEG_N 16
#define SEG_UNIFORM 0.2

/* The fitted integrand over cell j (from t_j, length dt): log-linear between its ends g0, g1
 * when both are positive (rate a), else constant at their mean. */
typedef struct {
    double g0, a, mass;
} seg_cell;

static void make_cell(double g0, double g1, double dt, seg_cell *c)
{
    if (g0 > 0 && g1 > 0) {
        double a = log(g1 / g0) / dt;
        if (a * dt > 700) a = 700 / dt;
        if (a * dt < -700) a = -700 / dt;
        c->g0 = g0, c->a = a;
        c->mass = fabs(a * dt) < 1e-9 ? g0 * dt : g0 * expm1(a * dt) / a;
    } else {
        c->g0 = 0.5 * (g0 + g1), c->a = 0, c->mass = c->g0 * dt;
    }
}

/* The column of an exponential profile (scale height H, 1 at the ground) from radius r to
 * space along a direction of zenith cosine mu, approximately: rising, the Chapman function
 * ch(x, mu) interpolated as c / ((c - 1) mu + 1), c = sqrt(pi x / 2), x = r / H (1 at the
 * zenith, the large-x horizontal value sqrt(pi x / 2) at mu = 0); sinking, the whole grazing
 * path through the perigee less the part behind the point. Only the sampling density uses it. */
static double column(double R, double r, double mu, double H)
{
    const double c = sqrt(ATMOS_PI * r / (2.0 * H)), rho = exp(-(r - R) / H);
    const double up = rho * H * c / ((c - 1.0) * fabs(mu) + 1.0);
    if (mu >= 0) return up;
    const double rp = r * sqrt(fmax(0.0, 1.0 - mu * mu));
    return fmax(2.0 * exp(-(rp - R) / H) * H * sqrt(ATMOS_PI * rp / (2.0 * H)) - up, 0.0);
}

/* The integrand's fit at a point t of the segment, without the view's transmittance: the
 * scattering toward the eye times an approximate transmittance of the sunlight (0 in the
 * planet's shadow); *ext: the extinction there. */
static double fit_at(const atmos__planet *pl, const double p[3], const double d[3], const double sun[3], double t, int k,
                     double PR, double PM, double *ext)
{
    const double x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
    const double h = atmos__planet_altitude(pl, x);
    *ext = atmos__planet_extinction(pl, h, k);
    if (atmos__planet_hit_ground(pl, x, sun) < INFINITY) return 0.0;
    const double r = h + pl->r_ground, mu = atmos__planet_mu(pl, x, sun);
    const double tau = pl->rayleigh[k] * column(pl->r_ground, r, mu, pl->h_rayleigh) +
                       pl->mie_ext[k] * column(pl->r_ground, r, mu, pl->h_mie);
    return (pl->rayleigh[k] * atmos__planet_rho_rayleigh(pl, h) * PR +
            pl->mie_sca[k] * atmos__planet_rho_mie(pl, h) * PM) *
           exp(-fmin(tau, 700.0));
}

/* Altitude steps (m above the lowest point of a monotone branch) at which the optical depth's
 * quadrature cuts the ray: 0.5 km near the lowest point (0.4 aerosol scale heights), growing
 * with the altitude, where the air thins out. */
static const double STEPS[] = {0,     500,   1000,  1500,  2000,  3000,  4000,  5000,  6500,  8000,  10000,
                               12500, 15000, 20000, 25000, 30000, 40000, 50000, 65000, 80000, 1e300};
#define NSTEPS ((int)(sizeof STEPS / sizeof STEPS[0]))

/* 4-point Gauss-Legendre of the extinction over [ta, tb] of the ray (b, pp as in planet_track.c). */
static double gl4(const atmos__planet *pl, double b, double pp, double ta, double tb, int k)
{
    static const double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
    static const double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
    const double mid = 0.5 * (ta + tb), half = 0.5 * (tb - ta);
    double s = 0;
    for (int g = 0; g < 4; g++) {
        const double t = mid + half * x[g], h = sqrt(pp + (b + t) * (b + t)) - pl->r_ground;
        s += w[g] * atmos__planet_extinction(pl, h, k);
    }
    return s * half;
}

/* The optical depth of p + t d, t in [t0, t1] inside the air, at wavelength k: each monotone
 * branch of the ray (falling to the perigee, rising after it) cut where it crosses the
 * altitudes STEPS above the branch's lowest point and the corners of ozone's tent profile,
 * 4-point Gauss-Legendre on each piece
 * (about 80 points a branch where planet.c's general quadrature takes 256; within 1e-6 of it,
 * tests/unit/test_planet_reference.c). */
double atmos__planet_depth1(const atmos__planet *pl, const double p[3], const double d[3], double t0, double t1, int k)
{
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double b = atmos__dot3(q, d), pp = fmax(atmos__dot3(q, q) - b * b, 0.0), tp = -b;
    double tau = 0;
    for (int br = 0; br < 2; br++) {
        /* branch 0: [t0, min(t1, tp)] falling; branch 1: [max(t0, tp), t1] rising */
        const double a = br ? fmax(t0, tp) : t0, e = br ? t1 : fmin(t1, tp);
        if (!(e > a)) continue;
        const double tlow = br ? a : e; /* the branch's lowest point */
        const double rlow = sqrt(pp + (b + tlow) * (b + tlow));
        /* the cuts: STEPS, and the ozone tent's three corners above the lowest point */
        double cut[NSTEPS + 3];
        int nc = 0;
        for (int j = 0; j < NSTEPS; j++) cut[nc++] = STEPS[j];
        const double corner[3] = {pl->ozone_centre - pl->ozone_half_width, pl->ozone_centre,
                                  pl->ozone_centre + pl->ozone_half_width};
        for (int j = 0; j < 3; j++) {
            const double c = corner[j] - (rlow - pl->r_ground);
            if (!(c > 0)) continue;
            int i = nc++;
            while (i > 0 && cut[i - 1] > c) cut[i] = cut[i - 1], i--;
            cut[i] = c;
        }
        double prev = tlow;
        for (int j = 1; j < nc; j++) {
            const double rr = rlow + cut[j];
            double u = rr * rr - pp > 0 ? sqrt(rr * rr - pp) : 0.0; /* |b + t| where the ray reaches rr */
            double t = br ? -b + u : -b - u;
            if (br ? t >= e : t <= a) t = br ? e : a;
            tau += br ? gl4(pl, b, pp, prev, t, k) : gl4(pl, b, pp, t, prev, k);
            prev = t;
            if (t == (br ? e : a)) break;
        }
    }
    return tau;
}

double atmos__planet_segment_sun(const atmos__planet *pl, const double p[3], const double d[3], double tmax,
                                 const double sun[3], int k, atmos__stream *r)
{
    if (!(tmax > 0) || !isfinite(tmax)) return 0.0;
    const double nu = atmos__dot3(d, sun), PR = atmos__planet_rayleigh_phase(pl, k, nu), PM = atmos__planet_mie_phase(pl, k, nu);
    const double dt = tmax / SEG_N;
    seg_cell cell[SEG_N];
    double cdf[SEG_N + 1], tau = 0, e0, e1;
    double g0 = fit_at(pl, p, d, sun, 0.0, k, PR, PM, &e0);
    cdf[0] = 0;
    for (int j = 0; j < SEG_N; j++) {
        double g1 = fit_at(pl, p, d, sun, (j + 1) * dt, k, PR, PM, &e1);
        const double tau1 = tau + 0.5 * (e0 + e1) * dt;
        make_cell(g0 * exp(-tau), g1 * exp(-tau1), dt, &cell[j]);
        cdf[j + 1] = cdf[j] + cell[j].mass;
        g0 = g1, e0 = e1, tau = tau1;
    }
    const double total = cdf[SEG_N], uni = total > 0 ? SEG_UNIFORM : 1.0;
    const double u = atmos__stream_u(r);
    double t;
    if (u < uni) {
        t = tmax * atmos__stream_u(r);
    } else {
        const double target = (u - uni) / (1.0 - uni) * total;
        int lo = 0, hi = SEG_N - 1;
        while (lo < hi) {
            const int mid = (lo + hi) / 2;
            if (cdf[mid + 1] > target) hi = mid;
            else lo = mid + 1;
        }
        while (lo < SEG_N - 1 && !(cell[lo].mass > 0)) lo++;
        const seg_cell *c = &cell[lo];
        const double v = atmos__stream_u(r);
        const double s = c->a == 0 ? v * dt : log1p(v * expm1(c->a * dt)) / c->a;
        t = lo * dt + fmin(fmax(s, 0.0), dt);
    }
    int j = (int)(t / dt);
    if (j > SEG_N - 1) j = SEG_N - 1;
    if (j < 0) j = 0;
    const double fit = cell[j].g0 * exp(cell[j].a * (t - j * dt));
    const double q = uni / tmax + (total > 0 ? (1.0 - uni) * fit / total : 0.0);
    const double x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
    const double h = atmos__planet_altitude(pl, x);
    const double sca = pl->rayleigh[k] * atmos__planet_rho_rayleigh(pl, h) * PR +
                       pl->mie_sca[k] * atmos__planet_rho_mie(pl, h) * PM;
    if (!(sca > 0) || !(q > 0)) return 0.0;
    const double Ts = atmos__planet_sun_depth_transmittance(pl, x, sun, k);
    if (!(Ts > 0)) return 0.0;
    return sca * Ts * exp(-atmos__planet_depth1(pl, p, d, 0.0, t, k)) / q;
}

double atmos__planet_sun_depth_transmittance(const atmos__planet *pl, const double p[3], const double sun[3], int k)
{
    if (atmos__planet_hit_ground(pl, p, sun) < INFINITY) return 0.0;
    return exp(-atmos__planet_depth1(pl, p, sun, 0.0, atmos__planet_exit_top(pl, p, sun), k));
}
