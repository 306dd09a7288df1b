/* Small 3-vector and scalar helpers shared by the renderers, the geometry code and the
 * atmosphere's tables. */
#ifndef ATMOS_CORE_VEC_H
#define ATMOS_CORE_VEC_H

#include <math.h>

/* The larger and the smaller of two numbers that are not NaN (a compare and a select, where
 * fmax and fmin may be library calls for their NaN rules). */
static inline double atmos__maxd(double a, double b) { return a > b ? a : b; }
static inline double atmos__mind(double a, double b) { return a < b ? a : b; }

/* x limited to [lo, hi]. */
static inline double atmos__clampd(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

static inline double atmos__dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void atmos__cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* Scales a to unit length; a zero vector stays zero. */
static inline void atmos__normalize3(double a[3])
{
    double l = sqrt(atmos__dot3(a, a));
    if (l > 0) a[0] /= l, a[1] /= l, a[2] /= l;
}

/* Slab intersection of o + t d with the box [lo, hi]: 1 and the interval [*t0, *t1]
 * (unclipped, may start behind o) if the line meets it, else 0. */
int atmos__ray_box(const double o[3], const double d[3], const double lo[3], const double hi[3], double *t0,
                   double *t1);

#endif
