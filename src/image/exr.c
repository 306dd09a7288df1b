/* OpenEXR reader and writer on OpenEXR's C core API (libOpenEXRCore): no C++.
 *
 * Files are single-part scanline images, ZIP compressed (16 lines per chunk),
 * half or float channels. OpenEXR stores channels sorted by name, so an RGBA image
 * is stored as A,B,G,R; every channel is mapped by name, never by position. */
#define _POSIX_C_SOURCE 200809L
#include "core/internal.h"
#include "image/channel_names.h"

#include <openexr.h>

#include <errno.h>
#include <math.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The core library reports errors through a callback that may run while it holds
 * its own context lock, so the callback must not call back into the library (not
 * even exr_get_user_data). It writes into a per-thread buffer set up around each
 * public call instead. */
typedef struct {
    char msg[512];
} exr_errbuf;
static _Thread_local exr_errbuf *tls_errbuf;

static void exr_error_handler(exr_const_context_t ectx, exr_result_t code, const char *msg)
{
    (void)ectx;
    /* Keep the first message: later ones are the generic "unable to ..." wrappers. */
    if (tls_errbuf && !tls_errbuf->msg[0])
        snprintf(tls_errbuf->msg, sizeof tls_errbuf->msg, "%s", msg ? msg : exr_get_default_error_message(code));
}

static const char *exr_message(const exr_errbuf *eb, exr_result_t rv)
{
    return eb->msg[0] ? eb->msg : exr_get_default_error_message(rv);
}

/* ---------------------------------------------------------------- writing ---- */

/* Our own output stream (pwrite on a descriptor we own) so that the data can be
 * fsync'ed before atmos__write_atomic renames the file into place. */
static int64_t exr_stream_write(exr_const_context_t ectx, void *user, const void *buf, uint64_t sz, uint64_t offset,
                                exr_stream_error_func_ptr_t error_cb)
{
    int fd = *(const int *)user;
    const unsigned char *p = buf;
    uint64_t done = 0;
    while (done < sz) {
        ssize_t n = pwrite(fd, p + done, (size_t)(sz - done), (off_t)(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (error_cb) error_cb(ectx, EXR_ERR_WRITE_IO, "write failed: %s", strerror(errno));
            return -1;
        }
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

typedef struct {
    const char *path; /* final name, for messages */
    const atmos_image *img;
    int half;
    const char *const *names; /* img->channels names, in image order */
} exr_write_job;

/* OpenEXR's default compressor keeps a chunk whose compressed data are exactly as long as
 * the raw data, and readers take a chunk of the raw size as stored raw: such a chunk is
 * stored raw here (the raw bytes are what any reader then decodes). */
static _Thread_local exr_result_t (*tls_compress)(exr_encode_pipeline_t *);
static exr_result_t compress_unless_raw_sized(exr_encode_pipeline_t *e)
{
    const exr_result_t rv = tls_compress(e);
    if (rv == EXR_ERR_SUCCESS && e->compressed_bytes == e->packed_bytes && e->compressed_buffer != e->packed_buffer)
        memcpy(e->compressed_buffer, e->packed_buffer, e->packed_bytes);
    return rv;
}

static atmos_status encode_image(atmos_context *ctx, const char *path, exr_context_t ex, const exr_write_job *job,
                                 exr_errbuf *eb)
{
    const atmos_image *img = job->img;
    const int nc = img->channels;
    int32_t lines = 1;
    exr_result_t rv = exr_get_scanlines_per_chunk(ex, 0, &lines);
    if (rv != EXR_ERR_SUCCESS || lines < 1)
        return atmos__error(ctx, ATMOS_E_IO, "%s: OpenEXR: %s", path, exr_message(eb, rv));

    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int initialized = 0;
    atmos_status st = ATMOS_OK;
    for (int y = 0; y < img->height && st == ATMOS_OK; y += lines) {
        exr_chunk_info_t cinfo;
        rv = exr_write_scanline_chunk_info(ex, 0, y, &cinfo);
        if (rv == EXR_ERR_SUCCESS)
            rv = initialized ? exr_encoding_update(ex, 0, &cinfo, &enc) : exr_encoding_initialize(ex, 0, &cinfo, &enc);
        if (rv != EXR_ERR_SUCCESS) {
            st = atmos__error(ctx, ATMOS_E_IO, "%s: OpenEXR: chunk at line %d: %s", path, y, exr_message(eb, rv));
            break;
        }
        initialized = 1;
        /* Point each (name-sorted) file channel at its interleaved image channel. */
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int src = -1;
            for (int k = 0; k < nc; k++)
                if (strcmp(ch->channel_name, job->names[k]) == 0) src = k;
            if (src < 0) {
                st = atmos__error(ctx, ATMOS_E_IO, "%s: OpenEXR: unexpected channel '%s'", path, ch->channel_name);
                break;
            }
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = (int32_t)(nc * 4);
            ch->user_line_stride = (int32_t)((size_t)img->width * (size_t)nc * 4);
            ch->encode_from_ptr =
                (const uint8_t *)(img->pixels + ((size_t)cinfo.start_y * (size_t)img->width) * (size_t)nc + (size_t)src);
        }
        if (st != ATMOS_OK) break;
        rv = exr_encoding_choose_default_routines(ex, 0, &enc);
        if (rv == EXR_ERR_SUCCESS && enc.compress_fn) {
            tls_compress = enc.compress_fn;
            enc.compress_fn = compress_unless_raw_sized;
        }
        if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(ex, 0, &enc);
        if (rv != EXR_ERR_SUCCESS)
            st = atmos__error(ctx, ATMOS_E_IO, "%s: OpenEXR: encoding line %d: %s", path, y, exr_message(eb, rv));
    }
    if (initialized) exr_encoding_destroy(ex, &enc);
    return st;
}

/* A metadata value that is a number as a whole ("12.5", "-3", "2.2e9"): 1 for an integer
 * that fits 32 bits (*iv), 2 for another finite number (*dv), 0 for text. */
static int meta_number(const char *v, int32_t *iv, double *dv)
{
    if (!*v || strlen(v) > 40 || v[0] == ' ' || v[0] == '\t' || v[0] == '\n') return 0;
    char *end = NULL;
    errno = 0;
    double d = strtod(v, &end);
    if (*end || errno || !isfinite(d)) return 0;
    if (v[0] == '+' || (v[0] == '0' && v[1] >= '0' && v[1] <= '9')) return 0; /* "007", "+1": keep the text */
    if (!strpbrk(v, ".eExXnNiI") && d >= -2147483648.0 && d <= 2147483647.0) {
        *iv = (int32_t)d;
        return 1;
    }
    if (strpbrk(v, "xXnNiI")) return 0; /* hex floats, nan, inf: text */
    *dv = d;
    return 2;
}

/* The header's attributes: the standard "chromaticities" (linear sRGB / Rec. 709
 * primaries, D65 white) when the image has R, G and B channels (names: its channels' names;
 * they describe those, so a file of other quantities, as a variance per wavelength or a
 * table, has none), and the image's metadata, numbers as int or double attributes and
 * everything else as strings. */
static atmos_status write_attributes(atmos_context *ctx, const char *path, exr_context_t ex, int part,
                                     const atmos_image *img, const char *const *names, exr_errbuf *eb)
{
    exr_result_t rv;
    int rgb[4];
    if (atmos__rgb_channels(names, img->channels, rgb) && !atmos_image_get_meta(img, "chromaticities")) {
        const exr_attr_chromaticities_t rec709 = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
        if ((rv = exr_attr_set_chromaticities(ex, part, "chromaticities", &rec709)) != EXR_ERR_SUCCESS)
            return atmos__error(ctx, ATMOS_E_IO, "%s: OpenEXR: chromaticities: %s", path, exr_message(eb, rv));
    }
    for (int i = 0; i < img->meta_count; i++) {
        const char *key = img->meta[i].key, *val = img->meta[i].value;
        if (strcmp(key, "type") == 0 || strcmp(key, "name") == 0)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: metadata key '%s' is reserved for the EXR part structure",
                                path, key);
        eb->msg[0] = '\0';
        int32_t iv = 0;
        double dv = 0;
        const int kind = meta_number(val, &iv, &dv);
        rv = kind == 1 ? exr_attr_set_int(ex, part, key, iv)
             : kind == 2 ? exr_attr_set_double(ex, part, key, dv)
                         : exr_attr_set_string(ex, part, key, val);
        if (rv != EXR_ERR_SUCCESS) /* typically a standard attribute of another type ("channels", ...) */
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: OpenEXR: metadata '%s' cannot be stored as %s attribute: %s",
                                path, key, kind == 1 ? "an int" : kind == 2 ? "a double" : "a string", exr_message(eb, rv));
    }
    return ATMOS_OK;
}

static atmos_status exr_write_file(atmos_context *ctx, const char *tmp, void *user)
{
    const exr_write_job *job = user;
    const atmos_image *img = job->img;
    exr_errbuf eb = {{0}};
    exr_errbuf *saved = tls_errbuf;
    tls_errbuf = &eb;

    atmos_status st = ATMOS_OK;
    exr_context_t ex = NULL;
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) {
        tls_errbuf = saved;
        return atmos__temp_create_error(ctx, job->path, errno);
    }

    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_error_handler;
    init.user_data = &fd;
    init.write_fn = exr_stream_write;
    exr_result_t rv = exr_start_write(&ex, tmp, EXR_WRITE_FILE_DIRECTLY, &init);
    int part = 0;
    if (rv == EXR_ERR_SUCCESS) rv = exr_add_part(ex, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ex, part, img->width, img->height, EXR_COMPRESSION_ZIP);
    if (rv != EXR_ERR_SUCCESS) {
        st = atmos__error(ctx, ATMOS_E_IO, "%s: OpenEXR: cannot start file: %s", job->path, exr_message(&eb, rv));
        goto done;
    }
    /* Names longer than 31 bytes need the "long names" header flag. */
    int need_long = 0;
    for (int c = 0; c < img->channels; c++)
        if (strlen(job->names[c]) > 31) need_long = 1;
    for (int i = 0; i < img->meta_count; i++)
        if (strlen(img->meta[i].key) > 31) need_long = 1;
    if (need_long && (rv = exr_set_longname_support(ex, 1)) != EXR_ERR_SUCCESS) {
        st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: OpenEXR: %s", job->path, exr_message(&eb, rv));
        goto done;
    }
    for (int c = 0; c < img->channels; c++) {
        rv = exr_add_channel(ex, part, job->names[c], job->half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LINEAR, 1, 1);
        if (rv != EXR_ERR_SUCCESS) {
            st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: OpenEXR: channel '%s': %s", job->path, job->names[c],
                              exr_message(&eb, rv));
            goto done;
        }
    }
    if ((st = write_attributes(ctx, job->path, ex, part, img, job->names, &eb)) != ATMOS_OK) goto done;
    rv = exr_write_header(ex);
    if (rv != EXR_ERR_SUCCESS) {
        st = atmos__error(ctx, ATMOS_E_IO, "%s: OpenEXR: cannot write header: %s", job->path, exr_message(&eb, rv));
        goto done;
    }
    st = encode_image(ctx, job->path, ex, job, &eb);

done:
    if (ex) {
        /* exr_finish writes the chunk offset table: its failure is a failed write. */
        rv = exr_finish(&ex);
        if (rv != EXR_ERR_SUCCESS && st == ATMOS_OK)
            st = atmos__error(ctx, ATMOS_E_IO, "%s: OpenEXR: cannot finish file: %s", job->path, exr_message(&eb, rv));
    }
    /* Data on disk before the rename, so a crash cannot leave an empty file behind
     * the final name. */
    if (st == ATMOS_OK && fsync(fd) != 0)
        st = atmos__error(ctx, ATMOS_E_IO, "%s: fsync failed: %s", job->path, strerror(errno));
    if (close(fd) != 0 && st == ATMOS_OK)
        st = atmos__error(ctx, ATMOS_E_IO, "%s: close failed: %s", job->path, strerror(errno));
    tls_errbuf = saved;
    return st;
}

/* Half floats end at 65504: a finite value beyond that would be stored as infinity.
 * Such values are clamped to +-65504 in a copy (*out; NULL when none is out of range),
 * with a warning that counts them. Infinities and NaN are stored as they are. */
#define EXR_HALF_MAX 65504.0f
static atmos_status clamp_to_half(atmos_context *ctx, const atmos_image *img, const char *path, atmos_image **out)
{
    *out = NULL;
    const size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
    size_t over = 0;
    float peak = 0;
    for (size_t i = 0; i < n; i++) {
        const float v = fabsf(img->pixels[i]);
        if (v > EXR_HALF_MAX && isfinite(v)) over++, peak = v > peak ? v : peak;
    }
    if (!over) return ATMOS_OK;
    atmos_status st = atmos_image_create(ctx, img->width, img->height, img->channels, out);
    if (st != ATMOS_OK) return st;
    for (size_t i = 0; i < n; i++) {
        const float v = img->pixels[i];
        (*out)->pixels[i] = !isfinite(v) ? v : v > EXR_HALF_MAX ? EXR_HALF_MAX : v < -EXR_HALF_MAX ? -EXR_HALF_MAX : v;
    }
    for (int i = 0; i < img->meta_count && st == ATMOS_OK; i++)
        st = atmos_image_set_meta(*out, img->meta[i].key, img->meta[i].value);
    if (st != ATMOS_OK) return atmos__error(ctx, st, "%s: out of memory", path);
    atmos__log(ctx, ATMOS_LOG_WARN,
               "%s: %zu sample%s beyond the largest half float (up to %.4g) clamped to 65504; "
               "32-bit float output keeps them", path, over, over == 1 ? "" : "s", (double)peak);
    return ATMOS_OK;
}

atmos_status atmos_write_exr(atmos_context *ctx, const atmos_image *img, const char *path, const atmos_exr_desc *desc)
{
    if (!img || !img->pixels || !path)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_write_exr: missing image or path");
    if (img->channels < 1 || img->channels > ATMOS_IMAGE_MAX_CHANNELS || img->width < 1 || img->height < 1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: invalid image size", path);

    static const char *const rgba[4] = {"R", "G", "B", "A"};
    char(*generated)[16] = NULL;
    const char **names = malloc((size_t)img->channels * sizeof *names);
    if (!names) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
    if (desc && desc->channel_names) {
        for (int c = 0; c < img->channels; c++) {
            const char *n = desc->channel_names[c];
            if (!n || !*n || strlen(n) > 255) {
                free(names);
                return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: channel %d: name must have 1 to 255 bytes", path, c);
            }
            for (int k = 0; k < c; k++) {
                if (strcmp(names[k], n) == 0) {
                    free(names);
                    return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: channel name '%s' is used twice", path, n);
                }
            }
            names[c] = n;
        }
    } else if (img->channels == 3 || img->channels == 4) {
        for (int c = 0; c < img->channels; c++) names[c] = rgba[c];
    } else {
        generated = malloc((size_t)img->channels * sizeof *generated);
        if (!generated) {
            free(names);
            return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        }
        for (int c = 0; c < img->channels; c++) {
            snprintf(generated[c], sizeof generated[c], "C%d", c);
            names[c] = generated[c];
        }
    }
    exr_write_job job = {path, img, desc ? desc->half : 0, names};
    atmos_image *clamped = NULL;
    atmos_status st = job.half ? clamp_to_half(ctx, img, path, &clamped) : ATMOS_OK;
    if (clamped) job.img = clamped;
    if (st == ATMOS_OK) st = atmos__write_atomic(ctx, path, exr_write_file, &job);
    atmos_image_destroy(clamped);
    free(generated);
    free(names);
    return st;
}

/* ---------------------------------------------------------------- reading ---- */

static atmos_status read_status(exr_result_t rv)
{
    switch (rv) {
    case EXR_ERR_FILE_ACCESS: return ATMOS_E_IO;
    case EXR_ERR_OUT_OF_MEMORY: return ATMOS_E_NOMEM;
    default: return ATMOS_E_FORMAT;
    }
}

/* Parses "C<n>" with n < count; -1 otherwise. */
static int generated_index(const char *name, int count)
{
    if (name[0] != 'C' || !name[1]) return -1;
    long v = 0;
    for (const char *p = name + 1; *p; p++) {
        if (*p < '0' || *p > '9' || v > ATMOS_IMAGE_MAX_CHANNELS) return -1;
        v = v * 10 + (*p - '0');
    }
    if (name[1] == '0' && name[2]) return -1; /* "C01" is not something we write */
    return v < count ? (int)v : -1;
}

/* Chooses the image channel of each file channel (file order is sorted by name):
 * R,G,B first in that order when the file has all three (plain, or the only layer's
 * "<layer>.R", ...), then that alpha if present, then the other channels in the file's
 * (alphabetical) order; C0..Cn by number when the file has exactly those; otherwise the
 * file's order. */
static void map_channels(const exr_attr_chlist_t *cl, int *dst)
{
    const int n = cl->num_channels;
    const char *names[ATMOS_IMAGE_MAX_CHANNELS];
    for (int i = 0; i < n; i++) names[i] = cl->entries[i].name.str;
    int rgba[4];
    if (atmos__rgb_channels(names, n, rgba)) {
        int next = 0;
        for (int i = 0; i < n; i++) dst[i] = -1;
        for (int k = 0; k < 4; k++)
            if (rgba[k] >= 0) dst[rgba[k]] = next++;
        for (int i = 0; i < n; i++)
            if (dst[i] < 0) dst[i] = next++;
        return;
    }
    int ok = 1;
    char seen[ATMOS_IMAGE_MAX_CHANNELS] = {0};
    for (int i = 0; i < n && ok; i++) {
        int k = generated_index(cl->entries[i].name.str, n);
        ok = k >= 0 && !seen[k];
        if (ok) seen[k] = 1;
        dst[i] = k;
    }
    if (ok) return;
    for (int i = 0; i < n; i++) dst[i] = i;
}

/* UINT channels were decoded as their 32-bit integers into the float slots: convert
 * them to the floats they stand for (exact up to 2^24). */
static void convert_uint_channels(const exr_attr_chlist_t *cl, const int *map, atmos_image *img)
{
    const size_t npx = (size_t)img->width * (size_t)img->height;
    for (int i = 0; i < cl->num_channels; i++) {
        if (cl->entries[i].pixel_type != EXR_PIXEL_UINT) continue;
        float *px = img->pixels + map[i];
        for (size_t p = 0; p < npx; p++, px += img->channels) {
            uint32_t u;
            memcpy(&u, px, sizeof u);
            *px = (float)u;
        }
    }
}

static atmos_status decode_image(atmos_context *ctx, const char *path, exr_context_t ex, const exr_attr_box2i_t *dw,
                                 const int *map, atmos_image *img, exr_errbuf *eb)
{
    const int nc = img->channels;
    int32_t lines = 1;
    exr_result_t rv = exr_get_scanlines_per_chunk(ex, 0, &lines);
    if (rv != EXR_ERR_SUCCESS || lines < 1)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: OpenEXR: %s", path, exr_message(eb, rv));

    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    int initialized = 0;
    atmos_status st = ATMOS_OK;
    for (int64_t y = dw->min.y; y <= dw->max.y && st == ATMOS_OK; y += lines) {
        exr_chunk_info_t cinfo;
        rv = exr_read_scanline_chunk_info(ex, 0, (int)y, &cinfo);
        if (rv == EXR_ERR_SUCCESS)
            rv = initialized ? exr_decoding_update(ex, 0, &cinfo, &dec) : exr_decoding_initialize(ex, 0, &cinfo, &dec);
        if (rv != EXR_ERR_SUCCESS) {
            st = atmos__error(ctx, read_status(rv), "%s: OpenEXR: chunk at line %lld: %s", path, (long long)y,
                              exr_message(eb, rv));
            break;
        }
        initialized = 1;
        /* Trust nothing from the file: the chunk must lie inside the image. */
        int64_t row0 = (int64_t)cinfo.start_y - dw->min.y;
        if (row0 < 0 || cinfo.height < 1 || row0 + cinfo.height > img->height || cinfo.width != img->width ||
            dec.channel_count != nc) {
            st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: OpenEXR: chunk at line %lld lies outside the data window",
                              path, (long long)y);
            break;
        }
        for (int c = 0; c < dec.channel_count; c++) {
            exr_coding_channel_info_t *ch = &dec.channels[c];
            /* A UINT channel is decoded as integers (a float destination would get its
             * raw bits) and converted once the whole image is in. */
            ch->user_data_type = ch->data_type == EXR_PIXEL_UINT ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = (int32_t)(nc * 4);
            ch->user_line_stride = (int32_t)((size_t)img->width * (size_t)nc * 4);
            ch->decode_to_ptr =
                (uint8_t *)(img->pixels + (size_t)row0 * (size_t)img->width * (size_t)nc + (size_t)map[c]);
        }
        rv = exr_decoding_choose_default_routines(ex, 0, &dec);
        if (rv == EXR_ERR_SUCCESS) rv = exr_decoding_run(ex, 0, &dec);
        if (rv != EXR_ERR_SUCCESS)
            st = atmos__error(ctx, read_status(rv), "%s: OpenEXR: cannot decode lines from %lld: %s", path,
                              (long long)y, exr_message(eb, rv));
    }
    if (initialized) exr_decoding_destroy(ex, &dec);
    return st;
}

/* The most a chunk's data can grow when decompressed: raw data not at all; RLE at most
 * 127 bytes from 2; zlib (ZIP, ZIPS) at most ~1032 times, PXR24 (zlib of 24-bit floats)
 * 4/3 of that; B44 32 bytes from 3. PIZ (Huffman codes with runs of up to 255 values)
 * and DWA (run lengths of zeros, Huffman or zlib coded, then 8x8 blocks from one DC
 * value) have no tight bound: generous ones, far above what either can reach in
 * practice but enough to refuse a few bytes that claim gigabytes. 0: not checked. */
static uint64_t max_expansion(exr_compression_t c)
{
    switch (c) {
    case EXR_COMPRESSION_NONE: return 1;
    case EXR_COMPRESSION_RLE: return 64;
    case EXR_COMPRESSION_ZIPS:
    case EXR_COMPRESSION_ZIP: return 1100;
    case EXR_COMPRESSION_PXR24: return 1500;
    case EXR_COMPRESSION_B44:
    case EXR_COMPRESSION_B44A: return 16;
    case EXR_COMPRESSION_PIZ: return (uint64_t)1 << 16;
    case EXR_COMPRESSION_DWAA:
    case EXR_COMPRESSION_DWAB: return (uint64_t)1 << 22;
    default: return 0;
    }
}

/* Every chunk's place and sizes, before the image is allocated: a few hundred bytes that
 * claim a 65536 x 65536 image are refused here, not after gigabytes were asked for. The
 * library checks the offset table and each chunk against the file's size; the data of a
 * chunk must be able to expand to what the header says it holds. */
static atmos_status check_chunks(atmos_context *ctx, const char *path, exr_context_t ex, const exr_attr_box2i_t *dw,
                                 exr_errbuf *eb)
{
    int32_t lines = 1;
    exr_compression_t comp = EXR_COMPRESSION_LAST_TYPE;
    exr_result_t rv = exr_get_scanlines_per_chunk(ex, 0, &lines);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_compression(ex, 0, &comp);
    if (rv != EXR_ERR_SUCCESS || lines < 1)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: OpenEXR: %s", path, exr_message(eb, rv));
    const uint64_t grow = max_expansion(comp);
    for (int64_t y = dw->min.y; y <= dw->max.y; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_read_scanline_chunk_info(ex, 0, (int)y, &ci);
        if (rv != EXR_ERR_SUCCESS)
            return atmos__error(ctx, read_status(rv), "%s: OpenEXR: chunk at line %lld: %s", path, (long long)y,
                                exr_message(eb, rv));
        if (grow && ci.unpacked_size / grow > ci.packed_size)
            return atmos__error(ctx, ATMOS_E_FORMAT,
                                "%s: OpenEXR: chunk at line %lld holds %llu bytes but claims %llu decompressed: more "
                                "than its compression can give (truncated or damaged file)",
                                path, (long long)y, (unsigned long long)ci.packed_size,
                                (unsigned long long)ci.unpacked_size);
    }
    return ATMOS_OK;
}

/* Copies every string attribute of the header into img->meta. */
static atmos_status read_meta(atmos_context *ctx, const char *path, exr_context_t ex, atmos_image *img)
{
    int32_t count = 0;
    if (exr_get_attribute_count(ex, 0, &count) != EXR_ERR_SUCCESS) return ATMOS_OK;
    for (int32_t i = 0; i < count; i++) {
        const exr_attribute_t *a = NULL;
        if (exr_get_attribute_by_index(ex, 0, EXR_ATTR_LIST_FILE_ORDER, i, &a) != EXR_ERR_SUCCESS || !a) continue;
        if (!a->name) continue;
        if (a->type == EXR_ATTR_INT || a->type == EXR_ATTR_DOUBLE) {
            /* numbers (as the writer stores numeric metadata) come back as their text */
            char num[40];
            if (a->type == EXR_ATTR_INT) {
                snprintf(num, sizeof num, "%d", (int)a->i);
            } else {
                for (int p = 15; p <= 17; p++) {
                    snprintf(num, sizeof num, "%.*g", p, a->d);
                    if (strtod(num, NULL) == a->d) break;
                }
            }
            if (atmos_image_set_meta(img, a->name, num) == ATMOS_E_NOMEM)
                return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
            continue;
        }
        if (a->type != EXR_ATTR_STRING || !a->string) continue;
        /* "type" and "name" describe the part's structure (the library writes
         * "type" itself); they are not image metadata. */
        if (strcmp(a->name, "type") == 0 || strcmp(a->name, "name") == 0) continue;
        /* EXR strings are counted, not terminated: copy exactly length bytes. */
        int32_t len = a->string->length;
        if (len < 0) continue;
        char *v = malloc((size_t)len + 1);
        if (!v) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        if (len) memcpy(v, a->string->str, (size_t)len);
        v[len] = '\0';
        atmos_status st = atmos_image_set_meta(img, a->name, v);
        free(v);
        if (st == ATMOS_E_NOMEM) return atmos__error(ctx, st, "%s: out of memory", path);
    }
    return ATMOS_OK;
}

/* The channel names in image order, in one allocation: the pointer array, then the strings. */
static char **channel_names(const exr_attr_chlist_t *cl, const int *map)
{
    const int n = cl->num_channels;
    size_t bytes = sizeof(char *) * (size_t)n;
    for (int i = 0; i < n; i++) bytes += strlen(cl->entries[i].name.str) + 1;
    char **names = malloc(bytes);
    if (!names) return NULL;
    char *s = (char *)(names + n);
    for (int i = 0; i < n; i++) {
        size_t len = strlen(cl->entries[i].name.str) + 1;
        memcpy(s, cl->entries[i].name.str, len);
        names[map[i]] = s;
        s += len;
    }
    return names;
}

atmos_status atmos_read_exr(atmos_context *ctx, const char *path, atmos_image **out)
{
    return atmos_read_exr_named(ctx, path, out, NULL);
}

atmos_status atmos_read_exr_named(atmos_context *ctx, const char *path, atmos_image **out, char ***names)
{
    if (names) *names = NULL;
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_read_exr: out is NULL");
    *out = NULL;
    if (!path || !*path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_read_exr: path is empty");

    exr_errbuf eb = {{0}};
    exr_errbuf *saved = tls_errbuf;
    tls_errbuf = &eb;
    atmos_status st = ATMOS_OK;
    atmos_image *img = NULL;
    exr_context_t ex = NULL;
    int *map = NULL;

    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_error_handler;
    /* The library rejects larger data windows while parsing the header, before it
     * allocates anything for them. */
    init.max_image_width = ATMOS_IMAGE_MAX_DIM;
    init.max_image_height = ATMOS_IMAGE_MAX_DIM;
    /* A damaged chunk offset table is an error, not something to guess around: the
     * library's reconstruction scans the file for plausible chunks instead. */
    init.flags = EXR_CONTEXT_FLAG_SILENT_HEADER_PARSE | EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    exr_result_t rv = exr_start_read(&ex, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        if (rv == EXR_ERR_FILE_ACCESS)
            st = atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, exr_message(&eb, rv));
        else
            st = atmos__error(ctx, read_status(rv), "%s: not a readable OpenEXR file: %s", path, exr_message(&eb, rv));
        ex = NULL; /* exr_start_read cleans up after itself on failure */
        goto done;
    }

    int parts = 0;
    exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
    const exr_attr_chlist_t *cl = NULL;
    exr_attr_box2i_t dw;
    if (exr_get_count(ex, &parts) != EXR_ERR_SUCCESS || parts < 1 ||
        exr_get_storage(ex, 0, &storage) != EXR_ERR_SUCCESS || exr_get_channels(ex, 0, &cl) != EXR_ERR_SUCCESS ||
        !cl || exr_get_data_window(ex, 0, &dw) != EXR_ERR_SUCCESS) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: OpenEXR header lacks parts, channels or data window", path);
        goto done;
    }
    if (storage != EXR_STORAGE_SCANLINE) {
        st = atmos__error(ctx, ATMOS_E_UNSUPPORTED, "%s: only scanline OpenEXR images are supported (this one is %s)",
                          path, storage == EXR_STORAGE_TILED ? "tiled" : "deep");
        goto done;
    }
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w < 1 || h < 1 || cl->num_channels < 1) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: OpenEXR image is empty (%lld x %lld, %d channels)", path,
                          (long long)w, (long long)h, cl->num_channels);
        goto done;
    }
    if (w > ATMOS_IMAGE_MAX_DIM || h > ATMOS_IMAGE_MAX_DIM || cl->num_channels > ATMOS_IMAGE_MAX_CHANNELS) {
        st = atmos__error(ctx, ATMOS_E_LIMIT, "%s: OpenEXR image %lld x %lld with %d channels exceeds the limits (%d per side, %d channels)",
                          path, (long long)w, (long long)h, cl->num_channels, ATMOS_IMAGE_MAX_DIM, ATMOS_IMAGE_MAX_CHANNELS);
        goto done;
    }
    for (int c = 0; c < cl->num_channels; c++) {
        if (cl->entries[c].x_sampling != 1 || cl->entries[c].y_sampling != 1) {
            st = atmos__error(ctx, ATMOS_E_UNSUPPORTED, "%s: channel '%s' is subsampled; not supported", path,
                              cl->entries[c].name.str);
            goto done;
        }
    }
    st = check_chunks(ctx, path, ex, &dw, &eb);
    if (st != ATMOS_OK) goto done;
    map = malloc((size_t)cl->num_channels * sizeof *map);
    if (!map) {
        st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        goto done;
    }
    map_channels(cl, map);
    st = atmos_image_create(ctx, (int)w, (int)h, cl->num_channels, &img);
    if (st == ATMOS_OK) st = read_meta(ctx, path, ex, img);
    if (st == ATMOS_OK) st = decode_image(ctx, path, ex, &dw, map, img, &eb);
    if (st == ATMOS_OK) convert_uint_channels(cl, map, img);
    if (st == ATMOS_OK && names && !(*names = channel_names(cl, map)))
        st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);

done:
    if (ex) exr_finish(&ex);
    free(map);
    tls_errbuf = saved;
    if (st != ATMOS_OK) {
        atmos_image_destroy(img);
        return st;
    }
    *out = img;
    return ATMOS_OK;
}
