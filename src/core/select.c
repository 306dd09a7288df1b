/* The k-th smallest of an array of floats by selection (internal.h): Hoare's quickselect with
 * a three-way partition (runs of equal values, as a heat map's zeros, cost one pass), the
 * pivot the median of the range's first, middle and last; past a depth of 2 log2 n
 * partitions (an adversarial order) the rest of the range is sorted. Linear time expected. */
#include "core/internal.h"

#include <stdlib.h>

static int cmp_float(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static float median3(float a, float b, float c)
{
    if (a > b) { const float t = a; a = b; b = t; }
    return c < a ? a : c > b ? b : c;
}

float atmos__select_float(float *v, size_t n, size_t k)
{
    int depth = 2;
    for (size_t m = n; m > 1; m >>= 1) depth += 2;
    return atmos__select_float_depth(v, n, k, depth);
}

float atmos__select_float_depth(float *v, size_t n, size_t k, int depth)
{
    size_t lo = 0, hi = n; /* the k-th lies in [lo, hi) */
    while (hi - lo > 1) {
        if (depth-- == 0) {
            qsort(v + lo, hi - lo, sizeof *v, cmp_float);
            return v[k];
        }
        const float pivot = median3(v[lo], v[lo + (hi - lo) / 2], v[hi - 1]);
        /* [lo, lt) < pivot, [lt, i) == pivot, [gt, hi) > pivot */
        size_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            const float x = v[i];
            if (x < pivot) v[i++] = v[lt], v[lt++] = x;
            else if (x > pivot) v[i] = v[--gt], v[gt] = x;
            else i++;
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else return pivot;
    }
    return v[k];
}
