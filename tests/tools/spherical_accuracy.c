/* The production sky (SPHERICAL) against the Monte Carlo reference
 * (atmos_atmosphere_reference_radiance): relative error of the luminance of the one-ray
 * radiance on a fixed set of views per eye altitude and sun elevation; prints one table row
 * per (altitude, sun) with the RMS and the worst error and the reference's mean relative
 * standard error. docs/sky.md, "The production sky".
 *
 * Build and run from the repository after `make build`:
 *   cc -O2 -fopenmp -DATMOS_STATIC -Iinclude -Isrc tests/tools/spherical_accuracy.c \
 *      build/libatmos_static.a $(pkg-config --libs libpng libcjson) -lm -o spherical_accuracy
 *   ./spherical_accuracy [walks per wavelength, default 20000] [max_order, default 0 = all]
 */
#include "atmos/atmos.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define DEG 0.017453292519943295

static double lum(const double *c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* View i of n for an eye at altitude h: from inside the air elevations x azimuths from the
 * sun; from space, toward the planet's disk and the limb. */
static int view(double h, int i, double d[3])
{
    static const double els[8] = {90, 45, 15, 5, 1, -1, -10, -60};
    static const double azs[3] = {0, 90, 180};
    if (i >= 24) return 0;
    const double az = azs[i % 3];
    if (h < 100e3) {
        atmos_direction_from_angles(els[i / 3], 180.0 + az, d);
        return 1;
    }
    /* angles from the nadir: fractions of the planet's angular radius, then the air above the limb */
    const double R = 6360e3, r = R + h;
    const double off[8] = {0, 0.4 * asin(R / r), 0.8 * asin(R / r), 0.97 * asin(R / r), asin((R + 2e3) / r),
                           asin((R + 15e3) / r), asin((R + 40e3) / r), asin((R + 70e3) / r)};
    atmos_direction_from_angles(-90.0 + off[i / 3] / DEG, 180.0 + az, d);
    return 1;
}

int main(int argc, char **argv)
{
    const long walks = argc > 1 ? atol(argv[1]) : 20000;
    const int order = argc > 2 ? atoi(argv[2]) : 0;
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    ad.ground_albedo = 0.3;
    ad.hide_sun_disk = 1;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    if (atmos_atmosphere_create(NULL, &ad, &wl, &a) != ATMOS_OK) return 1;
    const double alts[5] = {0, 10e3, 100e3, 1000e3, 36000e3}, suns[7] = {90, 45, 10, 2, -2, -6, -10};
    printf("| eye altitude | sun | views | RMS %% | worst %% | reference std. error %% |\n|---|---|---|---|---|---|\n");
    for (int ia = 0; ia < 5; ia++)
        for (int is = 0; is < 7; is++) {
            double sun[3], sum2 = 0, worst = 0, se_sum = 0;
            int n = 0;
            atmos_direction_from_angles(suns[is], 180.0, sun);
            const double p[3] = {0, alts[ia] == 100e3 ? 99.9e3 : alts[ia], 0};
            double d[3];
            for (int i = 0; view(alts[ia], i, d); i++) {
                double L[3], ref[3], se[3];
                atmos_atmosphere_radiance(a, p, d, sun, L, NULL);
                atmos_atmosphere_reference_radiance(a, p, d, sun, walks, 1234 + i, order, ref, se);
                const double lr = lum(ref), ls = lum(se);
                if (!(lr > 1e-7)) continue; /* below 1e-6 of a daylight sky: night */
                const double e = lum(L) / lr - 1.0;
                sum2 += e * e, n++, se_sum += ls / lr;
                if (fabs(e) > fabs(worst)) worst = e;
            }
            if (n)
                printf("| %g km | %g° | %d | %.2f | %+.2f | %.2f |\n", alts[ia] / 1e3, suns[is], n,
                       100 * sqrt(sum2 / n), 100 * worst, 100 * se_sum / n);
            else
                printf("| %g km | %g° | 0 | - | - | - |\n", alts[ia] / 1e3, suns[is]);
            fflush(stdout);
        }
    atmos_atmosphere_destroy(a);
    return 0;
}
