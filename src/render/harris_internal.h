/* Harris's particle renderer's part of a plan (harris_plan.c: the particles, their clouds,
 * the light passes; harris_frame.c: a frame). Internal to src/render/. */
#ifndef ATMOS_RENDER_HARRIS_INTERNAL_H
#define ATMOS_RENDER_HARRIS_INTERNAL_H

#include "atmosphere/atmosphere_ops.h"
#include "particles/pcloud.h"
#include "render/plan_internal.h"

#define ATMOS__HARRIS_MAX_LIGHTS 17

struct atmos__harris_plan {
    atmos__pcloud pc;
    atmos__poptics o;
    atmos__pclusters clouds;             /* the particles' clouds (the impostors') */
    atmos__pimpostor *imp;               /* [clouds.n] */
    int nlights;                         /* the sun, then the sky lights */
    double dir[ATMOS__HARRIS_MAX_LIGHTS][3];           /* toward each light */
    double e[ATMOS__HARRIS_MAX_LIGHTS][ATMOS_MAX_WAVELENGTHS]; /* its irradiance outside the cloud */
    float *light[ATMOS__HARRIS_MAX_LIGHTS], *order[ATMOS__HARRIS_MAX_LIGHTS];
    float *air_t, *air_l;                /* the air from the eye to each particle, this frame */
    atmos__aerial aerial;
    double sun[3];
    int have_sun, drawn, updates, direct;
    double shade_s;
};

/* The light passes of the sun sun and the sky lights (harris_plan.c); the impostors become
 * stale. */
atmos_status atmos__harris_lights(atmos_plan *p, atmos__harris_plan *h, const double sun[3]);

#endif
