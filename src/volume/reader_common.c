/* Helpers shared by the volume file readers (see reader_common.h). */
#include "volume/reader_common.h"

#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Particle presets a grid may be named after (atmos_particle_preset()). */
static int is_preset_name(const char *s)
{
    static const char *const names[] = {"cloud", "rain", "ice", "snow", "air"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(s, names[i]) == 0) return 1;
    return 0;
}

void atmos__reader_field_names(const char *grid, const atmos_volume_load_desc *desc, char field[64],
                               char particle[64])
{
    const char *user = desc && desc->field && *desc->field ? desc->field : NULL;
    if (strcmp(grid, "density") == 0) {
        snprintf(field, 64, "%s", user ? user : "cloud");
        /* a preset or a scene's own particle (resolved, and refused if unknown, by the
         * optics build) */
        snprintf(particle, 64, "%s", user ? user : "cloud");
    } else if (is_preset_name(grid)) {
        snprintf(field, 64, "%s", grid);
        snprintf(particle, 64, "%s", grid);
    } else {
        snprintf(field, 64, "%s", grid);
        snprintf(particle, 64, "%s", user ? user : "cloud");
    }
}

int atmos__reader_placement(const double A[9], const double t[3], const int imin[3], atmos_volume_desc *vd,
                            char *why, size_t cap)
{
    double s[3];
    for (int c = 0; c < 3; c++) s[c] = sqrt(A[c] * A[c] + A[3 + c] * A[3 + c] + A[6 + c] * A[6 + c]);
    for (int c = 0; c < 3; c++) {
        if (!isfinite(s[c]) || !(s[c] > 0)) {
            snprintf(why, cap, "degenerate voxel size along index axis %d (%g)", c, s[c]);
            return -1;
        }
    }
    /* Tolerance: files store single-precision-derived scales (3.33333 = 10/3). */
    const double tol = 1e-5;
    if (fabs(s[0] - s[1]) > tol * s[0] || fabs(s[0] - s[2]) > tol * s[0]) {
        snprintf(why, cap, "non-uniform voxel size (%g, %g, %g): atmos voxels are cubic; resample the grid "
                 "to a uniform voxel size first", s[0], s[1], s[2]);
        return -1;
    }
    const double vs = (s[0] + s[1] + s[2]) / 3.0;
    double R[9];
    for (int i = 0; i < 9; i++) R[i] = A[i] / vs;
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++) {
            double d = R[a] * R[b] + R[3 + a] * R[3 + b] + R[6 + a] * R[6 + b];
            if (fabs(d) > 1e-5) {
                snprintf(why, cap, "sheared transform (index axes %d and %d not orthogonal): not supported", a, b);
                return -1;
            }
        }
    double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                 R[2] * (R[3] * R[7] - R[4] * R[6]);
    if (det < 0) {
        snprintf(why, cap, "mirrored transform (negative determinant): not supported");
        return -1;
    }
    int identity = 1;
    for (int i = 0; i < 9; i++)
        if (fabs(R[i] - (i % 4 == 0 ? 1.0 : 0.0)) > 1e-9) identity = 0;
    vd->voxel_size_m = vs;
    for (int i = 0; i < 9; i++) vd->rotation[i] = identity ? 0.0 : R[i];
    /* Cell-centred sample points: OpenVDB/NanoVDB values sit at integer index
     * coordinates; atmos voxels have their value at the cell centre. */
    const double c0[3] = {imin[0] - 0.5, imin[1] - 0.5, imin[2] - 0.5};
    for (int r = 0; r < 3; r++) vd->origin_m[r] = t[r] + A[3 * r] * c0[0] + A[3 * r + 1] * c0[1] + A[3 * r + 2] * c0[2];
    return 0;
}

atmos_status atmos__reader_check_memory(atmos_context *ctx, const char *path, uint64_t voxels, uint64_t max_memory)
{
    const uint64_t limit = max_memory ? max_memory : ATMOS_VOLUME_DEFAULT_MAX_MEMORY;
    /* 4 bytes per stored float; a sparse volume needs at least that. */
    if (voxels > limit / 4)
        return atmos__error(ctx, ATMOS_E_LIMIT,
                            "%s: %llu active voxels need at least %.1f MB, over the memory limit of %.1f MB "
                            "(raise max_memory / --max-memory or load a sub-region)",
                            path, (unsigned long long)voxels, (double)voxels * 4.0 / 1e6, (double)limit / 1e6);
    return ATMOS_OK;
}

/* Chunk edge for constant fills: 32^3 floats = 128 KB on the stack's neighbour. */
#define FILL_EDGE 32

atmos_status atmos__reader_write_block(atmos_context *ctx, atmos_volume *vol, int field, const int64_t origin[3],
                                       const int64_t size[3], const float *values, float constant, float scale)
{
    const atmos_volume_desc *vd = atmos_volume_get_desc(vol);
    int64_t lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = origin[a] < 0 ? 0 : origin[a];
        hi[a] = origin[a] + size[a] > vd->dims[a] ? vd->dims[a] : origin[a] + size[a];
        if (hi[a] <= lo[a]) return ATMOS_OK; /* wholly outside */
    }
    if (!values && constant == 0.0f) return ATMOS_OK; /* zeros are the default */
    static _Thread_local float buf[FILL_EDGE * FILL_EDGE * FILL_EDGE];
    if (!values)
        for (int i = 0; i < FILL_EDGE * FILL_EDGE * FILL_EDGE; i++) buf[i] = constant;
    for (int64_t z0 = lo[2]; z0 < hi[2]; z0 += FILL_EDGE)
        for (int64_t y0 = lo[1]; y0 < hi[1]; y0 += FILL_EDGE)
            for (int64_t x0 = lo[0]; x0 < hi[0]; x0 += FILL_EDGE) {
                int n[3] = {(int)(hi[0] - x0 < FILL_EDGE ? hi[0] - x0 : FILL_EDGE),
                            (int)(hi[1] - y0 < FILL_EDGE ? hi[1] - y0 : FILL_EDGE),
                            (int)(hi[2] - z0 < FILL_EDGE ? hi[2] - z0 : FILL_EDGE)};
                if (values) {
                    /* Copy the clipped part of the source block (x fastest). */
                    for (int k = 0; k < n[2]; k++)
                        for (int j = 0; j < n[1]; j++) {
                            const float *src = values + (size_t)(x0 - origin[0]) +
                                               (size_t)size[0] * ((size_t)(y0 - origin[1] + j) +
                                                                  (size_t)size[1] * (size_t)(z0 - origin[2] + k));
                            memcpy(buf + (size_t)n[0] * (j + (size_t)n[1] * k), src, sizeof(float) * (size_t)n[0]);
                        }
                }
                const int off[3] = {(int)x0, (int)y0, (int)z0};
                /* A constant buffer is read with the chunk's own row length, so a
                 * partial chunk still sees only `constant`. */
                atmos_status st = atmos_volume_set_dense(ctx, vol, field, off, n, buf, scale);
                if (st != ATMOS_OK) return st;
            }
    return ATMOS_OK;
}

atmos_status atmos__reader_name_error(atmos_context *ctx, const char *path, atmos_status st)
{
    if (st == ATMOS_OK || !ctx) return st;
    const char *msg = atmos_context_error(ctx);
    if (strstr(msg, path)) {
        char keep[768];
        snprintf(keep, sizeof keep, "%s", msg);
        return atmos_context_error_status(ctx) == st ? st : atmos__error(ctx, st, "%s", keep);
    }
    char copy[768];
    snprintf(copy, sizeof copy, "%s", msg);
    return atmos__error(ctx, st, "%s: %s", path, copy);
}
