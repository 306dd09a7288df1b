/* atmos_image_kind, atmos_image_file_kind (src/image/image_kind.c): an image's format by its
 * first bytes, the magic numbers of the formats' own definitions (OpenEXR's 76 2F 31 01, PNG's
 * 8-byte signature, JPEG's SOI and a marker FF D8 FF, PFM's "PF"/"Pf" and a whitespace byte),
 * every header the PFM reader takes ("PF\r\n" and "PF " too), short or foreign bytes refused;
 * and the files the library's own writers write named by their format. */
#include "test.h"

#include "atmos/atmos.h"

#include <string.h>

static const char *kind(const char *bytes, size_t n) { return atmos_image_kind(bytes, n); }

static int is(const char *got, const char *want)
{
    return want ? got && !strcmp(got, want) : got == NULL;
}

int main(void)
{
    static const struct {
        const char *b;
        size_t n;
        const char *want;
    } cases[] = {
        {"\x76\x2f\x31\x01\x02\0\0\0", 8, "OpenEXR"},
        {"\x76\x2f\x31\x01", 4, "OpenEXR"},
        {"\x76\x2f\x31", 3, NULL},
        {"\x89PNG\r\n\x1a\n", 8, "PNG"},
        {"\x89PNG\r\n\x1a", 7, NULL},   /* a cut signature */
        {"\x89PNG\n\n\x1a\n", 8, NULL}, /* a signature mangled by a text-mode copy */
        {"\xff\xd8\xff\xe0\0\x10JF", 8, "JPEG"},
        {"\xff\xd8\xff", 3, "JPEG"},
        {"\xff\xd8", 2, NULL},
        {"PF\n4 2\n", 7, "PFM"},
        {"Pf\n4 2\n", 7, "PFM"},
        {"PF\r\n4 2", 7, "PFM"},
        {"PF 4 2 -1", 9, "PFM"},
        {"Pf\t4", 4, "PFM"},
        {"PF4 2\n", 6, NULL}, /* no whitespace after the magic: the reader refuses it */
        {"PF", 2, NULL},
        {"P6\n4 2\n", 7, NULL}, /* a PPM */
        {"pf\n4 2\n", 7, NULL},
        {"{\"camera\"", 9, NULL}, /* a scene */
        {"", 0, NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *got = kind(cases[i].b, cases[i].n);
        CHECK_MSG(is(got, cases[i].want), "case %zu: %s, expected %s", i, got ? got : "NULL",
                  cases[i].want ? cases[i].want : "NULL");
    }
    CHECK(atmos_image_kind(NULL, 8) == NULL);
    CHECK(atmos_image_file_kind(NULL) == NULL);

    /* the library's writers' files */
    char path[4096];
    atmos_image *img = NULL;
    CHECK(atmos_image_create(NULL, 4, 2, 3, &img) == ATMOS_OK);
    if (img) {
        for (int i = 0; i < 4 * 2 * 3; i++) img->pixels[i] = 0.1f * (float)i;
        test_tmp_path(path, sizeof path, "k.exr");
        CHECK(atmos_write_exr(NULL, img, path, NULL) == ATMOS_OK && is(atmos_image_file_kind(path), "OpenEXR"));
        test_tmp_path(path, sizeof path, "k.pfm");
        CHECK(atmos_write_pfm(NULL, img, path) == ATMOS_OK && is(atmos_image_file_kind(path), "PFM"));
        for (int i = 0; i < 4 * 2 * 3; i++) img->pixels[i] = 0.04f * (float)i;
        test_tmp_path(path, sizeof path, "k.png");
        CHECK(atmos_write_png(NULL, img, path, 8) == ATMOS_OK && is(atmos_image_file_kind(path), "PNG"));
        test_tmp_path(path, sizeof path, "missing.png");
        CHECK(atmos_image_file_kind(path) == NULL);
    }
    atmos_image_destroy(img);
    return test_summary("test_image_kind");
}
