/* Angle grids, their lookup table, and the density a tabulated phase function is sampled
 * from (angle_table.h). */
#include "optics/angle_table.h"

#include "core/internal.h"

#include <math.h>

int atmos__angle_segments(const atmos__angle_segment *seg, int count, double *out, int cap)
{
    int n = 0;
    for (int s = 0; s < count; s++) {
        const int steps = (int)lround((seg[s].to - seg[s].from) / seg[s].step);
        for (int i = 0; i < steps; i++) {
            if (n >= cap) return 0;
            out[n++] = seg[s].from + i * seg[s].step;
        }
    }
    if (n >= cap) return 0;
    out[n++] = 180.0;
    return n;
}

int atmos__angle_grid_init(atmos__angle_grid *g, const double *deg, int n)
{
    if (n < 2 || n > ATMOS__ANGLE_MAX || deg[0] != 0.0 || deg[n - 1] != 180.0) return 0;
    for (int i = 0; i + 1 < n; i++)
        if (!(deg[i] < deg[i + 1])) return 0;
    g->n = n;
    for (int i = 0; i < n; i++) {
        g->deg[i] = deg[i];
        g->rad[i] = deg[i] * ATMOS_DEG2RAD;
        g->sin[i] = sin(g->rad[i]);
    }
    /* lut[j] = the last i with bin(deg[i]) < j (0 for j = 0, where there is none: deg[0] = 0
     * is in bin 0). Every bin an angle inside the grid can fall in is covered:
     * bin(theta) <= bin(180) = 3600, and the reader reads lut[bin + 1]. */
    int i = 0;
    for (int j = 0; j < ATMOS__ANGLE_LUT; j++) {
        while (i + 1 < n && atmos__angle_bin(deg[i + 1]) < j) i++;
        g->lut[j] = (uint16_t)i;
    }
    return 1;
}

void atmos__angle_density_weights(const atmos__angle_grid *g, double mu, atmos__angle_weights *a)
{
    if (!(mu > -1)) mu = -1;
    if (mu > 1) mu = 1;
    const double th = acos(mu);
    const int i = atmos__angle_find(g, th * ATMOS_RAD2DEG);
    const double h = g->rad[i + 1] - g->rad[i];
    double s = (th - g->rad[i]) / h;
    if (s < 0) s = 0;
    if (s > 1) s = 1;
    a->i = i;
    a->s = s;
    if (i == 0) {
        a->w0 = 0;
        a->w1 = (th > 1e-12 ? th / sin(th) : 1.0) / h;
    } else if (i == g->n - 2) {
        const double e = ATMOS_PI - th;
        a->w0 = (e > 1e-12 ? e / sin(th) : 1.0) / h;
        a->w1 = 0;
    } else {
        const double is = 1.0 / sin(th);
        a->w0 = (1 - s) * is;
        a->w1 = s * is;
    }
}

double atmos__angle_invert(const atmos__angle_grid *g, const double *c, int i, double u, double f0, double f1)
{
    const double h = g->rad[i + 1] - g->rad[i], mass = c[i + 1] - c[i];
    double x = 0.0; /* offset into the interval, radians */
    if (mass > 0 && h > 0) {
        /* f is linear on [0, h] from f0 to f1: its integral to x, f0 x + (f1 - f0) x^2 / (2h),
         * equals the fraction (u - c_i) / mass of the interval's (f0 + f1) h / 2; the root
         * written as 2r / (f0 + sqrt(f0^2 + 2 (f1 - f0) r / h)) has no cancellation. */
        const double r = (u - c[i]) / mass * 0.5 * (f0 + f1) * h;
        double disc = f0 * f0 + 2.0 * (f1 - f0) * r / h;
        if (disc < 0) disc = 0;
        const double den = f0 + sqrt(disc);
        x = den > 0 ? 2.0 * r / den : 0.0;
        if (x < 0) x = 0;
        if (x > h) x = h;
    }
    const double mu = cos(g->rad[i] + x);
    return mu < -1 ? -1 : mu > 1 ? 1 : mu;
}
