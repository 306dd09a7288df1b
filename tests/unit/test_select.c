/* atmos__select_float (core/select.c): the k-th smallest of an array against the sorted array
 * (qsort), on random arrays, arrays of few distinct values, sorted, reversed and equal ones. */
#include "core/internal.h"
#include "test.h"

#include <stdlib.h>
#include <string.h>

static int cmp_float(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static unsigned lcg(unsigned *s)
{
    return *s = *s * 1664525u + 1013904223u, *s >> 8;
}

/* fills v (n values) by kind: 0 random, 1 of 3 values, 2 ascending, 3 descending, 4 equal */
static void fill(float *v, size_t n, int kind, unsigned *s)
{
    for (size_t i = 0; i < n; i++)
        v[i] = kind == 0 ? (float)(lcg(s) % 100000) / 7.0f
             : kind == 1 ? (float)(lcg(s) % 3)
             : kind == 2 ? (float)i
             : kind == 3 ? (float)(n - i)
                         : 0.5f;
}

int main(void)
{
    unsigned s = 7;
    const size_t sizes[] = {1, 2, 3, 5, 17, 100, 1001, 65536};
    int bad = 0, runs = 0;
    for (int kind = 0; kind < 5; kind++)
        for (size_t z = 0; z < sizeof sizes / sizeof *sizes; z++) {
            const size_t n = sizes[z];
            float *v = malloc(n * sizeof *v), *w = malloc(n * sizeof *w), *sorted = malloc(n * sizeof *v);
            if (!v || !w || !sorted) return free(v), free(w), free(sorted), test_summary("test_select");
            fill(v, n, kind, &s);
            memcpy(sorted, v, n * sizeof *v);
            qsort(sorted, n, sizeof *sorted, cmp_float);
            const size_t ks[] = {0, n / 2, (size_t)(0.99 * (double)(n - 1)), n - 1};
            for (int j = 0; j < 12; j++) { /* then after 0 and 1 partitions, the sort's fallback */
                memcpy(w, v, n * sizeof *v);
                const float got = j < 4 ? atmos__select_float(w, n, ks[j % 4])
                                        : atmos__select_float_depth(w, n, ks[j % 4], j < 8 ? 0 : 1);
                runs++;
                if (got != sorted[ks[j % 4]]) {
                    bad++;
                    fprintf(stderr, "kind %d n %zu k %zu (%d): %g, sorted %g\n", kind, n, ks[j % 4], j / 4, got,
                            sorted[ks[j % 4]]);
                }
            }
            free(v), free(w), free(sorted);
        }
    CHECK_MSG(bad == 0, "%d of %d selections differ from the sorted array's element", bad, runs);
    return test_summary("test_select");
}
