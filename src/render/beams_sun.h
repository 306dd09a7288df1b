/* The sun as a light of the beam renderer (docs/beams.md#the-sun): a directional light with
 * an orthographic shadow map over the scene's objects (terrain), the sunlight of the
 * atmosphere at the eye, and the fog's optical depth along a ray (uniform, or falling off
 * exponentially with height). For a directional light the scattering angle is the same all
 * along a ray. A height-dependent fog dims the sunlight on its way in by its layer above the
 * point, C(t) = sigma(t) H / sun_y (a uniform fog has no top and is lit undimmed: C = 0); with
 * the eye's optical depth tau as the variable, C(t) = C(0) (1 - gamma' tau) and the single
 * scattering is a closed form:
 *     int sigma_s p E exp(-tau - C) dt = omega p E exp(-C(0)) int exp(-gamma tau) d tau,
 * gamma = 1 - d_y / sun_y, omega = sigma_s / sigma_t; the ray is cut into steps of equal share
 * of that integral (each at most epsilon of the whole, Dobashi's criterion) and the visibility
 * H sampled once a step. Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_SUN_H
#define ATMOS_RENDER_BEAMS_SUN_H

#include "core/internal.h"
#include "scene/scene_fog.h"
#include "render/beams_tiles.h"
#include "render/beams_epipolar.h"

/* The fog along rays: sigma_t(y) = sigma0 exp(-(y - base) / H) (H = 0: uniform sigma0). */
typedef struct atmos__beams_fog {
    double sigma0, albedo, g;
    double base_m, height_m;
    const atmos__fog_optics *phase; /* the phase function; NULL: Henyey-Greenstein with g */
    /* the frame's eye (atmos__beams_fog_eye; eye_set 0: none): the density's factor
     * exp(-(y - base) / H) at its height eye_y, and the sunlight's dimming exp(-C) on its way in
     * to it, kept so that its rays do not compute them again (the same values: the same bits) */
    int eye_set;
    double eye_y, eye_e, eye_C, eye_expC;
} atmos__beams_fog;

/* Keeps in f the eye's factors (above) for the eye at o, the sun (unit, toward it) at sun. */
void atmos__beams_fog_eye(atmos__beams_fog *f, const double o[3], const double sun[3]);

/* The optical depth from the eye o to o + t d (t may be INFINITY). */
double atmos__beams_fog_tau(const atmos__beams_fog *f, const double o[3], const double d[3], double t);

typedef struct atmos__beams_sun {
    double dir[3];                      /* toward the sun, unit */
    double E[ATMOS_MAX_WAVELENGTHS];    /* the sunlight (W m^-2 nm^-1) */
    /* the shadow map: depth along fwd = -dir over n x n texels of size texel from (u0, v0) in
     * (right, up); empty (n = 0) without objects */
    double right[3], up[3], fwd[3];
    double u0, v0, texel, bias;
    double box[4];                      /* look-up coordinates x0, x1, y0, y1 round every object */
    int n;
    float *depth;
    atmos__beams_tiles tiles;           /* the map's min/max pyramid */
    unsigned long gen;                  /* counts the builds: what was made from the map knows it */
    int warned;                         /* atmos__beams_sun_warn_texel has spoken */
} atmos__beams_sun;

/* The map of the meshes seen from the sun dir (unit); size texels a side. */
atmos_status atmos__beams_sun_build(atmos_context *ctx, atmos__beams_sun *s, const double dir[3], atmos_mesh *const *mesh,
                                    int nmesh, int size);
void atmos__beams_sun_free(atmos__beams_sun *s);
/* Warns when the built map's texels exceed 16 times the median size of the meshes'
 * triangles, naming the object whose bounds set the map's extent (beams_sun_warn.c). */
void atmos__beams_sun_warn_texel(atmos_context *ctx, const atmos__beams_sun *s, atmos_mesh *const *mesh, int nmesh);
/* H at p: the share of sunlight reaching p past the meshes, in [0, 1] (2x2 filtered). */
double atmos__beams_sun_visibility(const atmos__beams_sun *s, const double p[3]);
/* 1 when p is surely in the meshes' shadow by the map: the depths over p's finest tile (8 x 8
 * texels and the ring a filtered look-up reads) all nearer the sun than p by more than two
 * texels; 0 when the map cannot tell (then a ray decides). Approximate only where an opening
 * narrower than a texel lets the sun through. */
int atmos__beams_sun_dark(const atmos__beams_sun *s, const double p[3]);
/* The sunlight the fog scatters toward o along [0, T) of the ray d (unit), per unit of E:
 * steps of at most epsilon of the unshadowed whole (at most max_steps), each weighted by H
 * at its middle (in optical depth). Runs of steps whose samples the map's tiles prove all lit
 * (or all in shadow) are counted without reading the map. */
double atmos__beams_sun_airlight(const atmos__beams_sun *s, const atmos__beams_fog *f, const double o[3],
                                 const double d[3], double T, double epsilon, int max_steps);
/* atmos__beams_sun_airlight from the map's epipolar lines e built for the eye o
 * (beams_epipolar.h): the integral in closed form over the lit stretches of the line nearest
 * the ray's projection (no steps: exact for the line's piecewise linear depths). Without lines
 * (or lines built for another eye, or a ray along the sun), atmos__beams_sun_airlight. */
double atmos__beams_sun_airlight_lines(const atmos__beams_sun *s, const atmos__beams_epi *e, const atmos__beams_fog *f,
                                       const double o[3], const double d[3], double T, double epsilon, int max_steps);
/* The fog's optical depth between p and the sun (unit sun, toward it): a height-dependent
 * fog's layer above p, sigma(p) H / sun_y (INFINITY with the sun below the horizon); 0 in a
 * uniform fog (it has no top, and is lit undimmed). */
double atmos__beams_sun_fog_in(const atmos__beams_fog *f, const double sun[3], const double p[3]);

#endif
