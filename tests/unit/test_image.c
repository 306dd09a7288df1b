/* Image module: allocation limits, EXR/PNG/PFM round trips and metadata, reading
 * malformed files, tone mapping and exposure, atomic writes (including a writer
 * killed with SIGKILL mid-write). */
#define _POSIX_C_SOURCE 200809L
#include "atmos/atmos.h"
#include "core/internal.h"
#include "test.h"

#include <openexr.h>
#include <png.h>

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* ------------------------------------------------------------------ helpers -- */

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double rnd(void) /* xorshift64*: deterministic, no libc rand() state */
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

static atmos_image *make_image(int w, int h, int c)
{
    atmos_image *img = NULL;
    if (atmos_image_create(NULL, w, h, c, &img) != ATMOS_OK) {
        fprintf(stderr, "cannot create %dx%dx%d test image\n", w, h, c);
        exit(2);
    }
    return img;
}

static size_t npix(const atmos_image *img)
{
    return (size_t)img->width * (size_t)img->height * (size_t)img->channels;
}

static int file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static long file_size(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 ? (long)sb.st_size : -1;
}

static void spit(const char *path, const void *buf, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        exit(2);
    }
    if (n) fwrite(buf, 1, n, f);
    fclose(f);
}

static atmos_context *new_ctx(void)
{
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) exit(2);
    return ctx;
}

/* ------------------------------------------------------------------ image ---- */

static void test_create(void)
{
    atmos_context *ctx = new_ctx();
    atmos_image *img = (atmos_image *)1;
    CHECK(atmos_image_create(ctx, 0, 10, 3, &img) == ATMOS_E_INVALID_ARG);
    CHECK(img == NULL);
    CHECK(strlen(atmos_context_error(ctx)) > 0);
    CHECK(atmos_image_create(ctx, 10, -1, 3, &img) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_image_create(ctx, 10, 10, 0, &img) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_image_create(ctx, ATMOS_IMAGE_MAX_DIM + 1, 10, 3, &img) == ATMOS_E_LIMIT);
    CHECK(strstr(atmos_context_error(ctx), "65537") != NULL);
    CHECK(atmos_image_create(ctx, 10, ATMOS_IMAGE_MAX_DIM + 1, 3, &img) == ATMOS_E_LIMIT);
    CHECK(atmos_image_create(ctx, 10, 10, ATMOS_IMAGE_MAX_CHANNELS + 1, &img) == ATMOS_E_LIMIT);
    CHECK(atmos_image_create(NULL, 10, 10, 3, NULL) == ATMOS_E_INVALID_ARG);

    CHECK_OK(atmos_image_create(ctx, 7, 5, 2, &img));
    CHECK(img && img->width == 7 && img->height == 5 && img->channels == 2);
    int zero = 1;
    for (size_t i = 0; i < npix(img); i++) zero &= img->pixels[i] == 0.0f;
    CHECK(zero);
    CHECK(atmos_image_get_meta(img, "a") == NULL);
    CHECK_OK(atmos_image_set_meta(img, "a", "1"));
    CHECK_OK(atmos_image_set_meta(img, "b", "2"));
    CHECK_OK(atmos_image_set_meta(img, "a", "3"));
    CHECK(img->meta_count == 2);
    CHECK(atmos_image_get_meta(img, "a") && strcmp(atmos_image_get_meta(img, "a"), "3") == 0);
    CHECK(atmos_image_get_meta(img, "b") && strcmp(atmos_image_get_meta(img, "b"), "2") == 0);
    CHECK(atmos_image_set_meta(img, "", "x") == ATMOS_E_INVALID_ARG);
    CHECK(atmos_image_set_meta(img, "k", NULL) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(img);
    atmos_image_destroy(NULL);
    atmos_context_destroy(ctx);
}

/* ------------------------------------------------------------------ EXR ------ */

/* Decodes one channel of one EXR with the core API directly, independently of
 * atmos_read_exr, so a mapping bug that the writer and reader share (R stored
 * under "A" and read back from "A") cannot hide. Returns the value at (x, y). */
static float exr_raw_channel_value(const char *path, const char *name, int x, int y)
{
    exr_context_t ex = NULL;
    float value = NAN;
    if (exr_start_read(&ex, path, NULL) != EXR_ERR_SUCCESS) return NAN;
    exr_attr_box2i_t dw;
    exr_get_data_window(ex, 0, &dw);
    int w = dw.max.x - dw.min.x + 1;
    exr_chunk_info_t ci;
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    if (exr_read_scanline_chunk_info(ex, 0, y, &ci) == EXR_ERR_SUCCESS &&
        exr_decoding_initialize(ex, 0, &ci, &dec) == EXR_ERR_SUCCESS) {
        float *plane = calloc((size_t)w * (size_t)ci.height, sizeof(float));
        for (int c = 0; c < dec.channel_count; c++) {
            exr_coding_channel_info_t *ch = &dec.channels[c];
            ch->decode_to_ptr = NULL; /* skipped */
            if (strcmp(ch->channel_name, name) == 0) {
                ch->decode_to_ptr = (uint8_t *)plane;
                ch->user_data_type = EXR_PIXEL_FLOAT;
                ch->user_bytes_per_element = 4;
                ch->user_pixel_stride = 4;
                ch->user_line_stride = 4 * w;
            }
        }
        if (exr_decoding_choose_default_routines(ex, 0, &dec) == EXR_ERR_SUCCESS &&
            exr_decoding_run(ex, 0, &dec) == EXR_ERR_SUCCESS)
            value = plane[(size_t)(y - ci.start_y) * (size_t)w + (size_t)x];
        exr_decoding_destroy(ex, &dec);
        free(plane);
    }
    exr_finish(&ex);
    return value;
}

static int exr_channel_names(const char *path, char *out, size_t cap)
{
    exr_context_t ex = NULL;
    out[0] = '\0';
    if (exr_start_read(&ex, path, NULL) != EXR_ERR_SUCCESS) return -1;
    const exr_attr_chlist_t *cl = NULL;
    exr_get_channels(ex, 0, &cl);
    exr_compression_t comp = EXR_COMPRESSION_NONE;
    exr_get_compression(ex, 0, &comp);
    for (int i = 0; cl && i < cl->num_channels; i++) {
        strncat(out, cl->entries[i].name.str, cap - strlen(out) - 1);
        strncat(out, ",", cap - strlen(out) - 1);
    }
    exr_finish(&ex);
    return (int)comp;
}

static void test_exr_roundtrip(void)
{
    atmos_context *ctx = new_ctx();
    char path[512];
    test_tmp_path(path, sizeof path, "rt_float.exr");

    /* Float: bit exact, including values no half could hold. 37 rows: not a
     * multiple of the 16-line ZIP chunk. */
    for (int nc = 1; nc <= 5; nc++) {
        atmos_image *img = make_image(29, 37, nc), *back = NULL;
        for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)((rnd() - 0.3) * pow(10.0, rnd() * 40 - 20));
        CHECK_OK(atmos_write_exr(ctx, img, path, NULL));
        CHECK_OK(atmos_read_exr(ctx, path, &back));
        CHECK(back && back->width == 29 && back->height == 37 && back->channels == nc);
        if (back && back->channels == nc)
            CHECK_MSG(memcmp(back->pixels, img->pixels, npix(img) * sizeof(float)) == 0, "float EXR %d channels not exact", nc);
        atmos_image_destroy(back);
        atmos_image_destroy(img);
    }

    /* Channel naming and mapping: RGBA stored as A,B,G,R (sorted), ZIP, and the R
     * channel holds image channel 0, checked with an independent decoder. */
    atmos_image *img = make_image(8, 20, 4);
    for (size_t p = 0; p < 8 * 20; p++)
        for (int c = 0; c < 4; c++) img->pixels[p * 4 + (size_t)c] = (float)(c + 1) + (float)p * 0.001f;
    CHECK_OK(atmos_write_exr(ctx, img, path, NULL));
    char names[256];
    int comp = exr_channel_names(path, names, sizeof names);
    CHECK_MSG(strcmp(names, "A,B,G,R,") == 0, "channels %s", names);
    CHECK(comp == EXR_COMPRESSION_ZIP);
    CHECK_NEAR(exr_raw_channel_value(path, "R", 3, 17), img->pixels[(17 * 8 + 3) * 4 + 0], 0);
    CHECK_NEAR(exr_raw_channel_value(path, "G", 3, 17), img->pixels[(17 * 8 + 3) * 4 + 1], 0);
    CHECK_NEAR(exr_raw_channel_value(path, "A", 3, 17), img->pixels[(17 * 8 + 3) * 4 + 3], 0);
    atmos_image_destroy(img);

    /* More than ten generated channels: C10 sorts before C2 in the file but must
     * come back as channel 10. */
    img = make_image(5, 3, 12);
    for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)(i % 12) * 10.0f + (float)(i / 12);
    atmos_image *back = NULL;
    CHECK_OK(atmos_write_exr(ctx, img, path, NULL));
    exr_channel_names(path, names, sizeof names);
    CHECK(strncmp(names, "C0,C1,C10,C11,C2,", 17) == 0);
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    CHECK(back && back->channels == 12 && memcmp(back->pixels, img->pixels, npix(img) * sizeof(float)) == 0);
    atmos_image_destroy(back);
    atmos_image_destroy(img);

    /* Named channels (given in sorted order, so they come back in the same order). */
    img = make_image(4, 4, 2);
    for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)i;
    const char *const sorted[2] = {"density", "depth"};
    atmos_exr_desc nd = {0, sorted};
    CHECK_OK(atmos_write_exr(ctx, img, path, &nd));
    exr_channel_names(path, names, sizeof names);
    CHECK(strcmp(names, "density,depth,") == 0);
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    CHECK(back && back->channels == 2 && memcmp(back->pixels, img->pixels, npix(img) * sizeof(float)) == 0);
    atmos_image_destroy(back);
    const char *const dup[2] = {"x", "x"};
    nd.channel_names = dup;
    CHECK(atmos_write_exr(ctx, img, path, &nd) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(img);

    /* Half: within half precision (11-bit significand: relative error <= 2^-11). */
    test_tmp_path(path, sizeof path, "rt_half.exr");
    img = make_image(33, 18, 3);
    for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)pow(10.0, rnd() * 7 - 2.5); /* 3e-3 .. 3e4 */
    atmos_exr_desc hd = {1, NULL};
    CHECK_OK(atmos_write_exr(ctx, img, path, &hd));
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    double worst = 0;
    if (back && back->channels == 3)
        for (size_t i = 0; i < npix(img); i++) {
            double e = fabs(back->pixels[i] - img->pixels[i]) / img->pixels[i];
            if (e > worst) worst = e;
        }
    else
        worst = 1;
    /* worst > 0: the values really went through half precision. */
    CHECK_MSG(worst <= 1.0 / 2048 && worst > 0, "half round trip worst relative error %g", worst);
    atmos_image_destroy(back);
    atmos_image_destroy(img);
    atmos_context_destroy(ctx);
}

static void test_exr_meta(void)
{
    atmos_context *ctx = new_ctx();
    char path[512];
    test_tmp_path(path, sizeof path, "meta.exr");
    remove(path);
    atmos_image *img = make_image(3, 2, 3), *back = NULL;
    const char *long_key = "a.metadata.key.longer.than.thirty.one.bytes";
    CHECK_OK(atmos_image_set_meta(img, "atmos:scene", "scenes/rainbow.json"));
    CHECK_OK(atmos_image_set_meta(img, "atmos:renderer", "slice"));
    CHECK_OK(atmos_image_set_meta(img, long_key, "long value \xc3\xa9 UTF-8"));
    CHECK_OK(atmos_image_set_meta(img, "empty", ""));
    CHECK_OK(atmos_write_exr(ctx, img, path, NULL));
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    const char *v;
    CHECK(back && (v = atmos_image_get_meta(back, "atmos:scene")) && strcmp(v, "scenes/rainbow.json") == 0);
    CHECK(back && (v = atmos_image_get_meta(back, "atmos:renderer")) && strcmp(v, "slice") == 0);
    CHECK(back && (v = atmos_image_get_meta(back, long_key)) && strcmp(v, "long value \xc3\xa9 UTF-8") == 0);
    CHECK(back && (v = atmos_image_get_meta(back, "empty")) && strcmp(v, "") == 0);
    /* Exactly what was written: no structural attributes ("type") leak in. */
    CHECK_MSG(back && back->meta_count == 4, "%d metadata entries read back", back ? back->meta_count : -1);
    atmos_image_destroy(back);

    /* "type" and "name" belong to the part structure. */
    atmos_image *r = make_image(1, 1, 1);
    CHECK_OK(atmos_image_set_meta(r, "type", "deeptile"));
    CHECK(atmos_write_exr(ctx, r, path, NULL) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(r);

    /* A key that is a standard attribute of another type: refused, and the file
     * written before stays intact under the final name. */
    long before = file_size(path);
    CHECK_OK(atmos_image_set_meta(img, "channels", "R,G,B"));
    CHECK(atmos_write_exr(ctx, img, path, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "channels") != NULL);
    /* Messages name the file the caller asked for, not the temporary. */
    CHECK(strstr(atmos_context_error(ctx), path) != NULL && strstr(atmos_context_error(ctx), ".tmp") == NULL);
    CHECK(file_size(path) == before);
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    atmos_image_destroy(back);
    atmos_image_destroy(img);
    atmos_context_destroy(ctx);
}

/* ------------------------------------------------------------------ PNG ------ */

static void test_png(void)
{
    atmos_context *ctx = new_ctx();
    char path[512];
    test_tmp_path(path, sizeof path, "rt.png");
    const int chans[3] = {1, 3, 4};
    for (int bi = 0; bi < 2; bi++) {
        int bits = bi ? 16 : 8;
        double step = bits == 16 ? 1.0 / 65535 : 1.0 / 255;
        for (int k = 0; k < 3; k++) {
            atmos_image *img = make_image(21, 13, chans[k]), *back = NULL;
            for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)rnd();
            img->pixels[0] = 0.0f;
            img->pixels[1 % npix(img)] = 1.0f;
            CHECK_OK(atmos_write_png(ctx, img, path, bits));
            CHECK_OK(atmos_read_png(ctx, path, &back));
            CHECK(back && back->width == 21 && back->height == 13 && back->channels == chans[k]);
            double worst = 0;
            if (back && back->channels == chans[k])
                for (size_t i = 0; i < npix(img); i++) worst = fmax(worst, fabs(back->pixels[i] - img->pixels[i]));
            else
                worst = 1;
            /* Rounding to nearest: at most half a step (plus float noise). */
            CHECK_MSG(worst <= 0.5 * step + 1e-6, "%d-bit PNG, %d channels: error %g (step %g)", bits, chans[k], worst, step);
            if (back) CHECK(back->pixels[0] == 0.0f && back->pixels[1 % npix(img)] == 1.0f);
            atmos_image_destroy(back);
            atmos_image_destroy(img);
        }
    }

    /* Out-of-range, NaN and Inf are clamped, never wrapped. */
    atmos_image *img = make_image(5, 1, 1), *back = NULL;
    const float odd[5] = {-1.0f, 2.0f, NAN, INFINITY, -INFINITY};
    memcpy(img->pixels, odd, sizeof odd);
    CHECK_OK(atmos_write_png(ctx, img, path, 8));
    CHECK_OK(atmos_read_png(ctx, path, &back));
    if (back) {
        CHECK(back->pixels[0] == 0.0f && back->pixels[1] == 1.0f && back->pixels[2] == 0.0f);
        CHECK(back->pixels[3] == 1.0f && back->pixels[4] == 0.0f);
    }
    atmos_image_destroy(back);
    CHECK(atmos_write_png(ctx, img, path, 12) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(img);
    img = make_image(2, 2, 2);
    CHECK(atmos_write_png(ctx, img, path, 8) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(img);

    /* Metadata: ASCII in tEXt, UTF-8 in iTXt. */
    img = make_image(4, 4, 3);
    CHECK_OK(atmos_image_set_meta(img, "Software", "atmos"));
    CHECK_OK(atmos_image_set_meta(img, "atmos:exposure_ev", "14.5"));
    CHECK_OK(atmos_image_set_meta(img, "Comment", "halo 22\xc2\xb0"));
    CHECK_OK(atmos_write_png(ctx, img, path, 16));
    CHECK_OK(atmos_read_png(ctx, path, &back));
    const char *v;
    CHECK(back && (v = atmos_image_get_meta(back, "Software")) && strcmp(v, "atmos") == 0);
    CHECK(back && (v = atmos_image_get_meta(back, "atmos:exposure_ev")) && strcmp(v, "14.5") == 0);
    CHECK(back && (v = atmos_image_get_meta(back, "Comment")) && strcmp(v, "halo 22\xc2\xb0") == 0);
    atmos_image_destroy(back);
    CHECK_OK(atmos_image_set_meta(img, "a key that is far too long for a PNG text chunk, which allows seventy-nine bytes", "x"));
    CHECK(atmos_write_png(ctx, img, path, 8) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(img);

    /* A grey+alpha PNG written by libpng itself comes back as RGBA. */
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    pi.width = 2;
    pi.height = 1;
    pi.format = PNG_FORMAT_GA;
    const unsigned char ga[4] = {51, 255, 204, 0};
    test_tmp_path(path, sizeof path, "ga.png");
    CHECK(png_image_write_to_file(&pi, path, 0, ga, 0, NULL) != 0);
    CHECK_OK(atmos_read_png(ctx, path, &back));
    CHECK(back && back->channels == 4);
    if (back && back->channels == 4) {
        CHECK_NEAR(back->pixels[0], 0.2, 1e-6);
        CHECK_NEAR(back->pixels[2], 0.2, 1e-6);
        CHECK_NEAR(back->pixels[3], 1.0, 1e-6);
        CHECK_NEAR(back->pixels[4], 0.8, 1e-6);
        CHECK_NEAR(back->pixels[7], 0.0, 1e-6);
    }
    atmos_image_destroy(back);
    atmos_context_destroy(ctx);
}

/* ------------------------------------------------------------------ PFM ------ */

static void test_pfm(void)
{
    atmos_context *ctx = new_ctx();
    char path[512];
    test_tmp_path(path, sizeof path, "rt.pfm");
    for (int nc = 1; nc <= 4; nc += 2) {
        atmos_image *img = make_image(11, 7, nc), *back = NULL;
        for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)((rnd() - 0.5) * 1e6);
        img->pixels[2] = NAN;
        img->pixels[3] = INFINITY;
        CHECK_OK(atmos_write_pfm(ctx, img, path));
        CHECK_OK(atmos_read_pfm(ctx, path, &back));
        CHECK(back && back->width == 11 && back->height == 7 && back->channels == nc);
        if (back && back->channels == nc)
            CHECK_MSG(memcmp(back->pixels, img->pixels, npix(img) * sizeof(float)) == 0, "PFM %d channels not exact", nc);
        atmos_image_destroy(back);
        atmos_image_destroy(img);
    }

    /* Layout: exact header, little-endian, bottom row first. */
    atmos_image *img = make_image(2, 2, 3), *back = NULL;
    for (size_t i = 0; i < 12; i++) img->pixels[i] = (float)i;
    CHECK_OK(atmos_write_pfm(ctx, img, path));
    size_t n = 0;
    unsigned char *b = test_slurp(path, &n);
    const char *hdr = "PF\n2 2\n-1.0\n";
    size_t hl = strlen(hdr);
    CHECK(b && n == hl + 48 && memcmp(b, hdr, hl) == 0);
    if (b && n == hl + 48) {
        /* first float is the bottom-left red: pixel (0,1), value 6.0f = 0x40c00000 */
        CHECK(b[hl] == 0x00 && b[hl + 1] == 0x00 && b[hl + 2] == 0xc0 && b[hl + 3] == 0x40);
    }
    free(b);

    /* Four channels: the first three are written. */
    atmos_image_destroy(img);
    img = make_image(3, 2, 4);
    for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)i;
    CHECK_OK(atmos_write_pfm(ctx, img, path));
    CHECK_OK(atmos_read_pfm(ctx, path, &back));
    CHECK(back && back->channels == 3);
    if (back && back->channels == 3) CHECK(back->pixels[3 * 4 + 2] == img->pixels[4 * 4 + 2]);
    atmos_image_destroy(back);
    atmos_image_destroy(img);
    img = make_image(3, 2, 2);
    CHECK(atmos_write_pfm(ctx, img, path) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(img);

    /* Big-endian grey file (positive scale), two rows, written by hand. */
    const unsigned char be[] = {'P', 'f', '\n', '2', ' ', '2', '\n', '1', '.', '0', '\n',
                                0x3f, 0x80, 0x00, 0x00, 0x40, 0x00, 0x00, 0x00,  /* bottom: 1, 2 */
                                0x40, 0x40, 0x00, 0x00, 0x40, 0x80, 0x00, 0x00}; /* top: 3, 4 */
    spit(path, be, sizeof be);
    CHECK_OK(atmos_read_pfm(ctx, path, &back));
    CHECK(back && back->channels == 1 && back->width == 2 && back->height == 2);
    if (back && back->channels == 1)
        CHECK(back->pixels[0] == 3.0f && back->pixels[1] == 4.0f && back->pixels[2] == 1.0f && back->pixels[3] == 2.0f);
    atmos_image_destroy(back);

    /* Malformed headers. */
    static const struct {
        const char *text;
        atmos_status want;
    } bad[] = {
        {"", ATMOS_E_FORMAT},
        {"P6\n2 2\n255\n", ATMOS_E_FORMAT},
        {"PF\n-2 2\n-1.0\n", ATMOS_E_FORMAT},
        {"PF\n2\n-1.0\n", ATMOS_E_FORMAT},
        {"PF2 2\n-1.0\n", ATMOS_E_FORMAT},
        {"PF\n0 2\n-1.0\n", ATMOS_E_FORMAT},
        {"PF\n2 2\nabc\n", ATMOS_E_FORMAT},
        {"PF\n2 2\n0.0\n", ATMOS_E_FORMAT},
        {"PF\n2 2\nnan\n", ATMOS_E_FORMAT},
        {"PF\n2 2\n-1.0", ATMOS_E_FORMAT},
        {"PF\n12345678901 2\n-1.0\n", ATMOS_E_FORMAT},
        {"PF\n2 2\n-1.0\n\x01\x02\x03", ATMOS_E_FORMAT},       /* truncated data */
        {"Pf\n1 1\n-1.0\n\x01\x02\x03\x04junk", ATMOS_E_FORMAT}, /* bytes after the data: a header's size not the data's */
        {"PF\n60000 60000\n-1.0\n", ATMOS_E_FORMAT},           /* claims 40 GB, has none */
        {"PF\n70000 2\n-1.0\n", ATMOS_E_LIMIT},
        {"Pf\n2 999999999\n-1.0\n", ATMOS_E_LIMIT},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        spit(path, bad[i].text, strlen(bad[i].text));
        back = (atmos_image *)1;
        atmos_status st = atmos_read_pfm(ctx, path, &back);
        CHECK_MSG(st == bad[i].want && back == NULL, "PFM header case %zu gave %s", i, atmos_status_string(st));
        CHECK(strstr(atmos_context_error(ctx), path) != NULL);
    }
    test_tmp_path(path, sizeof path, "does-not-exist.pfm");
    CHECK(atmos_read_pfm(ctx, path, &back) == ATMOS_E_IO);
    atmos_context_destroy(ctx);
}

/* ------------------------------------------------------- malformed files ---- */

typedef atmos_status (*reader_fn)(atmos_context *, const char *, atmos_image **);

/* Every strict prefix of a valid file must be rejected, and no byte-flipped copy
 * may crash (the sanitizer build turns any overflow into a failure). */
static void check_truncations(const char *name, const char *valid, reader_fn rd)
{
    atmos_context *ctx = new_ctx();
    size_t n = 0;
    unsigned char *buf = test_slurp(valid, &n);
    CHECK(buf && n > 0);
    if (!buf) return;
    char path[512];
    test_tmp_path(path, sizeof path, "cut.bin");
    int failures = 0, tried = 0;
    size_t stride = n > 400 ? n / 400 : 1;
    for (size_t len = 0; len < n; len += (len < 64 ? 1 : stride)) {
        spit(path, buf, len);
        atmos_image *img = NULL;
        atmos_status st = rd(ctx, path, &img);
        tried++;
        if (st != ATMOS_E_FORMAT || img != NULL) {
            failures++;
            if (failures < 5) fprintf(stderr, "%s truncated to %zu of %zu bytes: %s\n", name, len, n, atmos_status_string(st));
        }
        atmos_image_destroy(img);
    }
    CHECK_MSG(failures == 0, "%s: %d of %d truncations not rejected as malformed", name, failures, tried);

    /* Corrupted bytes: any status is acceptable as long as nothing crashes and a
     * failure hands back no image. */
    int bad = 0;
    for (int t = 0; t < 200; t++) {
        unsigned char *copy = malloc(n);
        memcpy(copy, buf, n);
        for (int k = 0; k < 4; k++) copy[(size_t)(rnd() * (double)n) % n] ^= (unsigned char)(1 + rnd() * 254);
        spit(path, copy, n);
        free(copy);
        atmos_image *img = NULL;
        atmos_status st = rd(ctx, path, &img);
        if ((st == ATMOS_OK) != (img != NULL)) bad++;
        atmos_image_destroy(img);
    }
    CHECK(bad == 0);
    free(buf);
    atmos_context_destroy(ctx);
}

static void test_malformed(void)
{
    char path[512];
    atmos_image *img = make_image(24, 40, 3);
    for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)rnd();
    atmos_image_set_meta(img, "note", "truncate me");

    test_tmp_path(path, sizeof path, "valid.exr");
    atmos_exr_desc hd = {1, NULL};
    CHECK_OK(atmos_write_exr(NULL, img, path, &hd));
    check_truncations("EXR", path, atmos_read_exr);

    test_tmp_path(path, sizeof path, "valid.png");
    CHECK_OK(atmos_write_png(NULL, img, path, 16));
    check_truncations("PNG", path, atmos_read_png);

    test_tmp_path(path, sizeof path, "valid.pfm");
    CHECK_OK(atmos_write_pfm(NULL, img, path));
    check_truncations("PFM", path, atmos_read_pfm);
    atmos_image_destroy(img);

    /* Garbage behind each format's magic, and files of another format. */
    test_tmp_path(path, sizeof path, "garbage.bin");
    unsigned char junk[3000];
    for (size_t i = 0; i < sizeof junk; i++) junk[i] = (unsigned char)(rnd() * 256);
    const unsigned char exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
    const unsigned char png_magic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    atmos_image *out = NULL;
    spit(path, junk, sizeof junk);
    CHECK(atmos_read_exr(NULL, path, &out) == ATMOS_E_FORMAT && !out);
    CHECK(atmos_read_png(NULL, path, &out) == ATMOS_E_FORMAT && !out);
    CHECK(atmos_read_pfm(NULL, path, &out) == ATMOS_E_FORMAT && !out);
    memcpy(junk, exr_magic, 4);
    spit(path, junk, sizeof junk);
    CHECK(atmos_read_exr(NULL, path, &out) == ATMOS_E_FORMAT && !out);
    memcpy(junk, png_magic, 8);
    spit(path, junk, sizeof junk);
    CHECK(atmos_read_png(NULL, path, &out) == ATMOS_E_FORMAT && !out);
    test_tmp_path(path, sizeof path, "does-not-exist.exr");
    CHECK(atmos_read_exr(NULL, path, &out) == ATMOS_E_IO);
    CHECK(atmos_read_png(NULL, path, &out) == ATMOS_E_IO);
    /* a short text file and a folder given as a PNG: said as what they are, not "truncated" or
       libpng's "Read Error" */
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_tmp_path(path, sizeof path, "text.png");
    spit(path, "hello", 5);
    CHECK(atmos_read_png(ctx, path, &out) == ATMOS_E_FORMAT && !out);
    CHECK(strstr(atmos_context_error(ctx), "not a PNG file") != NULL);
    spit(path, png_magic, 5);
    CHECK(atmos_read_png(ctx, path, &out) == ATMOS_E_FORMAT && strstr(atmos_context_error(ctx), "within PNG's signature"));
    test_tmp_path(path, sizeof path, "folder.png");
    (void)mkdir(path, 0700);
    CHECK(atmos_read_png(ctx, path, &out) == ATMOS_E_IO && strstr(atmos_context_error(ctx), "it is a folder"));
    rmdir(path);
    atmos_context_destroy(ctx);
}

/* Every file in tests/crashers/ must be rejected cleanly by the reader its
 * extension names. */
static void test_crashers(void)
{
    const char *src = getenv("ATMOS_SOURCE_DIR");
    CHECK_MSG(src && *src, "ATMOS_SOURCE_DIR is not set (run through ctest)");
    if (!src || !*src) return;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/tests/crashers", src);
    DIR *d = opendir(dir);
    CHECK_MSG(d != NULL, "cannot open %s", dir);
    if (!d) return;
    atmos_context *ctx = new_ctx();
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        const char *dot = strrchr(e->d_name, '.');
        if (!dot) continue;
        reader_fn rd = strcmp(dot, ".exr") == 0 ? atmos_read_exr
                       : strcmp(dot, ".png") == 0 ? atmos_read_png
                       : strcmp(dot, ".pfm") == 0 ? atmos_read_pfm
                                                  : NULL;
        if (!rd) continue;
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        atmos_image *img = NULL;
        atmos_status st = rd(ctx, path, &img);
        CHECK_MSG((st == ATMOS_E_FORMAT || st == ATMOS_E_LIMIT) && !img, "%s: %s", e->d_name, atmos_status_string(st));
        CHECK_MSG(strstr(atmos_context_error(ctx), e->d_name) != NULL, "%s: message lacks the path: %s", e->d_name,
                  atmos_context_error(ctx));
        atmos_image_destroy(img);
        count++;
    }
    closedir(d);
    CHECK_MSG(count >= 4, "only %d crasher files found in %s", count, dir);
    atmos_context_destroy(ctx);
}

/* ------------------------------------------------------------- tone mapping -- */

static void test_srgb(void)
{
    CHECK_NEAR(atmos_srgb_encode(0.0), 0.0, 0);
    CHECK_NEAR(atmos_srgb_encode(1.0), 1.0, 1e-12);
    /* IEC 61966-2-1: the linear segment 12.92 x meets the power segment at
     * x = 0.0031308, encoded 0.04045 (to the standard's four digits). */
    CHECK_NEAR(atmos_srgb_encode(0.0031308), 0.04045, 1e-5);
    CHECK_NEAR(atmos_srgb_encode(0.0031308 - 1e-9), atmos_srgb_encode(0.0031308 + 1e-9), 1e-7);
    CHECK_NEAR(atmos_srgb_decode(0.04045), 0.0031308, 1e-7);
    CHECK_NEAR(atmos_srgb_encode(0.001), 0.01292, 1e-12);
    CHECK_NEAR(atmos_srgb_encode(0.5), 0.735356983, 1e-8);
    CHECK_NEAR(atmos_srgb_decode(0.5), 0.214041140, 1e-8);
    double worst = 0, prev = -1;
    int monotonic = 1;
    for (int i = 0; i <= 10000; i++) {
        double x = i / 10000.0;
        double e = atmos_srgb_encode(x);
        if (e <= prev) monotonic = 0;
        prev = e;
        worst = fmax(worst, fabs(atmos_srgb_decode(e) - x));
        worst = fmax(worst, fabs(atmos_srgb_encode(atmos_srgb_decode(x)) - x));
    }
    CHECK(monotonic);
    CHECK_NEAR(worst, 0, 1e-12);
    CHECK(atmos_srgb_encode(NAN) == 0.0 && atmos_srgb_decode(NAN) == 0.0);
}

static void test_exposure(void)
{
    atmos_tonemap_desc d = {1, 15.0, ATMOS_TONE_FILMIC};
    CHECK_REL(atmos_tonemap_scale(NULL, &d), 1.0 / (1.2 * 32768.0), 1e-12);
    d.exposure_ev = 0;
    CHECK_REL(atmos_tonemap_scale(NULL, &d), 1.0 / 1.2, 1e-12);

    /* Automatic: a uniform image of luminance L is scaled to middle grey. */
    const double levels[3] = {0.5, 40.0, 20000.0};
    for (int k = 0; k < 3; k++) {
        atmos_image *img = make_image(16, 9, 3);
        for (size_t i = 0; i < npix(img); i++) img->pixels[i] = (float)levels[k];
        atmos_tonemap_desc a = {0, 0.0, ATMOS_TONE_FILMIC};
        double s = atmos_tonemap_scale(img, &a);
        CHECK_REL(s * levels[k], 0.18, 1e-3); /* the 1e-4 epsilon shifts L=0.5 by 2e-4 */
        a.exposure_ev = 1.0;
        CHECK_REL(atmos_tonemap_scale(img, &a), 2 * s, 1e-12);
        atmos_image_destroy(img);
    }
    /* Luminance weights: pure red of value R has Y = 0.2126 R. */
    atmos_image *img = make_image(4, 4, 3);
    for (size_t p = 0; p < 16; p++) img->pixels[3 * p] = 1000.0f;
    atmos_tonemap_desc a = {0, 0.0, ATMOS_TONE_FILMIC};
    CHECK_REL(atmos_tonemap_scale(img, &a) * 0.2126 * 1000.0, 0.18, 1e-6);
    /* Log average, not arithmetic: half the pixels at 100, half at 10000 -> 1000. */
    for (size_t p = 0; p < 16; p++)
        for (int c = 0; c < 3; c++) img->pixels[3 * p + (size_t)c] = p % 2 ? 100.0f : 10000.0f;
    CHECK_REL(atmos_tonemap_scale(img, &a), 0.18 / 1000.0, 1e-6);
    atmos_image_destroy(img);

    /* Alpha: transparent pixels do not count. */
    img = make_image(4, 4, 4);
    for (size_t p = 0; p < 16; p++) {
        float v = p < 4 ? 500.0f : 1e9f;
        img->pixels[4 * p] = img->pixels[4 * p + 1] = img->pixels[4 * p + 2] = v;
        img->pixels[4 * p + 3] = p < 4 ? 1.0f : 0.0f;
    }
    CHECK_REL(atmos_tonemap_scale(img, &a) * 500.0, 0.18, 1e-6);
    atmos_image_destroy(img);
}

/* A grey image of n pixels: counts[k] pixels of luminance levels[k], in that order. */
static atmos_image *levels_image(int n, const int *counts, const double *levels, int nlevels)
{
    atmos_image *img = make_image(n, 1, 3);
    int at = 0;
    for (int k = 0; k < nlevels; k++)
        for (int i = 0; i < counts[k]; i++, at++)
            for (int c = 0; c < 3; c++) img->pixels[3 * at + c] = (float)levels[k];
    return img;
}

/* Automatic exposure of a dark scene with a small bright beam and lamp (the beam renderer's
 * scenes): the black pixels do not vote for the key (a log average of mostly 1e-4 sent the
 * scale to thousands and the beam to white), and the 99th percentile, the beam, stays below
 * white (it is scaled to at most 4: 0.99 of white through the filmic curve) while the lamp's
 * 0.5 % may burn. */
static void test_exposure_dark_scene(void)
{
    atmos_tonemap_desc a = {0, 0.0, ATMOS_TONE_FILMIC};
    /* 1000 pixels: 960 black, 35 beam at 10 cd/m^2, 5 lamp at 1e5 */
    const int c1[3] = {960, 35, 5};
    const double l1[3] = {0, 10, 1e5};
    atmos_image *img = levels_image(1000, c1, l1, 3);
    const double lavg = exp((35 * log(1e-4 + 10) + 5 * log(1e-4 + 1e5)) / 40); /* over the lit pixels */
    double s = atmos_tonemap_scale(img, &a);
    CHECK_MSG(fabs(s / (0.18 / lavg) - 1) < 1e-6, "dark scene: scale %g, expected 0.18 / %g", s, lavg);
    atmos_image *out = NULL;
    CHECK_OK(atmos_tonemap(NULL, img, &a, &out));
    if (out) CHECK_MSG(out->pixels[3 * 970] > 0.05 && out->pixels[3 * 970] < 0.9, "the beam displays as %g", out->pixels[3 * 970]);
    atmos_image_destroy(out);
    atmos_image_destroy(img);
    /* a dim glow everywhere (1e-3), a beam on 9.5 % (0.2), lamps on 0.5 % (20): the glow's key
     * would scale the beam to 16 (white); the cap scales the 99th percentile to 4 */
    const int c2[3] = {900, 95, 5};
    const double l2[3] = {1e-3, 0.2, 20};
    img = levels_image(1000, c2, l2, 3);
    s = atmos_tonemap_scale(img, &a);
    CHECK_MSG(fabs(s * 0.2 / 4 - 1) < 0.02, "glow and beam: the beam scaled to %g, expected 4", s * 0.2);
    a.exposure_ev = 1;
    CHECK_REL(atmos_tonemap_scale(img, &a), 2 * s, 1e-12);
    atmos_image_destroy(img);
}

static float tm_one(atmos_tone_curve curve, float v)
{
    atmos_image *img = make_image(1, 1, 3), *out = NULL;
    img->pixels[0] = img->pixels[1] = img->pixels[2] = v;
    /* scale 1: 1.2 * 2^EV = 1 */
    atmos_tonemap_desc d = {1, -log2(1.2), curve};
    float r = NAN;
    if (atmos_tonemap(NULL, img, &d, &out) == ATMOS_OK) r = out->pixels[0];
    atmos_image_destroy(out);
    atmos_image_destroy(img);
    return r;
}

/* The tone map against the curves and the sRGB transfer function in double precision (the
 * formulas written out here): within 2e-6 (the sRGB table read linearly: 1.5e-6; its 16 385 even
 * steps were 3.3e-6) over 1e-5 .. 1e5 times the exposure's scale, every curve; atmos_tonemap_into
 * gives the same pixels as atmos_tonemap. */
static double curve_ref(atmos_tone_curve curve, double x)
{
    double y = curve == ATMOS_TONE_REINHARD ? x / (1 + x)
               : curve == ATMOS_TONE_CLAMP  ? x
                                            : x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
    return atmos_srgb_encode(y < 1 ? y : 1);
}

static void test_tonemap_precision(void)
{
    const atmos_tone_curve curves[3] = {ATMOS_TONE_FILMIC, ATMOS_TONE_REINHARD, ATMOS_TONE_CLAMP};
    const int n = 4001;
    atmos_image *img = make_image(n, 1, 4), *out = NULL, *into = make_image(n, 1, 4);
    for (int i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) img->pixels[4 * i + c] = (float)(pow(10.0, -5 + 10.0 * i / (n - 1)) * (1 + 0.37 * c));
        img->pixels[4 * i + 3] = 1.0f;
    }
    for (int k = 0; k < 3; k++) {
        atmos_tonemap_desc d = {1, 3.0, curves[k]};
        const double scale = atmos_tonemap_scale(img, &d);
        CHECK_OK(atmos_tonemap(NULL, img, &d, &out));
        CHECK_OK(atmos_tonemap_into(NULL, img, &d, into));
        double worst = 0;
        for (int i = 0; out && i < n; i++)
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(out->pixels[4 * i + c] - curve_ref(curves[k], img->pixels[4 * i + c] * scale)));
        printf("tone curve %d: largest difference from double precision %.2g\n", k, worst);
        CHECK_NEAR(worst, 0, 2e-6);
        CHECK(out && !memcmp(out->pixels, into->pixels, sizeof(float) * 4 * (size_t)n));
        atmos_image_destroy(out);
    }
    atmos_image *small = make_image(n - 1, 1, 4);
    CHECK(atmos_tonemap_into(NULL, img, NULL, small) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(small), atmos_image_destroy(into), atmos_image_destroy(img);
}

static void test_tonemap(void)
{
    const atmos_tone_curve curves[3] = {ATMOS_TONE_FILMIC, ATMOS_TONE_REINHARD, ATMOS_TONE_CLAMP};
    /* Known points of each curve (then sRGB encoded). */
    CHECK_NEAR(tm_one(ATMOS_TONE_FILMIC, 1.0f), atmos_srgb_encode(2.54 / 3.16), 1e-6);
    CHECK_NEAR(tm_one(ATMOS_TONE_REINHARD, 1.0f), atmos_srgb_encode(0.5), 1e-6);
    CHECK_NEAR(tm_one(ATMOS_TONE_REINHARD, 3.0f), atmos_srgb_encode(0.75), 1e-6);
    CHECK_NEAR(tm_one(ATMOS_TONE_CLAMP, 0.25f), atmos_srgb_encode(0.25), 1e-6);
    CHECK_NEAR(tm_one(ATMOS_TONE_CLAMP, 7.0f), 1.0, 0);
    CHECK_NEAR(tm_one(ATMOS_TONE_FILMIC, 1e6f), 1.0, 0);

    for (int k = 0; k < 3; k++) {
        /* Monotonic and in [0, 1] over a wide ramp. */
        const int n = 2000;
        atmos_image *img = make_image(n, 1, 3), *out = NULL;
        for (int i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) img->pixels[3 * i + c] = (float)(pow(10.0, -4 + 8.0 * i / n) * (1 + c));
        atmos_tonemap_desc d = {1, -log2(1.2), curves[k]};
        CHECK_OK(atmos_tonemap(NULL, img, &d, &out));
        int mono = 1, inrange = 1;
        for (int i = 0; out && i < n; i++)
            for (int c = 0; c < 3; c++) {
                float v = out->pixels[3 * i + c];
                if (!(v >= 0 && v <= 1)) inrange = 0;
                if (i && v < out->pixels[3 * (i - 1) + c]) mono = 0;
            }
        CHECK_MSG(mono && inrange, "curve %d: monotonic %d, in range %d", k, mono, inrange);
        /* Strictly increasing where the curve is not saturated. */
        if (out) CHECK(out->pixels[3 * 500] < out->pixels[3 * 1000]);
        atmos_image_destroy(out);

        /* NaN, Inf and negatives: finite output in [0, 1]; alpha copied and clamped. */
        atmos_image *bad = make_image(6, 1, 4);
        const float vals[6] = {NAN, INFINITY, -INFINITY, -5.0f, 1e38f, 0.5f};
        const float alpha[6] = {0.3f, 2.0f, NAN, -1.0f, 1.0f, 0.0f};
        for (int i = 0; i < 6; i++) {
            bad->pixels[4 * i] = bad->pixels[4 * i + 1] = bad->pixels[4 * i + 2] = vals[i];
            bad->pixels[4 * i + 3] = alpha[i];
        }
        for (int manual = 0; manual < 2; manual++) {
            atmos_tonemap_desc bd = {manual, 0.0, curves[k]};
            CHECK_OK(atmos_tonemap(NULL, bad, &bd, &out));
            int finite = 1;
            for (size_t i = 0; out && i < npix(out); i++)
                if (!(out->pixels[i] >= 0 && out->pixels[i] <= 1)) finite = 0;
            CHECK_MSG(finite, "curve %d manual %d: non-finite or out-of-range output", k, manual);
            if (out) {
                CHECK(out->pixels[0] == 0.0f);  /* NaN -> black */
                CHECK(out->pixels[4] == 1.0f);  /* +Inf -> white */
                CHECK(out->pixels[12] == 0.0f); /* negative -> black */
                CHECK_NEAR(out->pixels[3], 0.3, 1e-7);
                CHECK(out->pixels[7] == 1.0f && out->pixels[11] == 0.0f && out->pixels[15] == 0.0f);
            }
            atmos_image_destroy(out);
        }
        atmos_image_destroy(bad);
        atmos_image_destroy(img);
    }

    /* All-NaN image with automatic exposure. */
    atmos_image *img = make_image(3, 3, 3), *out = NULL;
    for (size_t i = 0; i < npix(img); i++) img->pixels[i] = NAN;
    atmos_tonemap_desc d = {0, 0.0, ATMOS_TONE_FILMIC};
    CHECK(isfinite(atmos_tonemap_scale(img, &d)));
    CHECK_OK(atmos_tonemap(NULL, img, &d, &out));
    CHECK(out && out->pixels[0] == 0.0f);
    atmos_image_destroy(out);
    /* Metadata travels with the image. */
    atmos_image_set_meta(img, "atmos:renderer", "path");
    CHECK_OK(atmos_tonemap(NULL, img, &d, &out));
    CHECK(out && atmos_image_get_meta(out, "atmos:renderer") && strcmp(atmos_image_get_meta(out, "atmos:renderer"), "path") == 0);
    atmos_image_destroy(out);
    atmos_image_destroy(img);
    img = make_image(3, 3, 2);
    atmos_context *ctx = new_ctx();
    CHECK(atmos_tonemap(ctx, img, &d, &out) == ATMOS_E_INVALID_ARG && out == NULL);
    CHECK(strlen(atmos_context_error(ctx)) > 0);
    atmos_context_destroy(ctx);
    atmos_image_destroy(img);
}

/* ------------------------------------------------------------ atomic writes -- */

static atmos_status failing_writer(atmos_context *ctx, const char *tmp, void *user)
{
    FILE *f = fopen(tmp, "wb");
    if (!f) return ATMOS_E_IO;
    fputs("partial data that must never be seen under the final name", f);
    fclose(f);
    *(int *)user = file_exists(tmp); /* the temporary really existed */
    return atmos__error(ctx, ATMOS_E_IO, "%s: simulated failure", tmp);
}

static void test_atomic_failure(void)
{
    atmos_context *ctx = new_ctx();
    char path[512], tmp[600];
    test_tmp_path(path, sizeof path, "atomic_fail.out");
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    remove(path);
    int existed = 0;
    CHECK(atmos__write_atomic(ctx, path, failing_writer, &existed) == ATMOS_E_IO);
    CHECK(existed);
    CHECK(!file_exists(path));
    CHECK(!file_exists(tmp));

    /* With an older file in place: it survives unchanged. */
    spit(path, "old", 3);
    CHECK(atmos__write_atomic(ctx, path, failing_writer, &existed) == ATMOS_E_IO);
    size_t n = 0;
    unsigned char *b = test_slurp(path, &n);
    CHECK(b && n == 3 && memcmp(b, "old", 3) == 0);
    free(b);
    CHECK(!file_exists(tmp));

    /* Writers into a directory that does not exist fail with IO and leave nothing. */
    atmos_image *img = make_image(2, 2, 3);
    test_tmp_path(path, sizeof path, "no-such-dir/x.exr");
    CHECK(atmos_write_exr(ctx, img, path, NULL) == ATMOS_E_IO);
    CHECK(atmos_write_png(ctx, img, path, 8) == ATMOS_E_IO);
    CHECK(atmos_write_pfm(ctx, img, path) == ATMOS_E_IO);
    CHECK(!file_exists(path));
    atmos_image_destroy(img);
    atmos_context_destroy(ctx);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void sleep_s(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    nanosleep(&ts, NULL);
}

#define KILL_W 4096
#define KILL_H 4096
static float kill_pattern(size_t i) { return (float)(i / 3) * 0.25f + (float)(i % 3); }

/* A child writes a large EXR to the same path over and over; the parent kills it
 * with SIGKILL while a write is in progress. Whatever is under the final name
 * must then be a complete image (or nothing, if no write ever finished). */
static void test_kill_during_write(void)
{
    char path[512], tmp[600];
    test_tmp_path(path, sizeof path, "killed.exr");
    for (int scenario = 0; scenario < 2; scenario++) {
        remove(path);
        fflush(NULL);
        pid_t pid = fork();
        if (pid < 0) {
            CHECK_MSG(0, "fork failed: %s", strerror(errno));
            return;
        }
        if (pid == 0) {
            atmos_image *img = NULL;
            if (atmos_image_create(NULL, KILL_W, KILL_H, 3, &img) != ATMOS_OK) _exit(3);
            for (size_t i = 0; i < npix(img); i++) img->pixels[i] = kill_pattern(i);
            atmos_exr_desc d = {0, NULL};
            for (;;)
                if (atmos_write_exr(NULL, img, path, &d) != ATMOS_OK) _exit(4);
        }
        snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)pid);
        double t0 = now_s();
        /* Scenario 0: kill during the first write (nothing complete yet).
         * Scenario 1: wait until a complete file exists, then kill during a later
         * write, i.e. while the temporary of the next write is growing. */
        if (scenario == 1)
            while (!file_exists(path) && now_s() - t0 < 120) sleep_s(0.005);
        int mid_write = 0;
        double t1 = now_s();
        while (now_s() - t1 < 60) {
            if (file_size(tmp) > 1 << 20) {
                mid_write = 1;
                break;
            }
            sleep_s(0.002);
        }
        kill(pid, SIGKILL);
        int status = 0;
        waitpid(pid, &status, 0);
        CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL, "writer child exited early (status %d)", status);
        CHECK_MSG(mid_write, "scenario %d: never saw a write in progress", scenario);

        if (scenario == 1) CHECK_MSG(file_exists(path), "no complete file after the first write finished");
        if (file_exists(path)) {
            atmos_image *img = NULL;
            atmos_status st = atmos_read_exr(NULL, path, &img);
            CHECK_MSG(st == ATMOS_OK, "scenario %d: file under the final name is unreadable: %s", scenario,
                      atmos_status_string(st));
            if (img) {
                CHECK(img->width == KILL_W && img->height == KILL_H && img->channels == 3);
                size_t wrong = 0;
                for (size_t i = 0; i < npix(img) && img->channels == 3; i++) wrong += img->pixels[i] != kill_pattern(i);
                CHECK_MSG(wrong == 0, "scenario %d: %zu pixels differ", scenario, wrong);
            }
            atmos_image_destroy(img);
        } else {
            CHECK(scenario == 0); /* killed before any write finished: nothing, not a fragment */
        }
        printf("kill test scenario %d: killed after %.2f s, final file %s\n", scenario, now_s() - t0,
               file_exists(path) ? "complete" : "absent");
        remove(tmp); /* a killed process leaves its temporary: expected, and never under the final name */
        remove(path);
    }
}

int main(void)
{
    test_create();
    test_exr_roundtrip();
    test_exr_meta();
    test_png();
    test_pfm();
    test_malformed();
    test_crashers();
    test_atomic_failure();
    /* Before anything that may start OpenMP threads: fork and libgomp do not mix. */
    test_kill_during_write();
    test_srgb();
    test_exposure();
    test_exposure_dark_scene();
    test_tonemap();
    test_tonemap_precision();
    return test_summary("test_image");
}
