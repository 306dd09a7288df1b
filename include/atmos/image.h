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

#include "atmos/base.h"
#include "atmos/spectrum.h"

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
/* Sets (or replaces) a metadata entry; key and value are copied. ATMOS_E_INVALID_ARG
 * for an empty key or a NULL value. */
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
 *   automatic: min(0.18 / Lavg, 4 / Y99) * 2^EV over the image's pixels with
 *              alpha > 0 (all pixels if there is no alpha channel): Y99 the 99th
 *              percentile of their Y (within 1.1 %; the cap leaves out a Y99 of 0),
 *              Lavg = exp(mean(log(1e-4 + Y))) over those of them with Y >= 1e-3 Y99
 *              (a black background does not set the key; the brightest 1 %, a lamp,
 *              may burn out); NaN and negative values count as 0, pixels with
 *              infinite Y are skipped; with no pixel left the scale is 2^EV.
 * img must have 3 or 4 channels (otherwise the automatic scale is 2^EV). */
ATMOS_API double atmos_tonemap_scale(const atmos_image *img, const atmos_tonemap_desc *desc);

/* Linear sRGB (3 or 4 channels; alpha copied, clamped to [0,1]) -> display sRGB in
 * [0,1]: scale, tone curve per channel, then the sRGB transfer function. NaN and
 * negative inputs give 0, +Inf gives 1: the output is always finite. *out gets a
 * new image of the same size carrying a copy of the metadata; the caller destroys
 * it. Rows are processed on atmos_context_threads(ctx) threads. */
ATMOS_API atmos_status atmos_tonemap(atmos_context *ctx, const atmos_image *linear,
                                     const atmos_tonemap_desc *desc, atmos_image **out);
/* atmos_tonemap into an existing image out of the input's size and channels (no metadata
 * copied): a viewer's frame without allocating one. The curve and the exposure are applied in
 * single precision, the sRGB transfer function from a table: within 4e-6 of the curve and the
 * transfer function in double precision (a quarter of a 16-bit PNG's level; atmos_tonemap is
 * the same). */
ATMOS_API atmos_status atmos_tonemap_into(atmos_context *ctx, const atmos_image *linear,
                                          const atmos_tonemap_desc *desc, atmos_image *out);

/* The sRGB transfer function (IEC 61966-2-1) and its inverse. NaN gives 0. */
ATMOS_API double atmos_srgb_encode(double linear);
ATMOS_API double atmos_srgb_decode(double encoded);

/* The writers (atmos_write_exr, _png, _png_level, _pfm) write their own format whatever
 * the path's extension: atmos_write_exr(ctx, img, "a.png", NULL) writes an EXR named a.png.
 * Choosing the name is the caller's (the CLI refuses an output whose extension is another
 * format's).
 *
 * OpenEXR: single-part scanline file, ZIP compression. Channels named by
 * channel_names when given (distinct, 1..255 bytes), else R,G,B[,A] for 3/4-channel
 * images and "C0".."Cn" otherwise. half: nonzero for 16-bit half floats, else 32-bit;
 * finite values beyond the largest half (+-65504) are written as +-65504, with a
 * warning (ATMOS_LOG_WARN) that counts them, instead of becoming infinite (infinities
 * and NaN are stored as they are). Every file with R, G and B channels (plain, or one
 * layer's "<layer>.R", ...) carries the standard "chromaticities" attribute of linear sRGB
 * (Rec. 709 primaries, D65 white) unless the metadata has that key; a file without them (a
 * variance per wavelength, a table) has none: the attribute describes R, G and B. Every metadata entry becomes an attribute: a value that is a decimal number as a
 * whole an int (integers that fit 32 bits, without a leading zero or '+') or a double
 * attribute, anything else a string; keys that are standard attributes of another type
 * ("channels", ...) or the structural "type"/"name" give ATMOS_E_INVALID_ARG. */
typedef struct atmos_exr_desc {
    int half;
    const char *const *channel_names; /* optional, img->channels entries */
} atmos_exr_desc;
ATMOS_API atmos_status atmos_write_exr(atmos_context *ctx, const atmos_image *img, const char *path,
                                       const atmos_exr_desc *desc);
/* Reads a scanline EXR (any channel count; half, float or unsigned-int channels, the
 * last converted to their values as floats, exact up to 2^24) into a float image;
 * string, int and double attributes are read back into img->meta (numbers as text: %d,
 * or the shortest %g that gives the double back). Channel order, by name: when the
 * file has R, G and B (or only one layer has "<layer>.R", ".G", ".B"), those first in
 * that order, then their A if present, then the others in the file's order (sorted by
 * name, as OpenEXR stores them); C0..Cn by number when
 * the file has exactly those; otherwise the file's order. Tiled, deep and subsampled
 * files: ATMOS_E_UNSUPPORTED. Malformed or truncated files: ATMOS_E_FORMAT, found before
 * the image is allocated when the chunk table or a chunk cannot hold what the header
 * claims (a chunk may not expand beyond what its compression allows); sizes
 * beyond ATMOS_IMAGE_MAX_DIM / _CHANNELS: ATMOS_E_LIMIT or ATMOS_E_FORMAT. */
ATMOS_API atmos_status atmos_read_exr(atmos_context *ctx, const char *path, atmos_image **out);
/* The same, and *names (if names is not NULL) gets the channel names in image order:
 * img->channels strings in one allocation that the caller frees with free(*names). */
ATMOS_API atmos_status atmos_read_exr_named(atmos_context *ctx, const char *path, atmos_image **out,
                                            char ***names);

/* PNG from a display-encoded image (values in [0,1], 1/3/4 channels: grey, RGB,
 * RGBA), bits 8 or 16; values are clamped (NaN -> 0) and rounded to the nearest
 * level. Metadata as tEXt chunks (iTXt for non-ASCII values; keys 1..79 bytes). */
ATMOS_API atmos_status atmos_write_png(atmos_context *ctx, const atmos_image *display, const char *path,
                                       int bits);
/* The same with zlib's compression level 0..9 (-1: libpng's default, what atmos_write_png
 * uses): the same pixels, 1 much faster and a larger file (the viewer's recorded frames). */
ATMOS_API atmos_status atmos_write_png_level(atmos_context *ctx, const atmos_image *display, const char *path,
                                             int bits, int level);
/* Reads a PNG (any bit depth and colour type) into a float image in [0,1] with 1
 * (grey), 3 (RGB) or 4 (RGBA; also for grey+alpha and palettes with transparency)
 * channels; text chunks go into img->meta. Malformed files: ATMOS_E_FORMAT. */
ATMOS_API atmos_status atmos_read_png(atmos_context *ctx, const char *path, atmos_image **out);

/* Reads a baseline or progressive JPEG (libjpeg) into a float image in [0,1], the file's
 * 8-bit values / 255 unchanged (sRGB-encoded for ordinary photographs): 1 channel for
 * greyscale files, 3 (RGB) for colour ones; CMYK files are refused. A malformed or
 * truncated file (libjpeg's warnings included) gives ATMOS_E_FORMAT, never a partial
 * image. atmos_read_jpeg_scaled decodes at 1/reduce of the size (reduce 1, 2, 4 or 8,
 * libjpeg's DCT scaling; each side rounded up): large maps at a fraction of the memory. */
ATMOS_API atmos_status atmos_read_jpeg(atmos_context *ctx, const char *path, atmos_image **out);
ATMOS_API atmos_status atmos_read_jpeg_scaled(atmos_context *ctx, const char *path, int reduce, atmos_image **out);

/* Portable float map: 3 channels ("PF") or 1 ("Pf"), little-endian, bottom row first
 * as the format requires. 4 or more channels: the first three are written; 2
 * channels: ATMOS_E_INVALID_ARG. The reader accepts either byte order, ignores the
 * scale's magnitude and takes a CRLF pair after the scale as the header's end (unless
 * the file's size says the data start at the LF); data shorter than the header claims:
 * ATMOS_E_FORMAT. */
ATMOS_API atmos_status atmos_write_pfm(atmos_context *ctx, const atmos_image *img, const char *path);
ATMOS_API atmos_status atmos_read_pfm(atmos_context *ctx, const char *path, atmos_image **out);

/* An image's format by its first n bytes: "OpenEXR" (76 2F 31 01), "PNG" (its 8-byte
 * signature), "JPEG" (FF D8 FF) or "PFM" ("PF" or "Pf" and a space, tab, CR or LF, as
 * atmos_read_pfm takes it), else NULL. atmos_image_file_kind: the same for a file's first 8
 * bytes (NULL also when it cannot be read). */
ATMOS_API const char *atmos_image_kind(const void *bytes, size_t n);
ATMOS_API const char *atmos_image_file_kind(const char *path);

/* Error statistics of an image against a reference (same size and colour channels;
 * the 4th channel of RGBA images is coverage and is ignored). rmse, rel_rmse (RMSE over
 * the reference's mean absolute value) and bias (mean of image - reference) per channel
 * and over all channels; the worst 16x16 region by RMSE; non-finite samples are counted
 * (in total and per image) and skipped, and statistics with no finite sample are NaN.
 * A caller that uses the result as a test must treat nonfinite > 0 as a failure.
 * heatmap (optional): a display-encoded RGB image of the per-pixel relative
 * difference, black -> red -> yellow -> white at heat_scale (the largest difference, at
 * most 10 times the 99th percentile of the pixels'; the few above it are white too). */
#define ATMOS_IMAGE_DIFF_MAX_CHANNELS 16
/* Which channels to compare: pair c is channel image[c] of the image against channel
 * reference[c] of the reference. exclude_above > 0 leaves out of every statistic, the worst
 * region, the bins and the heat map (black) the pixels where a compared channel of either
 * image is finite and exceeds it (the sun's disc, a lamp), every channel of them; their NaN or
 * infinite samples still count in nonfinite; 0 (as matched) keeps every pixel. */
typedef struct atmos_channel_match {
    int count;
    int image[ATMOS_IMAGE_DIFF_MAX_CHANNELS], reference[ATMOS_IMAGE_DIFF_MAX_CHANNELS];
    double exclude_above;
} atmos_channel_match;
/* Pairs channels by name ("A" and "<layer>.A" are coverage and never compared): R,G,B
 * when both images have all three (plain, or one layer's "<layer>.R", ...: the only layer
 * with all three); otherwise every other channel when both have the same set of names (in
 * the image's order); otherwise the only channel of each when both have one.
 * Anything else is ATMOS_E_INVALID_ARG with both name lists in the message; more than
 * ATMOS_IMAGE_DIFF_MAX_CHANNELS pairs is ATMOS_E_UNSUPPORTED. */
ATMOS_API atmos_status atmos_image_match_channels(atmos_context *ctx, const char *const *image_names, int image_count,
                                                  const char *const *reference_names, int reference_count,
                                                  atmos_channel_match *out);
typedef struct atmos_image_diff {
    int channels;
    double rmse[ATMOS_IMAGE_DIFF_MAX_CHANNELS], rel_rmse[ATMOS_IMAGE_DIFF_MAX_CHANNELS],
        bias[ATMOS_IMAGE_DIFF_MAX_CHANNELS];
    double rmse_all, rel_rmse_all;
    int worst_x, worst_y, worst_w, worst_h; /* pixels; w = h = 0 when no sample was compared */
    double worst_rmse;                      /* NaN when no sample was compared */
    size_t nonfinite;                       /* compared samples skipped: either value NaN or infinite */
    double heat_scale;                      /* relative difference shown as white */
    size_t nonfinite_image, nonfinite_reference; /* of those, the non-finite values in each image */
    size_t excluded;                        /* pixels left out by the match's exclude_above */
    size_t nonfinite_excluded;              /* of nonfinite, those in the excluded pixels (not compared) */
} atmos_image_diff;
ATMOS_API atmos_status atmos_image_compare(atmos_context *ctx, const atmos_image *image, const atmos_image *reference,
                                           atmos_image_diff *out, atmos_image **heatmap);
/* The same over the channel pairs of `match` (from atmos_image_match_channels). */
ATMOS_API atmos_status atmos_image_compare_matched(atmos_context *ctx, const atmos_image *image,
                                                   const atmos_image *reference, const atmos_channel_match *match,
                                                   atmos_image_diff *out, atmos_image **heatmap);

/* The same statistics split by a per-pixel key (e.g. the optical depth along each
 * pixel's ray, or the mean scattering order): pixels whose key (channel 0 of `key`,
 * same size) lies in [edges[i], edges[i+1]) form bin i. Per bin, over the colour
 * channels: the pixel count, rel_rmse (RMSE over the reference's mean absolute value
 * in the bin) and rel_bias (mean difference over the same). Empty bins have count 0
 * and NaN statistics. edges ascending, 2..ATMOS_IMAGE_BINS_MAX+1 of them. */
#define ATMOS_IMAGE_BINS_MAX 32
typedef struct atmos_image_bins {
    int bins;
    double edges[ATMOS_IMAGE_BINS_MAX + 1];
    size_t count[ATMOS_IMAGE_BINS_MAX];
    double rel_rmse[ATMOS_IMAGE_BINS_MAX], rel_bias[ATMOS_IMAGE_BINS_MAX], mean_reference[ATMOS_IMAGE_BINS_MAX];
} atmos_image_bins;
ATMOS_API atmos_status atmos_image_compare_binned(atmos_context *ctx, const atmos_image *image,
                                                  const atmos_image *reference, const atmos_image *key,
                                                  const double *edges, int n_edges, atmos_image_bins *out);
ATMOS_API atmos_status atmos_image_compare_binned_matched(atmos_context *ctx, const atmos_image *image,
                                                          const atmos_image *reference, const atmos_channel_match *match,
                                                          const atmos_image *key, const double *edges, int n_edges,
                                                          atmos_image_bins *out);

/* Spectral image (count radiance channels + alpha) -> linear sRGB + alpha (4
 * channels), scaled so that Y is luminance in cd m^-2. Metadata is copied. */
ATMOS_API atmos_status atmos_image_to_srgb(atmos_context *ctx, const atmos_image *spectral,
                                           const atmos_wavelengths *wl, atmos_image **out);
/* The same into an existing 4-channel image of the input's size (no metadata copied). */
ATMOS_API atmos_status atmos_image_to_srgb_into(atmos_context *ctx, const atmos_image *spectral,
                                                const atmos_wavelengths *wl, atmos_image *rgb);
/* Linear sRGB (3 or 4 channels) brought inside the sRGB gamut: a pixel with a negative
 * component (a spectrum more saturated than the primaries, atmos_image_to_srgb being exact and
 * linear) is moved toward the grey of its luminance, c' = Y + t (c - Y) with the t that makes
 * its smallest component 0, so Y (Rec. 709) and the hue are kept and the saturation reduced;
 * a pixel whose Y is <= 0 becomes black. Other pixels and alpha are untouched. *mapped (may be
 * NULL): the pixels moved. atmos render and atmos view apply it to what they write
 * (docs/colour.md). */
ATMOS_API atmos_status atmos_image_gamut_map(atmos_context *ctx, atmos_image *rgb, long long *mapped);

/* The three steps a frame takes to the screen in one pass, a row at a time: spectral radiance
 * (wl's channels + alpha or not) -> linear sRGB (atmos_image_to_srgb_into) -> gamut map
 * (atmos_image_gamut_map) -> tone map with desc's manual exposure (atmos_tonemap_into; an
 * automatic one is refused: atmos_tonemap_scale of the linear image gives the manual scale)
 * into disp (4 channels of display values; NULL: not kept) and/or rgba8 (width x height x 4
 * bytes rounded as atmos_write_png rounds, alpha 255; NULL: not made). The same values as the
 * three calls, bit for bit, for any thread count. */
ATMOS_API atmos_status atmos_image_display_into(atmos_context *ctx, const atmos_image *spectral,
                                                const atmos_wavelengths *wl, const atmos_tonemap_desc *desc,
                                                atmos_image *disp, unsigned char *rgba8);
/* atmos_image_display_into that refuses (ATMOS_E_UNSUPPORTED) a frame holding a NaN or an
 * infinity in any channel, found from the same reads of the frame (the viewer's frames rendered
 * with atmos_frame.no_check: one pass over the frame instead of two). The display values are
 * made either way; the message names the count and the first such pixel. */
ATMOS_API atmos_status atmos_image_display_checked(atmos_context *ctx, const atmos_image *spectral,
                                                   const atmos_wavelengths *wl, const atmos_tonemap_desc *desc,
                                                   atmos_image *disp, unsigned char *rgba8);

#ifdef __cplusplus
}
#endif
#endif
