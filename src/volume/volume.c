/* The volume object: creation and validation, the pooled brick storage, writes, and
 * finalize (statistics, the per-brick bounds of volume_range.c, the pool fixed).
 * Layout: volume_grid.h; reading: volume_access.h. */
#include "volume/volume_access.h"
#include "volume/volume_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void mat_identity(double r[9])
{
    memset(r, 0, 9 * sizeof r[0]);
    r[0] = r[4] = r[8] = 1;
}

static atmos_status check_desc(atmos_context *ctx, const atmos_volume_desc *d, atmos_volume_desc *out)
{
    *out = *d;
    out->periodic = d->periodic != 0;
    static const char axis[3] = {'x', 'y', 'z'};
    for (int a = 0; a < 3; a++) {
        if (d->dims[a] < 1 || d->dims[a] > ATMOS_VOLUME_MAX_DIM)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: dims[%d] (%c): must be in 1..%d, got %d", a,
                                axis[a], ATMOS_VOLUME_MAX_DIM, d->dims[a]);
        if (!isfinite(d->origin_m[a]))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: origin_m[%d]: must be finite", a);
    }
    if (!(isfinite(d->voxel_size_m) && d->voxel_size_m > 0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: voxel_size_m: must be finite and > 0, got %g",
                            d->voxel_size_m);
    /* A micrometre to 100 km: beyond, the renderers' walks in metres lose the voxel to the
     * precision of the positions (a path tracer's free flight stops advancing). */
    if (d->voxel_size_m < ATMOS_VOLUME_MIN_VOXEL_M || d->voxel_size_m > ATMOS_VOLUME_MAX_VOXEL_M)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "volume: voxel size %g m is outside the supported %g..%g m (a unit mix-up? the voxel size "
                            "is in metres)",
                            d->voxel_size_m, ATMOS_VOLUME_MIN_VOXEL_M, ATMOS_VOLUME_MAX_VOXEL_M);
    int zero = 1;
    for (int i = 0; i < 9; i++) {
        if (!isfinite(d->rotation[i]))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: rotation[%d]: must be finite", i);
        if (d->rotation[i] != 0) zero = 0;
    }
    if (zero) {
        mat_identity(out->rotation);
    } else {
        /* A rotation: R R^T = I and det R = +1 (a reflection would flip handedness). */
        const double *r = d->rotation;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double s = r[3 * i] * r[3 * j] + r[3 * i + 1] * r[3 * j + 1] + r[3 * i + 2] * r[3 * j + 2];
                if (fabs(s - (i == j)) > 1e-6)
                    return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                        "volume: rotation: not orthonormal (row %d . row %d = %g)", i, j, s);
            }
        double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
                     r[2] * (r[3] * r[7] - r[4] * r[6]);
        if (det < 0) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: rotation: determinant is -1 (a reflection)");
    }
    if (out->max_memory == 0) out->max_memory = ATMOS_VOLUME_DEFAULT_MAX_MEMORY;
    return ATMOS_OK;
}

atmos_status atmos_volume_create(atmos_context *ctx, const atmos_volume_desc *desc, atmos_volume **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: out is NULL");
    *out = NULL;
    if (!desc) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: desc is NULL");
    atmos_volume_desc d;
    atmos_status st = check_desc(ctx, desc, &d);
    if (st != ATMOS_OK) return st;
    if (sizeof(atmos_volume) + VOL_BRICK_BYTES > d.max_memory)
        return atmos__error(ctx, ATMOS_E_LIMIT,
                            "volume: max_memory %llu bytes is below the %llu bytes of the volume header and its zero brick",
                            (unsigned long long)d.max_memory, (unsigned long long)(sizeof(atmos_volume) + VOL_BRICK_BYTES));
    atmos_volume *v = calloc(1, sizeof *v);
    if (!v) return atmos__error(ctx, ATMOS_E_NOMEM, "volume: out of memory");
    /* The pool starts with brick 0, the zeros every empty table entry addresses. */
    v->pool = calloc(VOL_BRICK_VOXELS, sizeof(float));
    if (!v->pool) {
        free(v);
        return atmos__error(ctx, ATMOS_E_NOMEM, "volume: out of memory");
    }
    v->pool_used = v->pool_cap = 1;
    v->desc = d;
    atmos__vol_xform_init(v, NULL, &v->xform);
    v->memory = sizeof *v + VOL_BRICK_BYTES;
    v->nbricks = 1;
    for (int a = 0; a < 3; a++) {
        v->nb[a] = (d.dims[a] + VOL_BRICK - 1) / VOL_BRICK;
        v->nbricks *= (uint64_t)v->nb[a];
    }
    *out = v;
    return ATMOS_OK;
}

void atmos_volume_destroy(atmos_volume *vol)
{
    if (!vol) return;
    for (int f = 0; f < vol->nfields; f++) free(vol->field[f].table);
    free(vol->pool);
    free(vol->cell);
    free(vol->range);
    free(vol);
}

static int valid_name(const char *s)
{
    size_t n = s ? strlen(s) : 0;
    if (n == 0 || n >= VOL_NAME_MAX) return 0;
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)s[i] < 0x20 || s[i] == '"' || s[i] == '\\') return 0;
    return 1;
}

atmos_status atmos_volume_add_field(atmos_context *ctx, atmos_volume *vol, const char *name, const char *particle,
                                    int *index)
{
    if (!vol) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: vol is NULL");
    if (vol->finalized) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: add_field after finalize");
    if (!valid_name(name))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "volume: field name: must be 1..%d printable characters without quotes", VOL_NAME_MAX - 1);
    if (!particle) particle = name;
    if (!valid_name(particle))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: field '%s': particle name: must be 1..%d characters",
                            name, VOL_NAME_MAX - 1);
    for (int f = 0; f < vol->nfields; f++)
        if (!strcmp(vol->field[f].name, name))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: field '%s' already exists", name);
    if (vol->nfields >= ATMOS_VOLUME_MAX_FIELDS)
        return atmos__error(ctx, ATMOS_E_LIMIT, "volume: field '%s': at most %d fields", name, ATMOS_VOLUME_MAX_FIELDS);
    uint64_t bytes = vol->nbricks * sizeof(uint32_t);
    if (!atmos__volume_can_alloc(vol, bytes)) return atmos__volume_limit_error(ctx, vol, "the brick table of a field", bytes);
    vol_field *fl = &vol->field[vol->nfields];
    memset(fl, 0, sizeof *fl);
    fl->table = calloc((size_t)vol->nbricks, sizeof(uint32_t));
    if (!fl->table) return atmos__error(ctx, ATMOS_E_NOMEM, "volume: out of memory for a %llu-byte brick table",
                                        (unsigned long long)bytes);
    vol->memory += bytes;
    snprintf(fl->name, sizeof fl->name, "%s", name);
    snprintf(fl->particle, sizeof fl->particle, "%s", particle);
    if (index) *index = vol->nfields;
    vol->nfields++;
    return ATMOS_OK;
}

/* Room for one more brick in the pool: doubling (amortised O(1) per brick), but never
 * past max_memory, so a volume that fits brick by brick also fits the pool. */
static atmos_status pool_grow(atmos_context *ctx, atmos_volume *v, const vol_field *fl)
{
    if (v->pool_cap == UINT32_MAX)
        return atmos__error(ctx, ATMOS_E_LIMIT, "volume: field '%s': more than %u bricks", fl->name, UINT32_MAX - 1);
    uint64_t cap = (uint64_t)v->pool_cap * 2;
    if (cap < 16) cap = 16;
    if (cap > UINT32_MAX) cap = UINT32_MAX;
    const uint64_t room = v->memory <= v->desc.max_memory ? (v->desc.max_memory - v->memory) / VOL_BRICK_BYTES : 0;
    if (cap - v->pool_cap > room) cap = v->pool_cap + room;
    if (cap == v->pool_cap) return atmos__volume_limit_error(ctx, v, "another brick", VOL_BRICK_BYTES);
    const uint64_t extra = (cap - v->pool_cap) * VOL_BRICK_BYTES;
#if SIZE_MAX < UINT64_MAX
    if (cap * VOL_BRICK_BYTES > SIZE_MAX)
        return atmos__error(ctx, ATMOS_E_NOMEM, "volume: brick pool too large for this machine");
#endif
    float *p = realloc(v->pool, (size_t)(cap * VOL_BRICK_BYTES));
    if (!p) return atmos__error(ctx, ATMOS_E_NOMEM, "volume: out of memory for a %llu-byte brick pool",
                                (unsigned long long)(cap * VOL_BRICK_BYTES));
    v->pool = p;
    v->pool_cap = (uint32_t)cap;
    v->memory += extra;
    return ATMOS_OK;
}

/* The brick at brick index b of field fl, taken (zeroed) from the pool if needed. The
 * pointer is valid until the next brick is taken (the pool may move). */
static atmos_status brick_get(atmos_context *ctx, atmos_volume *v, vol_field *fl, uint64_t b, float **out)
{
    uint32_t s = fl->table[b];
    if (!s) {
        atmos_status st;
        if (v->pool_used == v->pool_cap && (st = pool_grow(ctx, v, fl)) != ATMOS_OK) return st;
        s = v->pool_used++;
        memset(v->pool + ((size_t)s << VOL_BRICK_VOXELS_LOG2), 0, VOL_BRICK_BYTES);
        fl->table[b] = s;
        fl->count++;
    }
    *out = v->pool + ((size_t)s << VOL_BRICK_VOXELS_LOG2);
    return ATMOS_OK;
}

static atmos_status check_field(atmos_context *ctx, const atmos_volume *vol, int field)
{
    if (!vol) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: vol is NULL");
    if (vol->finalized) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: write after finalize");
    if (field < 0 || field >= vol->nfields)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: field index %d out of range (0..%d)", field,
                            vol->nfields - 1);
    return ATMOS_OK;
}

atmos_status atmos_volume_set(atmos_context *ctx, atmos_volume *vol, int field, int i, int j, int k, float density)
{
    atmos_status st = check_field(ctx, vol, field);
    if (st != ATMOS_OK) return st;
    const int *n = vol->desc.dims;
    if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2])
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: set: voxel (%d, %d, %d) outside the %dx%dx%d grid", i, j,
                            k, n[0], n[1], n[2]);
    if (!isfinite(density) || density < 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "volume: field '%s': voxel (%d, %d, %d): density must be finite and >= 0, got %g",
                            vol->field[field].name, i, j, k, (double)density);
    vol_field *fl = &vol->field[field];
    uint64_t b = vol_brick_index(vol, i, j, k);
    if (density == 0 && !fl->table[b]) return ATMOS_OK;
    float *p;
    if ((st = brick_get(ctx, vol, fl, b, &p)) != ATMOS_OK) return st;
    p[vol_in_brick(i, j, k)] = density;
    return ATMOS_OK;
}

atmos_status atmos_volume_set_dense(atmos_context *ctx, atmos_volume *vol, int field, const int offset[3],
                                    const int size[3], const float *values, float scale)
{
    atmos_status st = check_field(ctx, vol, field);
    if (st != ATMOS_OK) return st;
    if (!offset || !size || !values) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: set_dense: NULL argument");
    const int *n = vol->desc.dims;
    for (int a = 0; a < 3; a++)
        if (size[a] < 1 || offset[a] < 0 || offset[a] > n[a] - size[a])
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "volume: set_dense: block offset[%d] %d + size[%d] %d outside 0..%d", a, offset[a], a,
                                size[a], n[a]);
    if (!isfinite(scale) || scale < 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: set_dense: scale must be finite and >= 0, got %g",
                            (double)scale);
    vol_field *fl = &vol->field[field];
    const size_t sx = (size_t)size[0], sxy = sx * (size_t)size[1];
    /* Validate everything first so a rejected block leaves the volume unchanged. */
    for (int k = 0; k < size[2]; k++)
        for (int j = 0; j < size[1]; j++)
            for (int i = 0; i < size[0]; i++) {
                float x = values[(size_t)k * sxy + (size_t)j * sx + (size_t)i];
                float y = x * scale;
                if (!isfinite(x) || x < 0 || !isfinite(y))
                    return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                        "volume: field '%s': value at block index (%d, %d, %d) (voxel %d, %d, %d): "
                                        "density must be finite and >= 0, got %g (scale %g)",
                                        fl->name, i, j, k, i + offset[0], j + offset[1], k + offset[2], (double)x,
                                        (double)scale);
            }
    /* Brick by brick so that all-zero parts of the block allocate nothing. */
    int b0[3], b1[3];
    for (int a = 0; a < 3; a++) {
        b0[a] = offset[a] >> VOL_BRICK_LOG2;
        b1[a] = (offset[a] + size[a] - 1) >> VOL_BRICK_LOG2;
    }
    for (int bk = b0[2]; bk <= b1[2]; bk++)
        for (int bj = b0[1]; bj <= b1[1]; bj++)
            for (int bi = b0[0]; bi <= b1[0]; bi++) {
                int lo[3] = {bi * VOL_BRICK, bj * VOL_BRICK, bk * VOL_BRICK}, hi[3];
                for (int a = 0; a < 3; a++) {
                    hi[a] = lo[a] + VOL_BRICK;
                    if (lo[a] < offset[a]) lo[a] = offset[a];
                    if (hi[a] > offset[a] + size[a]) hi[a] = offset[a] + size[a];
                }
                uint64_t b = vol_brick_index(vol, lo[0], lo[1], lo[2]);
                if (!fl->table[b]) {
                    int any = 0;
                    for (int k = lo[2]; k < hi[2] && !any; k++)
                        for (int j = lo[1]; j < hi[1] && !any; j++)
                            for (int i = lo[0]; i < hi[0]; i++)
                                if (values[(size_t)(k - offset[2]) * sxy + (size_t)(j - offset[1]) * sx +
                                           (size_t)(i - offset[0])] * scale != 0) {
                                    any = 1;
                                    break;
                                }
                    if (!any) continue;
                }
                float *p;
                if ((st = brick_get(ctx, vol, fl, b, &p)) != ATMOS_OK) return st;
                for (int k = lo[2]; k < hi[2]; k++)
                    for (int j = lo[1]; j < hi[1]; j++)
                        for (int i = lo[0]; i < hi[0]; i++)
                            p[vol_in_brick(i, j, k)] = values[(size_t)(k - offset[2]) * sxy +
                                                              (size_t)(j - offset[1]) * sx + (size_t)(i - offset[0])] *
                                                       scale;
            }
    return ATMOS_OK;
}

/* World-space AABB of the index-space box [lo, hi] (corners through the transform). */
static void index_box_to_world(const atmos_volume *v, const double lo[3], const double hi[3], double out[2][3])
{
    for (int a = 0; a < 3; a++) {
        out[0][a] = INFINITY;
        out[1][a] = -INFINITY;
    }
    for (int c = 0; c < 8; c++) {
        double q[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]}, w[3];
        atmos__vol_index_to_point(atmos__vol_xform_of(v), q, w);
        for (int a = 0; a < 3; a++) {
            if (w[a] < out[0][a]) out[0][a] = w[a];
            if (w[a] > out[1][a]) out[1][a] = w[a];
        }
    }
}

/* Statistics of one field: active voxels, their extremes and their world box. */
static void finalize_field(atmos_volume *v, vol_field *fl, int field)
{
    atmos_volume_field_stats *s = &fl->stats;
    memset(s, 0, sizeof *s);
    s->file_active_voxels = fl->file_active;
    int lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {-1, -1, -1};
    double mn = INFINITY, mx = 0;
    atmos__vol_brick_it it = {0};
    while (atmos__vol_next_brick(v, field, &it)) {
        for (int z = 0; z < VOL_BRICK; z++)
            for (int y = 0; y < VOL_BRICK; y++)
                for (int x = 0; x < VOL_BRICK; x++) {
                    float val = it.data[(z * VOL_BRICK + y) * VOL_BRICK + x];
                    if (!(val > 0)) continue;
                    int idx[3] = {it.o[0] + x, it.o[1] + y, it.o[2] + z};
                    s->active_voxels++;
                    if (val < mn) mn = val;
                    if (val > mx) mx = val;
                    for (int a = 0; a < 3; a++) {
                        if (idx[a] < lo[a]) lo[a] = idx[a];
                        if (idx[a] > hi[a]) hi[a] = idx[a];
                    }
                }
    }
    if (s->active_voxels) {
        s->min = mn;
        s->max = mx;
        double l[3] = {lo[0], lo[1], lo[2]}, h[3] = {hi[0] + 1.0, hi[1] + 1.0, hi[2] + 1.0};
        index_box_to_world(v, l, h, s->bounds_m);
    }
}

/* The pool is fixed from here on: give back the capacity no brick uses. */
static void pool_trim(atmos_volume *v)
{
    if (v->pool_used == v->pool_cap) return;
    float *p = realloc(v->pool, (size_t)v->pool_used * VOL_BRICK_BYTES);
    if (!p) return; /* keeping the larger block is harmless */
    v->pool = p;
    v->memory -= (uint64_t)(v->pool_cap - v->pool_used) * VOL_BRICK_BYTES;
    v->pool_cap = v->pool_used;
}

atmos_status atmos_volume_finalize(atmos_context *ctx, atmos_volume *vol)
{
    if (!vol) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: vol is NULL");
    if (vol->finalized) return ATMOS_OK;
    pool_trim(vol);
    atmos_status st = atmos__volume_build_ranges(ctx, vol);
    if (st != ATMOS_OK) return st;
    for (int f = 0; f < vol->nfields; f++) finalize_field(vol, &vol->field[f], f);
    vol->finalized = 1;
    return ATMOS_OK;
}

const atmos_volume_desc *atmos_volume_get_desc(const atmos_volume *vol) { return vol ? &vol->desc : NULL; }
int atmos_volume_field_count(const atmos_volume *vol) { return vol ? vol->nfields : 0; }

const char *atmos_volume_field_name(const atmos_volume *vol, int field)
{
    return vol && field >= 0 && field < vol->nfields ? vol->field[field].name : NULL;
}

const char *atmos_volume_field_particle(const atmos_volume *vol, int field)
{
    return vol && field >= 0 && field < vol->nfields ? vol->field[field].particle : NULL;
}

atmos_status atmos_volume_field_stats_get(atmos_context *ctx, const atmos_volume *vol, int field,
                                          atmos_volume_field_stats *out)
{
    if (!vol || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: field stats: %s is NULL", vol ? "out" : "vol");
    if (field < 0 || field >= vol->nfields)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: field stats: field index %d out of range (0..%d)", field,
                            vol->nfields - 1);
    if (!vol->finalized)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume: field stats of '%s': the volume is not finalized",
                            vol->field[field].name);
    *out = vol->field[field].stats;
    return ATMOS_OK;
}

uint64_t atmos_volume_memory(const atmos_volume *vol) { return vol ? vol->memory : 0; }

void atmos_volume_bounds(const atmos_volume *vol, double lo[3], double hi[3])
{
    if (!vol) {
        for (int a = 0; a < 3; a++) lo[a] = hi[a] = 0;
        return;
    }
    double l[3] = {0, 0, 0}, h[3] = {vol->desc.dims[0], vol->desc.dims[1], vol->desc.dims[2]}, b[2][3];
    index_box_to_world(vol, l, h, b);
    for (int a = 0; a < 3; a++) {
        lo[a] = b[0][a];
        hi[a] = b[1][a];
    }
}

void atmos__volume_set_file_active(atmos_volume *vol, int field, uint64_t count)
{
    if (vol && field >= 0 && field < vol->nfields) {
        vol->field[field].file_active = count;
        vol->field[field].stats.file_active_voxels = count;
    }
}

void atmos__volume_rescale(atmos_volume *vol, double factor)
{
    if (!vol || !(factor > 0) || factor == 1.0) return;
    vol->desc.voxel_size_m *= factor;
    for (int a = 0; a < 3; a++) vol->desc.origin_m[a] *= factor;
    atmos__vol_xform_init(vol, NULL, &vol->xform);
    /* A field's box is origin + R (index * voxel size): linear in both, so it scales too. */
    for (int f = 0; f < vol->nfields; f++)
        for (int c = 0; c < 2; c++)
            for (int a = 0; a < 3; a++) vol->field[f].stats.bounds_m[c][a] *= factor;
}

void atmos__volume_set_source_format(atmos_volume *vol, const char *format)
{
    if (vol) snprintf(vol->source_format, sizeof vol->source_format, "%s", format ? format : "");
}

const char *atmos_volume_source_format(const atmos_volume *vol) { return vol ? vol->source_format : ""; }
