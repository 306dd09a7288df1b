/* The sky's and the ground's light arriving at a volume (sky_inflow.h). */
#include "render/sky_inflow.h"
#include "atmosphere/atmosphere_check.h"

#include <math.h>

void atmos__sky_inflow_point(const atmos_atmosphere *atm, const atmos__vol_xform *x, const double cen[3],
                             double cw[3])
{
    atmos__vol_frame_to_point(x, cen, cw);
    atmos__atm_onto_ground(atm, cw, cw); /* the sky seen from above the ground */
}

void atmos__sky_seen(const atmos_atmosphere *atm, const double cw[3], const double d[3], const double sun_w[3], int n,
                     double *L)
{
    atmos_atmosphere_hit info;
    atmos_atmosphere_radiance(atm, cw, d, sun_w, L, &info);
    if (!info.in_sun_disk) return;
    double D[ATMOS_MAX_WAVELENGTHS]; /* the disk alone: the circumsolar sky behind it stays */
    atmos_atmosphere_sun_radiance(atm, cw, sun_w, D);
    for (int w = 0; w < n; w++) L[w] = fmax(0.0, L[w] - D[w]);
}

/* What the volume's shadow takes from the air's light that s holds (sh, the view ray along d). */
static void air_shadow(const atmos_atmosphere *atm, const double cw[3], const double d[3], int n,
                       const atmos__sky_air_shade *sh, double *s)
{
    double D[ATMOS_MAX_WAVELENGTHS];
    sh->take(sh->u, cw, d, atmos_atmosphere_ground_distance(atm, cw, d), D);
    for (int w = 0; w < n; w++) s[w] = fmax(0.0, s[w] - D[w]);
}

void atmos__sky_patch_inflow(const atmos_atmosphere *atm, const double cw[3], const double sun_w[3], int n, double mu0,
                             double mu1, double ph0, double ph1, int ns, const atmos__sky_air_shade *sh, double *L)
{
    for (int w = 0; w < n; w++) L[w] = 0;
    for (int a = 0; a < ns; a++)
        for (int b = 0; b < ns; b++) {
            const double mu = mu0 + (mu1 - mu0) * (a + 0.5) / ns, st = sqrt(fmax(0.0, 1 - mu * mu)),
                         ph = ph0 + (ph1 - ph0) * (b + 0.5) / ns;
            /* the view ray looks against the light's direction */
            const double d[3] = {-st * cos(ph), -st * sin(ph), -mu};
            double s[ATMOS_MAX_WAVELENGTHS];
            atmos__sky_seen(atm, cw, d, sun_w, n, s);
            if (sh) air_shadow(atm, cw, d, n, sh, s);
            for (int w = 0; w < n; w++) L[w] += s[w] / ((double)ns * ns);
        }
}
