/* atmos_image_display_into (src/image/display.c): the viewer's one-pass display path against
 * the three library calls it replaces, run one after the other (atmos_image_to_srgb_into,
 * atmos_image_gamut_map, atmos_tonemap_into): the same display values to the bit, for RGB and
 * spectral images with out-of-gamut colours, negatives, NaN, infinities and the sun's
 * radiance, on one thread and on three; its 8-bit RGBA equal to what atmos_write_png writes of
 * those values (read back with atmos_read_png), the bytes alone (from the curve's table) equal to
 * them over every 5th float of the table's range; atmos_image_display_checked refusing a frame with
 * a NaN or an infinity, naming the first. */
#include "test.h"

#include "atmos/atmos.h"

#include <stdint.h>

/* A repeatable spread of radiances: mostly sky-like, some far out of range or invalid. */
static float value(uint32_t *s, int k)
{
    *s = *s * 1664525u + 1013904223u;
    const double u = (*s >> 8) / 16777216.0;
    switch (k % 23) {
    case 0: return -0.2f * (float)u;         /* negative: out of the gamut */
    case 5: return (float)(1e9 * u);          /* the sun's disk */
    case 11: return k % 2 ? NAN : INFINITY;
    default: return (float)(0.05 * u * u * (1 + k % 7));
    }
}

static void check(atmos_context *ctx, const atmos_wavelengths *wl, int W, int H, atmos_tone_curve curve, double ev)
{
    const int C = wl->count + 1;
    atmos_image *img = NULL, *lin = NULL, *ref = NULL, *disp = NULL;
    CHECK_OK(atmos_image_create(NULL, W, H, C, &img));
    CHECK_OK(atmos_image_create(NULL, W, H, 4, &lin));
    CHECK_OK(atmos_image_create(NULL, W, H, 4, &ref));
    CHECK_OK(atmos_image_create(NULL, W, H, 4, &disp));
    unsigned char *bytes = malloc((size_t)W * H * 4);
    if (!img || !lin || !ref || !disp || !bytes) return;
    uint32_t seed = 12345u + (uint32_t)wl->count;
    for (size_t i = 0; i < (size_t)W * H * C; i++) img->pixels[i] = (i % C == (size_t)C - 1) ? 0.75f : value(&seed, (int)i);
    atmos_tonemap_desc td = {1, ev, curve};
    CHECK_OK(atmos_image_to_srgb_into(NULL, img, wl, lin));
    CHECK_OK(atmos_image_gamut_map(NULL, lin, NULL));
    CHECK_OK(atmos_tonemap_into(NULL, lin, &td, ref));
    CHECK_OK(atmos_image_display_into(ctx, img, wl, &td, disp, bytes));
    size_t diff = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; i++) diff += memcmp(&disp->pixels[i], &ref->pixels[i], sizeof(float)) != 0;
    CHECK_MSG(diff == 0, "%zu of %d display values differ from the three calls' (%d wavelengths, curve %d)", diff,
              W * H * 4, wl->count, (int)curve);
    /* the bytes: atmos_write_png's rounding of the display values, alpha 255 */
    char path[256];
    test_tmp_path(path, sizeof path, "display.png");
    CHECK_OK(atmos_write_png(NULL, ref, path, 8));
    atmos_image *png = NULL;
    CHECK_OK(atmos_read_png(NULL, path, &png));
    size_t bad = 0;
    for (size_t p = 0; png && p < (size_t)W * H; p++)
        for (int c = 0; c < 4; c++) {
            const int want = c < 3 ? (int)lrintf(png->pixels[p * png->channels + c] * 255.0f) : 255;
            bad += bytes[4 * p + c] != want;
        }
    CHECK_MSG(bad == 0, "%zu bytes differ from the PNG's", bad);
    /* into display values not 16-byte aligned (a caller's buffer one float in; the rows are
     * streamed past the cache only where aligned): the same values */
    float *raw = malloc(sizeof(float) * ((size_t)W * H * 4 + 1));
    atmos_image odd = {W, H, 4, raw ? raw + 1 : NULL, 0, NULL};
    if (raw) {
        CHECK_OK(atmos_image_display_into(ctx, img, wl, &td, &odd, NULL));
        CHECK(memcmp(odd.pixels, ref->pixels, sizeof(float) * (size_t)W * H * 4) == 0);
    }
    free(raw);
    /* only the bytes: the same bytes */
    unsigned char *again = malloc((size_t)W * H * 4);
    CHECK_OK(atmos_image_display_into(ctx, img, wl, &td, NULL, again));
    CHECK(again && memcmp(again, bytes, (size_t)W * H * 4) == 0);
    remove(path);
    free(again), free(bytes);
    atmos_image_destroy(png), atmos_image_destroy(img), atmos_image_destroy(lin), atmos_image_destroy(ref);
    atmos_image_destroy(disp);
}

/* atmos_image_display_checked: a finite frame's values and bytes as atmos_image_display_into's;
 * a frame with a NaN in alpha and an infinity in a radiance refused, the count and the first
 * pixel named (the least of the rows', on any thread count), where atmos_image_display_into takes
 * it. */
static void check_refusal(atmos_context *ctx, const atmos_wavelengths *wl, int W, int H)
{
    const int C = wl->count + 1;
    atmos_image *img = NULL, *a = NULL, *b = NULL;
    CHECK_OK(atmos_image_create(NULL, W, H, C, &img));
    CHECK_OK(atmos_image_create(NULL, W, H, 4, &a));
    CHECK_OK(atmos_image_create(NULL, W, H, 4, &b));
    unsigned char *ba = malloc((size_t)W * H * 4), *bb = malloc((size_t)W * H * 4);
    if (!img || !a || !b || !ba || !bb) return;
    for (size_t i = 0; i < (size_t)W * H * C; i++) img->pixels[i] = (i % C == (size_t)C - 1) ? 1.0f : 0.01f * (float)(i % 97);
    atmos_tonemap_desc td = {1, 3.0, ATMOS_TONE_FILMIC};
    CHECK_OK(atmos_image_display_into(ctx, img, wl, &td, a, ba));
    CHECK_OK(atmos_image_display_checked(ctx, img, wl, &td, b, bb));
    CHECK(memcmp(a->pixels, b->pixels, sizeof(float) * (size_t)W * H * 4) == 0);
    CHECK(memcmp(ba, bb, (size_t)W * H * 4) == 0);
    /* alpha NaN at (W - 2, H - 1), a radiance infinite at (W - 3, H / 2), the first */
    img->pixels[((size_t)(H - 1) * W + W - 2) * C + C - 1] = NAN;
    img->pixels[((size_t)(H / 2) * W + W - 3) * C + 1] = -INFINITY;
    CHECK_OK(atmos_image_display_into(ctx, img, wl, &td, a, ba));
    CHECK(atmos_image_display_checked(ctx, img, wl, &td, b, bb) == ATMOS_E_UNSUPPORTED);
    char want[160];
    snprintf(want, sizeof want, "2 of %d pixel values are NaN or infinite (the first at pixel %d, %d)", W * H * C, W - 3,
             H / 2);
    const char *msg = atmos_context_error(ctx);
    CHECK_MSG(msg && strstr(msg, want), "the refusal says \"%s\", not \"%s\"", msg ? msg : "", want);
    atmos_context_clear_error(ctx);
    free(ba), free(bb);
    atmos_image_destroy(img), atmos_image_destroy(a), atmos_image_destroy(b);
}

/* The bytes alone (atmos_image_display_into without display values: the curve's table over the
 * scaled value, tonemap_bytes.c) against the bytes made with the display values (the curve and
 * the sRGB table, then rounded): every 5th float from 2^-17 to 2^11 (the table's 2^-16..2^10 and
 * an octave either side) through each curve, the same bytes; every float of it with
 * ATMOS_TEST_EXHAUSTIVE=1 (6.4 s of CPU against 1.1 s). */
static void check_dense_bytes(atmos_context *ctx, const atmos_wavelengths *rgb, atmos_tone_curve curve)
{
    enum { W = 1024, H = 512 };
    atmos_image *img = NULL, *disp = NULL;
    CHECK_OK(atmos_image_create(NULL, W, H, 4, &img));
    CHECK_OK(atmos_image_create(NULL, W, H, 4, &disp));
    unsigned char *a = malloc((size_t)W * H * 4), *b = malloc((size_t)W * H * 4);
    if (!img || !disp || !a || !b) {
        free(a), free(b);
        atmos_image_destroy(img), atmos_image_destroy(disp);
        return;
    }
    const atmos_tonemap_desc td = {1, 0.0, curve};
    const uint32_t first = (127u - 17u) << 23, last = (127u + 11u) << 23;
    const char *all = getenv("ATMOS_TEST_EXHAUSTIVE");
    const uint32_t stride = all && all[0] == '1' ? 1 : 5;
    size_t bad = 0, seen = 0;
    for (uint32_t u = first; u < last;) {
        for (size_t i = 0; i < (size_t)W * H * 4; i++) {
            if (i % 4 == 3) {
                img->pixels[i] = 1.0f;
                continue;
            }
            memcpy(&img->pixels[i], &u, sizeof u);
            u = u < last ? u + stride : u;
        }
        CHECK_OK(atmos_image_display_into(ctx, img, rgb, &td, disp, a));
        CHECK_OK(atmos_image_display_into(ctx, img, rgb, &td, NULL, b));
        for (size_t i = 0; i < (size_t)W * H * 4; i++) bad += a[i] != b[i];
        seen += (size_t)W * H * 3;
    }
    CHECK_MSG(bad == 0, "curve %d: %zu of %zu bytes from the table differ from the display values' bytes", (int)curve, bad,
              seen);
    free(a), free(b);
    atmos_image_destroy(img), atmos_image_destroy(disp);
}

int main(void)
{
    atmos_context *one = NULL, *three = NULL;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 1;
    CHECK_OK(atmos_context_create(&d, &one));
    d.threads = 3;
    CHECK_OK(atmos_context_create(&d, &three));
    atmos_wavelengths rgb, spec, three_bands;
    atmos_wavelengths_rgb(&rgb);
    CHECK_OK(atmos_wavelengths_spectral(8, &spec));
    /* three bands with alpha, as the viewer's RGB frames (their vectorised path), but with a full
     * matrix to sRGB (RGB's is the identity): the sums' order shows in the bits */
    CHECK_OK(atmos_wavelengths_spectral(3, &three_bands));
    check(one, &rgb, 97, 31, ATMOS_TONE_FILMIC, 9.0);
    check(three, &rgb, 97, 31, ATMOS_TONE_FILMIC, 9.0);
    check(three, &rgb, 64, 17, ATMOS_TONE_REINHARD, 4.0);
    check(three, &spec, 53, 29, ATMOS_TONE_CLAMP, -3.0);
    check(one, &spec, 53, 29, ATMOS_TONE_FILMIC, 12.0);
    check(one, &three_bands, 97, 31, ATMOS_TONE_FILMIC, 9.0);
    check(three, &three_bands, 61, 23, ATMOS_TONE_CLAMP, 2.0);
    for (int c = 0; c < 3; c++) check_dense_bytes(three, &rgb, (atmos_tone_curve)c);
    check_refusal(one, &rgb, 37, 9);
    check_refusal(three, &rgb, 37, 9);
    check_refusal(three, &spec, 21, 7);
    /* refused: an automatic exposure, no output, a wrong size */
    atmos_image *img = NULL, *small = NULL;
    CHECK_OK(atmos_image_create(NULL, 8, 8, 4, &img));
    CHECK_OK(atmos_image_create(NULL, 4, 8, 4, &small));
    atmos_tonemap_desc autod = {0, 0.0, ATMOS_TONE_FILMIC}, man = {1, 0.0, ATMOS_TONE_FILMIC};
    unsigned char b[8 * 8 * 4];
    CHECK(atmos_image_display_into(one, img, &rgb, &autod, NULL, b) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_image_display_into(one, img, &rgb, &man, NULL, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_image_display_into(one, img, &rgb, &man, small, NULL) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(img), atmos_image_destroy(small);
    atmos_context_destroy(one), atmos_context_destroy(three);
    return test_summary("test_display");
}
