/* Linear sRGB pixels outside the gamut (a negative component: a spectrum more saturated than
 * the sRGB primaries, such as the sun's disc near the horizon) brought inside it by
 * desaturation at constant luminance (docs/colour.md). */
#include "core/internal.h"
#include "image/display_internal.h"

#include <math.h>

/* Rec. 709 / sRGB luminance row (IEC 61966-2-1): Y of linear R, G, B. */
static const double LUM[3] = {0.2126729, 0.7151522, 0.0721750};

int atmos__gamut_pixel(float *p)
{
    const double r = p[0], g = p[1], b = p[2];
    const double lo = fmin(r, fmin(g, b));
    if (!(lo < 0)) return 0; /* in gamut, or NaN: left as it is */
    const double y = LUM[0] * r + LUM[1] * g + LUM[2] * b;
    if (!(y > 0)) {
        p[0] = p[1] = p[2] = 0.0f;
        return 1;
    }
    /* c' = y + t (c - y), t = y / (y - lo) in (0, 1): the smallest component reaches 0 and
     * the luminance, a linear function of c with weights summing to 1, stays y */
    const double t = y / (y - lo);
    const double c[3] = {r, g, b};
    for (int k = 0; k < 3; k++) {
        const double v = y + t * (c[k] - y);
        p[k] = v > 0 ? (float)v : 0.0f;
    }
    return 1;
}

atmos_status atmos_image_gamut_map(atmos_context *ctx, atmos_image *rgb, long long *mapped)
{
    if (mapped) *mapped = 0;
    if (!rgb) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "gamut map: image is NULL");
    if (rgb->channels != 3 && rgb->channels != 4)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "gamut map: needs linear sRGB (3 or 4 channels), got %d channels",
                            rgb->channels);
    const long long npx = (long long)rgb->width * rgb->height;
    const int C = rgb->channels;
    long long n = 0;
#pragma omp parallel for schedule(static) reduction(+ : n) num_threads(atmos__threads(ctx))
    for (long long i = 0; i < npx; i++) n += atmos__gamut_pixel(rgb->pixels + i * C);
    if (mapped) *mapped = n;
    return ATMOS_OK;
}
