/* Large buffers that renderers read at random. */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE /* madvise */
#include "core/internal.h"

#include <stdlib.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

void *atmos__big_alloc(size_t bytes)
{
    const size_t huge = (size_t)2 << 20;
    if (bytes < huge / 2) return malloc(bytes ? bytes : 1);
    size_t sz = (bytes + huge - 1) / huge * huge;
    void *p = NULL;
    if (posix_memalign(&p, huge, sz) != 0) return NULL;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    (void)madvise(p, sz, MADV_HUGEPAGE);
#endif
    return p;
}
