/* Sorting indices by a key (internal.h, atmos__keyed_sort). The order is total (the key, then
 * the index), so any algorithm gives the same result: a least-significant-digit radix sort over
 * the key's bits (and the index's, unless the entries come in ascending index order already,
 * as the splats' lists do), a byte a pass, the passes whose byte is the same in every entry
 * skipped; qsort for short arrays, a NaN key (which the comparison does not order) or no
 * memory. */
#include "core/internal.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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

/* Below this many entries qsort is as quick. */
#define RADIX_MIN 256

/* The key as an unsigned integer in the sort's order (-0 and +0 equal, as the comparison has
 * them; descending: the complement). */
static uint64_t key_bits(double k, int desc)
{
    if (k == 0) k = 0.0;
    uint64_t u;
    memcpy(&u, &k, sizeof u);
    u = u >> 63 ? ~u : u | UINT64_C(0x8000000000000000);
    return desc ? ~u : u;
}

/* The entry's 12 bytes of order, least significant first: the index's 4 (signed order), then
 * the key's 8. */
static unsigned digit(uint64_t kb, int index, int d)
{
    return d < 4 ? ((uint32_t)index ^ UINT32_C(0x80000000)) >> (8 * d) & 255u : (unsigned)(kb >> (8 * (d - 4)) & 255u);
}

/* a[0..n) sorted with the radix passes over ka (their keys' bits); tb, kb: room for n each.
 * Returns 0 (a left as it was) without memory. */
static int radix(atmos__keyed *a, uint64_t *ka, atmos__keyed *tb, uint64_t *kb, size_t n, int by_index)
{
    static const int ND = 12;
    size_t (*count)[256] = calloc(ND, sizeof *count);
    if (!count) return 0;
    for (size_t i = 0; i < n; i++)
        for (int d = by_index ? 0 : 4; d < ND; d++) count[d][digit(ka[i], a[i].index, d)]++;
    atmos__keyed *src = a, *dst = tb;
    uint64_t *ks = ka, *kd = kb;
    for (int d = by_index ? 0 : 4; d < ND; d++) {
        if (count[d][digit(ks[0], src[0].index, d)] == n) continue; /* the same byte everywhere */
        size_t at = 0;
        for (int b = 0; b < 256; b++) {
            const size_t c = count[d][b];
            count[d][b] = at, at += c;
        }
        for (size_t i = 0; i < n; i++) {
            const size_t j = count[d][digit(ks[i], src[i].index, d)]++;
            dst[j] = src[i], kd[j] = ks[i];
        }
        atmos__keyed *t = src;
        src = dst, dst = t;
        uint64_t *u = ks;
        ks = kd, kd = u;
    }
    if (src != a) memcpy(a, src, sizeof *a * n);
    free(count);
    return 1;
}

void atmos__keyed_sort(atmos__keyed *a, size_t n, int desc)
{
    int (*cmp)(const void *, const void *) = desc ? descending : ascending;
    if (n < RADIX_MIN) {
        qsort(a, n, sizeof *a, cmp);
        return;
    }
    uint64_t *ka = malloc(sizeof *ka * 2 * n);
    atmos__keyed *tb = malloc(sizeof *tb * n);
    int by_index = 0, nan = 0;
    for (size_t i = 0; ka && i < n; i++) {
        nan |= a[i].key != a[i].key;
        ka[i] = key_bits(a[i].key, desc);
        by_index |= i > 0 && a[i].index <= a[i - 1].index;
    }
    if (!ka || !tb || nan || !radix(a, ka, tb, ka + n, n, by_index)) qsort(a, n, sizeof *a, cmp);
    free(ka), free(tb);
}
