/* The sky's light arriving at a volume (src/render/sky_inflow.c): atmos__sky_seen takes the
 * sun's disk off a view ray that looks into it, not the whole sample, so the circumsolar sky
 * (the brightest of the sky) stays:
 *   - looking at the sun's centre, what is left is the sky just beside the disk (half a degree
 *     from the centre, outside the disk), within a factor 2, for every wavelength; and it is
 *     not the disk (under 1 % of the disk's radiance);
 *   - beside the disk, the same as atmos_atmosphere_radiance.
 * And atmos__sky_patch_inflow's air in the volume's shadow: what the shade takes comes off every
 * sample, and nothing else (the path tracer's sky light is the air's less the volume's shadow on
 * it; the field's inflow had the air lit everywhere). */
#include "atmos/atmos.h"
#include "render/sky_inflow.h"
#include "test.h"

static void take_air(const void *u, const double cw[3], const double d[3], double K, double *D)
{
    (void)cw, (void)d, (void)K;
    for (int w = 0; w < ATMOS_MAX_WAVELENGTHS; w++) D[w] = *(const double *)u;
}

/* The whole sphere's mean inflow at p, with no shade, a shade that takes nothing and one that
 * takes 1e-4 from each sample (less than any sample holds): the same, and 1e-4 less. */
static void check_air_shade(const atmos_atmosphere *atm, const double p[3], const double sun[3], int n)
{
    enum { NS = 8 };
    const double zero = 0, tiny = 1e-4;
    const atmos__sky_air_shade s0 = {take_air, &zero}, s1 = {take_air, &tiny};
    double L[ATMOS_MAX_WAVELENGTHS], L0[ATMOS_MAX_WAVELENGTHS], L1[ATMOS_MAX_WAVELENGTHS];
    atmos__sky_patch_inflow(atm, p, sun, n, -1, 1, 0, 2 * ATMOS_PI, NS, NULL, L);
    atmos__sky_patch_inflow(atm, p, sun, n, -1, 1, 0, 2 * ATMOS_PI, NS, &s0, L0);
    atmos__sky_patch_inflow(atm, p, sun, n, -1, 1, 0, 2 * ATMOS_PI, NS, &s1, L1);
    for (int w = 0; w < n; w++) {
        printf("inflow %d: %.4g, the air shaded by 1e-4 %.6g\n", w, L[w], L1[w]);
        CHECK_REL(L0[w], L[w], 1e-12);
        CHECK_REL(L1[w], L[w] - tiny, 1e-9);
    }
}

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
    atmos_atmosphere_defaults(&desc); /* Riley's flat earth */
    CHECK_OK(atmos_atmosphere_create(ctx, &desc, &wl, &atm));
    check_air_shade(atm, p, sun, n);
    atmos_atmosphere_destroy(atm);
    atmos_context_destroy(ctx);
    return test_summary("test_sky_inflow");
}
