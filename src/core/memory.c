/* Large buffers that renderers read at random. */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE /* madvise */
#include "core/internal.h"

#include <stdlib.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#define HUGE_PAGE ((size_t)2 << 20)

size_t atmos__big_size(size_t bytes)
{
    return bytes < HUGE_PAGE / 2 ? bytes : (bytes + HUGE_PAGE - 1) / HUGE_PAGE * HUGE_PAGE;
}

void *atmos__big_alloc(size_t bytes)
{
    if (bytes < HUGE_PAGE / 2) return malloc(bytes ? bytes : 1);
    const size_t sz = atmos__big_size(bytes);
    void *p = NULL;
    if (posix_memalign(&p, HUGE_PAGE, sz) != 0) return NULL;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    (void)madvise(p, sz, MADV_HUGEPAGE);
#endif
    return p;
}
