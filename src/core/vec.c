/* Geometry helpers of core/vec.h that are too long to inline. */
#include "core/vec.h"

int atmos__ray_box(const double o[3], const double d[3], const double lo[3], const double hi[3], double *t0,
                   double *t1)
{
    double a = -INFINITY, b = INFINITY;
    for (int i = 0; i < 3; i++) {
        if (fabs(d[i]) < 1e-300) {
            if (o[i] < lo[i] || o[i] > hi[i]) return 0;
            continue;
        }
        double ta = (lo[i] - o[i]) / d[i], tb = (hi[i] - o[i]) / d[i];
        if (ta > tb) {
            double s = ta;
            ta = tb, tb = s;
        }
        if (ta > a) a = ta;
        if (tb < b) b = tb;
    }
    if (a > b) return 0;
    *t0 = a, *t1 = b;
    return 1;
}
