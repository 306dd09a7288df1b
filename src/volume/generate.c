/* atmos_volume_generate: preset dispatch and turning the fields into a sparse
 * atmos_volume. The presets are in generate_presets.c, the work grids in generate_grid.c. */
#include "volume/generate_job.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const names[] = {"cumulus", "cumulonimbus", "cumulus_field", "cirrus", "rain_shaft",
                                    "storm", "stratocumulus", "virga", NULL};

const char *const *atmos_volume_generator_names(void) { return names; }

/* Builds the volume from the work grids (already converted to m^-3). */
static atmos_status to_volume(gen_job *job, atmos_volume **out)
{
    atmos_volume_desc d = {.voxel_size_m = job->voxel, .max_memory = job->max_memory};
    memcpy(d.dims, job->dims, sizeof d.dims);
    memcpy(d.origin_m, job->origin, sizeof d.origin_m);
    atmos_volume *v = NULL;
    atmos_status st = atmos_volume_create(job->ctx, &d, &v);
    int off[3] = {0, 0, 0};
    for (int g = 0; g < job->ngrids && st == ATMOS_OK; g++) {
        int idx;
        st = atmos_volume_add_field(job->ctx, v, job->field_name[g], job->field_name[g], &idx);
        if (st == ATMOS_OK) st = atmos_volume_set_dense(job->ctx, v, idx, off, job->dims, job->grid[g].v, 1.0f);
        /* Free each work grid as soon as it is copied to keep the peak low. */
        free(job->grid[g].v);
        job->grid[g].v = NULL;
    }
    if (st == ATMOS_OK) st = atmos_volume_finalize(job->ctx, v);
    if (st != ATMOS_OK) {
        atmos_volume_destroy(v);
        return st;
    }
    *out = v;
    return ATMOS_OK;
}

atmos_status atmos_volume_generate(atmos_context *ctx, const char *preset, const atmos_volume_generate_desc *desc,
                                   atmos_volume **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "generate: out is NULL");
    *out = NULL;
    atmos_volume_generate_desc zero;
    if (!desc) {
        memset(&zero, 0, sizeof zero);
        desc = &zero;
    }
    int which = -1;
    for (int i = 0; preset && names[i]; i++)
        if (!strcmp(preset, names[i])) which = i;
    if (which < 0) {
        char list[256] = "";
        for (int i = 0; names[i]; i++) {
            strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
            strncat(list, names[i], sizeof list - strlen(list) - 1);
        }
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "generate: unknown preset '%s' (known: %s)",
                            preset ? preset : "(null)", list);
    }
    double scale = desc->scale == 0 ? 1 : desc->scale;
    if (!isfinite(scale) || scale < ATMOS_GENERATE_SCALE_MIN || scale > ATMOS_GENERATE_SCALE_MAX)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "generate %s: scale must be in [%g, %g], got %g", preset,
                            ATMOS_GENERATE_SCALE_MIN, ATMOS_GENERATE_SCALE_MAX, scale);
    if (desc->voxel_size_m != 0 && !(isfinite(desc->voxel_size_m) && desc->voxel_size_m > 0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "generate %s: voxel_size_m must be > 0, got %g", preset,
                            desc->voxel_size_m);
    gen_job job;
    memset(&job, 0, sizeof job);
    job.ctx = ctx;
    job.preset = preset;
    job.scale = scale;
    job.voxel_override = desc->voxel_size_m;
    job.max_memory = desc->max_memory ? desc->max_memory : ATMOS_VOLUME_DEFAULT_MAX_MEMORY;
    job.threads = atmos__threads(ctx);
    job.rng.s = desc->seed ^ 0xA7305C10D5ull;
    atmos__progress(ctx, "volume generate", 0.0);
    atmos_status st = atmos__gen_preset(&job, which);
    if (st == ATMOS_OK) st = to_volume(&job, out);
    if (st == ATMOS_OK) atmos__progress(ctx, "volume generate", 1.0);
    for (int g = 0; g < GEN_MAX_GRIDS; g++) free(job.grid[g].v);
    atmos__gen_balls_free(&job.balls);
    return st;
}
