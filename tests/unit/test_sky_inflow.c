/* The sky's light arriving at a volume (src/render/sky_inflow.c): atmos__sky_seen takes the
 * sun's disk off a view ray that looks into it, not the whole sample, so the circumsolar sky
 * (the brightest of the sky) stays:
 *   - looking at the sun's centre, what is left is the sky just beside the disk (half a degree
 *     from the centre, outside the disk), within a factor 2, for every wavelength; and it is
 *     not the disk (under 1 % of the disk's radiance);
 *   - beside the disk, the same as atmos_atmosphere_radiance. */
#include "atmos/atmos.h"
#include "render/sky_inflow.h"
#include "test.h"

int main(void)
{
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_atmosphere_desc desc;
    atmos_atmosphere_defaults(&desc);
    desc.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *atm = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &desc, &wl, &atm));
    const int n = wl.count;
    double sun[3], beside[3];
    atmos_direction_from_angles(30, 200, sun);
    atmos_direction_from_angles(30.5, 200, beside);
    const double p[3] = {0, 500, 0};
    double at[ATMOS_MAX_WAVELENGTHS], off[ATMOS_MAX_WAVELENGTHS], raw[ATMOS_MAX_WAVELENGTHS],
        disk[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_hit info;
    atmos_atmosphere_radiance(atm, p, sun, sun, raw, &info);
    CHECK_MSG(info.in_sun_disk, "the ray at the sun's centre is not in its disk");
    atmos_atmosphere_radiance(atm, p, beside, sun, raw, &info);
    CHECK_MSG(!info.in_sun_disk, "half a degree off is in the disk");
    atmos__sky_seen(atm, p, sun, sun, n, at);
    atmos__sky_seen(atm, p, beside, sun, n, off);
    atmos_atmosphere_sun_radiance(atm, p, sun, disk);
    for (int k = 0; k < n; k++) {
        printf("%.0f nm: at the sun's centre %.4g, half a degree off %.4g, the disk %.4g\n", wl.nm[k], at[k], off[k],
               disk[k]);
        CHECK_MSG(at[k] > 0.5 * off[k] && at[k] < 2 * off[k], "%.0f nm: the circumsolar sky %g against %g beside",
                  wl.nm[k], at[k], off[k]);
        CHECK_MSG(at[k] < 0.01 * disk[k], "%.0f nm: the disk left in (%g, the disk %g)", wl.nm[k], at[k], disk[k]);
        CHECK_REL(off[k], raw[k], 1e-12);
    }
    atmos_atmosphere_destroy(atm);
    atmos_context_destroy(ctx);
    return test_summary("test_sky_inflow");
}
