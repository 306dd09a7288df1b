/* Exposure, tone curves and the sRGB transfer function: linear HDR radiance to
 * display-referred values in [0, 1] for PNG output. */
#include "core/internal.h"
#include "image/display_internal.h"

#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Reinhard et al. 2002 ("Photographic tone reproduction"): the log average is taken
 * over log(eps + Y) so that black pixels do not send it to zero. 1e-4 cd/m^2 is
 * below anything a renderer of daylight scenes produces but keeps the log finite. */
#define LOG_AVG_EPSILON 1e-4
/* The tabulated sRGB transfer function: SRGB_SEGS intervals an octave over SRGB_OCTAVES octaves
 * below 1 (under them the function is linear: 12.92 x). */
#define SRGB_SEG_BITS 7
#define SRGB_SEGS (1 << SRGB_SEG_BITS)
#define SRGB_OCTAVES 13
#define SRGB_LUT (SRGB_OCTAVES * SRGB_SEGS)
/* Middle grey: the key value the log average is mapped to. */
#define KEY_VALUE 0.18

/* Rec. 709 / linear sRGB luminance weights (IEC 61966-2-1). */
static double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

/* NaN and negatives become 0 so that one bad sample cannot poison a whole image;
 * +Inf is kept (the curves map it to 1). */
static double sanitize(double x) { return (x > 0) ? x : 0.0; }

double atmos_srgb_encode(double linear)
{
    if (!(linear == linear)) return 0.0; /* NaN */
    if (linear <= 0.0031308) return 12.92 * linear;
    return 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
}

double atmos_srgb_decode(double encoded)
{
    if (!(encoded == encoded)) return 0.0;
    if (encoded <= 0.04045) return encoded / 12.92;
    return pow((encoded + 0.055) / 1.055, 2.4);
}

/* A pixel's luminance, or -1 for a pixel that does not count (alpha 0, infinite Y). */
static double pixel_luminance(const atmos_image *img, size_t i)
{
    const float *p = img->pixels + i * (size_t)img->channels;
    if (img->channels == 4 && !(p[3] > 0)) return -1;
    const double y = luminance(sanitize(p[0]), sanitize(p[1]), sanitize(p[2]));
    return isfinite(y) ? y : -1; /* an Inf pixel would drive the average to Inf */
}

/* The HIGH_PERCENTILE-th percentile of the counted pixels' luminance, from a histogram of
 * HIST_PER_STOP bins a stop over [2^HIST_LO, 2^(HIST_LO + HIST_STOPS)) cd/m^2 (the bin's
 * middle: within 1.1 % of the exact value); 0 when that many pixels are black. */
#define HIGH_PERCENTILE 99.0
#define HIST_PER_STOP 32
#define HIST_LO (-40)
#define HIST_STOPS 80
static double high_luminance(const atmos_image *img, size_t n)
{
    enum { BINS = HIST_STOPS * HIST_PER_STOP };
    size_t hist[BINS] = {0}, black = 0, count = 0;
    for (size_t i = 0; i < n; i++) {
        const double y = pixel_luminance(img, i);
        if (y < 0) continue;
        count++;
        const double b = (log2(y) - HIST_LO) * HIST_PER_STOP; /* -inf for y = 0 */
        if (!(b >= 0)) black++;
        else hist[b < BINS - 1 ? (int)b : BINS - 1]++;
    }
    const double need = ceil(HIGH_PERCENTILE / 100 * (double)count);
    size_t seen = black;
    if ((double)seen >= need) return 0;
    for (int b = 0; b < BINS; b++)
        if ((double)(seen += hist[b]) >= need) return exp2(HIST_LO + (b + 0.5) / HIST_PER_STOP);
    return 0;
}

/* Automatic exposure (docs/scene-format.md, "exposure"): Reinhard et al.'s key, the log
 * average mapped to middle grey, taken over the pixels within LIT_RANGE of the image's
 * highlights (the 99th percentile) only, so that a black background does not vote; and at
 * most HIGH_X / that percentile, so that a small bright part (a beam over a dim glow) stays
 * just below white (4: 0.99 of it in sRGB through the filmic curve) while the brightest 1 %
 * (a lamp, the sun's disc) may burn out. */
#define LIT_RANGE 1e-3
#define HIGH_X 4.0
double atmos_tonemap_scale(const atmos_image *img, const atmos_tonemap_desc *desc)
{
    atmos_tonemap_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    double ev = isfinite(d.exposure_ev) ? d.exposure_ev : 0.0;
    if (d.manual_exposure) return 1.0 / (1.2 * pow(2.0, ev));
    if (!img || !img->pixels || (img->channels != 3 && img->channels != 4)) return pow(2.0, ev);

    /* Serial sums in a fixed order so that the scale (and so the image) is the same
     * bit for bit whatever the thread count. */
    const size_t n = (size_t)img->width * (size_t)img->height;
    const double high = high_luminance(img, n), lit = LIT_RANGE * high;
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; i++) {
        const double y = pixel_luminance(img, i);
        if (y < 0 || y < lit) continue;
        sum += log(LOG_AVG_EPSILON + y);
        count++;
    }
    /* Nothing visible: any scale gives the same (empty) picture. */
    if (count == 0) return pow(2.0, ev);
    double scale = KEY_VALUE / exp(sum / (double)count);
    if (high > 0) scale = fmin(scale, HIGH_X / high);
    return scale * pow(2.0, ev);
}

/* The sRGB transfer function tabulated over [2^-13, 1] (a curve's output) in floats, read linearly
 * in intervals of 1/128 of an octave: entry i is the value at 2^(i / 128 - 13) (1 + (i mod 128) / 128),
 * found from the float's bits (exponent and the mantissa's first 7), the fraction from the
 * mantissa's other 16 bits. Within 1.5e-6 of atmos_srgb_encode (a tenth of a 16-bit PNG's
 * level; test_image's tonemap precision), in 6.7 KB that stay in the first-level cache (a table
 * of 16 385 even steps, 64 KB, was within 3.3e-6 and did not: a sixth of the viewer's display
 * pass). Made once, by the first call. */
static float srgb_lut[SRGB_LUT + 2];
static _Atomic int srgb_lut_ready;

static const float *srgb_table(void)
{
    if (atomic_load_explicit(&srgb_lut_ready, memory_order_acquire)) return srgb_lut;
#pragma omp critical(atmos_srgb_lut)
    if (!atomic_load_explicit(&srgb_lut_ready, memory_order_relaxed)) {
        for (int i = 0; i <= SRGB_LUT; i++)
            srgb_lut[i] = (float)atmos_srgb_encode(ldexp(1.0 + (double)(i % SRGB_SEGS) / SRGB_SEGS, i / SRGB_SEGS - SRGB_OCTAVES));
        srgb_lut[SRGB_LUT + 1] = srgb_lut[SRGB_LUT];
        atomic_store_explicit(&srgb_lut_ready, 1, memory_order_release);
    }
    return srgb_lut;
}

/* A tone curve of x >= 0 (finite or +Inf), in [0, 1]. Each curve reaches 1 below its clamp
 * (the filmic curve at x = 7.24), so clamping first keeps +Inf out of the arithmetic. */
ATMOS_CLONE_HELPER float curve_of(atmos_tone_curve curve, float x)
{
    float y;
    if (curve == ATMOS_TONE_REINHARD) {
        x = x < 1e30f ? x : 1e30f;
        y = x / (1.0f + x);
    } else if (curve == ATMOS_TONE_CLAMP) {
        y = x;
    } else {
        /* Narkowicz 2015, "ACES Filmic Tone Mapping Curve"; the rational fit tends to
         * 2.51/2.43 > 1, hence the clamp to 1 */
        x = x < 8.0f ? x : 8.0f;
        y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    }
    return y < 1.0f ? y : 1.0f;
}

/* A value of src scaled and through the curve: NaN and negatives 0. */
ATMOS_CLONE_HELPER float tone_of(atmos_tone_curve curve, float v, float scale)
{
    const float x = v * scale;
    return curve_of(curve, x > 0 ? x : 0.0f);
}

/* A curve's output v in [0, 1] sRGB encoded from the table: the entry from the float's exponent
 * and first mantissa bits (below 2^-13, clamped to the first: the linear part 12.92 v is taken
 * there), read linearly by the other bits; at most 1. Both branches computed, so that GCC
 * vectorises the loops (the table read a gather). */
ATMOS_CLONE_HELPER float encode_of(float v, const float *restrict enc)
{
    const union { float f; uint32_t u; } bits = {v};
    const uint32_t b = bits.u;
    const int k = (int)(b >> (23 - SRGB_SEG_BITS)) - ((127 - SRGB_OCTAVES) << SRGB_SEG_BITS), i = k > 0 ? k : 0;
    const float t = (float)(b & ((1u << (23 - SRGB_SEG_BITS)) - 1)) * (1.0f / (1u << (23 - SRGB_SEG_BITS)));
    const float l = enc[i] + t * (enc[i + 1] - enc[i]), e = v < 0x1p-13f ? 12.92f * v : l;
    return e < 1.0f ? e : 1.0f;
}

/* Values [0, n) of src to display values in dst: scale, the curve (per channel: it desaturates
 * very bright colours towards white, as film does the sun's disk), the sRGB transfer function.
 * Inlined per curve: no branch on the curve in the loop. In chunks of two loops, the curve's and
 * the table's: GCC 12 vectorises each (the table read a gather, given restrict) but not the two
 * as one loop. */
ATMOS_CLONE_HELPER void map_values(atmos_tone_curve curve, const float *restrict src,
                                   float *restrict dst, size_t n, float scale,
                                   const float *restrict enc)
{
    enum { CHUNK = 256 };
    float vb[CHUNK], ve[CHUNK];
    for (size_t j0 = 0; j0 < n; j0 += CHUNK) {
        const size_t m = n - j0 < CHUNK ? n - j0 : CHUNK;
        for (size_t j = 0; j < m; j++) vb[j] = tone_of(curve, src[j0 + j], scale);
        for (size_t j = 0; j < m; j++) ve[j] = encode_of(vb[j], enc);
        memcpy(dst + j0, ve, sizeof(float) * m);
    }
}

/* map_values for `width` RGBA pixels, alpha clamped to [0, 1] and not mapped: the colours of a
 * chunk of pixels split into three planes, each plane's values through the table, the planes
 * and alpha interleaved again (each a vector loop; mapping alpha with the colours and setting it
 * afterwards took a third more time). */
ATMOS_CLONE_HELPER void map_rgba(atmos_tone_curve curve, const float *restrict src,
                                 float *restrict dst, size_t width, float scale,
                                 const float *restrict enc)
{
    enum { CHUNK = 64 };
    float pl[3][CHUNK], pe[3][CHUNK];
    for (size_t p0 = 0; p0 < width; p0 += CHUNK) {
        const size_t m = width - p0 < CHUNK ? width - p0 : CHUNK;
        const float *s = src + 4 * p0;
        float *d = dst + 4 * p0;
        for (size_t p = 0; p < m; p++) {
            pl[0][p] = tone_of(curve, s[4 * p], scale);
            pl[1][p] = tone_of(curve, s[4 * p + 1], scale);
            pl[2][p] = tone_of(curve, s[4 * p + 2], scale);
        }
        for (int c = 0; c < 3; c++)
            for (size_t p = 0; p < m; p++) pe[c][p] = encode_of(pl[c][p], enc);
        for (size_t p = 0; p < m; p++) {
            const float a = s[4 * p + 3];
            d[4 * p] = pe[0][p], d[4 * p + 1] = pe[1][p], d[4 * p + 2] = pe[2][p];
            d[4 * p + 3] = a > 0 ? (a < 1 ? a : 1.0f) : 0.0f;
        }
    }
}

/* One row of `width` pixels of C channels; alpha clamped to [0, 1]. The AVX2 clone maps eight
 * values at a time with a gather from the table (no FMA: the same bits as the baseline). */
ATMOS_CLONES
static void map_row(atmos_tone_curve curve, const float *src, float *dst, size_t width, int C, float scale,
                    const float *enc)
{
    if (C == 4) {
        if (curve == ATMOS_TONE_REINHARD) map_rgba(ATMOS_TONE_REINHARD, src, dst, width, scale, enc);
        else if (curve == ATMOS_TONE_CLAMP) map_rgba(ATMOS_TONE_CLAMP, src, dst, width, scale, enc);
        else map_rgba(ATMOS_TONE_FILMIC, src, dst, width, scale, enc);
        return;
    }
    if (curve == ATMOS_TONE_REINHARD) map_values(ATMOS_TONE_REINHARD, src, dst, width * C, scale, enc);
    else if (curve == ATMOS_TONE_CLAMP) map_values(ATMOS_TONE_CLAMP, src, dst, width * C, scale, enc);
    else map_values(ATMOS_TONE_FILMIC, src, dst, width * C, scale, enc);
}

void atmos__tonemap_row(atmos_tone_curve curve, const float *src, float *dst, size_t width, int C, float scale)
{
    map_row(curve, src, dst, width, C, scale, srgb_table());
}

atmos_status atmos_tonemap_into(atmos_context *ctx, const atmos_image *linear, const atmos_tonemap_desc *desc,
                                atmos_image *out)
{
    if (!linear || !linear->pixels || !out || !out->pixels)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_tonemap: no input or output image");
    if (linear->channels != 3 && linear->channels != 4)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmos_tonemap: image has %d channels; tone mapping needs 3 (RGB) or 4 (RGBA)",
                            linear->channels);
    if (out->width != linear->width || out->height != linear->height || out->channels != linear->channels)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_tonemap: the output image's size differs from the input's");
    const atmos_tone_curve curve = desc ? desc->curve : ATMOS_TONE_FILMIC;
    if (curve != ATMOS_TONE_FILMIC && curve != ATMOS_TONE_REINHARD && curve != ATMOS_TONE_CLAMP)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_tonemap: unknown tone curve %d", (int)curve);
    const float scale = (float)atmos_tonemap_scale(linear, desc), *enc = srgb_table();
    const int C = linear->channels;
    const long rows = linear->height;
    const size_t width = (size_t)linear->width;
    /* Each row is independent: static schedule, no shared state. */
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (long y = 0; y < rows; y++) {
        map_row(curve, linear->pixels + (size_t)y * width * C, out->pixels + (size_t)y * width * C, width, C, scale, enc);
    }
    return ATMOS_OK;
}

atmos_status atmos_tonemap(atmos_context *ctx, const atmos_image *linear, const atmos_tonemap_desc *desc,
                           atmos_image **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_tonemap: out is NULL");
    *out = NULL;
    if (!linear || !linear->pixels)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_tonemap: no input image");
    if (linear->channels != 3 && linear->channels != 4)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmos_tonemap: image has %d channels; tone mapping needs 3 (RGB) or 4 (RGBA)",
                            linear->channels);
    atmos_image *img = NULL;
    atmos_status st = atmos_image_create(ctx, linear->width, linear->height, linear->channels, &img);
    if (st != ATMOS_OK) return st;
    /* Keep the render's metadata: the PNG written from this image should carry it. */
    for (int i = 0; i < linear->meta_count && st == ATMOS_OK; i++)
        if ((st = atmos_image_set_meta(img, linear->meta[i].key, linear->meta[i].value)) != ATMOS_OK)
            st = atmos__error(ctx, st, "atmos_tonemap: cannot copy metadata");
    if (st == ATMOS_OK) st = atmos_tonemap_into(ctx, linear, desc, img);
    if (st != ATMOS_OK) {
        atmos_image_destroy(img);
        return st;
    }
    *out = img;
    return ATMOS_OK;
}
