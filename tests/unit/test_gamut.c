/* atmos_image_gamut_map (src/image/gamut.c, docs/colour.md): linear sRGB pixels with a
 * negative component (a spectrum outside the sRGB gamut: the red sun near the horizon) are
 * moved toward the grey of the same luminance until the smallest component is 0. Checked
 * against Rec. 709's luminance row (IEC 61966-2-1: Y = 0.2126 R + 0.7152 G + 0.0722 B), not
 * against the code's own constants: luminance kept, no component negative, in-gamut pixels
 * untouched to the bit, alpha untouched, the result on the segment from the colour to its
 * grey (hue kept, saturation reduced). */
#include "test.h"

#include "atmos/atmos.h"

static double lum(const float *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

int main(void)
{
    static const float px[][4] = {
        {1.0f, 0.5f, 0.25f, 1.0f},          /* in gamut: untouched */
        {0.0f, 0.0f, 0.0f, 0.5f},           /* black: untouched */
        {5401.0f, 1705.2f, -13355853.0f, 1.0f}, /* luminance < 0 (no positive spectrum has it): black */
        {5.134e8f, 1.2066e8f, -1.3356e7f, 1.0f}, /* the low sun's disc (tests/cli/gamut.sh) */
        {2.0f, 0.5f, -0.3f, 0.75f},         /* a red beyond the gamut */
        {-0.05f, 1.0f, 0.2f, 1.0f},         /* a green beyond it */
        {0.3f, -0.01f, 3.0f, 1.0f},         /* a blue-violet */
    };
    const int n = (int)(sizeof px / sizeof px[0]);
    atmos_image *img = NULL;
    CHECK(atmos_image_create(NULL, n, 1, 4, &img) == ATMOS_OK);
    if (!img) return test_summary("test_gamut");
    memcpy(img->pixels, px, sizeof px);
    long long mapped = -1;
    CHECK(atmos_image_gamut_map(NULL, img, &mapped) == ATMOS_OK);
    CHECK_MSG(mapped == 5, "mapped %lld pixels, expected 5", mapped);
    for (int i = 0; i < n; i++) {
        const float *in = px[i], *out = img->pixels + 4 * i;
        const int outside = in[0] < 0 || in[1] < 0 || in[2] < 0;
        CHECK(out[3] == in[3]);
        for (int c = 0; c < 3; c++) CHECK_MSG(out[c] >= 0.0f, "pixel %d channel %d = %g", i, c, out[c]);
        if (!outside) {
            CHECK(memcmp(in, out, sizeof(float) * 4) == 0);
            continue;
        }
        const double y = lum(in);
        if (y <= 0) {
            CHECK(out[0] == 0 && out[1] == 0 && out[2] == 0);
            continue;
        }
        CHECK_REL(lum(out), y, 3e-4); /* the published 4-digit row: ~1e-4 */
        CHECK_NEAR(fmin(out[0], fmin(out[1], out[2])), 0.0, 1e-6 * y);
        /* out = y + t (in - y) with one t in (0, 1) for every channel */
        double t = -1;
        for (int c = 0; c < 3; c++)
            if (fabs(in[c] - y) > 1e-3 * y) {
                const double tc = (out[c] - y) / (in[c] - y);
                if (t < 0) t = tc;
                CHECK_NEAR(tc, t, 2e-3);
            }
        CHECK(t > 0 && t < 1);
    }
    /* a 3-channel image too; a 1-channel one is refused */
    atmos_image *rgb = NULL, *grey = NULL;
    CHECK(atmos_image_create(NULL, 1, 1, 3, &rgb) == ATMOS_OK);
    if (rgb) {
        rgb->pixels[0] = 2.0f, rgb->pixels[1] = 0.5f, rgb->pixels[2] = -0.3f;
        CHECK(atmos_image_gamut_map(NULL, rgb, NULL) == ATMOS_OK);
        CHECK(rgb->pixels[2] >= 0.0f);
        CHECK_REL(lum(rgb->pixels), 0.2126 * 2.0 + 0.7152 * 0.5 - 0.0722 * 0.3, 3e-4);
    }
    CHECK(atmos_image_create(NULL, 1, 1, 1, &grey) == ATMOS_OK);
    if (grey) CHECK(atmos_image_gamut_map(NULL, grey, NULL) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(img);
    atmos_image_destroy(rgb);
    atmos_image_destroy(grey);
    return test_summary("test_gamut");
}
