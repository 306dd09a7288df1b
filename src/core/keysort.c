/* Sorting indices by a key (internal.h, atmos__keyed_sort). */
#include "core/internal.h"

#include <stdlib.h>

static int ascending(const void *a, const void *b)
{
    const atmos__keyed *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

static int descending(const void *a, const void *b)
{
    const atmos__keyed *x = a, *y = b;
    if (x->key != y->key) return x->key > y->key ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

void atmos__keyed_sort(atmos__keyed *a, size_t n, int desc) { qsort(a, n, sizeof *a, desc ? descending : ascending); }
