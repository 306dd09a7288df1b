/* The sky's light on the beam renderer's surfaces (docs/beams.md#the-skys-light): the
 * irradiance a Lambertian surface receives from the sky model's upper hemisphere, tabulated
 * over the surface's normal, kept between frames while the ground under the eye stays within
 * the same quantum. Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_SKY_H
#define ATMOS_RENDER_BEAMS_SKY_H

#include "core/internal.h"
#include "atmos/atmosphere.h"

/* Normals of the table: BEAMS_SKY_NY values of n_y over [-1, 1] by BEAMS_SKY_NA azimuths. */
#define BEAMS_SKY_NY 17
#define BEAMS_SKY_NA 32

/* A height-dependent fog's layer above a surface dims the sky toward it by exp(-C / mu), C the
 * layer's vertical optical depth over the point and mu the direction's cos(zenith): the table
 * has BEAMS_SKY_NC values of C = BEAMS_SKY_CMAX x^2, x even in [0, 1] (beyond: the last), one
 * (C = 0) without such a fog. */
#define BEAMS_SKY_NC 65
#define BEAMS_SKY_CMAX 30.0

/* The ground point under the eye is quantised for the table kept between frames
 * (atmos__beams_sky_keep) on axes along and across the sun's azimuth: BEAMS_SKY_KEEP_M metres
 * along it, where the sun's height over the local horizon changes (the table half a quantum
 * off by 8e-5 relative with the sun 8 degrees up, 5.6e-4 at 3 degrees below), and
 * BEAMS_SKY_KEEP_ACROSS_M across it, where only the local vertical turns (2.5e-4 half a
 * quantum off, the sun between -3 and 30 degrees up): docs/beams.md, "The sky's light". */
#define BEAMS_SKY_KEEP_M 100.0
#define BEAMS_SKY_KEEP_ACROSS_M 1000.0

typedef struct atmos__beams_sky {
    int nw;   /* wavelengths; 0: no sky (a vacuum) */
    int nc;   /* values of C: 1 (no height-dependent fog) or BEAMS_SKY_NC */
    float *E; /* [((ic * BEAMS_SKY_NY + iy) * BEAMS_SKY_NA + ia) * nw + k]: W m^-2 nm^-1 */
    /* what a kept table was built for (atmos__beams_sky_keep): the atmosphere, the quantised
     * ground point (along the sun's azimuth in units of BEAMS_SKY_KEEP_M, across it in units of
     * BEAMS_SKY_KEEP_ACROSS_M), the sun; built: 0 before the first */
    const atmos_atmosphere *atm;
    long key[2];
    int layered;
    double sun[3];
    int built;
} atmos__beams_sky;

/* The table for the sun at sun_dir, the sky as seen from p (the ground under the eye): the
 * radiance of the atmosphere (atmos_atmosphere_radiance, without the sun's disk) over the
 * upper hemisphere on a grid of directions of equal solid angle, times max(0, n . w); layered:
 * also dimmed by a fog layer of each tabulated C (nc = BEAMS_SKY_NC). */
atmos_status atmos__beams_sky_build(atmos_context *ctx, const atmos_atmosphere *atm, const double p[3],
                                    const double sun_dir[3], int nw, int layered, atmos__beams_sky *s);
/* The sun's azimuth as a unit vector u in (x, z) ((1, 0) for a sun at the zenith): the axes
 * of atmos__beams_sky_keep's quantum, u along and (-u[1], u[0]) across. */
void atmos__beams_sky_axes(const double sun_dir[3], double u[2]);
/* The table of the frame whose eye is at eye, kept in s between frames: the ground under the
 * eye quantised to BEAMS_SKY_KEEP_M metres along the sun's azimuth and BEAMS_SKY_KEEP_ACROSS_M
 * across it (the point ka Q u + kc Q' u_perp on the ground plane y = 0), so the table is made
 * again only when that point, the sun, the atmosphere or nw change, and a frame's table is the
 * same whatever frames came before it. s starts zeroed. */
atmos_status atmos__beams_sky_keep(atmos_context *ctx, const atmos_atmosphere *atm, const double eye[3],
                                   const double sun_dir[3], int nw, int layered, atmos__beams_sky *s);
/* The sky's irradiance on a surface of unit normal n (bilinear in the table) under a fog layer
 * of vertical optical depth C (0: none; linear in sqrt(C) between the table's values; a table
 * without layers ignores it) into E[nw]. */
void atmos__beams_sky_irradiance(const atmos__beams_sky *s, const double n[3], double C, double *E);
/* The last irradiance a caller asked of a table (atmos__beams_sky_irradiance_memo): its normal
 * and C, bit for bit, and E; valid 0 before the first. A caller's own, within one table's use. */
typedef struct atmos__beams_sky_memo {
    double n[3], C;
    int valid;
    double E[ATMOS_MAX_WAVELENGTHS];
} atmos__beams_sky_memo;
/* As atmos__beams_sky_irradiance: returns the irradiance, memo's E (the same bits as a call),
 * evaluated again only when n or C differ from its last call's, bit for bit (a flat ground
 * under a fog of one height: the same normal and layer at every pixel); memo NULL: into E. */
const double *atmos__beams_sky_irradiance_memo(const atmos__beams_sky *s, const double n[3], double C, double *E,
                                               atmos__beams_sky_memo *memo);
void atmos__beams_sky_free(atmos__beams_sky *s);

#endif
