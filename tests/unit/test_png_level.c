/* atmos_write_png_level (src/image/png.c): the same pixels read back (atmos_read_png) at zlib's
 * levels 0, 1, 9 and libpng's default as written by atmos_write_png, the fast level's file not
 * smaller than the best level's; a level outside -1..9 refused with no file written. */
#include "test.h"

#include "atmos/atmos.h"

#include <stdio.h>

int main(void)
{
    const int W = 61, H = 37;
    atmos_image *img = NULL;
    CHECK_OK(atmos_image_create(NULL, W, H, 4, &img));
    if (!img) return test_summary("test_png_level");
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 4; c++)
                img->pixels[((size_t)y * W + x) * 4 + c] = (float)(((x * 7 + y * 13 + c * 29) % 256) / 255.0);
    char ref_path[256], path[256];
    test_tmp_path(ref_path, sizeof ref_path, "png_level_ref.png");
    CHECK_OK(atmos_write_png(NULL, img, ref_path, 8));
    atmos_image *ref = NULL;
    CHECK_OK(atmos_read_png(NULL, ref_path, &ref));
    static const int levels[] = {-1, 0, 1, 9};
    long size[4] = {0};
    for (int q = 0; q < 4 && ref; q++) {
        test_tmp_path(path, sizeof path, "png_level.png");
        CHECK_OK(atmos_write_png_level(NULL, img, path, 8, levels[q]));
        atmos_image *back = NULL;
        CHECK_OK(atmos_read_png(NULL, path, &back));
        CHECK(back && back->width == W && back->height == H && back->channels == 4 &&
              !memcmp(back->pixels, ref->pixels, sizeof(float) * (size_t)W * H * 4));
        FILE *f = fopen(path, "rb");
        if (f) fseek(f, 0, SEEK_END), size[q] = ftell(f), fclose(f);
        atmos_image_destroy(back);
        remove(path);
    }
    CHECK_MSG(size[2] >= size[3] && size[1] > size[2], "sizes: level 0 %ld, 1 %ld, 9 %ld", size[1], size[2], size[3]);
    test_tmp_path(path, sizeof path, "png_level_bad.png");
    CHECK(atmos_write_png_level(NULL, img, path, 8, 10) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_write_png_level(NULL, img, path, 8, -2) == ATMOS_E_INVALID_ARG);
    FILE *f = fopen(path, "rb");
    CHECK(!f);
    if (f) fclose(f);
    remove(ref_path);
    atmos_image_destroy(ref), atmos_image_destroy(img);
    return test_summary("test_png_level");
}
