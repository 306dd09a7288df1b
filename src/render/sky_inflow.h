/* The sky's and the ground's light arriving at a volume (sky_inflow.c): what a view ray from
 * the box's centre sees (atmos_atmosphere_radiance: the air and the lit ground; the sun's disk
 * taken off, the sun is the renderers' direct beam). The one source of both light fields'
 * boundaries: the P1 field's inward currents per face (dfield.c) and the discrete-ordinates
 * field's inflow per direction (nishita_do.c). Not part of the API. */
#ifndef ATMOS_RENDER_SKY_INFLOW_H
#define ATMOS_RENDER_SKY_INFLOW_H

#include "atmos/atmosphere.h"
#include "volume/volume_access.h"

/* The point the sky is seen from: the box's centre cen (grid frame, metres) placed by x, moved
 * onto the ground when it lies below it. */
void atmos__sky_inflow_point(const atmos_atmosphere *atm, const atmos__vol_xform *x, const double cen[3],
                             double cw[3]);

/* What a view ray from cw along the world direction d sees, into L (n wavelengths): the sky
 * without the sun's disk (atmos_atmosphere_sun_radiance taken off where d looks into it, so the
 * circumsolar sky around and behind the disk stays; the beam renderer's sky table too). */
void atmos__sky_seen(const atmos_atmosphere *atm, const double cw[3], const double d[3], const double sun_w[3], int n,
                     double *L);

/* The volume's shadow on the air: what it takes from the air's light along the view ray
 * cw + t d, t in [0, K] (K: the ground's distance, or infinite), into D (u: the caller's). */
typedef struct {
    void (*take)(const void *u, const double cw[3], const double d[3], double K, double *D);
    const void *u;
} atmos__sky_air_shade;

/* The mean radiance travelling along the directions of a patch of the sphere, mu in [mu0, mu1]
 * (the cosine to the world's z axis) and azimuth in [ph0, ph1) about it, arriving at cw: what the
 * view rays along the opposite directions see, over ns x ns cells of equal solid angle, into L.
 * With sh, what the volume's shadow takes from the air's light is taken off each sample (the
 * path tracer's sky light is the air's in the volume's shadow). */
void atmos__sky_patch_inflow(const atmos_atmosphere *atm, const double cw[3], const double sun_w[3], int n, double mu0,
                             double mu1, double ph0, double ph1, int ns, const atmos__sky_air_shade *sh, double *L);

#endif
