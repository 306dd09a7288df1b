/* OpenVDB file structure checks before the library reads the file (see vdb_header.h).
 *
 * Layout (little-endian; OpenVDB io/Archive.cc, io/File.cc, io/GridDescriptor.cc):
 *   header     = int64 magic 0x56444220, uint32 file_version, uint32 lib_major, uint32 lib_minor,
 *                uint8 has_grid_offsets, [uint8 compressed if 220 <= version < 222],
 *                char uuid[36]
 *   metadata   = int32 count, count x { string name, string type, int32 size, size bytes }
 *   grids      = int32 count, count x descriptor, each followed by its grid, which ends at end_pos:
 *   descriptor = string unique_name, string grid_type, [string instance_parent if version >= 216],
 *                int64 grid_pos, int64 block_pos, int64 end_pos
 *   grid       = at grid_pos: [uint32 compression if version >= 222], metadata, transform, topology;
 *                at block_pos: the leaf buffers, up to end_pos
 *   string     = uint32 length, length bytes
 * Checked: every length within the file, grid types that look like OpenVDB's ("Tree_..."),
 * offsets ordered and within the file, and each grid's metadata inside [grid_pos, block_pos).
 */
#define _POSIX_C_SOURCE 200809L /* fseeko, ftello */
#include "volume/vdb_header.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>

#define VDB_MAGIC 0x56444220u
#define MAX_NAME 4096u  /* longest metadata or grid name accepted */
#define MAX_TYPE 256u   /* longest type name accepted */
#define MAX_COUNT 100000 /* metadata entries or grids */

typedef struct {
    FILE *f;                   /* a file, or */
    const unsigned char *mem;  /* a buffer */
    uint64_t size, pos;
    uint32_t version;
    char *why;
    size_t cap;
} src;

static int fail(src *s, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->why, s->cap, fmt, ap);
    va_end(ap);
    return -1;
}

static int cut(src *s, const char *what, uint64_t need)
{
    return fail(s, "truncated: %s needs %llu bytes at offset %llu, the file has %llu", what,
                (unsigned long long)need, (unsigned long long)s->pos, (unsigned long long)s->size);
}

static int get(src *s, void *dst, uint64_t n, const char *what)
{
    if (n > s->size - s->pos) return cut(s, what, n);
    if (s->mem) memcpy(dst, s->mem + s->pos, (size_t)n);
    else if (fseeko(s->f, (off_t)s->pos, SEEK_SET) != 0 || fread(dst, 1, (size_t)n, s->f) != (size_t)n)
        return fail(s, "read error at offset %llu", (unsigned long long)s->pos);
    s->pos += n;
    return 0;
}

static int get_u32(src *s, uint32_t *v, const char *what)
{
    unsigned char b[4];
    if (get(s, b, 4, what)) return -1;
    *v = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    return 0;
}

static int get_i64(src *s, int64_t *v, const char *what)
{
    unsigned char b[8];
    if (get(s, b, 8, what)) return -1;
    uint64_t u = 0;
    for (int i = 7; i >= 0; i--) u = u << 8 | b[i];
    *v = (int64_t)u;
    return 0;
}

static int skip(src *s, uint64_t n, const char *what)
{
    if (n > s->size - s->pos) return cut(s, what, n);
    s->pos += n;
    return 0;
}

/* A string of at most max bytes; copied (truncated, NUL-terminated) into out when given.
 * printable: every byte must be printable ASCII (type names). */
static int get_string(src *s, uint32_t max, int printable, char *out, size_t outcap, const char *what)
{
    uint32_t len;
    if (get_u32(s, &len, what)) return -1;
    if (len > max)
        return fail(s, "%s at offset %llu claims %u bytes (more than %u): damaged file", what,
                    (unsigned long long)(s->pos - 4), len, max);
    char buf[MAX_NAME];
    if (get(s, buf, len, what)) return -1;
    for (uint32_t i = 0; printable && i < len; i++)
        if (buf[i] < 0x20 || buf[i] > 0x7e)
            return fail(s, "%s at offset %llu is not text: damaged file", what, (unsigned long long)(s->pos - len));
    if (out && outcap) {
        size_t n = len < outcap - 1 ? len : outcap - 1;
        memcpy(out, buf, n);
        out[n] = '\0';
    }
    return 0;
}

/* A metadata block (file or grid level) ending no later than `limit`. */
static int check_meta(src *s, uint64_t limit, const char *where)
{
    uint32_t count;
    const uint64_t size = s->size;
    s->size = limit;
    int rc = get_u32(s, &count, where);
    if (rc == 0 && count > MAX_COUNT) rc = fail(s, "%s: %u metadata entries: damaged file", where, count);
    for (uint32_t i = 0; i < count && rc == 0; i++) {
        uint32_t n;
        rc = get_string(s, MAX_NAME, 0, NULL, 0, where);
        if (rc == 0) rc = get_string(s, MAX_TYPE, 1, NULL, 0, where);
        if (rc == 0) rc = get_u32(s, &n, where);
        if (rc == 0) rc = skip(s, n, where);
    }
    s->size = size;
    return rc;
}

static int check_header(src *s)
{
    unsigned char h[8];
    uint32_t major, minor;
    if (get(s, h, 8, "the header")) return -1;
    if (h[0] != 0x20 || h[1] != 0x42 || h[2] != 0x44 || h[3] != 0x56 || h[4] || h[5] || h[6] || h[7])
        return fail(s, "not an OpenVDB file (bad magic number)");
    if (get_u32(s, &s->version, "the header") || get_u32(s, &major, "the header") ||
        get_u32(s, &minor, "the header"))
        return -1;
    if (s->version > 1000) return fail(s, "OpenVDB file format version %u: damaged file", s->version);
    if (s->version < 218) return 0; /* before OpenVDB 2 (2013): left to the library */
    unsigned char has_offsets;
    if (get(s, &has_offsets, 1, "the header")) return -1;
    if (has_offsets > 1) return fail(s, "header flag %u at offset %llu is not 0 or 1: damaged file", has_offsets,
                                     (unsigned long long)(s->pos - 1));
    if (s->version >= 220 && s->version < 222 && skip(s, 1, "the header")) return -1;
    if (skip(s, 36, "the header")) return -1;
    return has_offsets;
}

/* One grid descriptor and its grid's metadata; *next = where the next descriptor starts. */
static int check_grid(src *s, int g, uint64_t *next)
{
    char name[128], type[MAX_TYPE + 1], where[200];
    snprintf(where, sizeof where, "grid descriptor %d", g);
    if (get_string(s, MAX_NAME, 0, name, sizeof name, where)) return -1;
    for (char *p = name; *p; p++)
        if (*p == 0x1e) *p = '#'; /* OpenVDB's separator of duplicate names */
    snprintf(where, sizeof where, "grid '%s'", name);
    if (get_string(s, MAX_TYPE, 1, type, sizeof type, where)) return -1;
    if (strncmp(type, "Tree_", 5) != 0) return fail(s, "%s: type '%s' is not an OpenVDB tree type: damaged file", where, type);
    if (s->version >= 216 && get_string(s, MAX_NAME, 0, NULL, 0, where)) return -1;
    int64_t gp, bp, ep;
    if (get_i64(s, &gp, where) || get_i64(s, &bp, where) || get_i64(s, &ep, where)) return -1;
    if (gp < (int64_t)s->pos || bp < gp || ep < bp)
        return fail(s, "%s: offsets %lld, %lld, %lld out of order: damaged file", where, (long long)gp, (long long)bp,
                    (long long)ep);
    if ((uint64_t)ep > s->size)
        return fail(s, "truncated: grid '%s' ends at byte %lld, the file has %llu bytes", name, (long long)ep,
                    (unsigned long long)s->size);
    s->pos = (uint64_t)gp;
    uint32_t compression;
    if (s->version >= 222 && get_u32(s, &compression, where)) return -1;
    if (check_meta(s, (uint64_t)bp, where)) return -1;
    *next = (uint64_t)ep;
    return 0;
}

static int check(src *s, int *ngrids)
{
    *ngrids = 0;
    int has_offsets = check_header(s);
    if (has_offsets < 0) return -1;
    if (!has_offsets) return 0; /* an old or streamed file: no offsets to check */
    if (check_meta(s, s->size, "the file metadata")) return -1;
    uint32_t count;
    if (get_u32(s, &count, "the grid count")) return -1;
    if (count > MAX_COUNT || count > (s->size - s->pos) / 36)
        return fail(s, "%u grids claimed in %llu bytes: damaged file", count, (unsigned long long)(s->size - s->pos));
    for (uint32_t g = 0; g < count; g++) {
        uint64_t next;
        if (check_grid(s, (int)g, &next)) return -1;
        s->pos = next;
    }
    *ngrids = (int)count;
    return 0;
}

int atmos__vdb_check_header_mem(const unsigned char *data, uint64_t size, int *ngrids, char *why, size_t cap)
{
    src s = {NULL, data, size, 0, 0, why, cap};
    if (cap) why[0] = '\0';
    return check(&s, ngrids);
}

int atmos__vdb_check_header(const char *path, int *ngrids, char *why, size_t cap)
{
    src s = {NULL, NULL, 0, 0, 0, why, cap};
    if (cap) why[0] = '\0';
    *ngrids = 0;
    s.f = fopen(path, "rb");
    if (!s.f) return fail(&s, "cannot open");
    off_t n = -1;
    if (fseeko(s.f, 0, SEEK_END) == 0) n = ftello(s.f);
    int rc = -1;
    if (n < 0) fail(&s, "cannot measure the file");
    else {
        s.size = (uint64_t)n;
        rc = check(&s, ngrids);
    }
    fclose(s.f);
    return rc;
}
