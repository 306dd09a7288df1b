/* Cameras: pinhole, equidistant fisheye, equirectangular. */
#include "core/internal.h"

#include <math.h>

void atmos_direction_from_angles(double elevation_deg, double azimuth_deg, double dir[3])
{
    double e = elevation_deg * ATMOS_DEG2RAD, a = azimuth_deg * ATMOS_DEG2RAD;
    double ce = cos(e);
    /* x east, y up, z south: north is -z, azimuth clockwise from north towards east. */
    dir[0] = ce * sin(a);
    dir[1] = sin(e);
    dir[2] = -ce * cos(a);
}

void atmos_direction_to_angles(const double dir[3], double *elevation_deg, double *azimuth_deg)
{
    double h = sqrt(dir[0] * dir[0] + dir[2] * dir[2]);
    double e = atan2(dir[1], h) * ATMOS_RAD2DEG;
    double a = h > 0 ? atan2(dir[0], -dir[2]) * ATMOS_RAD2DEG : 0.0;
    if (a < 0) a += 360.0;
    if (a >= 360.0) a -= 360.0;
    if (elevation_deg) *elevation_deg = e;
    if (azimuth_deg) *azimuth_deg = a;
}
