/* The plan-based render benchmarks (bench_render.c) of atmos bench. */
#ifndef ATMOS_CLI_BENCH_RENDER_H
#define ATMOS_CLI_BENCH_RENDER_H

#include "cli.h"

typedef struct {
    int size, frames;  /* the image is size^2; frames per mode */
    double eye_scale;  /* > 0: overriding the scene's */
    int field;         /* an atmos_slice_field: the scene's "slice" setting */
    int air_shadows;   /* the scene's "slice" setting */
    int cold_field;    /* 1: the sun-moving frames solve the field afresh; 0: warm-started, as the viewer's */
    int field_ratio;   /* 1: the field's cost against none, frames in turns (bench_slice_ratio) */
    int json;
} bench_slice_opts;

/* The slice renderer on v (densities times density_scale) at size^2 (Riley et al. 2004 Fig. 14:
 * 256 slices): frames per mode (camera moving, sun moving, static). */
int bench_slice_case(atmos_context *ctx, const char *name, atmos_volume *v, double density_scale,
                     const bench_slice_opts *o);

/* The field's cost (--field-ratio): two plans of the bench view of v, the field's (o->field) and
 * none, their sun-moving frames in turns, each frame's CPU time by itself; the ratio of the means
 * and the median of the frames' ratios. */
int bench_slice_ratio(atmos_context *ctx, const char *name, atmos_volume *v, double density_scale,
                      const bench_slice_opts *o);

/* The aerial-perspective case: the slice renderer on v (densities times density_scale) under
 * each atmosphere model of the comma-separated list (riley, dobashi, spherical; NULL:
 * riley,spherical), frames frames with the camera moving and with the sun moving; the frame's
 * time, the atmosphere's shares, the first frame against the per-pixel air's. */
int bench_slice_aerial(atmos_context *ctx, const char *name, atmos_volume *v, int size, int frames, const char *models,
                       double density_scale, int json);

typedef struct {
    int size, spp;
    double density_scale;
    int no_forced, no_sky_nee, no_aureole;
    int json;
} bench_path_opts;

/* The path tracer on v, in vacuum or in the sky. */
int bench_path_case(atmos_context *ctx, const char *name, atmos_volume *v, const bench_path_opts *o, int vacuum);

#endif
