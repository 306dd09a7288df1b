/* libFuzzer target for the image readers as `atmos compare` uses them: the input goes
 * to a scratch file and through the PFM, OpenEXR (with channel names) and PNG readers,
 * and every image read is compared with itself through the pairing by name.
 *
 * Beyond "does not crash, hang or leak", it aborts when a promise is broken:
 *  - a failure has a status a reader may return (FORMAT, UNSUPPORTED, LIMIT, NOMEM, IO),
 *    a message naming the file, and no image;
 *  - an accepted image has a size within the limits, as many names as channels (EXR),
 *    1 or 3 channels (PFM), values in [0, 1] (PNG);
 *  - compared with itself, it differs by nothing, and its NaN/Inf samples are counted
 *    exactly, once in each image.
 * Build with -DATMOS_FUZZ=ON (clang), or replay a corpus with fuzz/replay.c.
 */
#define _POSIX_C_SOURCE 200809L /* getpid */
#include "atmos/atmos.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char scratch[1024];

static void fail(const char *reader, const char *what, const char *msg)
{
    fprintf(stderr, "fuzz_compare: %s: %s (message: %s)\n", reader, what, msg ? msg : "");
    abort();
}

static void remove_scratch(void) { remove(scratch); }

static const char *scratch_path(void)
{
    if (!scratch[0]) {
        const char *dir = getenv("ATMOS_TEST_TMP");
        if (!dir || !*dir) dir = getenv("TMPDIR");
        if (!dir || !*dir) dir = "/tmp";
        snprintf(scratch, sizeof scratch, "%s/fuzz_compare.%ld.img", dir, (long)getpid());
        atexit(remove_scratch);
    }
    return scratch;
}

/* The image compared with itself: zero difference; non-finite samples counted in both. */
static void self_compare(atmos_context *ctx, const char *reader, const atmos_image *img, const char *const *names)
{
    atmos_channel_match m;
    if (atmos_image_match_channels(ctx, names, img->channels, names, img->channels, &m) != ATMOS_OK) return;
    size_t bad = 0, npx = (size_t)img->width * (size_t)img->height;
    for (size_t p = 0; p < npx; p++)
        for (int c = 0; c < m.count; c++) bad += !isfinite(img->pixels[p * (size_t)img->channels + (size_t)m.image[c]]);
    atmos_image_diff d;
    if (atmos_image_compare_matched(ctx, img, img, &m, &d, NULL) != ATMOS_OK) fail(reader, "self-compare failed", NULL);
    if (d.nonfinite != bad || d.nonfinite_image != bad || d.nonfinite_reference != bad)
        fail(reader, "non-finite samples miscounted", NULL);
    if (bad < npx * (size_t)m.count && !(d.rmse_all == 0 && d.worst_rmse == 0)) fail(reader, "differs from itself", NULL);
    if (bad == npx * (size_t)m.count && !isnan(d.rmse_all)) fail(reader, "no finite sample but a number", NULL);
}

static void check_read(atmos_context *ctx, const char *reader, const char *path, atmos_status st, atmos_image *img,
                       char **owned)
{
    const char *msg = atmos_context_error(ctx);
    if (st != ATMOS_OK) {
        if (st != ATMOS_E_FORMAT && st != ATMOS_E_UNSUPPORTED && st != ATMOS_E_LIMIT && st != ATMOS_E_NOMEM &&
            st != ATMOS_E_IO)
            fail(reader, "unexpected status", msg);
        if (strncmp(msg, path, strlen(path)) != 0) fail(reader, "message does not name the file", msg);
        if (img || owned) fail(reader, "image returned on failure", msg);
        return;
    }
    if (!img || !img->pixels || img->width < 1 || img->height < 1 || img->width > ATMOS_IMAGE_MAX_DIM ||
        img->height > ATMOS_IMAGE_MAX_DIM || img->channels < 1 || img->channels > ATMOS_IMAGE_MAX_CHANNELS)
        fail(reader, "accepted image out of limits", NULL);
    static const char *const rgba[4] = {"R", "G", "B", "A"}, *const grey[1] = {"Y"};
    const char *const *names = (const char *const *)owned;
    if (!strcmp(reader, "exr")) {
        if (!owned) fail(reader, "no channel names", NULL);
        for (int c = 0; c < img->channels; c++)
            if (!owned[c]) fail(reader, "missing channel name", NULL);
    } else if (!strcmp(reader, "pfm")) {
        if (img->channels != 1 && img->channels != 3) fail(reader, "PFM with neither 1 nor 3 channels", NULL);
        names = img->channels == 3 ? rgba : grey;
    } else {
        size_t n = (size_t)img->width * img->height * img->channels;
        for (size_t i = 0; i < n; i++)
            if (!(img->pixels[i] >= 0 && img->pixels[i] <= 1)) fail(reader, "PNG value outside [0, 1]", NULL);
        names = img->channels == 1 ? grey : rgba; /* 1, 3 or 4 channels; A is not compared */
        if (img->channels == 2) return;
    }
    self_compare(ctx, reader, img, names);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = scratch_path();
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    int ok = fwrite(data, 1, size, f) == size;
    if (fclose(f) != 0 || !ok) return 0;
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) return 0;
    atmos_image *img = NULL;
    char **names = NULL;

    atmos_status st = atmos_read_pfm(ctx, path, &img);
    check_read(ctx, "pfm", path, st, img, NULL);
    atmos_image_destroy(img), img = NULL;

    st = atmos_read_exr_named(ctx, path, &img, &names);
    check_read(ctx, "exr", path, st, img, names);
    atmos_image_destroy(img), img = NULL;
    free(names);

    st = atmos_read_png(ctx, path, &img);
    check_read(ctx, "png", path, st, img, NULL);
    atmos_image_destroy(img);

    atmos_context_destroy(ctx);
    return 0;
}
