/* Portable float map (PFM) reader and writer.
 *
 * Format: "PF" (RGB) or "Pf" (grey), width, height, a scale whose sign gives the
 * byte order (negative = little-endian), one whitespace byte (the reader also takes
 * a CRLF pair there), then width*height*c 32-bit IEEE floats, rows from the BOTTOM of
 * the image to the top. */
#define _POSIX_C_SOURCE 200809L
#include "core/internal.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The header is a few dozen bytes; anything longer than this is not a PFM we accept. */
#define PFM_MAX_HEADER 256

static void put_le32(unsigned char *b, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    b[0] = (unsigned char)(u & 0xff);
    b[1] = (unsigned char)((u >> 8) & 0xff);
    b[2] = (unsigned char)((u >> 16) & 0xff);
    b[3] = (unsigned char)((u >> 24) & 0xff);
}

static float get32(const unsigned char *b, int little_endian)
{
    uint32_t u = little_endian
                     ? (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24
                     : (uint32_t)b[3] | (uint32_t)b[2] << 8 | (uint32_t)b[1] << 16 | (uint32_t)b[0] << 24;
    float f;
    memcpy(&f, &u, 4);
    return f;
}

typedef struct {
    const char *path; /* final name, for messages */
    const atmos_image *img;
    int out_channels;
} pfm_job;

static atmos_status pfm_write_file(atmos_context *ctx, const char *tmp, void *user)
{
    const pfm_job *job = user;
    const atmos_image *img = job->img;
    const int oc = job->out_channels;
    FILE *f = fopen(tmp, "wb");
    if (!f) return atmos__temp_create_error(ctx, job->path, errno);
    size_t row_bytes = (size_t)img->width * (size_t)oc * 4;
    unsigned char *row = malloc(row_bytes);
    if (!row) {
        fclose(f);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", job->path);
    }
    int ok = fprintf(f, "%s\n%d %d\n-1.0\n", oc == 3 ? "PF" : "Pf", img->width, img->height) > 0;
    for (int y = img->height - 1; ok && y >= 0; y--) { /* bottom row first */
        const float *src = img->pixels + (size_t)y * (size_t)img->width * (size_t)img->channels;
        for (int x = 0; x < img->width; x++)
            for (int c = 0; c < oc; c++)
                put_le32(row + ((size_t)x * (size_t)oc + (size_t)c) * 4, src[(size_t)x * (size_t)img->channels + (size_t)c]);
        ok = fwrite(row, 1, row_bytes, f) == row_bytes;
    }
    free(row);
    /* Flush and sync before atmos__write_atomic renames the file into place; a full
     * disk shows up here, so check every step. */
    if (ok && (fflush(f) != 0 || fsync(fileno(f)) != 0)) ok = 0;
    if (fclose(f) != 0) ok = 0;
    if (!ok) return atmos__error(ctx, ATMOS_E_IO, "%s: write failed: %s", job->path, strerror(errno));
    return ATMOS_OK;
}

atmos_status atmos_write_pfm(atmos_context *ctx, const atmos_image *img, const char *path)
{
    if (!img || !img->pixels || !path)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_write_pfm: missing image or path");
    pfm_job job = {path, img, 0};
    if (img->channels == 1) job.out_channels = 1;
    else if (img->channels >= 3) job.out_channels = 3;
    else
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "%s: PFM stores 1 or 3 channels; a %d-channel image has no natural mapping", path,
                            img->channels);
    return atmos__write_atomic(ctx, path, pfm_write_file, &job);
}

static int is_space(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

/* Parses a decimal integer of at most 9 digits at hdr[*pos]. Returns 0 if absent. */
static int parse_uint(const char *hdr, size_t len, size_t *pos, long *out)
{
    size_t p = *pos, start = p;
    long v = 0;
    while (p < len && hdr[p] >= '0' && hdr[p] <= '9') {
        if (p - start >= 9) return 0;
        v = v * 10 + (hdr[p] - '0');
        p++;
    }
    if (p == start) return 0;
    *pos = p;
    *out = v;
    return 1;
}

static int skip_spaces(const char *hdr, size_t len, size_t *pos)
{
    size_t p = *pos;
    while (p < len && is_space((unsigned char)hdr[p])) p++;
    int any = p > *pos;
    *pos = p;
    return any;
}

atmos_status atmos_read_pfm(atmos_context *ctx, const char *path, atmos_image **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_read_pfm: out is NULL");
    *out = NULL;
    if (!path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_read_pfm: path is NULL");
    FILE *f = fopen(path, "rb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));

    atmos_status st = ATMOS_OK;
    atmos_image *img = NULL;
    unsigned char *row = NULL;
    char hdr[PFM_MAX_HEADER + 1];
    size_t len = fread(hdr, 1, PFM_MAX_HEADER, f);
    hdr[len] = '\0';

    /* Strict header: magic, whitespace, width, whitespace, height, whitespace, scale,
     * exactly one whitespace byte. */
    size_t pos = 2;
    long w = 0, h = 0;
    int channels;
    if (len < 2 || hdr[0] != 'P' || (hdr[1] != 'F' && hdr[1] != 'f')) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: not a PFM file (expected \"PF\" or \"Pf\")", path);
        goto done;
    }
    channels = hdr[1] == 'F' ? 3 : 1;
    if (!skip_spaces(hdr, len, &pos) || !parse_uint(hdr, len, &pos, &w) || !skip_spaces(hdr, len, &pos) ||
        !parse_uint(hdr, len, &pos, &h) || !skip_spaces(hdr, len, &pos)) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: malformed PFM header: expected width and height", path);
        goto done;
    }
    size_t scale_start = pos;
    while (pos < len && !is_space((unsigned char)hdr[pos])) pos++;
    if (pos >= len || pos == scale_start || pos - scale_start > 32) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: malformed PFM header: missing scale", path);
        goto done;
    }
    char scale_text[40];
    memcpy(scale_text, hdr + scale_start, pos - scale_start);
    scale_text[pos - scale_start] = '\0';
    char *end = NULL;
    double scale = strtod(scale_text, &end);
    if (*end != '\0' || !(scale == scale) || scale == 0 || scale > 1e30 || scale < -1e30) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: malformed PFM header: scale '%s' is not a nonzero number",
                          path, scale_text);
        goto done;
    }
    int little = scale < 0;

    if (w < 1 || h < 1) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: PFM size %ld x %ld: must be at least 1 x 1", path, w, h);
        goto done;
    }
    if (w > ATMOS_IMAGE_MAX_DIM || h > ATMOS_IMAGE_MAX_DIM) {
        st = atmos__error(ctx, ATMOS_E_LIMIT, "%s: PFM size %ld x %ld exceeds the limit of %d per side", path, w,
                          h, ATMOS_IMAGE_MAX_DIM);
        goto done;
    }
    /* The data must be in the file before we allocate for it: a 20-byte file
     * claiming 65536 x 65536 must not cost 48 GB. */
    size_t row_bytes = (size_t)w * (size_t)channels * 4;
    struct stat sb;
    if (fstat(fileno(f), &sb) != 0) {
        st = atmos__error(ctx, ATMOS_E_IO, "%s: cannot stat: %s", path, strerror(errno));
        goto done;
    }
    /* One whitespace byte ends the header. A header written with CRLF line ends has
     * two ("\r\n"): taking only the '\r' would shift every float by a byte. The "\r\n"
     * counts as one terminator unless the file's size says the data start at the '\n'. */
    uint64_t data_bytes = (uint64_t)row_bytes * (uint64_t)h;
    if (hdr[pos] == '\r' && pos + 1 < len && hdr[pos + 1] == '\n' && sb.st_size >= 0 &&
        (uint64_t)sb.st_size != (uint64_t)pos + 1 + data_bytes)
        pos++;
    pos++;
    if (sb.st_size < 0 || (uint64_t)sb.st_size < (uint64_t)pos ||
        ((uint64_t)sb.st_size - (uint64_t)pos) / (uint64_t)row_bytes < (uint64_t)h) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated PFM: %ld x %ld x %d floats need %llu bytes of data, file has %llu",
                          path, w, h, channels, (unsigned long long)row_bytes * (unsigned long long)h,
                          (unsigned long long)(sb.st_size > (off_t)pos ? (uint64_t)sb.st_size - pos : 0));
        goto done;
    }
    if ((uint64_t)sb.st_size - (uint64_t)pos > data_bytes) { /* a header whose size is not the data's */
        st = atmos__error(ctx, ATMOS_E_FORMAT,
                          "%s: %llu bytes after the PFM's data (%ld x %ld x %d floats): its header's size is not its data's",
                          path, (unsigned long long)((uint64_t)sb.st_size - pos - data_bytes), w, h, channels);
        goto done;
    }
    if (fseek(f, (long)pos, SEEK_SET) != 0) {
        st = atmos__error(ctx, ATMOS_E_IO, "%s: seek failed: %s", path, strerror(errno));
        goto done;
    }
    st = atmos_image_create(ctx, (int)w, (int)h, channels, &img);
    if (st != ATMOS_OK) goto done;
    row = malloc(row_bytes);
    if (!row) {
        st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        goto done;
    }
    for (long y = h - 1; y >= 0; y--) {
        if (fread(row, 1, row_bytes, f) != row_bytes) {
            st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated PFM data at row %ld", path, h - 1 - y);
            goto done;
        }
        float *dst = img->pixels + (size_t)y * row_bytes / 4;
        for (size_t i = 0; i < row_bytes / 4; i++) dst[i] = get32(row + 4 * i, little);
    }

done:
    free(row);
    fclose(f);
    if (st != ATMOS_OK) {
        atmos_image_destroy(img);
        return st;
    }
    *out = img;
    return ATMOS_OK;
}
