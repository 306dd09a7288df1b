/* OpenVDB .vdb reader: picks the float grids, checks their values and transform,
 * and copies leaves and active tiles into an atmos volume. The file itself is
 * parsed by the OpenVDB library through openvdb_shim.cpp (the module libatmos_openvdb.so,
 * opened on the first .vdb file: openvdb_module.c); without it (the library
 * was not found at configure time) the reader says which package to install. */
#include "core/internal.h"
#include "volume/reader_common.h"
#include "volume/volume_internal.h"

#include <errno.h>
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
#include "volume/reader_fence.h"
#include "volume/vdb_header.h"

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

/* One load: the open file, the selected grids and their measurements, the index box
 * they span, the volume. atmos__volume_load_openvdb closes the file and, on
 * failure, destroys the volume, whichever step failed. */
typedef struct {
    atmos_context *ctx;
    const char *path;
    const atmos_volume_load_desc *desc;
    atmos__vdb *f;
    int sel[ATMOS_VOLUME_MAX_FIELDS], nsel;
    atmos__vdb_grid_stats gs[ATMOS_VOLUME_MAX_FIELDS];
    int lo[3], hi[3], any; /* inclusive index box of all grids' active values */
    uint64_t total;        /* active voxels of all grids */
    atmos_volume *vol;
    char msg[MSG_CAP];     /* the shim's last message */
} vdb_load;

static atmos_status shim_error(vdb_load *L, int rc)
{
    return atmos__error(L->ctx, shim_status(rc), "%s: %s", L->path, L->msg);
}

/* Loads selected grid s and checks its values and its transform against the first. */
static atmos_status measure_grid(vdb_load *L, int s)
{
    atmos__vdb_grid_stats *gs = &L->gs[s];
    atmos__vdb_grid_info info;
    atmos__vdb_get_grid_info(L->f, L->sel[s], &info);
    int rc = atmos__vdb_load_grid(L->f, L->sel[s], gs, L->msg, sizeof L->msg);
    if (rc != ATMOS__VDB_OK) return shim_error(L, rc);
    /* Real fog volumes (the Disney cloud, dragon.vdb) hold no negative or non-finite
     * values, so any such value marks a broken or non-density grid (an SDF, say):
     * refuse rather than guess. */
    if (gs->bad_values)
        return atmos__error(L->ctx, ATMOS_E_FORMAT,
                            "%s: grid '%s': value %g at index (%d, %d, %d) is %s (%llu bad values); densities "
                            "must be finite and >= 0 (is this a level set rather than a fog volume?)",
                            L->path, info.name, gs->bad_value, gs->bad_ijk[0], gs->bad_ijk[1], gs->bad_ijk[2],
                            gs->bad_value < 0 ? "negative" : "not finite", (unsigned long long)gs->bad_values);
    if (!gs->linear)
        return atmos__error(L->ctx, ATMOS_E_UNSUPPORTED,
                            "%s: grid '%s' has a non-linear transform (%s, e.g. a frustum): atmos needs a linear "
                            "(scale, rotation, translation) transform; resample the grid first",
                            L->path, info.name, gs->map_type);
    if (s > 0 && memcmp(gs->mat, L->gs[0].mat, sizeof gs->mat) != 0) {
        atmos__vdb_grid_info first;
        atmos__vdb_get_grid_info(L->f, L->sel[0], &first);
        return atmos__error(L->ctx, ATMOS_E_UNSUPPORTED,
                            "%s: grids '%s' and '%s' have different transforms; atmos puts all fields on one "
                            "grid: load them separately or resample",
                            L->path, first.name, info.name);
    }
    L->total += gs->active_voxels;
    if (gs->empty) return ATMOS_OK;
    for (int a = 0; a < 3; a++) {
        if (!L->any || gs->bbox_min[a] < L->lo[a]) L->lo[a] = gs->bbox_min[a];
        if (!L->any || gs->bbox_max[a] > L->hi[a]) L->hi[a] = gs->bbox_max[a];
    }
    L->any = 1;
    atmos__log(L->ctx, ATMOS_LOG_INFO,
               "%s: grid '%s': %llu active voxels (%llu in leaves, %llu active tiles), index box [%d %d %d]..[%d "
               "%d %d], values %g..%g%s",
               L->path, info.name, (unsigned long long)gs->active_voxels, (unsigned long long)gs->leaf_voxels,
               (unsigned long long)gs->active_tiles, gs->bbox_min[0], gs->bbox_min[1], gs->bbox_min[2],
               gs->bbox_max[0], gs->bbox_max[1], gs->bbox_max[2], gs->min, gs->max,
               gs->compressed ? ", compressed" : "");
    return ATMOS_OK;
}

/* The memory check, then the volume spanning the grids' index box, placed by their
 * shared transform. */
static atmos_status create_volume(vdb_load *L)
{
    if (!L->any) {
        atmos__log(L->ctx, ATMOS_LOG_WARN, "%s: the selected grids have no active voxels; the volume is empty",
                   L->path);
        L->lo[0] = L->lo[1] = L->lo[2] = 0;
        L->hi[0] = L->hi[1] = L->hi[2] = 0;
    }
    atmos_status st = atmos__reader_check_memory(L->ctx, L->path, L->total, L->desc->max_memory);
    if (st != ATMOS_OK) return st;
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    for (int a = 0; a < 3; a++) {
        int64_t n = (int64_t)L->hi[a] - L->lo[a] + 1;
        if (n > ATMOS_VOLUME_MAX_DIM)
            return atmos__error(L->ctx, ATMOS_E_LIMIT, "%s: the grids span %lld voxels along axis %d (limit %d)",
                                L->path, (long long)n, a, ATMOS_VOLUME_MAX_DIM);
        vd.dims[a] = (int)n;
    }
    /* OpenVDB maps row vectors: world = [i j k 1] * M; atmos's A is column-major
     * in that sense, so A = M3^T and the translation is M's last row. */
    double A[9], t[3];
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) A[3 * r + c] = L->gs[0].mat[c][r];
        t[r] = L->gs[0].mat[3][r];
    }
    char why[256];
    if (atmos__reader_placement(A, t, L->lo, &vd, why, sizeof why) != 0) {
        atmos__vdb_grid_info info;
        atmos__vdb_get_grid_info(L->f, L->sel[0], &info);
        return atmos__error(L->ctx, ATMOS_E_UNSUPPORTED, "%s: grid '%s': %s", L->path, info.name, why);
    }
    vd.max_memory = L->desc->max_memory;
    st = atmos_volume_create(L->ctx, &vd, &L->vol);
    /* a grid placement the core refuses (not a rotation, absurd size) is a malformed file */
    return st == ATMOS_E_INVALID_ARG ? ATMOS_E_FORMAT : st;
}

/* Adds selected grid s as a field and copies its leaves and active tiles. */
static atmos_status write_grid(vdb_load *L, int s)
{
    atmos__vdb_grid_info info;
    atmos__vdb_get_grid_info(L->f, L->sel[s], &info);
    char field[64], particle[64];
    atmos__reader_field_names(info.name, L->desc, field, particle);
    const float scale = L->desc->density_scale > 0 ? (float)L->desc->density_scale : 1.0f;
    visit_state vs = {L->ctx, L->vol, 0, {L->lo[0], L->lo[1], L->lo[2]}, scale, ATMOS_OK};
    atmos_status st = atmos_volume_add_field(L->ctx, L->vol, field, particle, &vs.field);
    if (st != ATMOS_OK) return st;
    atmos__volume_set_file_active(L->vol, vs.field, L->gs[s].active_voxels);
    int rc = atmos__vdb_visit(L->f, L->sel[s], on_block, &vs, L->msg, sizeof L->msg);
    if (rc == ATMOS__VDB_E_STOPPED) return vs.status;
    return rc == ATMOS__VDB_OK ? ATMOS_OK : shim_error(L, rc);
}

static atmos_status load(vdb_load *L)
{
    int rc = atmos__vdb_open(L->path, &L->f, L->msg, sizeof L->msg);
    if (rc != ATMOS__VDB_OK) return shim_error(L, rc);
    atmos_status st = select_grids(L->ctx, L->path, L->f, L->desc->grids, L->sel, &L->nsel);
    for (int s = 0; s < L->nsel && st == ATMOS_OK; s++) st = measure_grid(L, s);
    if (st == ATMOS_OK) st = create_volume(L);
    for (int s = 0; s < L->nsel && st == ATMOS_OK; s++) {
        st = write_grid(L, s);
        atmos__progress(L->ctx, "volume load", 0.5 * (s + 1.0) / L->nsel);
    }
    return st == ATMOS_OK ? atmos_volume_finalize(L->ctx, L->vol) : st;
}

/* The load itself, run in the fence's child process. */
static atmos_status load_direct(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                atmos_volume **out)
{
    static const atmos_volume_load_desc zero_desc;
    vdb_load L;
    memset(&L, 0, sizeof L);
    L.ctx = ctx;
    L.path = path;
    L.desc = desc ? desc : &zero_desc;
    L.hi[0] = L.hi[1] = L.hi[2] = -1;
    atmos_status st = load(&L);
    if (L.f) atmos__vdb_close(L.f);
    if (st != ATMOS_OK) {
        atmos_volume_destroy(L.vol);
        return atmos__reader_name_error(ctx, path, st);
    }
    *out = L.vol;
    return ATMOS_OK;
}

/* The file's own structure is checked first (no library involved): a truncated or damaged
 * header is refused here with what is wrong. The library then reads the file behind the
 * fence (reader_fence.h), so a crash or a runaway in it becomes an error naming the file. */
atmos_status atmos__volume_load_openvdb(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                        atmos_volume **out)
{
    if (!out || !path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "openvdb: path and out are required");
    *out = NULL;
    FILE *probe = fopen(path, "rb");
    if (!probe) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));
    fclose(probe);
    char why[MSG_CAP];
    int ngrids = 0;
    if (atmos__vdb_check_header(path, &ngrids, why, sizeof why) != 0)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s", path, why);
    /* the library's module, opened here so the fence's children inherit it */
    if (!atmos__vdb_module_load(why, sizeof why))
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED, "%s: %s (install it next to libatmos)", path, why);
    return atmos__reader_fenced(ctx, path, desc, "OpenVDB", load_direct, out);
}

#endif /* ATMOS_HAVE_OPENVDB */
