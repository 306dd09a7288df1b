/* The spherical planet's geometry and numerics (planet.h): ray-sphere distances and the
 * optical depth of a segment by quadrature, with which the solvers' tables are built and
 * tested (brute-force single scattering: planet_numeric.c). */
#include "atmosphere/planet.h"

#include "core/vec.h"

#include <math.h>

double atmos__planet_radius(const atmos__planet *pl, const double p[3])
{
    const double y = p[1] + pl->r_ground;
    return sqrt(p[0] * p[0] + y * y + p[2] * p[2]);
}

double atmos__planet_altitude(const atmos__planet *pl, const double p[3])
{
    return atmos__planet_radius(pl, p) - pl->r_ground;
}

double atmos__planet_mu(const atmos__planet *pl, const double p[3], const double d[3])
{
    const double r = atmos__planet_radius(pl, p);
    return r > 0 ? (p[0] * d[0] + (p[1] + pl->r_ground) * d[1] + p[2] * d[2]) / r : 1.0;
}

/* Roots of |q + t d|^2 = r^2 with q = p - centre: t = -b +- sqrt(b^2 - c), b = q.d,
 * c = |q|^2 - r^2; the small root computed without cancellation. */
static int sphere_roots(const atmos__planet *pl, const double p[3], const double d[3], double r, double *ta,
                        double *tb)
{
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double b = atmos__dot3(q, d), c = atmos__dot3(q, q) - r * r;
    const double disc = b * b - c;
    if (disc < 0) return 0;
    const double s = sqrt(disc), big = b > 0 ? -b - s : -b + s;
    const double other = big != 0 ? c / big : 0.0;
    *ta = fmin(big, other);
    *tb = fmax(big, other);
    return 1;
}

double atmos__planet_sphere_hit(const atmos__planet *pl, const double p[3], const double d[3], double r)
{
    double ta, tb;
    if (!sphere_roots(pl, p, d, r, &ta, &tb)) return INFINITY;
    if (ta >= 0) return ta;
    if (tb >= 0) return tb;
    return INFINITY;
}

double atmos__planet_ground_distance(const atmos__planet *pl, const double p[3], const double d[3])
{
    const double r = atmos__planet_radius(pl, p);
    const double mu = atmos__planet_mu(pl, p, d);
    if (r <= pl->r_ground) return mu < 0 || r < pl->r_ground ? 0.0 : INFINITY;
    double ta, tb;
    if (!sphere_roots(pl, p, d, pl->r_ground, &ta, &tb) || ta < 0) return INFINITY;
    return ta;
}

int atmos__planet_clip(const atmos__planet *pl, const double p[3], const double d[3], double dist, double *t0,
                       double *t1)
{
    double ta, tb;
    if (!sphere_roots(pl, p, d, pl->r_top, &ta, &tb)) return 0;
    double a = fmax(ta, 0.0), b = fmin(tb, dist);
    b = fmin(b, atmos__planet_ground_distance(pl, p, d));
    if (!(b > a)) return 0;
    *t0 = a, *t1 = b;
    return 1;
}

void atmos__planet_ground_point(const atmos__planet *pl, double p[3], double n[3])
{
    const double r = atmos__planet_radius(pl, p);
    double up[3] = {p[0], p[1] + pl->r_ground, p[2]};
    if (r > 0) up[0] /= r, up[1] /= r, up[2] /= r;
    else up[0] = 0, up[1] = 1, up[2] = 0;
    for (int i = 0; i < 3; i++) {
        n[i] = up[i];
        p[i] = up[i] * pl->r_ground;
    }
    p[1] -= pl->r_ground;
}

double atmos__planet_sun_frame(const double q[3], const double sun[3], double up[3], double e1[3], double e2[3])
{
    const double r = sqrt(atmos__dot3(q, q));
    for (int i = 0; i < 3; i++) up[i] = r > 0 ? q[i] / r : (i == 1);
    const double mu_s = atmos__dot3(up, sun);
    double t[3] = {sun[0] - mu_s * up[0], sun[1] - mu_s * up[1], sun[2] - mu_s * up[2]};
    double len = sqrt(atmos__dot3(t, t));
    if (len < 1e-9) { /* the sun at the zenith or nadir: any horizontal axis */
        const double a[3] = {fabs(up[0]) < 0.9 ? 1.0 : 0.0, fabs(up[0]) < 0.9 ? 0.0 : 1.0, 0.0};
        const double c = atmos__dot3(a, up);
        for (int i = 0; i < 3; i++) t[i] = a[i] - c * up[i];
        len = sqrt(atmos__dot3(t, t));
    }
    for (int i = 0; i < 3; i++) e1[i] = t[i] / len;
    atmos__cross3(up, e1, e2);
    return mu_s;
}

double atmos__planet_dist_top(const atmos__planet *pl, double r, double mu)
{
    const double disc = r * r * (mu * mu - 1.0) + pl->r_top * pl->r_top;
    return fmax(0.0, -r * mu + sqrt(fmax(disc, 0.0)));
}

double atmos__planet_dist_ground(const atmos__planet *pl, double r, double mu)
{
    const double disc = r * r * (mu * mu - 1.0) + pl->r_ground * pl->r_ground;
    if (mu >= 0 || disc < 0) return INFINITY;
    return fmax(0.0, -r * mu - sqrt(disc));
}

/* ------------------------------------------------------------------ quadrature */

/* Composite 4-point Gauss-Legendre over QN equal pieces of the clipped segment: for a
 * horizontal ray from the ground (1130 km to a 100 km top) a piece is 18 km long but the
 * ray rises only 25 m over the first one; a vertical piece of 1.6 km spans 1.3 aerosol
 * scale heights, where the 4-point rule is exact to ~1e-7. */
#define QN 64
static const double gl_x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
static const double gl_w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};

void atmos__planet_optical_depth(const atmos__planet *pl, const double p[3], const double d[3], double dist, int m,
                                 const int *k, double *out)
{
    for (int i = 0; i < m; i++) out[i] = 0.0;
    double t0, t1;
    if (!atmos__planet_clip(pl, p, d, dist, &t0, &t1)) return;
    const double piece = (t1 - t0) / QN;
    for (int s = 0; s < QN; s++) {
        const double mid = t0 + (s + 0.5) * piece;
        for (int g = 0; g < 4; g++) {
            const double t = mid + 0.5 * piece * gl_x[g], w = 0.5 * piece * gl_w[g];
            const double x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
            const double h = atmos__planet_altitude(pl, x);
            for (int i = 0; i < m; i++) out[i] += w * atmos__planet_extinction(pl, h, k ? k[i] : i);
        }
    }
}

void atmos__planet_sun_transmittance(const atmos__planet *pl, const double p[3], const double sun[3], int m,
                                     const int *k, double *out)
{
    double q[3] = {p[0], p[1], p[2]};
    int on_ground = 0;
    if (atmos__planet_radius(pl, q) < pl->r_ground) {
        double n[3];
        atmos__planet_ground_point(pl, q, n);
        on_ground = 1;
    }
    /* a point moved onto the ground may land a rounding error below it, where the ground
     * test would hide every sun: there the horizon decides */
    const int hidden = on_ground ? atmos__planet_mu(pl, q, sun) < 0
                                 : atmos__planet_ground_distance(pl, q, sun) < INFINITY;
    if (hidden) {
        for (int i = 0; i < m; i++) out[i] = 0.0;
        return;
    }
    atmos__planet_optical_depth(pl, q, sun, INFINITY, m, k, out);
    for (int i = 0; i < m; i++) out[i] = exp(-out[i]);
}
