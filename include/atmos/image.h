/* Float images, exposure and tone mapping, and the writers (OpenEXR, PNG, PFM).
 *
 * An image is width x height pixels of `channels` floats each, row-major, top row
 * first, channels interleaved. Images carry string metadata (key/value pairs) that
 * the writers store (EXR header attributes, PNG tEXt chunks). Every writer writes
 * to a temporary name and renames, so no partial file appears under the final name.
 * An image is not thread-safe for concurrent writes to the same pixels.
 */
#ifndef ATMOS_IMAGE_H
#define ATMOS_IMAGE_H

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_IMAGE_MAX_DIM 65536
#define ATMOS_IMAGE_MAX_CHANNELS 256

typedef struct atmos_image_meta {
    char *key;
    char *value;
} atmos_image_meta;

typedef struct atmos_image {
    int width, height, channels;
    float *pixels;               /* width*height*channels floats */
    int meta_count;
    atmos_image_meta *meta;
} atmos_image;

/* Allocates a zeroed image. Fails with ATMOS_E_INVALID_ARG / ATMOS_E_LIMIT for
 * sizes outside 1..ATMOS_IMAGE_MAX_DIM or channels outside 1..ATMOS_IMAGE_MAX_CHANNELS. */
ATMOS_API atmos_status atmos_image_create(atmos_context *ctx, int width, int height, int channels,
                                          atmos_image **out);
ATMOS_API void atmos_image_destroy(atmos_image *img);
/* Sets (or replaces) a metadata entry. */
ATMOS_API atmos_status atmos_image_set_meta(atmos_image *img, const char *key, const char *value);
ATMOS_API const char *atmos_image_get_meta(const atmos_image *img, const char *key);

typedef enum {
    ATMOS_TONE_FILMIC = 0,   /* ACES-style filmic curve (Narkowicz 2015 fit); default */
    ATMOS_TONE_REINHARD = 1, /* x / (1 + x) */
    ATMOS_TONE_CLAMP = 2     /* min(x, 1) */
} atmos_tone_curve;

typedef struct atmos_tonemap_desc {
    int manual_exposure;     /* 0 (default): automatic exposure from the image; 1: use exposure_ev */
    double exposure_ev;      /* manual: photographic EV at ISO 100 (daylight ~15); automatic:
                                compensation in stops added to the automatic choice */
    atmos_tone_curve curve;
} atmos_tonemap_desc;

/* The linear scale the tone mapper applies before the curve, for an image whose
 * values are linear sRGB scaled so that Y is luminance in cd m^-2 (what the
 * renderers produce):
 *   manual:    1 / (1.2 * 2^EV)  (saturation-based EV100: 1.2*2^EV cd/m^2 maps to 1)
 *   automatic: 0.18 / Lavg * 2^EV, Lavg the log-average luminance of the image's
 *              pixels with alpha > 0 (all pixels if there is no alpha channel).
 * img must have 3 or 4 channels. */
ATMOS_API double atmos_tonemap_scale(const atmos_image *img, const atmos_tonemap_desc *desc);

/* Linear sRGB (3 or 4 channels; alpha copied) -> display sRGB in [0,1] (tone curve
 * then the sRGB transfer function). *out gets a new image of the same size. */
ATMOS_API atmos_status atmos_tonemap(atmos_context *ctx, const atmos_image *linear,
                                     const atmos_tonemap_desc *desc, atmos_image **out);

/* The sRGB transfer function (IEC 61966-2-1) and its inverse. */
ATMOS_API double atmos_srgb_encode(double linear);
ATMOS_API double atmos_srgb_decode(double encoded);

/* OpenEXR: channels R,G,B[,A] for 3/4-channel images, otherwise named by
 * channel_names (or "C0".."Cn"). half: nonzero for 16-bit half floats, else 32-bit. */
typedef struct atmos_exr_desc {
    int half;
    const char *const *channel_names; /* optional, img->channels entries */
} atmos_exr_desc;
ATMOS_API atmos_status atmos_write_exr(atmos_context *ctx, const atmos_image *img, const char *path,
                                       const atmos_exr_desc *desc);
/* Reads an EXR written by atmos_write_exr (any channel count, half or float) into a
 * float image; metadata strings are read back into img->meta. */
ATMOS_API atmos_status atmos_read_exr(atmos_context *ctx, const char *path, atmos_image **out);

/* PNG from a display-encoded image (values in [0,1], 1/3/4 channels: grey, RGB,
 * RGBA), bits 8 or 16. Metadata as tEXt chunks. */
ATMOS_API atmos_status atmos_write_png(atmos_context *ctx, const atmos_image *display, const char *path,
                                       int bits);
/* Reads a PNG into a float image in [0,1] (for tests and tools). */
ATMOS_API atmos_status atmos_read_png(atmos_context *ctx, const char *path, atmos_image **out);

/* Portable float map: 3 channels ("PF") or 1 ("Pf"), little-endian, bottom row first
 * as the format requires. Other channel counts: the first three are written. */
ATMOS_API atmos_status atmos_write_pfm(atmos_context *ctx, const atmos_image *img, const char *path);
ATMOS_API atmos_status atmos_read_pfm(atmos_context *ctx, const char *path, atmos_image **out);

#ifdef __cplusplus
}
#endif
#endif
