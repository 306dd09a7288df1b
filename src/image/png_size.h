/* A PNG file's size from its header alone (libpng), so that a caller with its own bound on
 * the pixels can refuse a large image before it is decoded. Not part of the API. */
#ifndef ATMOS_IMAGE_PNG_SIZE_H
#define ATMOS_IMAGE_PNG_SIZE_H

#include <stdint.h>

/* 1 with the width and height in *w, *h; 0 when the file cannot be opened or its header read
 * (atmos_read_png then says why). */
int atmos__png_size(const char *path, uint32_t *w, uint32_t *h);

#endif
