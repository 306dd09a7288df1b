/* A frame's display path in one pass (atmos_image_display_into): radiance -> linear sRGB ->
 * gamut map -> tone map -> display values, a chunk of a row at a time so that it stays in the
 * cache (three passes over a 1280 x 720 frame took a quarter of the viewer's frame). The
 * per-pixel steps are those of atmos_image_to_srgb_into, atmos_image_gamut_map and
 * atmos_tonemap_into, in the same order: the same bits. */
#include "core/finite.h"
#include "core/internal.h"
#include "image/display_internal.h"

#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
#include <emmintrin.h>
#endif

/* One row: spectral pixels src (C channels, n radiance + alpha or not) to linear sRGB + alpha
 * in lin (4 channels), as atmos_image_to_srgb_into does, then gamut mapped. Returns the count of
 * the row's values (every channel) that are NaN or infinite. */
static unsigned linear_row(const float *src, int width, int C, int n, int has_alpha, const float (*w)[3], float *lin)
{
    unsigned bad = 0;
    for (int x = 0; x < width; x++) {
        const float *s = src + (size_t)x * C;
        float r = 0, g = 0, b = 0;
        for (int i = 0; i < C; i++) bad += atmos__not_finite(s[i]);
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
    return bad;
}

#if defined(__SSE2__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
/* linear_row for three radiances and alpha (the viewer's RGB frames) a pixel to a vector: the
 * matrix's three columns times the radiances broadcast, added in linear_row's order from 0 (the
 * same bits: 0 + w s as the first term turns a -0 into +0 there too), alpha in the last lane.
 * Returns the count of the row's values that are NaN or infinite (exponent bits all set), counted
 * from the same loads. */
static unsigned linear_row3a(const float *src, int width, const float (*w)[3], float *lin)
{
    const __m128 zero = _mm_setzero_ps(), w0 = _mm_setr_ps(w[0][0], w[0][1], w[0][2], 0),
                 w1 = _mm_setr_ps(w[1][0], w[1][1], w[1][2], 0), w2 = _mm_setr_ps(w[2][0], w[2][1], w[2][2], 0),
                 last = _mm_castsi128_ps(_mm_setr_epi32(0, 0, 0, -1));
    const __m128i expo = _mm_set1_epi32(0x7f800000);
    __m128i bad = _mm_setzero_si128(); /* minus the count, a lane a channel */
    for (int x = 0; x < width; x++) {
        const __m128 s = _mm_loadu_ps(src + 4 * x);
        bad = _mm_add_epi32(bad, _mm_cmpeq_epi32(_mm_and_si128(_mm_castps_si128(s), expo), expo));
        __m128 a = _mm_add_ps(zero, _mm_mul_ps(w0, _mm_shuffle_ps(s, s, 0x00)));
        a = _mm_add_ps(a, _mm_mul_ps(w1, _mm_shuffle_ps(s, s, 0x55)));
        a = _mm_add_ps(a, _mm_mul_ps(w2, _mm_shuffle_ps(s, s, 0xaa)));
        _mm_storeu_ps(lin + 4 * x, _mm_or_ps(_mm_and_ps(last, s), _mm_andnot_ps(last, a)));
        if (_mm_movemask_ps(_mm_cmplt_ps(a, zero)) & 7) atmos__gamut_pixel(lin + 4 * x);
    }
    uint32_t lane[4];
    _mm_storeu_si128((__m128i *)lane, bad);
    return 0u - (lane[0] + lane[1] + lane[2] + lane[3]);
}
#endif

/* Row src of width 4-channel pixels to dst, past the cache where the target has streaming
 * stores (the frame's display values are not read again while it is made: a plain store would
 * first read each line of dst from memory). */
static void stream_row(const float *src, float *dst, int width)
{
#if defined(__SSE2__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
    if (((uintptr_t)dst & 15) == 0) {
        for (int x = 0; x < width; x++) _mm_stream_ps(dst + 4 * x, _mm_loadu_ps(src + 4 * x));
        return;
    }
#endif
    memcpy(dst, src, sizeof(float) * 4 * (size_t)width);
}

/* Display values [0, 1] to 8-bit RGBA as atmos_write_png rounds them, alpha 255. With SSE2
 * four values a vector: max(v, 0) is 0 for NaN as well (maxps gives its second operand then),
 * min(., 1), then v 255 + 1/2 truncated, the same expression as the scalar one. */
static void bytes_row(const float *d, int width, unsigned char *out)
{
    int x0 = 0;
#if defined(__SSE2__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), k = _mm_set1_ps(255.0f), half = _mm_set1_ps(0.5f);
    const __m128i opaque = _mm_setr_epi32(0, 0, 0, 255);
    const __m128i keep = _mm_setr_epi32(-1, -1, -1, 0);
    for (; x0 + 4 <= width; x0 += 4) {
        __m128i q[4];
        for (int p = 0; p < 4; p++) {
            const __m128 v = _mm_min_ps(_mm_max_ps(_mm_loadu_ps(d + 4 * (x0 + p)), zero), one);
            q[p] = _mm_or_si128(_mm_and_si128(_mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(v, k), half)), keep), opaque);
        }
        const __m128i w = _mm_packus_epi16(_mm_packs_epi32(q[0], q[1]), _mm_packs_epi32(q[2], q[3]));
        _mm_storeu_si128((__m128i *)(out + 4 * x0), w);
    }
#endif
    for (int x = x0; x < width; x++) {
        for (int c = 0; c < 3; c++) {
            const float v = d[4 * x + c];
            out[4 * x + c] = !(v > 0) ? 0 : v >= 1 ? 255 : (unsigned char)(v * 255.0f + 0.5f);
        }
        out[4 * x + 3] = 255;
    }
}

/* A row's pixels a chunk at a time, so that the chunk's linear values and display values stay in
 * the first-level cache between the steps (a whole 1280-pixel row's were 40 KB). */
#define DISPLAY_CHUNK 128

/* Chunk src of width pixels (C channels) to display values: linear sRGB + alpha in buf, its
 * display values in buf + 4 DISPLAY_CHUNK, then to disp (floats) and rgba8 (bytes) where not NULL.
 * Returns the count of the chunk's values that are NaN or infinite. */
static unsigned display_chunk(const float *src, int width, int C, int n, int has_alpha, const float (*w)[3],
                              atmos_tone_curve curve, float scale, const uint32_t *bytes_lut, float *buf, float *disp,
                              unsigned char *rgba8)
{
    float *out = buf + (size_t)4 * DISPLAY_CHUNK;
    unsigned b;
#if defined(__SSE2__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
    if (n == 3 && has_alpha) b = linear_row3a(src, width, w, buf);
    else
#endif
        b = linear_row(src, width, C, n, has_alpha, w, buf);
    if (!disp && bytes_lut) { /* the bytes alone: from the curve's table over the scaled value */
        atmos__tonemap_bytes_row(curve, bytes_lut, buf, rgba8, (size_t)width, scale);
        return b;
    }
    atmos__tonemap_row(curve, buf, out, (size_t)width, 4, scale);
    if (disp) stream_row(out, disp, width);
    if (rgba8) bytes_row(out, width, rgba8);
    return b;
}

/* atmos_image_display_into, and with check atmos_image_display_checked: the count of the frame's
 * NaN and infinite values from the rows' own loads, and the first of them (y W C + i, the least
 * over the rows: the same for any thread count). */
static atmos_status display_pass(atmos_context *ctx, const atmos_image *spectral, const atmos_wavelengths *wl,
                                 const atmos_tonemap_desc *desc, atmos_image *disp, unsigned char *rgba8, int check)
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
    const uint32_t *bytes_lut = disp ? NULL : atmos__tonemap_byte_table(curve);
    int nomem = 0;
    size_t bad = 0;
    long long first = LLONG_MAX;
#pragma omp parallel num_threads(atmos__threads(ctx)) reduction(+ : bad) reduction(min : first)
    {
        float *buf = malloc(sizeof(float) * 8 * DISPLAY_CHUNK);
        if (!buf) {
#pragma omp atomic write
            nomem = 1;
        }
#pragma omp for schedule(static)
        for (int y = 0; y < spectral->height; y++) {
            if (!buf) continue;
            const float *row = spectral->pixels + (size_t)y * W * C;
            unsigned b = 0;
            for (int x0 = 0; x0 < W; x0 += DISPLAY_CHUNK)
                b += display_chunk(row + (size_t)x0 * C, W - x0 < DISPLAY_CHUNK ? W - x0 : DISPLAY_CHUNK, C, n, has_alpha,
                                   (const float(*)[3])w, curve, scale, bytes_lut, buf,
                                   disp ? disp->pixels + ((size_t)y * W + x0) * 4 : NULL,
                                   rgba8 ? rgba8 + ((size_t)y * W + x0) * 4 : NULL);
            if (b && check) {
                bad += b;
                const long long at = (long long)y * W * C + (long long)atmos__first_not_finite(row, (size_t)W * C);
                first = first < at ? first : at;
            }
        }
#if defined(__SSE2__) && defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
        _mm_sfence(); /* the streamed rows visible before the barrier closing the region */
#endif
        free(buf);
    }
    if (nomem) return atmos__error(ctx, ATMOS_E_NOMEM, "display: out of memory");
    if (bad)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                            "display: %zu of %zu pixel values are NaN or infinite (the first at pixel %lld, %lld): a "
                            "renderer bug for this scene; the frame is not shown, please report the scene",
                            bad, (size_t)W * spectral->height * C, (first % ((long long)W * C)) / C, first / ((long long)W * C));
    return ATMOS_OK;
}

atmos_status atmos_image_display_into(atmos_context *ctx, const atmos_image *spectral, const atmos_wavelengths *wl,
                                      const atmos_tonemap_desc *desc, atmos_image *disp, unsigned char *rgba8)
{
    return display_pass(ctx, spectral, wl, desc, disp, rgba8, 0);
}

atmos_status atmos_image_display_checked(atmos_context *ctx, const atmos_image *spectral, const atmos_wavelengths *wl,
                                         const atmos_tonemap_desc *desc, atmos_image *disp, unsigned char *rgba8)
{
    return display_pass(ctx, spectral, wl, desc, disp, rgba8, 1);
}
