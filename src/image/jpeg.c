/* JPEG reader on libjpeg (Debian's libjpeg62-turbo).
 *
 * libjpeg reports fatal errors through error_exit, which must not return: ours longjmps
 * back to the reader. Resources assigned after setjmp are volatile-qualified pointers so
 * that the error branch sees their current values (C11 7.13.2.1p3). A truncated file is
 * not fatal to libjpeg (it warns and pads the rest with grey); the reader turns that
 * warning into an error, so a damaged file never yields an image. */
#define _POSIX_C_SOURCE 200809L
#include "core/internal.h"

#include <errno.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jpeglib.h>

typedef struct {
    struct jpeg_error_mgr mgr; /* first: libjpeg passes a pointer to it */
    jmp_buf jump;
    char msg[JMSG_LENGTH_MAX];
} jpeg_err;

static void jpeg_error_exit_cb(j_common_ptr cinfo)
{
    jpeg_err *e = (jpeg_err *)cinfo->err;
    if (!e->msg[0]) (*cinfo->err->format_message)(cinfo, e->msg);
    longjmp(e->jump, 1);
}

/* Warnings (level -1) include "premature end of data segment": a damaged file. Trace
 * messages (level >= 0) are ignored. */
static void jpeg_emit_cb(j_common_ptr cinfo, int level)
{
    if (level < 0) jpeg_error_exit_cb(cinfo);
}

atmos_status atmos_read_jpeg_scaled(atmos_context *ctx, const char *path, int reduce, atmos_image **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_read_jpeg: out is NULL");
    *out = NULL;
    if (!path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_read_jpeg: path is NULL");
    if (reduce != 1 && reduce != 2 && reduce != 4 && reduce != 8)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: JPEG reduction must be 1, 2, 4 or 8, got %d", path,
                            reduce);
    FILE *f = fopen(path, "rb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));

    struct jpeg_decompress_struct cinfo;
    jpeg_err err;
    memset(&err, 0, sizeof err);
    cinfo.err = jpeg_std_error(&err.mgr);
    err.mgr.error_exit = jpeg_error_exit_cb;
    err.mgr.emit_message = jpeg_emit_cb;
    atmos_image *volatile img = NULL;
    unsigned char *volatile row = NULL;
    atmos_status volatile st = ATMOS_E_FORMAT;
    if (setjmp(err.jump)) {
        jpeg_destroy_decompress(&cinfo);
        fclose(f);
        free(row);
        atmos_image_destroy(img);
        if (st == ATMOS_E_FORMAT) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: not a valid JPEG file: %s", path, err.msg);
        return st; /* already reported */
    }
    jpeg_create_decompress(&cinfo);
    jpeg_stdio_src(&cinfo, f);
    jpeg_read_header(&cinfo, TRUE);
    /* grey stays grey; everything else (YCbCr, CMYK is refused) becomes RGB */
    if (cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK) {
        snprintf(err.msg, sizeof err.msg, "CMYK JPEG files are not supported");
        longjmp(err.jump, 1);
    }
    cinfo.out_color_space = cinfo.num_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
    cinfo.scale_num = 1;
    cinfo.scale_denom = (unsigned)reduce;
    jpeg_start_decompress(&cinfo);
    const int w = (int)cinfo.output_width, h = (int)cinfo.output_height, nc = cinfo.output_components;
    {
        atmos_image *tmp = NULL;
        atmos_status s = atmos_image_create(ctx, w, h, nc, &tmp);
        if (s != ATMOS_OK) {
            st = s;
            longjmp(err.jump, 1);
        }
        img = tmp;
    }
    row = malloc((size_t)w * (size_t)nc);
    if (!row) {
        st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        longjmp(err.jump, 1);
    }
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW rp = row;
        const int y = (int)cinfo.output_scanline;
        if (jpeg_read_scanlines(&cinfo, &rp, 1) != 1) {
            snprintf(err.msg, sizeof err.msg, "no data for row %d", y);
            longjmp(err.jump, 1);
        }
        float *dst = img->pixels + (size_t)y * (size_t)w * (size_t)nc;
        for (size_t i = 0; i < (size_t)w * (size_t)nc; i++) dst[i] = (float)row[i] / 255.0f;
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    fclose(f);
    free(row);
    *out = img;
    return ATMOS_OK;
}

atmos_status atmos_read_jpeg(atmos_context *ctx, const char *path, atmos_image **out)
{
    return atmos_read_jpeg_scaled(ctx, path, 1, out);
}
