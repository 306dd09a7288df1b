/* The end of a classic NetCDF file's data, from its header (see netcdf_classic.h).
 *
 * Header grammar (NetCDF Users Guide, "File Format Specifications"; big-endian):
 *   header   = magic numrecs dim_list gatt_list var_list
 *   magic    = 'C' 'D' 'F' version        version 1 (classic), 2 (64-bit offset), 5 (64-bit data)
 *   dim_list = ABSENT | NC_DIMENSION nelems [name dim_length ...]
 *   att_list = ABSENT | NC_ATTRIBUTE nelems [name nc_type nelems values ...]
 *   var_list = ABSENT | NC_VARIABLE nelems [name nelems [dimid ...] att_list nc_type vsize begin ...]
 *   name     = nelems bytes, padded to 4;  values padded to 4
 * Tags and nc_type are 4 bytes; counts, lengths and dimids (NON_NEG) are 4 bytes, 8 in
 * CDF-5; begin is 4 bytes in CDF-1, 8 in CDF-2 and CDF-5. The record size is the sum of
 * the record variables' per-record sizes each padded to 4 bytes, except that a single
 * record variable is not padded.
 *
 * The header is untrusted: every count is bounded by the bytes left in the file
 * before anything is allocated or multiplied, and sizes saturate instead of wrapping.
 */
#define _POSIX_C_SOURCE 200809L /* fseeko, ftello */
#include "volume/netcdf_classic.h"

#include <stdlib.h>
#include <sys/types.h>

#define TAG_DIMENSION 0x0Au
#define TAG_VARIABLE 0x0Bu
#define TAG_ATTRIBUTE 0x0Cu

typedef struct {
    FILE *f;
    uint64_t pos, size; /* read position, file size */
    int cdf5;           /* 8-byte counts, lengths and dimids */
    int off8;           /* 8-byte begin offsets */
    int cut;            /* the header runs past the end of the file */
} reader;

/* Per variable: where its data starts, its size (per record for a record variable). */
typedef struct {
    uint64_t begin, size;
    int record;
} var_extent;

static uint64_t sat_add(uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }
static uint64_t sat_mul(uint64_t a, uint64_t b) { return b && a > UINT64_MAX / b ? UINT64_MAX : a * b; }
static uint64_t pad4(uint64_t n) { return sat_add(n, (4 - n % 4) % 4); }

static uint64_t left(const reader *r) { return r->size - r->pos; }

static int read_uint(reader *r, int nbytes, uint64_t *v)
{
    unsigned char b[8];
    if ((uint64_t)nbytes > left(r) || fread(b, 1, (size_t)nbytes, r->f) != (size_t)nbytes) {
        r->cut = 1;
        return -1;
    }
    r->pos += (uint64_t)nbytes;
    *v = 0;
    for (int i = 0; i < nbytes; i++) *v = *v << 8 | b[i];
    return 0;
}

static int read_nonneg(reader *r, uint64_t *v) { return read_uint(r, r->cdf5 ? 8 : 4, v); }

static int skip(reader *r, uint64_t n)
{
    if (n > left(r)) {
        r->cut = 1;
        return -1;
    }
    r->pos += n;
    return fseeko(r->f, (off_t)r->pos, SEEK_SET) == 0 ? 0 : -1;
}

/* Bytes per value of an nc_type (NC_BYTE = 1 .. NC_UINT64 = 11); 0 if unknown. */
static uint64_t type_size(uint64_t type)
{
    static const unsigned char sz[12] = {0, 1, 1, 2, 4, 4, 8, 1, 2, 4, 8, 8};
    return type < 12 ? sz[type] : 0;
}

static int skip_name(reader *r)
{
    uint64_t len;
    if (read_nonneg(r, &len)) return -1;
    return skip(r, pad4(len));
}

/* A list's tag and length: ABSENT (both zero) gives *n = 0. Every element takes at
 * least `min_bytes`, which bounds n by the bytes left. */
static int read_list_head(reader *r, uint64_t tag, uint64_t min_bytes, uint64_t *n)
{
    uint64_t t;
    if (read_uint(r, 4, &t) || read_nonneg(r, n)) return -1;
    if (t == 0 && *n == 0) return 0;
    if (t != tag) return -1;
    if (*n > left(r) / min_bytes) {
        r->cut = 1;
        return -1;
    }
    return 0;
}

static int skip_attributes(reader *r)
{
    uint64_t n;
    if (read_list_head(r, TAG_ATTRIBUTE, 12, &n)) return -1;
    for (uint64_t i = 0; i < n; i++) {
        uint64_t type, count;
        if (skip_name(r) || read_uint(r, 4, &type) || read_nonneg(r, &count)) return -1;
        if (!type_size(type)) return -1;
        if (skip(r, pad4(sat_mul(count, type_size(type))))) return -1;
    }
    return 0;
}

/* The dimension lengths (0 = the record dimension). */
static int read_dims(reader *r, uint64_t **len, uint64_t *n)
{
    if (read_list_head(r, TAG_DIMENSION, 8, n)) return -1;
    *len = malloc((size_t)(*n ? *n : 1) * sizeof **len);
    if (!*len) return -1;
    for (uint64_t i = 0; i < *n; i++)
        if (skip_name(r) || read_nonneg(r, &(*len)[i])) return -1;
    return 0;
}

/* One variable's header entry: its data's start and size (per record if it is a
 * record variable, i.e. its first dimension is the record dimension). */
static int read_var(reader *r, const uint64_t *dim_len, uint64_t ndims, var_extent *v)
{
    uint64_t nd, type, vsize;
    if (skip_name(r) || read_nonneg(r, &nd)) return -1;
    if (nd > left(r) / 4) {
        r->cut = 1;
        return -1;
    }
    uint64_t size = 1;
    v->record = 0;
    for (uint64_t d = 0; d < nd; d++) {
        uint64_t id;
        if (read_nonneg(r, &id)) return -1;
        if (id >= ndims) return -1;
        if (d == 0 && dim_len[id] == 0) v->record = 1;
        else size = sat_mul(size, dim_len[id]);
    }
    if (skip_attributes(r) || read_uint(r, 4, &type) || read_nonneg(r, &vsize) ||
        read_uint(r, r->off8 ? 8 : 4, &v->begin))
        return -1;
    if (!type_size(type)) return -1;
    v->size = sat_mul(size, type_size(type));
    return 0;
}

/* The end of the data of n variables with numrecs records. */
static uint64_t data_end(const var_extent *v, uint64_t n, uint64_t numrecs)
{
    uint64_t recsize = 0, nrec = 0, end = 0;
    for (uint64_t i = 0; i < n; i++)
        if (v[i].record) {
            recsize = sat_add(recsize, pad4(v[i].size));
            nrec++;
        }
    for (uint64_t i = 0; i < n; i++)
        if (v[i].record && nrec == 1) recsize = v[i].size;
    for (uint64_t i = 0; i < n; i++) {
        if (v[i].size == 0 || (v[i].record && numrecs == 0)) continue;
        uint64_t e = v[i].begin;
        if (v[i].record) e = sat_add(e, sat_mul(numrecs - 1, recsize));
        e = sat_add(e, v[i].size);
        if (e > end) end = e;
    }
    return end;
}

static int parse(reader *r, uint64_t *end)
{
    unsigned char magic[4];
    if (r->size < 4 || fread(magic, 1, 4, r->f) != 4) return -1;
    if (magic[0] != 'C' || magic[1] != 'D' || magic[2] != 'F' || (magic[3] != 1 && magic[3] != 2 && magic[3] != 5))
        return -1;
    r->pos = 4;
    r->cdf5 = magic[3] == 5;
    r->off8 = magic[3] != 1;
    uint64_t numrecs = 0, ndims = 0, nvars = 0, *dim_len = NULL;
    var_extent *vars = NULL;
    int rc = 0;
    if (read_nonneg(r, &numrecs) || read_dims(r, &dim_len, &ndims) || skip_attributes(r) ||
        read_list_head(r, TAG_VARIABLE, 20, &nvars))
        rc = -1;
    if (rc == 0) {
        if (numrecs == (r->cdf5 ? UINT64_MAX : 0xFFFFFFFFu)) numrecs = 0; /* streaming: records unknown */
        vars = malloc((size_t)(nvars ? nvars : 1) * sizeof *vars);
        if (!vars) rc = -1;
    }
    for (uint64_t i = 0; i < nvars && rc == 0; i++) rc = read_var(r, dim_len, ndims, &vars[i]);
    if (rc == 0) *end = data_end(vars, nvars, numrecs);
    free(dim_len);
    free(vars);
    return rc;
}

int atmos__netcdf_classic_data_end(FILE *f, uint64_t *end, uint64_t *size)
{
    reader r = {f, 0, 0, 0, 0, 0};
    *end = *size = 0;
    if (fseeko(f, 0, SEEK_END) != 0) return -1;
    off_t n = ftello(f);
    if (n < 0 || fseeko(f, 0, SEEK_SET) != 0) return -1;
    r.size = *size = (uint64_t)n;
    if (parse(&r, end) == 0) return 0;
    return r.cut ? 1 : -1;
}
