/* Spectral images to linear sRGB (Rec. 709 primaries, D65) with Y in cd/m^2, through the
 * wavelength set's colour-matching weights (spectrum.c). */
#include "core/internal.h"

atmos_status atmos_image_to_srgb_into(atmos_context *ctx, const atmos_image *spectral, const atmos_wavelengths *wl,
                                      atmos_image *rgb)
{
    if (!spectral || !wl || !rgb) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "to_srgb: missing argument");
    const int n = wl->count;
    if (spectral->channels != n + 1 && spectral->channels != n)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "to_srgb: image has %d channels, wavelength set %d (+alpha)",
                            spectral->channels, n);
    if (rgb->width != spectral->width || rgb->height != spectral->height || rgb->channels != 4)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "to_srgb: the output is not a 4-channel image of the input's size");
    const int has_alpha = spectral->channels == n + 1;
    float w[ATMOS_MAX_WAVELENGTHS][3];
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) w[i][c] = (float)wl->to_srgb[i][c];
    const long long npx = (long long)spectral->width * spectral->height;
    const int C = spectral->channels;
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (long long p = 0; p < npx; p++) {
        const float *s = spectral->pixels + p * C;
        float r = 0, g = 0, b = 0;
        for (int i = 0; i < n; i++) {
            r += w[i][0] * s[i];
            g += w[i][1] * s[i];
            b += w[i][2] * s[i];
        }
        float *o = rgb->pixels + p * 4;
        o[0] = r, o[1] = g, o[2] = b;
        o[3] = has_alpha ? s[n] : 1.0f;
    }
    return ATMOS_OK;
}

atmos_status atmos_image_to_srgb(atmos_context *ctx, const atmos_image *spectral, const atmos_wavelengths *wl,
                                 atmos_image **out)
{
    if (!spectral || !wl || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "to_srgb: missing argument");
    *out = NULL;
    atmos_image *rgb = NULL;
    atmos_status st = atmos_image_create(ctx, spectral->width, spectral->height, 4, &rgb);
    if (st == ATMOS_OK) st = atmos_image_to_srgb_into(ctx, spectral, wl, rgb);
    if (st != ATMOS_OK) {
        atmos_image_destroy(rgb);
        return st;
    }
    for (int i = 0; i < spectral->meta_count; i++) atmos_image_set_meta(rgb, spectral->meta[i].key, spectral->meta[i].value);
    atmos_image_set_meta(rgb, "atmos:units", "linear sRGB (Rec. 709 primaries, D65), Y = luminance in cd/m^2");
    *out = rgb;
    return ATMOS_OK;
}
