/* The sky-view table (Hillaire 2020, "A Scalable and Production Ready Sky and Atmosphere
 * Rendering Technique", §5.3): the sky's radiance seen from the eye's height, tabulated over
 * view directions (the azimuth from the sun's vertical plane over [0, pi], the sky being
 * symmetric about it, times the elevation, its nodes crowded at the horizon: elevation =
 * +-(pi/2) v^2 with v uniform, the sky's half and the ground's half apart so that no read
 * mixes the two), read bilinearly a pixel. For the flat kinds (Riley's, the homogeneous
 * layer: the same sky wherever the eye is at one height). Not part of the API. */
#ifndef ATMOS_RENDER_SKY_VIEW_H
#define ATMOS_RENDER_SKY_VIEW_H

#include "atmosphere/atmosphere_ops.h"

#define ATMOS__SKY_VIEW_AZIMUTHS 96    /* nodes over [0, pi] (192 over the circle) */
#define ATMOS__SKY_VIEW_ELEVATIONS 108  /* nodes over each half, [0, pi/2] and [-pi/2, 0] */
#define ATMOS__SKY_VIEW_REMAKE_M 4.0   /* made again when the eye's height moved more than this */

typedef struct atmos__sky_view {
    const atmos_atmosphere *atm; /* what it was made for (NULL: never made) */
    double height, sun[3];
    double e1[3], e2[3];         /* horizontal: toward the sun's azimuth, and across */
    int n, stride;               /* wavelengths; floats a node (n + 1 rounded up to 4: alpha 1) */
    float *tab;                  /* [2 halves][ELEVATIONS][AZIMUTHS][stride] */
} atmos__sky_view;

/* 1 when the table can stand for atm's sky seen from eye (a flat kind, the eye above ground). */
int atmos__sky_view_wanted(const atmos_atmosphere *atm, const double eye[3]);
/* Makes t again for batch's eye and sun (batch answers for atm) unless it was made for the same
 * atmosphere, sun and wavelengths at a height within ATMOS__SKY_VIEW_REMAKE_M; `threads` threads.
 * 0: out of memory. */
int atmos__sky_view_update(atmos__sky_view *t, const atmos_atmosphere *atm, const atmos__atm_batch *batch,
                           int threads);
void atmos__sky_view_free(atmos__sky_view *t);

/* The view rays o(x) = base + u[x] right (not normalised) of pixels x in [0, count) of one row read
 * from the table into dst (stride C: n values and alpha 1). Pixels whose ray is within the angle
 * of cosine cos_near of the sun are not written: their indices go to near[], their number is
 * returned. coord: 3 * count floats of scratch. */
int atmos__sky_view_row(const atmos__sky_view *t, const double base[3], const double right[3], const float *u,
                        int count, double cos_near, float *dst, int C, float *coord, int *near);

#endif
