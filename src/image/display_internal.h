/* The per-pixel steps of the display path (gamut.c, tonemap.c), shared with the one-pass
 * version of it (display.c) so that both give the same bits. Internal to src/image/. */
#ifndef ATMOS_IMAGE_DISPLAY_INTERNAL_H
#define ATMOS_IMAGE_DISPLAY_INTERNAL_H

#include "atmos/image.h"

#include <stddef.h>
#include <stdint.h>

/* One linear sRGB pixel (3 components at p) brought inside the gamut (atmos_image_gamut_map);
 * 1 when it was moved. */
int atmos__gamut_pixel(float *p);
/* One row of width pixels of C (3 or 4) channels tone mapped with the linear scale `scale`
 * (atmos_tonemap_into's row: the curve, the sRGB table, alpha clamped). */
void atmos__tonemap_row(atmos_tone_curve curve, const float *src, float *dst, size_t width, int C, float scale);
/* The table of the 8-bit display values of a curve over the scaled linear value (tonemap_bytes.c,
 * made by the first call); NULL when it cannot stand for atmos__tonemap_row and the rounding. */
const uint32_t *atmos__tonemap_byte_table(atmos_tone_curve curve);
/* One row of width RGBA linear sRGB pixels scaled by `scale` to 8-bit display values from the
 * curve's table, alpha 255: the bytes of atmos__tonemap_row's values rounded as a PNG's. */
void atmos__tonemap_bytes_row(atmos_tone_curve curve, const uint32_t *lut, const float *src, unsigned char *dst,
                              size_t width, float scale);

#endif
