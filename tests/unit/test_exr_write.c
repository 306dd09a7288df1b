/* The OpenEXR writer's header and values, read back with the OpenEXR library itself:
 * channel names given by the caller (also for 3 or 4 channels), half floats that do not
 * overflow to infinity (clamped to 65504 with a warning), the standard chromaticities
 * attribute, and numeric metadata stored as int and double attributes. */
#include "atmos/atmos.h"
#include "test.h"

#include <openexr.h>
#include <stdint.h>
#include <string.h>

static int warnings;
static char last_warning[512];

static void count_log(void *user, atmos_log_level level, const char *msg)
{
    (void)user;
    if (level != ATMOS_LOG_WARN) return;
    warnings++;
    snprintf(last_warning, sizeof last_warning, "%s", msg);
}

static atmos_context *new_ctx(void)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.log = count_log;
    d.log_level = ATMOS_LOG_WARN;
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) exit(2);
    return ctx;
}

static atmos_image *ramp(atmos_context *ctx, int w, int h, int nc)
{
    atmos_image *img = NULL;
    if (atmos_image_create(ctx, w, h, nc, &img) != ATMOS_OK) exit(2);
    for (size_t i = 0; i < (size_t)w * h * nc; i++) img->pixels[i] = 0.25f * (float)(i % 17);
    return img;
}

/* 1 if the file at path has the "chromaticities" attribute. */
static int has_chromaticities(const char *path)
{
    exr_context_t ex = NULL;
    const exr_attribute_t *a = NULL;
    if (exr_start_read(&ex, path, NULL) != EXR_ERR_SUCCESS) return -1;
    const int has = exr_get_attribute_by_name(ex, 0, "chromaticities", &a) == EXR_ERR_SUCCESS;
    exr_finish(&ex);
    return has;
}

/* Names given for a 4-channel image are the file's channels (sorted by OpenEXR); the
 * chromaticities (of R, G and B) only on a file that has R, G and B, plain or in a layer. */
static void test_names(atmos_context *ctx, const char *path)
{
    atmos_image *img = ramp(ctx, 6, 5, 4), *back = NULL;
    static const char *const names[4] = {"variance.680nm", "variance.550nm", "variance.386,25nm", "variance.Y"};
    atmos_exr_desc d = {0, names};
    CHECK_OK(atmos_write_exr(ctx, img, path, &d));
    exr_context_t ex = NULL;
    const exr_attr_chlist_t *cl = NULL;
    CHECK(exr_start_read(&ex, path, NULL) == EXR_ERR_SUCCESS && exr_get_channels(ex, 0, &cl) == EXR_ERR_SUCCESS);
    char got[256] = "";
    for (int i = 0; cl && i < cl->num_channels; i++)
        snprintf(got + strlen(got), sizeof got - strlen(got), "%s%s", i ? "," : "", cl->entries[i].name.str);
    CHECK_MSG(strcmp(got, "variance.386,25nm,variance.550nm,variance.680nm,variance.Y") == 0, "channels %s", got);
    exr_finish(&ex);
    CHECK_MSG(has_chromaticities(path) == 0, "a file without R, G, B has chromaticities");
    static const char *const layered[4] = {"beauty.B", "beauty.G", "beauty.R", "beauty.A"};
    d.channel_names = layered;
    CHECK_OK(atmos_write_exr(ctx, img, path, &d));
    CHECK_MSG(has_chromaticities(path) == 1, "one layer's R, G, B without chromaticities");
    /* RGBA images without names keep R,G,B,A */
    CHECK_OK(atmos_write_exr(ctx, img, path, NULL));
    CHECK(exr_start_read(&ex, path, NULL) == EXR_ERR_SUCCESS && exr_get_channels(ex, 0, &cl) == EXR_ERR_SUCCESS);
    CHECK(cl && cl->num_channels == 4 && !strcmp(cl->entries[0].name.str, "A") && !strcmp(cl->entries[3].name.str, "R"));
    exr_finish(&ex);
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    CHECK(back && !memcmp(back->pixels, img->pixels, sizeof(float) * 6 * 5 * 4));
    atmos_image_destroy(back);
    atmos_image_destroy(img);
}

/* Half floats: 1e9 (a sun's disc in cd/m^2) and -7e4 clamp to +-65504 with one warning
 * that counts them; values a half holds, infinities and NaN are stored as they are. */
static void test_half(atmos_context *ctx, const char *path)
{
    atmos_image *img = ramp(ctx, 4, 3, 3), *back = NULL;
    img->pixels[0] = 1e9f, img->pixels[4] = -7e4f, img->pixels[5] = 65504.0f, img->pixels[7] = INFINITY;
    img->pixels[8] = NAN;
    atmos_exr_desc d = {1, NULL};
    warnings = 0;
    CHECK_OK(atmos_write_exr(ctx, img, path, &d));
    CHECK_MSG(warnings == 1 && strstr(last_warning, "2 samples") && strstr(last_warning, "65504"), "%d warnings: %s",
              warnings, last_warning);
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    CHECK(back && back->pixels[0] == 65504.0f && back->pixels[4] == -65504.0f && back->pixels[5] == 65504.0f);
    CHECK(back && isinf(back->pixels[7]) && isnan(back->pixels[8]) && back->pixels[1] == img->pixels[1]);
    CHECK(img->pixels[0] == 1e9f); /* the caller's image is left alone */
    atmos_image_destroy(back);
    back = NULL;
    /* nothing out of range: no warning */
    img->pixels[0] = img->pixels[4] = 1.0f, img->pixels[7] = img->pixels[8] = 2.0f;
    warnings = 0;
    CHECK_OK(atmos_write_exr(ctx, img, path, &d));
    CHECK(warnings == 0);
    atmos_image_destroy(img);
}

/* The header: chromaticities of linear sRGB; numbers as int / double attributes, text
 * as strings; read back by atmos_read_exr as the same text. */
static void test_header(atmos_context *ctx, const char *path)
{
    atmos_image *img = ramp(ctx, 3, 2, 4), *back = NULL;
    atmos_image_set_meta(img, "atmos:threads", "2");
    atmos_image_set_meta(img, "atmos:sun_elevation_deg", "22.500000");
    atmos_image_set_meta(img, "atmos:error", "0.0811739");
    atmos_image_set_meta(img, "atmos:scene", "default");
    atmos_image_set_meta(img, "atmos:version", "0.1.0");
    atmos_image_set_meta(img, "atmos:code", "007");
    CHECK_OK(atmos_write_exr(ctx, img, path, NULL));
    exr_context_t ex = NULL;
    CHECK(exr_start_read(&ex, path, NULL) == EXR_ERR_SUCCESS);
    exr_attr_chromaticities_t c = {0};
    CHECK(exr_attr_get_chromaticities(ex, 0, "chromaticities", &c) == EXR_ERR_SUCCESS);
    CHECK(c.red_x == 0.64f && c.red_y == 0.33f && c.green_x == 0.30f && c.green_y == 0.60f && c.blue_x == 0.15f &&
          c.blue_y == 0.06f && c.white_x == 0.3127f && c.white_y == 0.3290f);
    int32_t iv = 0;
    double dv = 0;
    CHECK(exr_attr_get_int(ex, 0, "atmos:threads", &iv) == EXR_ERR_SUCCESS && iv == 2);
    CHECK(exr_attr_get_double(ex, 0, "atmos:sun_elevation_deg", &dv) == EXR_ERR_SUCCESS && dv == 22.5);
    CHECK(exr_attr_get_double(ex, 0, "atmos:error", &dv) == EXR_ERR_SUCCESS && dv == 0.0811739);
    const exr_attribute_t *a = NULL;
    const char *strings[3] = {"atmos:scene", "atmos:version", "atmos:code"};
    for (int i = 0; i < 3; i++)
        CHECK_MSG(exr_get_attribute_by_name(ex, 0, strings[i], &a) == EXR_ERR_SUCCESS && a->type == EXR_ATTR_STRING,
                  "%s is not a string", strings[i]);
    exr_finish(&ex);
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    const char *v;
    CHECK(back && (v = atmos_image_get_meta(back, "atmos:threads")) && !strcmp(v, "2"));
    CHECK(back && (v = atmos_image_get_meta(back, "atmos:sun_elevation_deg")) && !strcmp(v, "22.5"));
    CHECK(back && (v = atmos_image_get_meta(back, "atmos:error")) && !strcmp(v, "0.0811739"));
    CHECK(back && (v = atmos_image_get_meta(back, "atmos:code")) && !strcmp(v, "007"));
    atmos_image_destroy(back);
    atmos_image_destroy(img);
}

/* A chunk whose ZIP data come out exactly as long as the raw data is read back right: a
 * reader takes a chunk of the raw size as stored raw (a 3x2 one-channel image of these bit
 * patterns compresses to exactly its 24 bytes). */
static void test_raw_sized_chunk(atmos_context *ctx, const char *path)
{
    static const uint32_t bits[6] = {0, 1, 2, 7, 1000, 16777216};
    atmos_image *img = NULL, *back = NULL;
    if (atmos_image_create(ctx, 3, 2, 1, &img) != ATMOS_OK) exit(2);
    memcpy(img->pixels, bits, sizeof bits);
    static const char *const names[1] = {"Y"};
    atmos_exr_desc d = {0, names};
    CHECK_OK(atmos_write_exr(ctx, img, path, &d));
    CHECK_OK(atmos_read_exr(ctx, path, &back));
    int wrong = 0;
    for (int i = 0; back && i < 6; i++) wrong += memcmp(&back->pixels[i], &bits[i], 4) != 0;
    CHECK_MSG(back && !wrong, "%d of 6 values of a raw-sized chunk read back wrong", wrong);
    atmos_image_destroy(img), atmos_image_destroy(back);
}

int main(void)
{
    atmos_context *ctx = new_ctx();
    char path[512];
    test_tmp_path(path, sizeof path, "exr_write.exr");
    test_names(ctx, path);
    test_half(ctx, path);
    test_header(ctx, path);
    test_raw_sized_chunk(ctx, path);
    remove(path);
    atmos_context_destroy(ctx);
    return test_summary("test_exr_write");
}
