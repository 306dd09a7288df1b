/* Complex refractive indices of liquid water and ice in the visible.
 *
 * Water, real part: the Sellmeier fit of M. Daimon and A. Masumura, Appl. Opt. 46,
 * 3811 (2007), distilled water at 20.0 °C, valid 182-1129 nm. The rainbow's angle
 * depends on n (d(theta_bow)/dn ~ 2.5 degrees per 0.01), and Daimon & Masumura is the
 * most accurate modern measurement; Segelstein's compilation is 0.004-0.007 higher
 * in the blue.
 * Water, imaginary part: Hale & Querry 1973 (tabulated), log-linear interpolation.
 * Ice: Warren & Brandt 2008 (tabulated n and k), linear in n, log-linear in k.
 * Signs follow MIEV0: m = n - i k. */
#include "core/internal.h"
#include "optics/refractive_data.h"

#include <math.h>

/* Daimon & Masumura 2007, Table (20.0 °C): n^2 = 1 + sum B_i l^2 / (l^2 - C_i), l in um. */
static const double daimon_B[4] = {5.684027565e-1, 1.726177391e-1, 2.086189578e-2, 1.130748688e-1};
static const double daimon_C[4] = {5.101829712e-3, 1.821153936e-2, 2.620722293e-2, 1.069792721e1};

static double clamp_um(double nm, double lo, double hi)
{
    double um = nm * 1e-3;
    if (!(um >= lo)) um = lo; /* also catches NaN */
    if (um > hi) um = hi;
    return um;
}

/* Interpolates column c of a (wavelength, n, k) table at um; log-linear if logk. */
static double table_interp(const double (*t)[3], int count, double um, int c, int logk)
{
    if (um <= t[0][0]) return t[0][c];
    if (um >= t[count - 1][0]) return t[count - 1][c];
    int lo = 0, hi = count - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (t[mid][0] <= um) lo = mid;
        else hi = mid;
    }
    double f = (um - t[lo][0]) / (t[hi][0] - t[lo][0]);
    if (logk && t[lo][c] > 0 && t[hi][c] > 0) return exp(log(t[lo][c]) * (1 - f) + log(t[hi][c]) * f);
    return t[lo][c] * (1 - f) + t[hi][c] * f;
}

atmos_complex atmos_refractive_index_water(double nm)
{
    double um = clamp_um(nm, 0.182, 1.129);
    double l2 = um * um, n2 = 1.0;
    for (int i = 0; i < 4; i++) n2 += daimon_B[i] * l2 / (l2 - daimon_C[i]);
    double k = table_interp(atmos__water_hale_querry, atmos__water_hale_querry_count, um, 2, 1);
    atmos_complex m = {sqrt(n2), -k};
    return m;
}

atmos_complex atmos_refractive_index_ice(double nm)
{
    double um = clamp_um(nm, 0.182, 1.2);
    atmos_complex m = {table_interp(atmos__ice_warren_brandt, atmos__ice_warren_brandt_count, um, 1, 0),
                       -table_interp(atmos__ice_warren_brandt, atmos__ice_warren_brandt_count, um, 2, 1)};
    return m;
}
