/* Shared state of one atmos_volume_generate() call (generate.c, generate_grid.c, generate_presets.c). */
#ifndef ATMOS_GENERATE_JOB_H
#define ATMOS_GENERATE_JOB_H

#include "core/internal.h"
#include "volume/generator.h"

#define GEN_MAX_GRIDS 3

typedef struct {
    atmos_context *ctx;
    const char *preset;
    double scale, voxel_override, voxel;
    uint64_t max_memory;
    int threads;
    gen_rng rng;
    int ngrids;
    const char *field_name[GEN_MAX_GRIDS];
    gen_grid grid[GEN_MAX_GRIDS];
    int dims[3];
    double origin[3];
    gen_balls balls;
} gen_job;

/* The generators' small shared pieces: x clamped to [0, 1]; the smooth step from a to b; the
 * world coordinate along axis a of voxel centre i; the out-of-memory error. */
static inline double gen_clamp01(double x) { return x < 0 ? 0 : (x > 1 ? 1 : x); }
static inline double gen_smoothstep(double a, double b, double x)
{
    const double t = gen_clamp01((x - a) / (b - a));
    return t * t * (3 - 2 * t);
}
static inline double gen_vox(const gen_job *job, int i, int a) { return job->origin[a] + (i + 0.5) * job->voxel; }
static inline atmos_status gen_nomem(gen_job *job)
{
    return atmos__error(job->ctx, ATMOS_E_NOMEM, "generate %s: out of memory", job->preset);
}

/* Sets dims/origin from the world box [lo, hi] at job->voxel and allocates the
 * job->ngrids zeroed work grids after checking sizes and the memory limit. */
atmos_status atmos__gen_grid_init(gen_job *job, const double lo[3], const double hi[3]);
/* First grid row j whose voxel centre lies at or above height y. */
int atmos__gen_floor_j(const gen_job *job, double y);
/* Fills the job's grids (number densities, m^-3) for preset number `which`
 * (order of atmos_volume_generator_names()). */
atmos_status atmos__gen_preset(gen_job *job, int which);
/* The layer clouds, one file each (generate_cirrus.c, generate_stratocumulus.c). */
atmos_status atmos__gen_cirrus(gen_job *job);
atmos_status atmos__gen_stratocumulus(gen_job *job);
/* The storm presets (generate_storm.c): cumulonimbus (with_rain 0) and storm (1);
 * rain_shaft (virga 0) and virga (1). */
atmos_status atmos__gen_cumulonimbus(gen_job *job, int with_rain);
atmos_status atmos__gen_rain_shaft(gen_job *job, int virga);
/* Per column (x fastest) the height above which the cumulus field's cloud is cut: the clouds'
 * fractal footprints (generate_footprint.c); NULL when out of memory. */
float *atmos__gen_fractal_tops(gen_job *job, int n, const double *cx, const double *cz, const double *cw,
                               double base, double depth);

#endif
