/* A frame's display path in one pass (atmos_image_display_into): radiance -> linear sRGB ->
 * gamut map -> tone map -> display values, a row at a time so that each row stays in the
 * cache (three passes over a 1280 x 720 frame took a quarter of the viewer's frame). The
 * per-pixel steps are those of atmos_image_to_srgb_into, atmos_image_gamut_map and
 * atmos_tonemap_into, in the same order: the same bits. */
#include "core/internal.h"
#include "image/display_internal.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
#include <xmmintrin.h>
#endif

/* One row: spectral pixels src (C channels, n radiance + alpha or not) to linear sRGB + alpha
 * in lin (4 channels), as atmos_image_to_srgb_into does, then gamut mapped. */
static void linear_row(const float *src, int width, int C, int n, int has_alpha, const float (*w)[3], float *lin)
{
    for (int x = 0; x < width; x++) {
        const float *s = src + (size_t)x * C;
        float r = 0, g = 0, b = 0;
        for (int i = 0; i < n; i++) {
            r += w[i][0] * s[i];
            g += w[i][1] * s[i];
            b += w[i][2] * s[i];
        }
        float *o = lin + (size_t)x * 4;
        o[0] = r, o[1] = g, o[2] = b;
        o[3] = has_alpha ? s[n] : 1.0f;
        if (r < 0 || g < 0 || b < 0) atmos__gamut_pixel(o);
    }
}

/* Row src of width 4-channel pixels to dst, past the cache where the target has streaming
 * stores (the frame's display values are not read again while it is made: a plain store would
 * first read each line of dst from memory). */
static void stream_row(const float *src, float *dst, int width)
{
#if defined(__SSE__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
    if (((uintptr_t)dst & 15) == 0) {
        for (int x = 0; x < width; x++) _mm_stream_ps(dst + 4 * x, _mm_loadu_ps(src + 4 * x));
        return;
    }
#endif
    memcpy(dst, src, sizeof(float) * 4 * (size_t)width);
}

/* Display values [0, 1] to 8-bit RGBA as atmos_write_png rounds them, alpha 255. */
static void bytes_row(const float *d, int width, unsigned char *out)
{
    for (int x = 0; x < width; x++) {
        for (int c = 0; c < 3; c++) {
            const float v = d[4 * x + c];
            out[4 * x + c] = !(v > 0) ? 0 : v >= 1 ? 255 : (unsigned char)(v * 255.0f + 0.5f);
        }
        out[4 * x + 3] = 255;
    }
}

atmos_status atmos_image_display_into(atmos_context *ctx, const atmos_image *spectral, const atmos_wavelengths *wl,
                                      const atmos_tonemap_desc *desc, atmos_image *disp, unsigned char *rgba8)
{
    if (!spectral || !spectral->pixels || !wl || !desc || (!disp && !rgba8))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "display: missing argument");
    const int n = wl->count, C = spectral->channels, W = spectral->width;
    if (C != n + 1 && C != n)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "display: image has %d channels, wavelength set %d (+alpha)", C, n);
    if (disp && (disp->width != W || disp->height != spectral->height || disp->channels != 4 || !disp->pixels))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "display: the output is not a 4-channel image of the input's size");
    if (!desc->manual_exposure)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "display: needs a manual exposure (atmos_tonemap_scale gives one)");
    const atmos_tone_curve curve = desc->curve;
    if (curve != ATMOS_TONE_FILMIC && curve != ATMOS_TONE_REINHARD && curve != ATMOS_TONE_CLAMP)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "display: unknown tone curve %d", (int)curve);
    float w[ATMOS_MAX_WAVELENGTHS][3];
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) w[i][c] = (float)wl->to_srgb[i][c];
    const float scale = (float)atmos_tonemap_scale(NULL, desc);
    const int has_alpha = C == n + 1;
    int nomem = 0;
#pragma omp parallel num_threads(atmos__threads(ctx))
    {
        float *buf = malloc(sizeof(float) * 8 * (size_t)W);
        if (!buf) {
#pragma omp atomic write
            nomem = 1;
        }
#pragma omp for schedule(static)
        for (int y = 0; y < spectral->height; y++) {
            if (!buf) continue;
            float *out = buf + (size_t)4 * W;
            linear_row(spectral->pixels + (size_t)y * W * C, W, C, n, has_alpha, (const float(*)[3])w, buf);
            atmos__tonemap_row(curve, buf, out, (size_t)W, 4, scale);
            if (disp) stream_row(out, disp->pixels + (size_t)y * W * 4, W);
            if (rgba8) bytes_row(out, W, rgba8 + (size_t)y * W * 4);
        }
#if defined(__SSE__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
        _mm_sfence(); /* the streamed rows visible before the barrier closing the region */
#endif
        free(buf);
    }
    return nomem ? atmos__error(ctx, ATMOS_E_NOMEM, "display: out of memory") : ATMOS_OK;
}
