/* The readers as `atmos compare` uses them, and its pairing of channels by name: a PFM
 * header with CRLF line ends, EXR channels beyond R,G,B,A, an unsigned-int EXR channel
 * (its values, not its bits), and pairs chosen by name whatever the order. */
#define _POSIX_C_SOURCE 200809L /* strnlen */
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    int ok = fwrite(data, 1, n, f) == n;
    return fclose(f) == 0 && ok;
}

static size_t put_le_floats(unsigned char *b, const float *v, int n)
{
    for (int i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &v[i], 4);
        for (int k = 0; k < 4; k++) b[4 * i + k] = (unsigned char)(u >> (8 * k));
    }
    return (size_t)n * 4;
}

/* A 2 x 1 RGB PFM under the given header: the pixels must read back exactly. */
static void check_pfm(const char *header, const float *v, const char *what)
{
    char path[512];
    test_tmp_path(path, sizeof path, "compare_readers.pfm");
    unsigned char buf[256];
    size_t n = strlen(header);
    memcpy(buf, header, n);
    n += put_le_floats(buf + n, v, 6);
    CHECK(write_file(path, buf, n));
    atmos_image *img = NULL;
    CHECK_OK(atmos_read_pfm(NULL, path, &img));
    if (!img) return;
    CHECK(img->width == 2 && img->height == 1 && img->channels == 3);
    for (int i = 0; i < 6; i++) CHECK_MSG(img->pixels[i] == v[i], "%s: sample %d is %g, wrote %g", what, i, img->pixels[i], v[i]);
    atmos_image_destroy(img);
}

static void pfm_line_ends(void)
{
    const float v[6] = {1, 2, 3, 4, 5, 6};
    check_pfm("PF\n2 1\n-1.0\n", v, "LF header");
    check_pfm("PF\r\n2 1\r\n-1.0\r\n", v, "CRLF header");
    /* A single '\r' ends the header and the first float's first byte is '\n' (0x0a): the
     * file's size says the data start right after the '\r'. */
    float w[6] = {0, 2, 3, 4, 5, 6};
    uint32_t u = 0x3f80000aU;
    memcpy(&w[0], &u, 4);
    check_pfm("PF\n2 1\n-1.0\r", w, "CR header, data starting with 0x0a");
}

/* R, G, B and A among other channels (stored sorted: A, B, G, R, Z): read back as R, G, B,
 * A, then the rest, with the names in that order. */
static void exr_channel_order(void)
{
    char path[512];
    test_tmp_path(path, sizeof path, "compare_readers_order.exr");
    static const char *const names[5] = {"Z", "B", "A", "R", "G"};
    atmos_image *img = NULL, *back = NULL;
    CHECK_OK(atmos_image_create(NULL, 3, 2, 5, &img));
    if (!img) return;
    for (int p = 0; p < 6; p++)
        for (int c = 0; c < 5; c++) img->pixels[p * 5 + c] = (float)(10 * c + p);
    atmos_exr_desc desc = {0, names};
    CHECK_OK(atmos_write_exr(NULL, img, path, &desc));
    char **got = NULL;
    CHECK_OK(atmos_read_exr_named(NULL, path, &back, &got));
    static const char *const want[5] = {"R", "G", "B", "A", "Z"};
    static const int from[5] = {3, 4, 1, 2, 0}; /* where each wanted name was written */
    if (back && got) {
        CHECK(back->channels == 5);
        for (int c = 0; c < 5; c++) {
            CHECK_MSG(strcmp(got[c], want[c]) == 0, "channel %d is '%s', expected '%s'", c, got[c], want[c]);
            for (int p = 0; p < 6; p++) CHECK(back->pixels[p * 5 + c] == (float)(10 * from[c] + p));
        }
    }
    free(got);
    atmos_image_destroy(back);
    atmos_image_destroy(img);
}

/* Finds the pixel type of channel `name` in an EXR header's chlist; NULL if absent. */
static unsigned char *chlist_type(unsigned char *buf, size_t n, const char *name)
{
    static const char tag[] = "channels\0chlist";
    for (size_t i = 0; i + sizeof tag + 4 < n; i++) {
        if (memcmp(buf + i, tag, sizeof tag) != 0) continue;
        unsigned char *p = buf + i + sizeof tag + 4, *end = buf + n;
        while (p < end && *p) {
            size_t len = strnlen((const char *)p, (size_t)(end - p));
            if (p + len + 17 > end) return NULL;
            if (strcmp((const char *)p, name) == 0) return p + len + 1;
            p += len + 17; /* name, NUL, type, pLinear + 3 reserved, x and y sampling */
        }
    }
    return NULL;
}

/* An unsigned-int channel: written as a FLOAT channel holding the integers' bit patterns,
 * then retyped UINT in the header (same 4 bytes per sample). It must read back as the
 * integers' values, not as those bits taken for floats (denormals near 1e-45). 16 x 2
 * pixels: the ZIP chunk must come out smaller than the raw data (a tiny chunk whose
 * compressed size equals its raw size is read back as raw by the library). */
static void exr_uint_channel(void)
{
    char path[512];
    test_tmp_path(path, sizeof path, "compare_readers_uint.exr");
    static const char *const names[1] = {"N"};
    uint32_t ints[32];
    for (int p = 0; p < 32; p++) ints[p] = p < 6 ? (uint32_t[]){0, 1, 2, 7, 1000, 16777216}[p] : (uint32_t)(p % 4);
    atmos_image *img = NULL, *back = NULL;
    CHECK_OK(atmos_image_create(NULL, 16, 2, 1, &img));
    if (!img) return;
    for (int p = 0; p < 32; p++) memcpy(&img->pixels[p], &ints[p], 4);
    atmos_exr_desc desc = {0, names};
    CHECK_OK(atmos_write_exr(NULL, img, path, &desc));
    atmos_image_destroy(img);
    FILE *f = fopen(path, "rb");
    unsigned char buf[4096];
    size_t n = f ? fread(buf, 1, sizeof buf, f) : 0;
    if (f) fclose(f);
    unsigned char *type = chlist_type(buf, n, "N");
    CHECK(type && type[0] == 2 && type[1] == 0 && type[2] == 0 && type[3] == 0); /* FLOAT */
    if (!type) return;
    type[0] = 0; /* UINT */
    CHECK(write_file(path, buf, n));
    CHECK_OK(atmos_read_exr(NULL, path, &back));
    if (back) {
        CHECK(back->channels == 1);
        for (int p = 0; p < 32; p++)
            CHECK_MSG(back->pixels[p] == (float)ints[p], "UINT sample %d reads %g, expected %u", p, back->pixels[p], ints[p]);
    }
    atmos_image_destroy(back);
}

static void check_pairs(const char *const *a, int na, const char *const *r, int nr, int count, const int *ia,
                        const int *ir)
{
    atmos_channel_match m;
    atmos_status st = atmos_image_match_channels(NULL, a, na, r, nr, &m);
    if (count == 0) {
        CHECK_MSG(st == ATMOS_E_INVALID_ARG, "%s.. vs %s..: expected no pairing, got status %d", a[0], r[0], (int)st);
        return;
    }
    CHECK_OK(st);
    CHECK_MSG(m.count == count, "%s.. vs %s..: %d pairs, expected %d", a[0], r[0], m.count, count);
    for (int c = 0; c < count && c < m.count; c++) CHECK(m.image[c] == ia[c] && m.reference[c] == ir[c]);
}

static void pairing(void)
{
    static const char *const rgba[4] = {"R", "G", "B", "A"}, *const bgr[3] = {"B", "G", "R"},
                             *const y[1] = {"Y"}, *const c0[1] = {"C0"}, *const c3[3] = {"C0", "C1", "C2"},
                             *const xy[2] = {"x", "y"}, *const yx[2] = {"y", "x"}, *const xz[2] = {"x", "z"};
    check_pairs(rgba, 4, bgr, 3, 3, (const int[]){0, 1, 2}, (const int[]){2, 1, 0});
    check_pairs(y, 1, c0, 1, 1, (const int[]){0}, (const int[]){0});
    check_pairs(xy, 2, yx, 2, 2, (const int[]){0, 1}, (const int[]){1, 0});
    check_pairs(rgba, 4, c3, 3, 0, NULL, NULL);
    check_pairs(xy, 2, xz, 2, 0, NULL, NULL);
    check_pairs(rgba, 4, y, 1, 0, NULL, NULL);
    /* One layer's colour pairs with plain R,G,B; two layers' colour is ambiguous. */
    static const char *const layer[5] = {"view.A", "view.B", "view.G", "view.R", "depth.Z"},
                             *const two[6] = {"a.B", "a.G", "a.R", "b.B", "b.G", "b.R"};
    check_pairs(layer, 5, bgr, 3, 3, (const int[]){3, 2, 1}, (const int[]){2, 1, 0});
    check_pairs(two, 6, bgr, 3, 0, NULL, NULL);
    /* Compared through the pairing, an image and the same pixels in B,G,R order agree. */
    atmos_image *a = NULL, *b = NULL;
    CHECK_OK(atmos_image_create(NULL, 4, 4, 4, &a));
    CHECK_OK(atmos_image_create(NULL, 4, 4, 3, &b));
    if (!a || !b) return;
    for (int p = 0; p < 16; p++)
        for (int c = 0; c < 3; c++) a->pixels[p * 4 + c] = b->pixels[p * 3 + 2 - c] = (float)(p + 100 * c);
    atmos_channel_match m;
    atmos_image_diff d;
    CHECK_OK(atmos_image_match_channels(NULL, rgba, 4, bgr, 3, &m));
    CHECK_OK(atmos_image_compare_matched(NULL, a, b, &m, &d, NULL));
    CHECK(d.channels == 3 && d.rmse_all == 0 && d.nonfinite == 0);
    atmos_image_destroy(a);
    atmos_image_destroy(b);
}

int main(void)
{
    pfm_line_ends();
    exr_channel_order();
    exr_uint_channel();
    pairing();
    return test_summary("test_compare_readers");
}
