/* atmos__keyed_sort: the key, then the index, ascending or descending (ties by ascending
 * index), the same order as qsort with that comparison for any input: short and long arrays
 * (the radix sort), indices in order or shuffled or repeated, keys with many ties, negative,
 * +0 and -0 (equal), infinities, all equal, and a NaN (left to qsort). */
#include "core/internal.h"
#include "test.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int ref_cmp(const atmos__keyed *x, const atmos__keyed *y, int desc)
{
    if (x->key != y->key) return (desc ? x->key > y->key : x->key < y->key) ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}
static int ref_asc(const void *a, const void *b) { return ref_cmp(a, b, 0); }
static int ref_desc(const void *a, const void *b) { return ref_cmp(a, b, 1); }

/* The key of entry i for a kind of input (u: a uniform draw). */
static double key_of(int kind, size_t i, double u)
{
    switch (kind) {
    case 0: return 2000.0 * u - 1000.0;                         /* distinct, both signs */
    case 1: return floor(8.0 * u) - 4.0;                        /* many ties */
    case 2: return u < 0.3 ? 0.0 : u < 0.6 ? -0.0 : (u < 0.8 ? INFINITY : -INFINITY); /* zeros, infinities */
    case 3: return 5.0;                                         /* all equal */
    default: return i % 3 ? 1e-300 * u : 1e300 * (u - 0.5);     /* wide exponents */
    }
}

static void check_one(size_t n, int kind, int indices, int desc, uint64_t *rng)
{
    atmos__keyed *a = malloc(sizeof *a * (n ? n : 1)), *b = malloc(sizeof *b * (n ? n : 1));
    if (!a || !b) {
        free(a), free(b);
        CHECK(0);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        a[i].key = key_of(kind, i, test_uniform_from(rng));
        /* in order (the splats' lists), shuffled (negative too), or repeated */
        a[i].index = indices == 0 ? (int)i
                                  : indices == 1 ? (int)(test_uniform_from(rng) * 2e9) - 1000000000
                                                 : (int)(test_uniform_from(rng) * 5);
    }
    memcpy(b, a, sizeof *a * n);
    atmos__keyed_sort(a, n, desc);
    qsort(b, n, sizeof *b, desc ? ref_desc : ref_asc);
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) bad += memcmp(&a[i].key, &b[i].key, sizeof a[i].key) != 0 || a[i].index != b[i].index;
    /* -0 and +0 are equal keys, so entries equal by the order may hold either zero */
    if (kind == 2) {
        bad = 0;
        for (size_t i = 0; i < n; i++) bad += a[i].key != b[i].key || a[i].index != b[i].index;
    }
    CHECK_MSG(bad == 0, "n %zu kind %d indices %d desc %d: %zu entries out of place", n, kind, indices, desc, bad);
    free(a), free(b);
}

int main(void)
{
    uint64_t rng = 12345;
    const size_t sizes[] = {0, 1, 7, 255, 256, 257, 1000, 40000};
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++)
        for (int kind = 0; kind < 5; kind++)
            for (int indices = 0; indices < 3; indices++)
                for (int desc = 0; desc < 2; desc++) check_one(sizes[s], kind, indices, desc, &rng);
    /* a NaN: the same order as qsort's with the comparison (whatever that makes of it) */
    atmos__keyed a[600], b[600];
    for (int i = 0; i < 600; i++) a[i].key = i == 300 ? NAN : (double)((i * 7919) % 600), a[i].index = i;
    memcpy(b, a, sizeof a);
    atmos__keyed_sort(a, 600, 0);
    qsort(b, 600, sizeof *b, ref_asc);
    int same = 1;
    for (int i = 0; i < 600; i++) same &= a[i].index == b[i].index;
    CHECK(same);
    return test_summary("test_keysort");
}
