/* The beam renderer's buffers kept between frames (beams_kept.h). */
#include "render/beams_kept.h"
#include "core/internal.h"

#include <stdlib.h>

void *atmos__beams_kept_get(atmos__beams_kept *k, size_t bytes)
{
    if (bytes == 0) bytes = 1;
    if (k->p && k->size >= bytes) return k->p;
    free(k->p); /* no realloc: the old contents need not be copied */
    bytes = atmos__big_size(bytes); /* its whole pages */
    k->p = atmos__big_alloc(bytes); /* on 2 MB pages where large: a few faults, not one a 4 KB page */
    k->size = k->p ? bytes : 0;
    return k->p;
}

void atmos__beams_kept_free(atmos__beams_kept *k)
{
    free(k->p);
    k->p = NULL, k->size = 0;
}
