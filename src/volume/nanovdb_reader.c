/* NanoVDB .nvdb reader in C, on top of PNanoVDB.h (Debian's libnanovdb-dev).
 *
 * File layout (nanovdb/util/IO.h, format version 32.x): one or more segments, each
 *   a 16-byte header  {u64 magic "NanoVDB0", u32 version, u16 grid count, u16 codec},
 *   per grid 176 bytes of metadata followed by its NUL-terminated name,
 *   then the grid buffers, one per grid, `fileSize` bytes each.
 * A grid buffer is the in-memory NanoVDB grid: GridData, TreeData, the root with its
 * tile table, then the upper internal nodes (32^3), lower internal nodes (16^3) and
 * leaves (8^3), children addressed by byte offsets.
 *
 * Everything in the file is untrusted (this is a fuzzing target): PNanoVDB's reads
 * are compiled with PNANOVDB_BUF_BOUNDS_CHECK so no read leaves the buffer, and on
 * top of that every node offset is checked to point at a node of the right level,
 * each node is visited at most once (so the walk is linear in the file size), and
 * the voxel count is measured in a first pass and checked against the memory limit
 * before the volume is created.
 */
#define _POSIX_C_SOURCE 200809L /* fseeko, ftello */
#include "core/internal.h"
#include "volume/reader_common.h"
#include "volume/volume_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef ATMOS_HAVE_NANOVDB

atmos_status atmos__volume_load_nanovdb(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                        atmos_volume **out)
{
    (void)desc;
    if (out) *out = NULL;
    return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                        "%s: this build of atmos cannot read NanoVDB files: install libnanovdb-dev and reconfigure",
                        path);
}

atmos_status atmos__volume_load_nanovdb_mem(atmos_context *ctx, const char *name, const void *data, size_t size,
                                            const atmos_volume_load_desc *desc, atmos_volume **out)
{
    (void)data;
    (void)size;
    return atmos__volume_load_nanovdb(ctx, name, desc, out);
}

#else

#define PNANOVDB_C
#define PNANOVDB_BUF_BOUNDS_CHECK
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wmissing-prototypes"
#pragma GCC diagnostic ignored "-Wstrict-prototypes"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#endif
#include <nanovdb/PNanoVDB.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#define NVDB_HEADER_SIZE 16u
#define NVDB_META_SIZE 176u
#define NVDB_MAX_NAME 4096u
#define NVDB_CODEC_NONE 0u
#define NVDB_MAX_GRIDS 4096u

/* ------------------------------------------------------------ byte source */

/* The reader works over either an open file or a memory buffer (the fuzzing
 * entry point), read at explicit offsets. */
typedef struct {
    FILE *fp;
    const unsigned char *mem;
    uint64_t size;
} source;

static int src_read(const source *s, uint64_t off, void *dst, uint64_t n)
{
    if (off > s->size || n > s->size - off) return -1;
    if (s->mem) {
        memcpy(dst, s->mem + off, (size_t)n);
        return 0;
    }
    if (fseeko(s->fp, (off_t)off, SEEK_SET) != 0) return -1;
    return fread(dst, 1, (size_t)n, s->fp) == (size_t)n ? 0 : -1;
}

static uint64_t rd_u64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--) v = (v << 8) | p[i];
    return v;
}
static uint32_t rd_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* One grid as listed in a segment's metadata. */
typedef struct {
    char name[256];
    uint64_t grid_size, file_size, offset; /* offset of the buffer in the file */
    uint32_t grid_type;
    uint16_t codec;
} grid_entry;

static const char *codec_name(unsigned c)
{
    return c == 0 ? "none" : c == 1 ? "zip" : c == 2 ? "blosc" : "unknown";
}

/* The grids listed so far, in file order. */
typedef struct {
    grid_entry *g;
    int n, cap;
} grid_list;

/* Checks the 16-byte segment header at off; *gcount is its number of grids. */
static atmos_status segment_header(atmos_context *ctx, const char *path, const source *s, uint64_t off, int listed,
                                   unsigned *gcount)
{
    unsigned char h[NVDB_HEADER_SIZE];
    if (src_read(s, off, h, sizeof h) != 0)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated NanoVDB segment header at byte %llu", path,
                            (unsigned long long)off);
    const uint64_t magic = rd_u64(h);
    const uint32_t version = rd_u32(h + 8);
    const unsigned codec = (unsigned)h[14] | (unsigned)h[15] << 8;
    *gcount = (unsigned)h[12] | (unsigned)h[13] << 8;
    if (magic != PNANOVDB_MAGIC_NUMBER)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: not a NanoVDB file (bad magic number at byte %llu)", path,
                            (unsigned long long)off);
    if ((version >> 21) != PNANOVDB_MAJOR_VERSION_NUMBER)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                            "%s: NanoVDB file format version %u.%u; this reader handles major version %u", path,
                            version >> 21, (version >> 10) & 0x7ffu, (unsigned)PNANOVDB_MAJOR_VERSION_NUMBER);
    if (codec != NVDB_CODEC_NONE)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                            "%s: %s-compressed NanoVDB file; atmos reads uncompressed .nvdb only (re-save it "
                            "with codec NONE, e.g. nanovdb_convert without -z/-b)",
                            path, codec_name(codec));
    if (*gcount == 0 || (unsigned)listed + *gcount > NVDB_MAX_GRIDS)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: segment at byte %llu declares %u grids", path,
                            (unsigned long long)off, *gcount);
    return ATMOS_OK;
}

/* Reads one grid's metadata and name at *off (advanced past them) into a new entry. */
static atmos_status grid_metadata(atmos_context *ctx, const char *path, const source *s, uint64_t *off,
                                  grid_list *l)
{
    unsigned char m[NVDB_META_SIZE];
    if (src_read(s, *off, m, sizeof m) != 0)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated grid metadata (grid %d)", path, l->n);
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 4;
        grid_entry *ng = realloc(l->g, (size_t)cap * sizeof *ng);
        if (!ng) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        l->g = ng;
        l->cap = cap;
    }
    grid_entry *e = &l->g[l->n];
    memset(e, 0, sizeof *e);
    e->grid_size = rd_u64(m);
    e->file_size = rd_u64(m + 8);
    e->grid_type = rd_u32(m + 32);
    const uint32_t name_size = rd_u32(m + 136);
    e->codec = (uint16_t)(m[168] | m[169] << 8);
    *off += NVDB_META_SIZE;
    if (name_size == 0 || name_size > NVDB_MAX_NAME)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid %d: implausible name length %u", path, l->n, name_size);
    char name[NVDB_MAX_NAME];
    if (src_read(s, *off, name, name_size) != 0)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated grid name (grid %d)", path, l->n);
    name[name_size - 1] = '\0';
    /* Longer names than NanoVDB's own 256-byte limit are cut, not trusted. */
    size_t nl = strnlen(name, sizeof e->name - 1);
    memcpy(e->name, name, nl);
    e->name[nl] = '\0';
    *off += name_size;
    l->n++;
    return ATMOS_OK;
}

/* The buffers of grids first.. follow all of the segment's metadata, in order, from
 * *off (advanced past them). */
static atmos_status place_buffers(atmos_context *ctx, const char *path, const source *s, uint64_t *off,
                                  grid_list *l, int first)
{
    for (int i = first; i < l->n; i++) {
        grid_entry *e = &l->g[i];
        if (e->file_size != e->grid_size)
            return atmos__error(ctx, ATMOS_E_FORMAT,
                                "%s: grid '%s': stored size %llu differs from its size %llu in an uncompressed file",
                                path, e->name, (unsigned long long)e->file_size, (unsigned long long)e->grid_size);
        if (e->file_size > s->size - *off)
            return atmos__error(ctx, ATMOS_E_FORMAT,
                                "%s: grid '%s': truncated (needs %llu bytes at byte %llu, the file has %llu)", path,
                                e->name, (unsigned long long)e->file_size, (unsigned long long)*off,
                                (unsigned long long)s->size);
        e->offset = *off;
        *off += e->file_size;
    }
    return ATMOS_OK;
}

/* One segment at *off: header, metadata, buffers. */
static atmos_status list_segment(atmos_context *ctx, const char *path, const source *s, uint64_t *off, grid_list *l)
{
    unsigned gcount = 0;
    atmos_status st = segment_header(ctx, path, s, *off, l->n, &gcount);
    if (st != ATMOS_OK) return st;
    *off += NVDB_HEADER_SIZE;
    const int first = l->n;
    for (unsigned i = 0; i < gcount; i++)
        if ((st = grid_metadata(ctx, path, s, off, l)) != ATMOS_OK) return st;
    return place_buffers(ctx, path, s, off, l, first);
}

/* Lists the grids of every segment. */
static atmos_status list_file(atmos_context *ctx, const char *path, const source *s, grid_entry **out, int *count)
{
    grid_list l = {NULL, 0, 0};
    uint64_t off = 0;
    atmos_status st = ATMOS_OK;
    while (off < s->size && st == ATMOS_OK) st = list_segment(ctx, path, s, &off, &l);
    if (st == ATMOS_OK && l.n == 0) st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: empty file, no NanoVDB grids", path);
    if (st != ATMOS_OK) {
        free(l.g);
        l.g = NULL;
        l.n = 0;
    }
    *out = l.g;
    *count = l.n;
    return st;
}

/* ------------------------------------------------------------ tree walk */

typedef struct {
    pnanovdb_buf_t buf;
    uint64_t size;                   /* bytes in buf */
    uint64_t base[3];                /* first leaf / lower / upper node address */
    uint32_t count[3];               /* node counts: leaf, lower, upper */
    uint32_t node_size[3];
    unsigned char *seen[3];          /* one byte per node: visited already */
    /* pass 1 results */
    uint64_t active;                 /* voxels, tiles counted in full */
    int64_t lo[3], hi[3];            /* inclusive index box of active values */
    int any;
    /* first bad value */
    int bad;
    int64_t bad_ijk[3];
    float bad_value;
    const char *why;                 /* structural problem, for the message */
    /* pass 2 */
    atmos_context *ctx;
    atmos_volume *vol;
    int field;
    float scale;
    atmos_status status;
} walk;

static const char *const level_name[3] = {"leaf", "lower internal node", "upper internal node"};

/* Resolves a child at parent + rel as a node of `level`; NULL handle (0) and a
 * message when it does not point at an unvisited node of that level. */
static int child_ok(walk *w, int level, uint64_t parent, int64_t rel, uint64_t *addr)
{
    uint64_t a = parent + (uint64_t)rel; /* wraps on purpose; checked below */
    if (w->count[level] == 0 || a < w->base[level]) goto bad;
    uint64_t idx = (a - w->base[level]) / w->node_size[level];
    if ((a - w->base[level]) % w->node_size[level] != 0 || idx >= w->count[level]) goto bad;
    if (w->seen[level][idx]) {
        w->why = "a node is referenced twice";
        return 0;
    }
    w->seen[level][idx] = 1;
    *addr = a;
    return 1;
bad:
    w->why = level == 0 ? "a child offset does not point at a leaf"
             : level == 1 ? "a child offset does not point at a lower internal node"
                          : "a root tile's child does not point at an upper internal node";
    return 0;
}

/* One active block: a voxel (dim 1) or a tile (dim 8, 128, 4096). Pass 1 measures,
 * pass 2 writes. */
static int visit_tile(walk *w, int pass, const int64_t ijk[3], int64_t dim, float v)
{
    if (!isfinite(v) || v < 0) {
        if (!w->bad) {
            w->bad = 1;
            memcpy(w->bad_ijk, ijk, sizeof w->bad_ijk);
            w->bad_value = v;
        }
        return 0;
    }
    if (pass == 1) {
        w->active += (uint64_t)(dim * dim * dim);
        for (int a = 0; a < 3; a++) {
            if (!w->any || ijk[a] < w->lo[a]) w->lo[a] = ijk[a];
            if (!w->any || ijk[a] + dim - 1 > w->hi[a]) w->hi[a] = ijk[a] + dim - 1;
        }
        w->any = 1;
        return 0;
    }
    const int64_t o[3] = {ijk[0] - w->lo[0], ijk[1] - w->lo[1], ijk[2] - w->lo[2]};
    const int64_t n[3] = {dim, dim, dim};
    w->status = atmos__reader_write_block(w->ctx, w->vol, w->field, o, n, NULL, v, w->scale);
    return w->status != ATMOS_OK;
}

static int walk_leaf(walk *w, int pass, uint64_t addr, const int64_t org[3])
{
    pnanovdb_leaf_handle_t leaf = {{addr}};
    float block[512];
    int any = 0;
    for (uint32_t n = 0; n < 512; n++) {
        /* NanoVDB orders a leaf z fastest: n = x*64 + y*8 + z. */
        const int x = (int)(n >> 6), y = (int)((n >> 3) & 7), z = (int)(n & 7);
        float v = 0.0f;
        if (pnanovdb_leaf_get_value_mask(w->buf, leaf, n)) {
            v = pnanovdb_read_float(w->buf, pnanovdb_leaf_get_table_address(PNANOVDB_GRID_TYPE_FLOAT, w->buf, leaf, n));
            const int64_t ijk[3] = {org[0] + x, org[1] + y, org[2] + z};
            if (pass == 1) {
                if (visit_tile(w, 1, ijk, 1, v)) return 1;
            } else {
                any = 1;
            }
        }
        block[x + 8 * (y + 8 * z)] = v;
    }
    if (pass == 2 && any) {
        const int64_t o[3] = {org[0] - w->lo[0], org[1] - w->lo[1], org[2] - w->lo[2]}, sz[3] = {8, 8, 8};
        w->status = atmos__reader_write_block(w->ctx, w->vol, w->field, o, sz, block, 0.0f, w->scale);
        return w->status != ATMOS_OK;
    }
    return 0;
}

static int walk_lower(walk *w, int pass, uint64_t addr, const int64_t org[3])
{
    pnanovdb_lower_handle_t lower = {{addr}};
    for (uint32_t n = 0; n < 4096; n++) {
        const int64_t ijk[3] = {org[0] + 8 * (int64_t)(n >> 8), org[1] + 8 * (int64_t)((n >> 4) & 15),
                                org[2] + 8 * (int64_t)(n & 15)};
        if (pnanovdb_lower_get_child_mask(w->buf, lower, n)) {
            uint64_t child;
            if (!child_ok(w, 0, addr, pnanovdb_lower_get_table_child(PNANOVDB_GRID_TYPE_FLOAT, w->buf, lower, n),
                          &child))
                return 1;
            if (walk_leaf(w, pass, child, ijk)) return 1;
        } else if (pnanovdb_lower_get_value_mask(w->buf, lower, n)) {
            float v = pnanovdb_read_float(
                w->buf, pnanovdb_lower_get_table_address(PNANOVDB_GRID_TYPE_FLOAT, w->buf, lower, n));
            if (visit_tile(w, pass, ijk, 8, v)) return 1;
        }
    }
    return 0;
}

static int walk_upper(walk *w, int pass, uint64_t addr, const int64_t org[3])
{
    pnanovdb_upper_handle_t upper = {{addr}};
    for (uint32_t n = 0; n < 32768; n++) {
        const int64_t ijk[3] = {org[0] + 128 * (int64_t)(n >> 10), org[1] + 128 * (int64_t)((n >> 5) & 31),
                                org[2] + 128 * (int64_t)(n & 31)};
        if (pnanovdb_upper_get_child_mask(w->buf, upper, n)) {
            uint64_t child;
            if (!child_ok(w, 1, addr, pnanovdb_upper_get_table_child(PNANOVDB_GRID_TYPE_FLOAT, w->buf, upper, n),
                          &child))
                return 1;
            if (walk_lower(w, pass, child, ijk)) return 1;
        } else if (pnanovdb_upper_get_value_mask(w->buf, upper, n)) {
            float v = pnanovdb_read_float(
                w->buf, pnanovdb_upper_get_table_address(PNANOVDB_GRID_TYPE_FLOAT, w->buf, upper, n));
            if (visit_tile(w, pass, ijk, 128, v)) return 1;
        }
    }
    return 0;
}

/* Root tile keys pack the tile origin's coordinates >> 12 in 21 bits each
 * (pnanovdb_coord_to_key): i in bits 42.., j in 21.., k in 0... */
static int64_t key_coord(uint64_t key, int shift)
{
    uint32_t u = (uint32_t)((key >> shift) & 0x1fffffu) << 12;
    return (int64_t)(int32_t)u;
}

static int walk_root(walk *w, int pass, pnanovdb_root_handle_t root, uint32_t tiles)
{
    for (int l = 0; l < 3; l++)
        if (w->count[l]) memset(w->seen[l], 0, w->count[l]);
    for (uint32_t t = 0; t < tiles; t++) {
        pnanovdb_root_tile_handle_t tile = pnanovdb_root_get_tile(PNANOVDB_GRID_TYPE_FLOAT, root, t);
        const uint64_t key = pnanovdb_root_tile_get_key(w->buf, tile);
        const int64_t org[3] = {key_coord(key, 42), key_coord(key, 21), key_coord(key, 0)};
        const int64_t child = pnanovdb_root_tile_get_child(w->buf, tile);
        if (child != 0) {
            uint64_t addr;
            if (!child_ok(w, 2, root.address.byte_offset, child, &addr)) return 1;
            if (walk_upper(w, pass, addr, org)) return 1;
        } else if (pnanovdb_root_tile_get_state(w->buf, tile)) {
            float v = pnanovdb_read_float(w->buf, pnanovdb_root_tile_get_value_address(PNANOVDB_GRID_TYPE_FLOAT,
                                                                                        w->buf, tile));
            if (visit_tile(w, pass, org, 4096, v)) return 1;
        }
    }
    return 0;
}

/* ------------------------------------------------------------ one grid */

static atmos_status load_grid(atmos_context *ctx, const char *path, const grid_entry *e, walk *w,
                              pnanovdb_root_handle_t *root, uint32_t *tiles, double A[9], double t[3])
{
    const uint64_t sz = w->size;
    pnanovdb_grid_handle_t grid = {{0}};
    const uint32_t min_size = PNANOVDB_GRID_SIZE + PNANOVDB_TREE_SIZE;
    if (sz < min_size)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%s': %llu bytes, too small for a NanoVDB grid", path,
                            e->name, (unsigned long long)sz);
    if (pnanovdb_grid_get_magic(w->buf, grid) != PNANOVDB_MAGIC_NUMBER)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%s': bad magic number in the grid buffer", path, e->name);
    if ((pnanovdb_grid_get_version(w->buf, grid) >> 21) != PNANOVDB_MAJOR_VERSION_NUMBER)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED, "%s: grid '%s': NanoVDB grid version %u, expected major %u",
                            path, e->name, pnanovdb_grid_get_version(w->buf, grid) >> 21,
                            (unsigned)PNANOVDB_MAJOR_VERSION_NUMBER);
    const uint32_t type = pnanovdb_grid_get_grid_type(w->buf, grid);
    if (type != PNANOVDB_GRID_TYPE_FLOAT)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                            "%s: grid '%s' has NanoVDB value type %u%s; atmos reads 32-bit float grids", path, e->name,
                            type, type >= PNANOVDB_GRID_TYPE_FP4 && type <= PNANOVDB_GRID_TYPE_FPN ? " (quantized)" : "");
    if (pnanovdb_grid_get_grid_size(w->buf, grid) > sz)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%s': the grid claims %llu bytes, the file holds %llu",
                            path, e->name, (unsigned long long)pnanovdb_grid_get_grid_size(w->buf, grid),
                            (unsigned long long)sz);

    pnanovdb_map_handle_t map = pnanovdb_grid_get_map(w->buf, grid);
    for (int i = 0; i < 9; i++) A[i] = pnanovdb_map_get_matd(w->buf, map, (uint32_t)i);
    for (int i = 0; i < 3; i++) t[i] = pnanovdb_map_get_vecd(w->buf, map, (uint32_t)i);
    for (int i = 0; i < 12; i++)
        if (!isfinite(i < 9 ? A[i] : t[i - 9]))
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%s': non-finite transform", path, e->name);

    pnanovdb_tree_handle_t tree = pnanovdb_grid_get_tree(w->buf, grid);
    const uint64_t ta = tree.address.byte_offset;
    const uint64_t off[3] = {pnanovdb_tree_get_node_offset_leaf(w->buf, tree),
                             pnanovdb_tree_get_node_offset_lower(w->buf, tree),
                             pnanovdb_tree_get_node_offset_upper(w->buf, tree)};
    const uint32_t cnt[3] = {pnanovdb_tree_get_node_count_leaf(w->buf, tree),
                             pnanovdb_tree_get_node_count_lower(w->buf, tree),
                             pnanovdb_tree_get_node_count_upper(w->buf, tree)};
    const uint32_t nsz[3] = {PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, leaf_size),
                             PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, lower_size),
                             PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, upper_size)};
    for (int l = 0; l < 3; l++) {
        w->count[l] = cnt[l];
        w->node_size[l] = nsz[l];
        w->base[l] = ta + off[l];
        if (cnt[l] == 0) continue;
        /* The whole node array must lie inside the buffer. */
        if (off[l] > sz || w->base[l] > sz || (uint64_t)cnt[l] > (sz - w->base[l]) / nsz[l])
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%s': %u %ss at offset %llu do not fit in %llu bytes",
                                path, e->name, cnt[l], level_name[l], (unsigned long long)off[l],
                                (unsigned long long)sz);
        w->seen[l] = malloc(cnt[l]);
        if (!w->seen[l]) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
    }
    const uint64_t roff = pnanovdb_tree_get_node_offset_root(w->buf, tree);
    const uint32_t rsize = PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_size);
    const uint32_t tsize = PNANOVDB_GRID_TYPE_GET(PNANOVDB_GRID_TYPE_FLOAT, root_tile_size);
    if (roff > sz || ta + roff > sz || sz - (ta + roff) < rsize)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%s': root node offset %llu outside the grid", path,
                            e->name, (unsigned long long)roff);
    root->address.byte_offset = ta + roff;
    *tiles = pnanovdb_root_get_tile_count(w->buf, *root);
    if ((uint64_t)*tiles > (sz - root->address.byte_offset - rsize) / tsize)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid '%s': root claims %u tiles, more than fit in the grid",
                            path, e->name, *tiles);
    return ATMOS_OK;
}

static int select_grid(const grid_entry *g, int n, const char *name, size_t len)
{
    for (int i = 0; i < n; i++)
        if (strlen(g[i].name) == len && strncmp(g[i].name, name, len) == 0) return i;
    return -1;
}

/* " (quantized Fp16)" and the like for a grid atmos does not read; "" for a float grid. */
static const char *type_note(uint32_t type)
{
    switch (type) {
    case PNANOVDB_GRID_TYPE_FLOAT: return "";
    case PNANOVDB_GRID_TYPE_FP4: return " (quantized Fp4)";
    case PNANOVDB_GRID_TYPE_FP8: return " (quantized Fp8)";
    case PNANOVDB_GRID_TYPE_FP16: return " (quantized Fp16)";
    case PNANOVDB_GRID_TYPE_FPN: return " (quantized FpN)";
    default: return " (not float)";
    }
}

static void list_names(const grid_entry *g, int n, char *buf, size_t cap)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int i = 0; i < n && len + 1 < cap; i++) {
        int wr = snprintf(buf + len, cap - len, "%s%s%s", i ? ", " : "", g[i].name[0] ? g[i].name : "(unnamed)",
                          type_note(g[i].grid_type));
        if (wr < 0) break;
        len += (size_t)wr;
    }
}

/* ------------------------------------------------------------ the reader */

/* One load: the file's grids, the selection, what pass 1 measured, the volume.
 * Two passes over the selected grids: measure all (bounding box, voxel count, value
 * check), then create the volume and write. Each grid buffer is read again in pass 2
 * rather than all being held at once. */
typedef struct {
    atmos_context *ctx;
    const char *path;
    const source *s;
    const atmos_volume_load_desc *desc;
    grid_entry *g;
    int ng;
    int sel[ATMOS_VOLUME_MAX_FIELDS], nsel;
    /* pass 1 */
    double A0[9], t0[3];            /* the first grid's transform, which all must share */
    uint64_t total, grid_active[64]; /* active voxels: all grids, each grid */
    int64_t glo[3], ghi[3];         /* inclusive index box of all grids' active values */
    int gany;
    atmos_volume *vol;
} nvdb_load;

/* Which grids: the list asked for, else "density", else every float grid. */
static atmos_status choose_grids(nvdb_load *L)
{
    char present[512];
    list_names(L->g, L->ng, present, sizeof present);
    L->nsel = 0;
    if (L->desc->grids && *L->desc->grids) {
        const char *p = L->desc->grids;
        while (*p) {
            const char *c = strchr(p, ',');
            size_t len = c ? (size_t)(c - p) : strlen(p);
            if (len) {
                int i = select_grid(L->g, L->ng, p, len);
                if (i < 0)
                    return atmos__error(L->ctx, ATMOS_E_FORMAT, "%s: grid '%.*s' not found; grids present: %s",
                                        L->path, (int)len, p, present);
                if (L->nsel == ATMOS_VOLUME_MAX_FIELDS)
                    return atmos__error(L->ctx, ATMOS_E_LIMIT, "%s: more than %d grids requested", L->path,
                                        ATMOS_VOLUME_MAX_FIELDS);
                L->sel[L->nsel++] = i;
            }
            p += len;
            if (*p == ',') p++;
        }
    } else {
        int i = select_grid(L->g, L->ng, "density", 7);
        if (i >= 0 && L->g[i].grid_type == PNANOVDB_GRID_TYPE_FLOAT) {
            L->sel[L->nsel++] = i;
        } else {
            for (i = 0; i < L->ng && L->nsel < ATMOS_VOLUME_MAX_FIELDS; i++)
                if (L->g[i].grid_type == PNANOVDB_GRID_TYPE_FLOAT) L->sel[L->nsel++] = i;
        }
    }
    int quantized = 0;
    for (int i = 0; i < L->ng; i++)
        quantized |= L->g[i].grid_type >= PNANOVDB_GRID_TYPE_FP4 && L->g[i].grid_type <= PNANOVDB_GRID_TYPE_FPN;
    if (L->nsel == 0)
        return atmos__error(L->ctx, quantized ? ATMOS_E_UNSUPPORTED : ATMOS_E_FORMAT,
                            "%s: no float grid to load; grids present: %s%s", L->path, present,
                            quantized ? "; atmos reads 32-bit float grids only, not quantized ones: write the grid "
                                        "as float (without Fp4/Fp8/Fp16/FpN quantization)"
                                      : "");
    return ATMOS_OK;
}

/* One selected grid's buffer, read and checked: the walk over it, its root and its
 * transform. grid_release frees it whatever grid_open returned. */
typedef struct {
    walk w;
    uint64_t *mem;
    pnanovdb_root_handle_t root;
    uint32_t tiles;
    double A[9], t[3];
} grid_buf;

static atmos_status grid_open(const nvdb_load *L, const grid_entry *e, grid_buf *b)
{
    memset(b, 0, sizeof *b);
    const uint64_t limit = L->desc->max_memory ? L->desc->max_memory : ATMOS_VOLUME_DEFAULT_MAX_MEMORY;
    /* Reading the buffer is itself an allocation the file asks for. */
    if (e->file_size > limit)
        return atmos__error(L->ctx, ATMOS_E_LIMIT, "%s: grid '%s' is %llu bytes, over the memory limit", L->path,
                            e->name, (unsigned long long)e->file_size);
    b->w.size = e->file_size;
    /* Whole 8-byte words so PNanoVDB's 64-bit reads stay aligned. */
    const uint64_t words = (b->w.size + 7) / 8;
    b->mem = calloc((size_t)(words ? words : 1), 8);
    if (!b->mem)
        return atmos__error(L->ctx, ATMOS_E_NOMEM, "%s: out of memory reading grid '%s'", L->path, e->name);
    if (src_read(L->s, e->offset, b->mem, b->w.size) != 0)
        return atmos__error(L->ctx, ATMOS_E_IO, "%s: cannot read grid '%s': %s", L->path, e->name, strerror(errno));
    b->w.buf = pnanovdb_make_buf((uint32_t *)b->mem, words * 2);
    return load_grid(L->ctx, L->path, e, &b->w, &b->root, &b->tiles, b->A, b->t);
}

static void grid_release(grid_buf *b)
{
    for (int l = 0; l < 3; l++) free(b->w.seen[l]);
    free(b->mem);
}

/* Pass 1 over selected grid si: checks its tree, values and transform, and adds its
 * active voxels and index box to the totals. */
static atmos_status measure_grid(nvdb_load *L, int si, grid_buf *b)
{
    const grid_entry *e = &L->g[L->sel[si]];
    walk *w = &b->w;
    if (walk_root(w, 1, b->root, b->tiles))
        return atmos__error(L->ctx, ATMOS_E_FORMAT, "%s: grid '%s': corrupt tree: %s", L->path, e->name,
                            w->why ? w->why : "invalid node");
    if (w->bad)
        return atmos__error(L->ctx, ATMOS_E_FORMAT,
                            "%s: grid '%s': value %g at index (%lld, %lld, %lld) is %s; densities must be "
                            "finite and >= 0",
                            L->path, e->name, w->bad_value, (long long)w->bad_ijk[0], (long long)w->bad_ijk[1],
                            (long long)w->bad_ijk[2], w->bad_value < 0 ? "negative" : "not finite");
    if (si > 0 && (memcmp(b->A, L->A0, sizeof b->A) != 0 || memcmp(b->t, L->t0, sizeof b->t) != 0))
        return atmos__error(L->ctx, ATMOS_E_UNSUPPORTED,
                            "%s: grids '%s' and '%s' have different transforms; load them separately", L->path,
                            L->g[L->sel[0]].name, e->name);
    if (si == 0) {
        memcpy(L->A0, b->A, sizeof b->A);
        memcpy(L->t0, b->t, sizeof b->t);
    }
    if (w->active > UINT64_MAX - L->total) L->total = UINT64_MAX;
    else L->total += w->active;
    if (si < 64) L->grid_active[si] = w->active;
    if (w->any)
        for (int a = 0; a < 3; a++) {
            if (!L->gany || w->lo[a] < L->glo[a]) L->glo[a] = w->lo[a];
            if (!L->gany || w->hi[a] > L->ghi[a]) L->ghi[a] = w->hi[a];
        }
    L->gany |= w->any;
    atmos__log(L->ctx, ATMOS_LOG_INFO, "%s: grid '%s': %llu active voxels (tiles counted in full)", L->path, e->name,
               (unsigned long long)w->active);
    return ATMOS_OK;
}

/* After pass 1: the memory check, then the volume spanning all grids' index box,
 * placed by their shared transform. */
static atmos_status create_volume(nvdb_load *L)
{
    atmos_status st = atmos__reader_check_memory(L->ctx, L->path, L->total, L->desc->max_memory);
    if (st != ATMOS_OK) return st;
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    for (int a = 0; a < 3; a++) {
        int64_t n = L->gany ? L->ghi[a] - L->glo[a] + 1 : 1;
        if (n > ATMOS_VOLUME_MAX_DIM)
            return atmos__error(L->ctx, ATMOS_E_LIMIT, "%s: the grids span %lld voxels along axis %d (limit %d)",
                                L->path, (long long)n, a, ATMOS_VOLUME_MAX_DIM);
        vd.dims[a] = (int)n;
    }
    if (!L->gany)
        atmos__log(L->ctx, ATMOS_LOG_WARN, "%s: the selected grids have no active voxels; the volume is empty",
                   L->path);
    const int imin[3] = {(int)L->glo[0], (int)L->glo[1], (int)L->glo[2]};
    char why[256];
    if (atmos__reader_placement(L->A0, L->t0, imin, &vd, why, sizeof why) != 0)
        return atmos__error(L->ctx, ATMOS_E_UNSUPPORTED, "%s: grid '%s': %s", L->path, L->g[L->sel[0]].name, why);
    vd.max_memory = L->desc->max_memory;
    st = atmos_volume_create(L->ctx, &vd, &L->vol);
    /* a grid placement the core refuses (not a rotation, absurd size) is a malformed file */
    return st == ATMOS_E_INVALID_ARG ? ATMOS_E_FORMAT : st;
}

/* Pass 2 over selected grid si: adds its field and writes its values. */
static atmos_status write_grid(nvdb_load *L, int si, grid_buf *b)
{
    const grid_entry *e = &L->g[L->sel[si]];
    walk *w = &b->w;
    char field[64], particle[64];
    atmos__reader_field_names(e->name, L->desc, field, particle);
    atmos_status st = atmos_volume_add_field(L->ctx, L->vol, field, particle, &w->field);
    if (st != ATMOS_OK) return st;
    if (si < 64) atmos__volume_set_file_active(L->vol, w->field, L->grid_active[si]);
    w->ctx = L->ctx;
    w->vol = L->vol;
    w->scale = L->desc->density_scale > 0 ? (float)L->desc->density_scale : 1.0f;
    memcpy(w->lo, L->glo, sizeof L->glo);
    if (walk_root(w, 2, b->root, b->tiles))
        return w->status != ATMOS_OK
                   ? w->status
                   : atmos__error(L->ctx, ATMOS_E_FORMAT, "%s: grid '%s': corrupt tree", L->path, e->name);
    return ATMOS_OK;
}

/* One pass over the selected grids, each read, used and released in turn. */
static atmos_status run_pass(nvdb_load *L, int pass)
{
    for (int si = 0; si < L->nsel; si++) {
        grid_buf b;
        atmos_status st = grid_open(L, &L->g[L->sel[si]], &b);
        if (st == ATMOS_OK) st = pass == 1 ? measure_grid(L, si, &b) : write_grid(L, si, &b);
        grid_release(&b);
        if (st != ATMOS_OK) return st;
    }
    return ATMOS_OK;
}

static atmos_status load_source(atmos_context *ctx, const char *path, const source *s,
                                const atmos_volume_load_desc *desc, atmos_volume **out)
{
    nvdb_load L;
    memset(&L, 0, sizeof L);
    L.ctx = ctx;
    L.path = path;
    L.s = s;
    L.desc = desc;
    atmos_status st = list_file(ctx, path, s, &L.g, &L.ng);
    if (st != ATMOS_OK) return st;
    st = choose_grids(&L);
    if (st == ATMOS_OK) st = run_pass(&L, 1);
    if (st == ATMOS_OK) st = create_volume(&L);
    if (st == ATMOS_OK) st = run_pass(&L, 2);
    if (st == ATMOS_OK) st = atmos_volume_finalize(ctx, L.vol);
    if (st != ATMOS_OK) atmos_volume_destroy(L.vol);
    else *out = L.vol;
    free(L.g);
    return atmos__reader_name_error(ctx, path, st);
}

atmos_status atmos__volume_load_nanovdb_mem(atmos_context *ctx, const char *name, const void *data, size_t size,
                                            const atmos_volume_load_desc *desc, atmos_volume **out)
{
    static const atmos_volume_load_desc zero_desc;
    if (!out || !name || (!data && size)) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "nanovdb: bad arguments");
    *out = NULL;
    source s = {NULL, data, size};
    return load_source(ctx, name, &s, desc ? desc : &zero_desc, out);
}

atmos_status atmos__volume_load_nanovdb(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                        atmos_volume **out)
{
    static const atmos_volume_load_desc zero_desc;
    if (!out || !path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "nanovdb: path and out are required");
    *out = NULL;
    FILE *fp = fopen(path, "rb");
    if (!fp) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));
    source s = {fp, NULL, 0};
    atmos_status st;
    if (fseeko(fp, 0, SEEK_END) != 0 || ftello(fp) < 0) {
        st = atmos__error(ctx, ATMOS_E_IO, "%s: cannot determine the file size: %s", path, strerror(errno));
    } else {
        s.size = (uint64_t)ftello(fp);
        st = load_source(ctx, path, &s, desc ? desc : &zero_desc, out);
    }
    fclose(fp);
    return st;
}

#endif /* ATMOS_HAVE_NANOVDB */
