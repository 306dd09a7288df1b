/* The generators' dense work grids (generate_job.h): their size from a world box and a voxel
 * size, checked against the memory limit, and the row at a height. */
#include "volume/generate_job.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

atmos_status atmos__gen_grid_init(gen_job *job, const double lo[3], const double hi[3])
{
    static const char axis[3] = {'x', 'y', 'z'};
    uint64_t total = 1;
    for (int a = 0; a < 3; a++) {
        double n = ceil((hi[a] - lo[a]) / job->voxel);
        if (!(n >= 1 && n <= ATMOS_VOLUME_MAX_DIM))
            return atmos__error(job->ctx, ATMOS_E_INVALID_ARG,
                                "generate %s: voxel_size_m %g m gives %.*g voxels along %c (allowed 1..%d)", job->preset,
                                job->voxel, n < 1e9 ? 10 : 3, n, axis[a], ATMOS_VOLUME_MAX_DIM);
        job->dims[a] = (int)n;
        job->origin[a] = lo[a];
        total *= (uint64_t)n;
    }
    /* The dense work grids (one per field) must fit the memory limit with the result. */
    uint64_t bytes = total * sizeof(float) * (uint64_t)job->ngrids;
    if (bytes > job->max_memory)
        return atmos__error(job->ctx, ATMOS_E_LIMIT,
                            "generate %s: %dx%dx%d voxels need %llu bytes of work grids, above the %llu-byte limit "
                            "(use a larger voxel size)",
                            job->preset, job->dims[0], job->dims[1], job->dims[2], (unsigned long long)bytes,
                            (unsigned long long)job->max_memory);
    for (int g = 0; g < job->ngrids; g++) {
        gen_grid *gr = &job->grid[g];
        memcpy(gr->n, job->dims, sizeof gr->n);
        memcpy(gr->origin, job->origin, sizeof gr->origin);
        gr->voxel = job->voxel;
        gr->v = calloc((size_t)total, sizeof(float));
        if (!gr->v) return atmos__error(job->ctx, ATMOS_E_NOMEM, "generate %s: out of memory", job->preset);
    }
    return ATMOS_OK;
}

int atmos__gen_floor_j(const gen_job *job, double y)
{
    /* first j whose voxel centre is at or above y */
    double j = ceil((y - job->origin[1]) / job->voxel - 0.5);
    return j < 0 ? 0 : (int)j;
}
