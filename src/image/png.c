/* PNG reader and writer on libpng.
 *
 * libpng reports errors by longjmp'ing out of the failing call. Every resource is
 * therefore either acquired before setjmp and never reassigned afterwards, or is a
 * volatile-qualified pointer, so that the error branch sees its current value
 * (C11 7.13.2.1p3). */
#define _POSIX_C_SOURCE 200809L
#include "core/internal.h"
#include "image/png_size.h"

#include <png.h>
#include <sys/stat.h>

#include <errno.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* zlib's deflate cannot compress better than about 1032:1, so a PNG needs at least
 * (raw size / 1032) bytes; with some margin this bounds what a tiny file can make
 * us allocate. */
#define DEFLATE_MAX_RATIO 1100

/* Passed to libpng as the error pointer: our error callback stores the message here. */
typedef struct {
    char msg[256];
} png_errctx;

static void png_error_cb(png_structp png, png_const_charp msg)
{
    png_errctx *e = png_get_error_ptr(png);
    if (e && !e->msg[0]) snprintf(e->msg, sizeof e->msg, "%s", msg ? msg : "unknown libpng error");
    png_longjmp(png, 1);
}

/* Warnings (unknown chunks, bad gamma values, ...) do not stop the read or write. */
static void png_warning_cb(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

/* [0,1] -> 0..maxv with rounding; NaN and negatives -> 0, above 1 -> maxv. */
static unsigned quantize(float v, unsigned maxv)
{
    if (!(v > 0)) return 0;
    if (v >= 1) return maxv;
    return (unsigned)(v * (float)maxv + 0.5f);
}

/* ---------------------------------------------------------------- writing ---- */

typedef struct {
    const char *path; /* final name, for messages */
    const atmos_image *img;
    int bits, level;  /* level: zlib's 0..9, -1 libpng's default */
} png_write_job;

static atmos_status png_write_file(atmos_context *ctx, const char *tmp, void *user)
{
    const png_write_job *job = user;
    const atmos_image *img = job->img;
    const int nc = img->channels;
    const size_t bytes_per_sample = job->bits == 16 ? 2 : 1;
    const size_t row_bytes = (size_t)img->width * (size_t)nc * bytes_per_sample;
    png_errctx err = {{0}};

    /* All resources acquired before setjmp and not reassigned after it. */
    FILE *f = fopen(tmp, "wb");
    if (!f) return atmos__temp_create_error(ctx, job->path, errno);
    unsigned char *row = malloc(row_bytes);
    png_text *texts = img->meta_count > 0 ? calloc((size_t)img->meta_count, sizeof *texts) : NULL;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, png_error_cb, png_warning_cb);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!row || !png || !info || (img->meta_count > 0 && !texts)) {
        png_destroy_write_struct(png ? &png : NULL, info ? &info : NULL);
        free(texts);
        free(row);
        fclose(f);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", job->path);
    }

    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        free(texts);
        free(row);
        fclose(f);
        return atmos__error(ctx, ATMOS_E_IO, "%s: PNG write failed: %s", job->path, err.msg);
    }

    png_init_io(png, f);
    if (job->level >= 0) png_set_compression_level(png, job->level);
    int color = nc == 1 ? PNG_COLOR_TYPE_GRAY : nc == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGB_ALPHA;
    png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height, job->bits, color, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    /* The input is display-encoded sRGB (what atmos_tonemap produces): say so, so
     * that colour-managed viewers do not reinterpret it. */
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    for (int i = 0; i < img->meta_count; i++) {
        texts[i].compression = PNG_TEXT_COMPRESSION_NONE;
        texts[i].key = img->meta[i].key;
        texts[i].text = img->meta[i].value;
        texts[i].text_length = strlen(img->meta[i].value);
        /* tEXt is Latin-1; non-ASCII values (UTF-8) go into an iTXt chunk. */
        for (const unsigned char *p = (const unsigned char *)img->meta[i].value; *p; p++)
            if (*p >= 0x80) texts[i].compression = PNG_ITXT_COMPRESSION_NONE;
    }
    if (img->meta_count > 0) png_set_text(png, info, texts, img->meta_count);
    png_write_info(png, info);

    const unsigned maxv = job->bits == 16 ? 65535u : 255u;
    for (int y = 0; y < img->height; y++) {
        const float *src = img->pixels + (size_t)y * (size_t)img->width * (size_t)nc;
        size_t n = (size_t)img->width * (size_t)nc;
        if (job->bits == 16) {
            for (size_t i = 0; i < n; i++) { /* PNG samples are big-endian */
                unsigned q = quantize(src[i], maxv);
                row[2 * i] = (unsigned char)(q >> 8);
                row[2 * i + 1] = (unsigned char)(q & 0xff);
            }
        } else {
            for (size_t i = 0; i < n; i++) row[i] = (unsigned char)quantize(src[i], maxv);
        }
        png_write_row(png, row);
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(texts);
    free(row);
    /* On disk before atmos__write_atomic renames it into place. */
    if (fflush(f) != 0 || ferror(f) || fsync(fileno(f)) != 0) {
        fclose(f);
        return atmos__error(ctx, ATMOS_E_IO, "%s: write failed: %s", job->path, strerror(errno));
    }
    if (fclose(f) != 0) return atmos__error(ctx, ATMOS_E_IO, "%s: write failed: %s", job->path, strerror(errno));
    return ATMOS_OK;
}

atmos_status atmos_write_png(atmos_context *ctx, const atmos_image *display, const char *path, int bits)
{
    return atmos_write_png_level(ctx, display, path, bits, -1);
}

atmos_status atmos_write_png_level(atmos_context *ctx, const atmos_image *display, const char *path, int bits,
                                   int level)
{
    if (level < -1 || level > 9)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: PNG compression level must be -1 or 0..9, got %d",
                            path ? path : "PNG", level);
    if (!display || !display->pixels || !path)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_write_png: missing image or path");
    if (bits != 8 && bits != 16)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: PNG bit depth must be 8 or 16, got %d", path, bits);
    if (display->channels != 1 && display->channels != 3 && display->channels != 4)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: PNG needs 1, 3 or 4 channels, image has %d", path,
                            display->channels);
    /* Check what libpng would reject with a less helpful message (PNG spec 11.3.4.3). */
    for (int i = 0; i < display->meta_count; i++) {
        size_t n = strlen(display->meta[i].key);
        const char *k = display->meta[i].key;
        if (n < 1 || n > 79 || k[0] == ' ' || k[n - 1] == ' ')
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "%s: metadata key '%s': PNG text keys need 1 to 79 bytes and no leading or trailing space",
                                path, k);
    }
    png_write_job job = {path, display, bits, level};
    return atmos__write_atomic(ctx, path, png_write_file, &job);
}

/* ---------------------------------------------------------------- reading ---- */

int atmos__png_size(const char *path, uint32_t *w, uint32_t *h)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    png_errctx err = {{0}};
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, png_error_cb, png_warning_cb);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    int ok = 0;
    if (png && info && !setjmp(png_jmpbuf(png))) {
        png_init_io(png, f);
        png_read_info(png, info);
        *w = png_get_image_width(png, info), *h = png_get_image_height(png, info);
        ok = 1;
    }
    png_destroy_read_struct(png ? &png : NULL, info ? &info : NULL, NULL);
    fclose(f);
    return ok;
}

atmos_status atmos_read_png(atmos_context *ctx, const char *path, atmos_image **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_read_png: out is NULL");
    *out = NULL;
    if (!path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_read_png: path is NULL");
    FILE *f = fopen(path, "rb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat whole; /* a folder, or an empty file: libpng would say "Read Error", "truncated" */
    const int known = fstat(fileno(f), &whole) == 0;
    if (known && S_ISDIR(whole.st_mode)) {
        fclose(f);
        return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: it is a folder, not a file", path);
    }
    if (known && S_ISREG(whole.st_mode) && whole.st_size == 0) {
        fclose(f);
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: empty file (0 bytes): not a PNG image", path);
    }
    png_byte sig[8]; /* a file that does not start as a PNG: said so, not "truncated" when it is short */
    const size_t got = fread(sig, 1, sizeof sig, f);
    if (png_sig_cmp(sig, 0, got) != 0 || got < sizeof sig) {
        fclose(f);
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: not a PNG file (%s)", path,
                            png_sig_cmp(sig, 0, got) != 0 ? "it does not start with PNG's signature"
                                                          : "it ends within PNG's signature");
    }

    png_errctx err = {{0}};
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, png_error_cb, png_warning_cb);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_read_struct(png ? &png : NULL, info ? &info : NULL, NULL);
        fclose(f);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
    }
    /* Assigned after setjmp: volatile, so the error branch frees what exists. */
    atmos_image *volatile img = NULL;
    unsigned char *volatile buf = NULL;
    png_bytep *volatile rows = NULL;
    atmos_status volatile st = ATMOS_E_FORMAT;

    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, NULL);
        const int ended = feof(f); /* libpng's "Read Error": the file ended before the image did */
        fclose(f);
        free(rows);
        free(buf);
        atmos_image_destroy(img);
        if (st == ATMOS_E_FORMAT && ended)
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated: the PNG file ends before its image does (libpng: %s)",
                                path, err.msg);
        if (st == ATMOS_E_FORMAT)
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: not a valid PNG file: %s", path, err.msg);
        return st; /* already reported */
    }

    png_init_io(png, f);
    png_set_sig_bytes(png, 8); /* read above */
    /* Reject huge images in the header, before any row is allocated. */
    png_set_user_limits(png, ATMOS_IMAGE_MAX_DIM, ATMOS_IMAGE_MAX_DIM);
    png_read_info(png, info);

    struct stat sb;
    size_t raw = png_get_rowbytes(png, info) * (size_t)png_get_image_height(png, info);
    if (fstat(fileno(f), &sb) == 0 && sb.st_size >= 0 &&
        (uint64_t)sb.st_size * DEFLATE_MAX_RATIO < (uint64_t)raw)
        png_error(png, "file is far too small for the image size in its header (truncated?)");

    /* Everything to 8 or 16-bit grey, grey+alpha, RGB or RGBA. */
    png_set_expand(png);                                       /* palette, low-bit grey, tRNS */
    /* Grey with alpha (or with a tRNS colour, which expands to alpha) -> RGBA: the
     * rest of atmos uses 1, 3 or 4 channels. */
    int ct = png_get_color_type(png, info);
    if (ct == PNG_COLOR_TYPE_GRAY_ALPHA || (ct == PNG_COLOR_TYPE_GRAY && png_get_valid(png, info, PNG_INFO_tRNS)))
        png_set_gray_to_rgb(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);

    png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    int depth = png_get_bit_depth(png, info);
    int nc = png_get_channels(png, info);
    size_t rowbytes = png_get_rowbytes(png, info);
    if ((depth != 8 && depth != 16) || (nc != 1 && nc != 3 && nc != 4) ||
        rowbytes != (size_t)w * (size_t)nc * (size_t)(depth / 8))
        png_error(png, "unexpected pixel layout after transforms");
    {
        atmos_image *tmp = NULL;
        atmos_status s = atmos_image_create(ctx, (int)w, (int)h, nc, &tmp);
        if (s != ATMOS_OK) {
            st = s;
            png_longjmp(png, 1);
        }
        img = tmp;
    }
    if ((size_t)h > SIZE_MAX / rowbytes) png_error(png, "image too large");
    buf = malloc((size_t)h * rowbytes);
    rows = malloc((size_t)h * sizeof(png_bytep));
    if (!buf || !rows) {
        st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        png_longjmp(png, 1);
    }
    for (png_uint_32 y = 0; y < h; y++) rows[y] = buf + (size_t)y * rowbytes;
    png_read_image(png, rows);
    /* Reads to IEND: a truncated file fails here, and text after IDAT is collected. */
    png_read_end(png, info);

    const float inv = 1.0f / (depth == 16 ? 65535.0f : 255.0f);
    const size_t n = (size_t)w * (size_t)h * (size_t)nc;
    for (size_t i = 0; i < n; i++) {
        unsigned v = depth == 16 ? ((unsigned)buf[2 * i] << 8 | buf[2 * i + 1]) : buf[i];
        img->pixels[i] = (float)v * inv;
    }
    png_textp text = NULL;
    int ntext = png_get_text(png, info, &text, NULL);
    for (int i = 0; i < ntext; i++) {
        if (!text[i].key || !text[i].text) continue;
        if (atmos_image_set_meta(img, text[i].key, text[i].text) != ATMOS_OK) {
            st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
            png_longjmp(png, 1);
        }
    }

    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    free(rows);
    free(buf);
    *out = img;
    return ATMOS_OK;
}
