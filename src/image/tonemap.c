/* Exposure, tone curves and the sRGB transfer function: linear HDR radiance to
 * display-referred values in [0, 1] for PNG output. */
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Reinhard et al. 2002 ("Photographic tone reproduction"): the log average is taken
 * over log(eps + Y) so that black pixels do not send it to zero. 1e-4 cd/m^2 is
 * below anything a renderer of daylight scenes produces but keeps the log finite. */
#define LOG_AVG_EPSILON 1e-4
#define SRGB_LUT 16384 /* intervals of the tabulated sRGB transfer function */
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

double atmos_tonemap_scale(const atmos_image *img, const atmos_tonemap_desc *desc)
{
    atmos_tonemap_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    double ev = isfinite(d.exposure_ev) ? d.exposure_ev : 0.0;
    if (d.manual_exposure) return 1.0 / (1.2 * pow(2.0, ev));
    if (!img || !img->pixels || (img->channels != 3 && img->channels != 4)) return pow(2.0, ev);

    /* Serial sum in a fixed order so that the scale (and so the image) is the same
     * bit for bit whatever the thread count. */
    const int nc = img->channels;
    const size_t n = (size_t)img->width * (size_t)img->height;
    double sum = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < n; i++) {
        const float *p = img->pixels + i * (size_t)nc;
        if (nc == 4 && !(p[3] > 0)) continue;
        double y = luminance(sanitize(p[0]), sanitize(p[1]), sanitize(p[2]));
        if (!isfinite(y)) continue; /* an Inf pixel would drive the average to Inf */
        sum += log(LOG_AVG_EPSILON + y);
        count++;
    }
    /* Nothing visible: any scale gives the same (empty) picture. */
    if (count == 0) return pow(2.0, ev);
    double lavg = exp(sum / (double)count);
    return KEY_VALUE / lavg * pow(2.0, ev);
}

static double apply_curve(atmos_tone_curve curve, double x)
{
    double y;
    switch (curve) {
    case ATMOS_TONE_REINHARD:
        y = isinf(x) ? 1.0 : x / (1.0 + x);
        break;
    case ATMOS_TONE_CLAMP:
        y = x;
        break;
    case ATMOS_TONE_FILMIC:
    default:
        /* Narkowicz 2015, "ACES Filmic Tone Mapping Curve". The rational fit tends to
         * 2.51/2.43 > 1, hence the clamp below; evaluate Inf directly (Inf/Inf = NaN). */
        y = isinf(x) ? 1.0 : (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
        break;
    }
    if (!(y > 0)) return 0.0;
    return y < 1.0 ? y : 1.0;
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
    atmos_tone_curve curve = desc ? desc->curve : ATMOS_TONE_FILMIC;
    if (curve != ATMOS_TONE_FILMIC && curve != ATMOS_TONE_REINHARD && curve != ATMOS_TONE_CLAMP)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_tonemap: unknown tone curve %d", (int)curve);

    atmos_image *img = NULL;
    atmos_status st = atmos_image_create(ctx, linear->width, linear->height, linear->channels, &img);
    if (st != ATMOS_OK) return st;
    /* Keep the render's metadata: the PNG written from this image should carry it. */
    for (int i = 0; i < linear->meta_count; i++) {
        st = atmos_image_set_meta(img, linear->meta[i].key, linear->meta[i].value);
        if (st != ATMOS_OK) {
            atmos_image_destroy(img);
            return atmos__error(ctx, st, "atmos_tonemap: cannot copy metadata");
        }
    }

    const double scale = atmos_tonemap_scale(linear, desc);
    /* The sRGB transfer function tabulated over [0, 1] (a curve's output), read linearly: within
     * 1e-6 of atmos_srgb_encode, a thousandth of a 16-bit PNG's level; a frame of the viewer
     * spent a third of its time in pow() without it. */
    float *enc = malloc(sizeof(float) * (SRGB_LUT + 2));
    if (!enc) {
        atmos_image_destroy(img);
        return atmos__error(ctx, ATMOS_E_NOMEM, "atmos_tonemap: out of memory");
    }
    for (int i = 0; i <= SRGB_LUT; i++) enc[i] = (float)atmos_srgb_encode((double)i / SRGB_LUT);
    enc[SRGB_LUT + 1] = enc[SRGB_LUT];
    const int nc = linear->channels;
    const long rows = linear->height;
    const size_t width = (size_t)linear->width;
    /* Each row is independent: static schedule, no shared state. */
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (long y = 0; y < rows; y++) {
        for (size_t x = 0; x < width; x++) {
            size_t o = ((size_t)y * width + x) * (size_t)nc;
            const float *src = linear->pixels + o;
            float *dst = img->pixels + o;
            for (int c = 0; c < 3; c++) {
                /* Per-channel curve: desaturates very bright colours towards white,
                 * which is what film does and what viewers expect of the sun disk. */
                double v = apply_curve(curve, sanitize(src[c]) * scale);
                v = v < 0 ? 0 : (v > 1 ? 1 : v) * SRGB_LUT;
                const int i = (int)v;
                const double e = enc[i] + (v - i) * (enc[i + 1] - enc[i]);
                dst[c] = (float)(e < 0 ? 0 : (e > 1 ? 1 : e));
            }
            if (nc == 4) {
                float a = src[3];
                dst[3] = a > 0 ? (a < 1 ? a : 1.0f) : 0.0f;
            }
        }
    }
    free(enc);
    *out = img;
    return ATMOS_OK;
}
