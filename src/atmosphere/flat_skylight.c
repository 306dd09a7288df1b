/* The sky's light on the flat ground of Riley's air and the homogeneous layer.
 *
 * The ground of a flat earth is lit by the sun and by the sky above it. The sky's part is
 * the irradiance E_sky = integral over the upper hemisphere of L(d) cos(theta) dw, L the
 * kind's own single-scattered in-scatter seen from the ground (Riley's Eq. 11-15, the layer's
 * closed form), which the path tracer's paths leaving the ground also find. Over a flat,
 * horizontally uniform air it depends on the sun's elevation alone, so it is tabulated once
 * per atmosphere over l_y = sin(elevation) and read linearly. The quadrature is the midpoint
 * rule in cos(theta) and in the azimuth from the sun's plane (the sky is symmetric about
 * it): the Rayleigh phase function and the sky's slow change with elevation leave it within
 * about 10^-3 of a finer sum (test_path's ground against the path tracer checks it). */
#include "atmosphere/atmosphere_internal.h"

#include <math.h>
#include <stdlib.h>

#define MU_STEPS 16  /* cos(theta) in (0, 1] */
#define PHI_STEPS 16 /* azimuth in (0, pi), doubled for the other side */

static void sky_irradiance(const atmos_atmosphere *a, double ly, double *E)
{
    const int n = a->wl.count;
    for (int k = 0; k < n; k++) E[k] = 0.0;
    if (!(ly > 0)) return;
    const double sun[3] = {sqrt(fmax(1.0 - ly * ly, 0.0)), ly, 0.0};
    const double w = 2.0 * (1.0 / MU_STEPS) * (ATMOS_PI / PHI_STEPS);
    double L[ATMOS_MAX_WAVELENGTHS];
    for (int i = 0; i < MU_STEPS; i++) {
        const double mu = (i + 0.5) / MU_STEPS, s = sqrt(1.0 - mu * mu);
        for (int j = 0; j < PHI_STEPS; j++) {
            const double phi = (j + 0.5) * ATMOS_PI / PHI_STEPS, d[3] = {s * cos(phi), mu, s * sin(phi)};
            const int lit = a->desc.kind == ATMOS_ATMOSPHERE_RILEY
                                ? atmos__riley_inscatter(a, 0.0, d, INFINITY, sun, n, NULL, L)
                                : atmos__homog_inscatter(a, 0.0, d, INFINITY, sun, n, NULL, L);
            if (!lit) continue;
            for (int k = 0; k < n; k++) E[k] += w * mu * L[k];
        }
    }
}

int atmos__flat_skylight_build(atmos_atmosphere *a)
{
    const int n = a->wl.count;
    if (a->planet || a->desc.kind == ATMOS_ATMOSPHERE_VACUUM || !(a->desc.ground_albedo > 0)) return 1;
    a->sky_ground = malloc(sizeof(double) * ATMOS__SKYLIGHT_NODES * n);
    if (!a->sky_ground) return 0;
    for (int j = 0; j < ATMOS__SKYLIGHT_NODES; j++)
        sky_irradiance(a, (double)j / (ATMOS__SKYLIGHT_NODES - 1), a->sky_ground + (size_t)j * n);
    return 1;
}

void atmos__flat_skylight(const atmos_atmosphere *a, double ly, double *out)
{
    const int n = a->wl.count;
    for (int k = 0; k < n; k++) out[k] = 0.0;
    if (!a->sky_ground || !(ly > 0)) return;
    const double x = fmin(ly, 1.0) * (ATMOS__SKYLIGHT_NODES - 1);
    const int j = (int)fmin(x, ATMOS__SKYLIGHT_NODES - 2.0);
    const double f = x - j, *e0 = a->sky_ground + (size_t)j * n, *e1 = e0 + n;
    for (int k = 0; k < n; k++) out[k] = (1.0 - f) * e0[k] + f * e1[k];
}
