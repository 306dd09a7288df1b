/* OpenVDB .vdb reader: picks the float grids, checks their values and transform,
 * and copies leaves and active tiles into an atmos volume. The file itself is
 * parsed by the OpenVDB library through openvdb_shim.cpp; without it (the library
 * was not found at configure time) the reader says which package to install. */
#include "core/internal.h"
#include "volume/reader_common.h"
#include "volume/volume_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef ATMOS_HAVE_OPENVDB

atmos_status atmos__volume_load_openvdb(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                        atmos_volume **out)
{
    (void)desc;
    if (out) *out = NULL;
    return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                        "%s: this build of atmos cannot read OpenVDB files: install libopenvdb-dev (and "
                        "libboost-dev) and reconfigure (scripts/install-deps.sh does both)",
                        path);
}

#else

#include "volume/openvdb_shim.h"

#define MSG_CAP 512

typedef struct {
    atmos_context *ctx;
    atmos_volume *vol;
    int field;
    int bbox_min[3];
    float scale;
    atmos_status status;
} visit_state;

static int on_block(void *user, const int origin[3], const int size[3], const float *values, float constant)
{
    visit_state *s = user;
    int64_t o[3], n[3];
    for (int a = 0; a < 3; a++) {
        o[a] = (int64_t)origin[a] - s->bbox_min[a];
        n[a] = size[a];
    }
    s->status = atmos__reader_write_block(s->ctx, s->vol, s->field, o, n, values, constant, s->scale);
    return s->status != ATMOS_OK;
}

static atmos_status shim_status(int rc)
{
    switch (rc) {
    case ATMOS__VDB_E_IO: return ATMOS_E_IO;
    case ATMOS__VDB_E_NOMEM: return ATMOS_E_NOMEM;
    default: return ATMOS_E_FORMAT;
    }
}

/* "density (float), vel (vec3s)" for messages. */
static void list_grids(const atmos__vdb *f, char *buf, size_t cap)
{
    size_t len = 0;
    buf[0] = '\0';
    int n = atmos__vdb_grid_count(f);
    if (n == 0) snprintf(buf, cap, "(none)");
    for (int g = 0; g < n && len + 1 < cap; g++) {
        atmos__vdb_grid_info info;
        atmos__vdb_get_grid_info(f, g, &info);
        int w = snprintf(buf + len, cap - len, "%s%s (%s)", g ? ", " : "", info.name, info.value_type);
        if (w < 0) break;
        len += (size_t)w;
    }
}

static int find_grid(const atmos__vdb *f, const char *name, size_t len)
{
    for (int g = 0; g < atmos__vdb_grid_count(f); g++) {
        atmos__vdb_grid_info info;
        atmos__vdb_get_grid_info(f, g, &info);
        if (strlen(info.name) == len && strncmp(info.name, name, len) == 0) return g;
    }
    return -1;
}

/* Resolves desc->grids (or the default) to grid indices. */
static atmos_status select_grids(atmos_context *ctx, const char *path, const atmos__vdb *f, const char *wanted,
                                 int *sel, int *nsel)
{
    char present[MSG_CAP];
    *nsel = 0;
    if (wanted && *wanted) {
        const char *p = wanted;
        while (*p) {
            const char *e = strchr(p, ',');
            size_t len = e ? (size_t)(e - p) : strlen(p);
            if (len > 0) {
                int g = find_grid(f, p, len);
                list_grids(f, present, sizeof present);
                if (g < 0)
                    return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%.*s' not found; grids present: %s", path,
                                        (int)len, p, present);
                atmos__vdb_grid_info info;
                atmos__vdb_get_grid_info(f, g, &info);
                if (!info.is_float)
                    return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%s' holds %s values; atmos reads float grids",
                                        path, info.name, info.value_type);
                if (*nsel >= ATMOS_VOLUME_MAX_FIELDS)
                    return atmos__error(ctx, ATMOS_E_LIMIT, "%s: more than %d grids requested", path,
                                        ATMOS_VOLUME_MAX_FIELDS);
                sel[(*nsel)++] = g;
            }
            p += len;
            if (*p == ',') p++;
        }
        if (*nsel == 0) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: empty grid list '%s'", path, wanted);
        return ATMOS_OK;
    }
    int g = find_grid(f, "density", 7);
    atmos__vdb_grid_info info;
    if (g >= 0 && atmos__vdb_get_grid_info(f, g, &info) == ATMOS__VDB_OK && info.is_float) {
        sel[(*nsel)++] = g;
        return ATMOS_OK;
    }
    for (g = 0; g < atmos__vdb_grid_count(f); g++) {
        atmos__vdb_get_grid_info(f, g, &info);
        if (!info.is_float) continue;
        if (*nsel >= ATMOS_VOLUME_MAX_FIELDS)
            return atmos__error(ctx, ATMOS_E_LIMIT, "%s: more than %d float grids; choose some with grids=", path,
                                ATMOS_VOLUME_MAX_FIELDS);
        sel[(*nsel)++] = g;
    }
    if (*nsel == 0) {
        list_grids(f, present, sizeof present);
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: no float grid to load; grids present: %s", path, present);
    }
    return ATMOS_OK;
}

atmos_status atmos__volume_load_openvdb(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                        atmos_volume **out)
{
    static const atmos_volume_load_desc zero_desc;
    if (!out || !path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "openvdb: path and out are required");
    *out = NULL;
    if (!desc) desc = &zero_desc;
    char msg[MSG_CAP];
    atmos__vdb *f = NULL;
    int rc = atmos__vdb_open(path, &f, msg, sizeof msg);
    if (rc != ATMOS__VDB_OK) return atmos__error(ctx, shim_status(rc), "%s: %s", path, msg);

    atmos_status st;
    atmos_volume *vol = NULL;
    int sel[ATMOS_VOLUME_MAX_FIELDS], nsel = 0;
    atmos__vdb_grid_stats gs[ATMOS_VOLUME_MAX_FIELDS];
    st = select_grids(ctx, path, f, desc->grids, sel, &nsel);
    if (st != ATMOS_OK) goto done;

    int lo[3] = {0, 0, 0}, hi[3] = {-1, -1, -1}, any = 0;
    uint64_t total = 0;
    for (int s = 0; s < nsel; s++) {
        atmos__vdb_grid_info info;
        atmos__vdb_get_grid_info(f, sel[s], &info);
        rc = atmos__vdb_load_grid(f, sel[s], &gs[s], msg, sizeof msg);
        if (rc != ATMOS__VDB_OK) {
            st = atmos__error(ctx, shim_status(rc), "%s: %s", path, msg);
            goto done;
        }
        /* Real fog volumes (the Disney cloud, dragon.vdb) hold no negative or
         * non-finite values, so any such value marks a broken or non-density
         * grid (an SDF, say): refuse rather than guess. */
        if (gs[s].bad_values) {
            st = atmos__error(ctx, ATMOS_E_FORMAT,
                              "%s: grid '%s': value %g at index (%d, %d, %d) is %s (%llu bad values); densities "
                              "must be finite and >= 0 (is this a level set rather than a fog volume?)",
                              path, info.name, gs[s].bad_value, gs[s].bad_ijk[0], gs[s].bad_ijk[1], gs[s].bad_ijk[2],
                              gs[s].bad_value < 0 ? "negative" : "not finite", (unsigned long long)gs[s].bad_values);
            goto done;
        }
        if (!gs[s].linear) {
            st = atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                              "%s: grid '%s' has a non-linear transform (%s, e.g. a frustum): atmos needs a linear "
                              "(scale, rotation, translation) transform; resample the grid first",
                              path, info.name, gs[s].map_type);
            goto done;
        }
        if (s > 0 && memcmp(gs[s].mat, gs[0].mat, sizeof gs[0].mat) != 0) {
            atmos__vdb_grid_info first;
            atmos__vdb_get_grid_info(f, sel[0], &first);
            st = atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                              "%s: grids '%s' and '%s' have different transforms; atmos puts all fields on one "
                              "grid: load them separately or resample",
                              path, first.name, info.name);
            goto done;
        }
        total += gs[s].active_voxels;
        if (gs[s].empty) continue;
        for (int a = 0; a < 3; a++) {
            if (!any || gs[s].bbox_min[a] < lo[a]) lo[a] = gs[s].bbox_min[a];
            if (!any || gs[s].bbox_max[a] > hi[a]) hi[a] = gs[s].bbox_max[a];
        }
        any = 1;
        atmos__log(ctx, ATMOS_LOG_INFO,
                   "%s: grid '%s': %llu active voxels (%llu in leaves, %llu active tiles), index box [%d %d %d]..[%d "
                   "%d %d], values %g..%g%s",
                   path, info.name, (unsigned long long)gs[s].active_voxels, (unsigned long long)gs[s].leaf_voxels,
                   (unsigned long long)gs[s].active_tiles, gs[s].bbox_min[0], gs[s].bbox_min[1], gs[s].bbox_min[2],
                   gs[s].bbox_max[0], gs[s].bbox_max[1], gs[s].bbox_max[2], gs[s].min, gs[s].max,
                   gs[s].compressed ? ", compressed" : "");
    }
    if (!any) {
        atmos__log(ctx, ATMOS_LOG_WARN, "%s: the selected grids have no active voxels; the volume is empty", path);
        lo[0] = lo[1] = lo[2] = 0;
        hi[0] = hi[1] = hi[2] = 0;
    }
    st = atmos__reader_check_memory(ctx, path, total, desc->max_memory);
    if (st != ATMOS_OK) goto done;

    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    for (int a = 0; a < 3; a++) {
        int64_t n = (int64_t)hi[a] - lo[a] + 1;
        if (n > ATMOS_VOLUME_MAX_DIM) {
            st = atmos__error(ctx, ATMOS_E_LIMIT, "%s: the grids span %lld voxels along axis %d (limit %d)", path,
                              (long long)n, a, ATMOS_VOLUME_MAX_DIM);
            goto done;
        }
        vd.dims[a] = (int)n;
    }
    /* OpenVDB maps row vectors: world = [i j k 1] * M; atmos's A is column-major
     * in that sense, so A = M3^T and the translation is M's last row. */
    double A[9], t[3];
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) A[3 * r + c] = gs[0].mat[c][r];
        t[r] = gs[0].mat[3][r];
    }
    char why[256];
    if (atmos__reader_placement(A, t, lo, &vd, why, sizeof why) != 0) {
        atmos__vdb_grid_info info;
        atmos__vdb_get_grid_info(f, sel[0], &info);
        st = atmos__error(ctx, ATMOS_E_UNSUPPORTED, "%s: grid '%s': %s", path, info.name, why);
        goto done;
    }
    vd.max_memory = desc->max_memory;
    st = atmos_volume_create(ctx, &vd, &vol);
    /* a grid placement the core refuses (not a rotation, absurd size) is a malformed file */
    if (st == ATMOS_E_INVALID_ARG) st = ATMOS_E_FORMAT;
    if (st != ATMOS_OK) goto done;

    const float scale = desc->density_scale > 0 ? (float)desc->density_scale : 1.0f;
    for (int s = 0; s < nsel; s++) {
        atmos__vdb_grid_info info;
        atmos__vdb_get_grid_info(f, sel[s], &info);
        char field[64], particle[64];
        atmos__reader_field_names(info.name, desc, field, particle);
        visit_state vs = {ctx, vol, 0, {lo[0], lo[1], lo[2]}, scale, ATMOS_OK};
        st = atmos_volume_add_field(ctx, vol, field, particle, &vs.field);
        if (st != ATMOS_OK) goto done;
        atmos__volume_set_file_active(vol, vs.field, gs[s].active_voxels);
        rc = atmos__vdb_visit(f, sel[s], on_block, &vs, msg, sizeof msg);
        if (rc == ATMOS__VDB_E_STOPPED) {
            st = vs.status;
            goto done;
        }
        if (rc != ATMOS__VDB_OK) {
            st = atmos__error(ctx, shim_status(rc), "%s: %s", path, msg);
            goto done;
        }
    }
    st = atmos_volume_finalize(ctx, vol);

done:
    atmos__vdb_close(f);
    if (st != ATMOS_OK) {
        atmos_volume_destroy(vol);
        return atmos__reader_name_error(ctx, path, st);
    }
    *out = vol;
    return ATMOS_OK;
}

#endif /* ATMOS_HAVE_OPENVDB */
