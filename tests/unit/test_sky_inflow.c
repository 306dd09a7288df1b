/* The sky's light arriving at a volume (src/render/sky_inflow.c): atmos__sky_seen takes the
 * sun's disk off a view ray that looks into it, not the whole sample, so the circumsolar sky
 * (the brightest of the sky) stays:
 *   - looking at the sun's centre, what is left is the sky just beside the disk (half a degree
 *     from the centre, outside the disk), within a factor 2, for every wavelength; and it is
 *     not the disk (under 1 % of the disk's radiance);
 *   - beside the disk, the same as atmos_atmosphere_radiance.
 * And atmos__sky_patch_inflow's ground in the volume's shadow: a shade of transmittance 0 takes
 * the ground's sunlit part (atmos__atm_ground_sunlit) off every sample that sees the ground, and
 * nothing else; a shade of 1 changes nothing (the path tracer's ground in a cloud's shadow is lit
 * by the sky alone; the field's inflow had it sunlit); the air's shadow is taken off each sample. */
#include "atmos/atmos.h"
#include "render/sky_inflow.h"
#include "atmosphere/atmosphere_ops.h"

#include <math.h>
#include "test.h"

static void take_air(const void *u, const double cw[3], const double d[3], double K, double *D)
{
    (void)cw, (void)d, (void)K;
    for (int w = 0; w < ATMOS_MAX_WAVELENGTHS; w++) D[w] = 0.1 * *(const double *)u;
}

static void shade_T(const void *u, const double gw[3], double *T)
{
    (void)gw;
    for (int w = 0; w < ATMOS_MAX_WAVELENGTHS; w++) T[w] = *(const double *)u;
}

/* The whole sphere's mean inflow at p, unshaded and shaded by 0 and 1, against the mean of what
 * the samples see less the ground's sunlit part (the patch's own cells, ns x ns). */
static void check_ground_shade(const atmos_atmosphere *atm, const double p[3], const double sun[3], int n)
{
    enum { NS = 8 };
    const double zero = 0, one = 1;
    const double tiny = 1e-3;
    const atmos__sky_ground_shade s0 = {shade_T, NULL, &zero}, s1 = {shade_T, NULL, &one}, sa = {shade_T, take_air, &tiny};
    double L[ATMOS_MAX_WAVELENGTHS], L0[ATMOS_MAX_WAVELENGTHS], L1[ATMOS_MAX_WAVELENGTHS], La[ATMOS_MAX_WAVELENGTHS],
        G[ATMOS_MAX_WAVELENGTHS] = {0};
    atmos__sky_patch_inflow(atm, p, sun, n, -1, 1, 0, 2 * ATMOS_PI, NS, NULL, L);
    atmos__sky_patch_inflow(atm, p, sun, n, -1, 1, 0, 2 * ATMOS_PI, NS, &s0, L0);
    atmos__sky_patch_inflow(atm, p, sun, n, -1, 1, 0, 2 * ATMOS_PI, NS, &s1, L1);
    atmos__sky_patch_inflow(atm, p, sun, n, -1, 1, 0, 2 * ATMOS_PI, NS, &sa, La);
    for (int a = 0; a < NS; a++)
        for (int b = 0; b < NS; b++) {
            const double mu = -1 + 2.0 * (a + 0.5) / NS, st = sqrt(1 - mu * mu), ph = 2 * ATMOS_PI * (b + 0.5) / NS;
            const double d[3] = {-st * cos(ph), -st * sin(ph), -mu};
            double g[ATMOS_MAX_WAVELENGTHS];
            atmos__atm_ground_sunlit(atm, p, d, atmos_atmosphere_ground_distance(atm, p, d), sun, g);
            for (int w = 0; w < n; w++) G[w] += g[w] / (NS * NS);
        }
    for (int w = 0; w < n; w++) {
        printf("inflow %d: %.4g, the ground shaded %.4g (its sunlit part %.4g)\n", w, L[w], L0[w], G[w]);
        CHECK_MSG(G[w] > 0.05 * L[w], "the sunlit ground is %g of an inflow of %g: not tested", G[w], L[w]);
        CHECK_REL(L0[w], L[w] - G[w], 1e-9);
        CHECK_REL(L1[w], L[w], 1e-12);
        /* the air's shadow (1e-4 here, less than any sample) taken off every sample; the ground
           shaded by 1e-3 */
        CHECK_REL(La[w], L[w] - 1e-4 - (1 - 1e-3) * G[w], 1e-9);
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
    atmos_atmosphere_defaults(&desc); /* Riley's flat earth, a bright ground */
    desc.ground_albedo = 0.3;
    CHECK_OK(atmos_atmosphere_create(ctx, &desc, &wl, &atm));
    check_ground_shade(atm, p, sun, n);
    atmos_atmosphere_destroy(atm);
    atmos_context_destroy(ctx);
    return test_summary("test_sky_inflow");
}
