/* The per-pixel steps of the display path (gamut.c, tonemap.c), shared with the one-pass
 * version of it (display.c) so that both give the same bits. Internal to src/image/. */
#ifndef ATMOS_IMAGE_DISPLAY_INTERNAL_H
#define ATMOS_IMAGE_DISPLAY_INTERNAL_H

#include "atmos/image.h"

#include <stddef.h>

/* One linear sRGB pixel (3 components at p) brought inside the gamut (atmos_image_gamut_map);
 * 1 when it was moved. */
int atmos__gamut_pixel(float *p);
/* One row of width pixels of C (3 or 4) channels tone mapped with the linear scale `scale`
 * (atmos_tonemap_into's row: the curve, the sRGB table, alpha clamped). */
void atmos__tonemap_row(atmos_tone_curve curve, const float *src, float *dst, size_t width, int C, float scale);

#endif
