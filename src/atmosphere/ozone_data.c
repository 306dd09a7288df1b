/* Ozone's absorption cross-section in the visible (the Chappuis band and the tail of the
 * Huggins bands): the measurements of Serdyuchenko et al. 2014 and Gorshelev et al. 2014
 * (Atmos. Meas. Tech. 7, 609-624 and 625-636; University of Bremen ozone reference spectra,
 * 233 K) averaged over 10 nm bins, as published in Bruneton's 2017 precomputed atmospheric
 * scattering demo: entry i is the mean over [360 + 10 i, 370 + 10 i] nm and is placed at the
 * bin's centre. In the Chappuis band the cross-section changes by about 1 % between 223 K
 * and 293 K (Gorshelev et al. 2014), less than the spread between data sets. */
#include "atmosphere/planet_optics.h"

#include <math.h>

#define O3_N 48
#define O3_FIRST_NM 365.0
#define O3_STEP_NM 10.0

static const double o3_m2[O3_N] = {
    1.18e-27,  2.182e-28, 2.818e-28, 6.636e-28, 1.527e-27, 2.763e-27, 5.52e-27,  8.451e-27, /* 365-435 */
    1.582e-26, 2.316e-26, 3.669e-26, 4.924e-26, 7.752e-26, 9.016e-26, 1.48e-25,  1.602e-25, /* 445-515 */
    2.139e-25, 2.755e-25, 3.091e-25, 3.5e-25,   4.266e-25, 4.672e-25, 4.398e-25, 4.701e-25, /* 525-595 */
    5.019e-25, 4.305e-25, 3.74e-25,  3.215e-25, 2.662e-25, 2.238e-25, 1.852e-25, 1.473e-25, /* 605-675 */
    1.209e-25, 9.423e-26, 7.455e-26, 6.566e-26, 5.105e-26, 4.15e-26,  4.228e-26, 3.237e-26, /* 685-755 */
    2.451e-26, 2.801e-26, 2.534e-26, 1.624e-26, 1.465e-26, 2.078e-26, 1.383e-26, 7.105e-27  /* 765-835 */
};

double atmos__ozone_cross_section(double nm)
{
    double x = (nm - O3_FIRST_NM) / O3_STEP_NM;
    if (!(x > 0)) return o3_m2[0];
    if (x >= O3_N - 1) return o3_m2[O3_N - 1];
    const int i = (int)x;
    const double f = x - i;
    return (1.0 - f) * o3_m2[i] + f * o3_m2[i + 1];
}

double atmos__ozone_cross_section_mean(double lo, double hi)
{
    if (!(hi > lo)) return atmos__ozone_cross_section(lo);
    /* the interpolant is piecewise linear: the trapezoid rule on a 1 nm grid is exact to
     * within the kinks' share */
    const int m = (int)ceil(hi - lo) + 1;
    const double h = (hi - lo) / m;
    double s = 0.5 * (atmos__ozone_cross_section(lo) + atmos__ozone_cross_section(hi));
    for (int i = 1; i < m; i++) s += atmos__ozone_cross_section(lo + i * h);
    return s * h / (hi - lo);
}
