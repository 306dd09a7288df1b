/* The path tracer's integrator (path.c): what one camera path needs, and the tracing of one.
 * Not part of the API. */
#ifndef ATMOS_RENDER_PATH_TRACE_H
#define ATMOS_RENDER_PATH_TRACE_H

#include "render/path_internal.h"

typedef struct {
    const path_medium *med; /* NULL: no volume */
    const path_phase *ph;
    const atmos_atmosphere *atm; /* the air, the ground, the sun and what lies beyond */
    const path_env *env;    /* NULL: no next-event estimation of the sky */
    int forced;             /* camera rays estimate their single scattering by forced_single() */
    int aureole;            /* the aureole estimate (a phase function with a forward peak) */
    atmos_camera cam;
    int n;                  /* wavelengths */
    double sun[3];
    double cos_sun, sun_omega;
    int disk_visible;       /* the sun's disk is drawn */
    double bg;              /* radiance from beyond the atmosphere (a vacuum's background) */
    double albedo;          /* the ground's */
    int max_depth;          /* 0 = unlimited */
    uint64_t seed;
} path_job;

typedef struct {
    long long events, tentative, shadow;
} path_counts;

/* One camera path through world ray (o, d); adds the radiance of the carried wavelengths to
 * L[] and, for the scattering-order image, each contribution times the number of volume
 * scattering events before it to Lo[]. */
void atmos__path_trace(const path_job *J, const path_bundle *b, const double o[3], const double d[3], atmos__stream *r,
                       double *L, double *Lo, path_counts *cnt);

#endif
