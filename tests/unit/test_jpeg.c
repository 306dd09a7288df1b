/* JPEG reader: tiny fixtures written here with libjpeg itself (quality 100, no chroma
 * subsampling, uniform 8x8 blocks, which the DCT carries exactly up to rounding) read
 * back; the reduced decode's size; damaged files (truncated, garbage, missing) fail with
 * an error and no image. */
#include "atmos/atmos.h"
#include "test.h"

#include <stdio.h>
#include <jpeglib.h>

/* Writes a w x h JPEG whose pixel (x, y) channel c is value(x, y, c). */
static int write_jpeg(const char *path, int w, int h, int nc, int (*value)(int x, int y, int c))
{
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    struct jpeg_compress_struct c;
    struct jpeg_error_mgr e;
    c.err = jpeg_std_error(&e);
    jpeg_create_compress(&c);
    jpeg_stdio_dest(&c, f);
    c.image_width = (JDIMENSION)w;
    c.image_height = (JDIMENSION)h;
    c.input_components = nc;
    c.in_color_space = nc == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 100, TRUE);
    for (int i = 0; i < c.num_components; i++) c.comp_info[i].h_samp_factor = c.comp_info[i].v_samp_factor = 1;
    jpeg_start_compress(&c, TRUE);
    unsigned char row[256 * 3];
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++)
            for (int k = 0; k < nc; k++) row[(x * nc) + k] = (unsigned char)value(x, y, k);
        JSAMPROW rp = row;
        jpeg_write_scanlines(&c, &rp, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    fclose(f);
    return 1;
}

static int halves(int x, int y, int c) { (void)y, (void)c; return x < 8 ? 40 : 200; }
static int quadrants(int x, int y, int c)
{
    static const int col[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {128, 128, 128}};
    return col[(y >= 8) * 2 + (x >= 8)][c];
}

static void test_grey_and_rgb(void)
{
    char path[512];
    test_tmp_path(path, sizeof path, "grey.jpg");
    CHECK(write_jpeg(path, 16, 8, 1, halves));
    atmos_image *img = NULL;
    CHECK_OK(atmos_read_jpeg(NULL, path, &img));
    if (img) {
        CHECK(img->width == 16 && img->height == 8 && img->channels == 1);
        CHECK_NEAR(img->pixels[0] * 255.0, 40.0, 1.0);
        CHECK_NEAR(img->pixels[15] * 255.0, 200.0, 1.0);
        CHECK_NEAR(img->pixels[7 * 16 + 3] * 255.0, 40.0, 1.0);
        atmos_image_destroy(img);
    }
    test_tmp_path(path, sizeof path, "rgb.jpg");
    CHECK(write_jpeg(path, 16, 16, 3, quadrants));
    CHECK_OK(atmos_read_jpeg(NULL, path, &img));
    if (img) {
        CHECK(img->width == 16 && img->height == 16 && img->channels == 3);
        const int px[4][2] = {{2, 2}, {13, 3}, {4, 12}, {12, 12}};
        for (int q = 0; q < 4; q++)
            for (int c = 0; c < 3; c++)
                CHECK_NEAR(img->pixels[(px[q][1] * 16 + px[q][0]) * 3 + c] * 255.0, quadrants(px[q][0], px[q][1], c),
                           3.0);
        atmos_image_destroy(img);
    }
    /* at half size: 8 x 8, the quadrants 4 x 4 */
    CHECK_OK(atmos_read_jpeg_scaled(NULL, path, 2, &img));
    if (img) {
        CHECK(img->width == 8 && img->height == 8);
        CHECK_NEAR(img->pixels[(1 * 8 + 6) * 3 + 1] * 255.0, 255.0, 3.0);
        atmos_image_destroy(img);
    }
    CHECK(atmos_read_jpeg_scaled(NULL, path, 3, &img) == ATMOS_E_INVALID_ARG && !img);
}

static void test_damaged(void)
{
    char path[512], cut[512];
    test_tmp_path(path, sizeof path, "whole.jpg");
    test_tmp_path(cut, sizeof cut, "cut.jpg");
    CHECK(write_jpeg(path, 64, 64, 3, quadrants));
    size_t n = 0;
    unsigned char *bytes = test_slurp(path, &n);
    CHECK(bytes && n > 100);
    atmos_image *img = NULL;
    /* cut at several places: inside the headers and inside the entropy-coded data */
    const size_t cuts[] = {2, 20, n / 3, n / 2, n - 8};
    for (size_t i = 0; bytes && i < sizeof cuts / sizeof cuts[0]; i++) {
        FILE *f = fopen(cut, "wb");
        fwrite(bytes, 1, cuts[i], f);
        fclose(f);
        atmos_status st = atmos_read_jpeg(NULL, cut, &img);
        CHECK_MSG(st == ATMOS_E_FORMAT && img == NULL, "cut at %zu of %zu: %s", cuts[i], n, atmos_status_string(st));
        atmos_image_destroy(img);
        img = NULL;
    }
    /* not a JPEG at all */
    FILE *f = fopen(cut, "wb");
    fputs("this is not a JPEG file, just some text of reasonable length\n", f);
    fclose(f);
    CHECK(atmos_read_jpeg(NULL, cut, &img) == ATMOS_E_FORMAT && !img);
    CHECK(atmos_read_jpeg(NULL, "no/such/file.jpg", &img) == ATMOS_E_IO && !img);
    free(bytes);
}

int main(void)
{
    test_grey_and_rgb();
    test_damaged();
    return test_summary("test_jpeg");
}
