/* A buffer the beam renderer's plan keeps between frames: a frame's per-pixel arrays made once
 * and used again by the next frame of the same size or smaller, so that each frame does not
 * fault fresh pages in (about 17 MB a frame at 720x480). Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_KEPT_H
#define ATMOS_RENDER_BEAMS_KEPT_H

#include <stddef.h>

typedef struct atmos__beams_kept {
    void *p;
    size_t size; /* bytes held */
} atmos__beams_kept;

/* At least bytes of k's buffer (its contents undefined), made larger when needed; NULL when out
 * of memory (k then holds nothing). */
void *atmos__beams_kept_get(atmos__beams_kept *k, size_t bytes);
void atmos__beams_kept_free(atmos__beams_kept *k);

#endif
