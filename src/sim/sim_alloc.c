/* The simulation's arrays: 64-byte aligned, on 2 MB pages where large (atmos__big_alloc), so
 * that a level's FFT plan does not depend on where malloc put it (sim_internal.h). */
#include "sim/sim_internal.h"

#include <stdlib.h>

void *atmos__sim_alloc(size_t bytes)
{
    if (bytes >= ((size_t)1 << 20)) return atmos__big_alloc(bytes); /* 2 MB aligned */
    return aligned_alloc(64, (bytes + 63) / 64 * 64 + (bytes ? 0 : 64));
}
