/* The plan's one pass over a rendered frame (atmos__copy_not_finite, core/finite.c): over rows of
 * every length from 0 to 40 and a frame's row (720 pixels of 17 channels), with one NaN, one
 * infinity of either sign or none at each position, among finite values that come nearest
 * (the largest float, a subnormal, -0), each row and its copy at every offset from a 16-byte
 * boundary: the count of NaNs and infinities is the count value by
 * value, with and without the copy, and the copy holds the row's bits. */
#include "core/finite.h"
#include "test.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

static size_t naive(const float *row, size_t n)
{
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) bad += !isfinite(row[i]);
    return bad;
}

/* Row n with value bad at position at (at == n: no bad value); the finite values cycle
 * through the edges of the finite range. */
static void fill(float *row, size_t n, size_t at, float bad)
{
    static const float edge[] = {FLT_MAX, -FLT_MAX, 1e-45f, -0.0f, 0.0f, 1.0f, 3.4e38f, -1e-40f};
    for (size_t i = 0; i < n; i++) row[i] = edge[(i * 5 + n) % 8];
    if (at < n) row[at] = bad;
}

static int check_row(float *row, float *dst, size_t n, size_t at, float bad)
{
    fill(row, n, at, bad);
    for (size_t i = 0; i <= n; i++) dst[i] = 7.0f; /* dst[n]: must stay */
    const size_t want = naive(row, n);
    const size_t got = atmos__copy_not_finite(dst, row, n), alone = atmos__copy_not_finite(NULL, row, n);
    int ok = got == want && alone == want && dst[n] == 7.0f && !memcmp(dst, row, sizeof(float) * n);
    if (!ok) fprintf(stderr, "n %zu, %g at %zu: counted %zu and %zu, want %zu\n", n, (double)bad, at, got, alone, want);
    return ok;
}

int main(void)
{
    const float bads[] = {NAN, -NAN, INFINITY, -INFINITY};
    const size_t frame_row = 720 * 17;
    float *row = malloc(sizeof(float) * (frame_row + 4)), *dst = malloc(sizeof(float) * (frame_row + 4));
    if (!row || !dst) return 1;
    int failed = 0, rows = 0;
    /* the rows and their copies at every offset from a 16-byte boundary (the kept frame's rows
       start anywhere: the copy's first values go one by one up to the boundary) */
    for (size_t so = 0; so < 4; so++)
        for (size_t doff = 0; doff < 4; doff++)
            for (size_t n = 0; n <= 40; n++)
                for (int b = 0; b < 4; b++)
                    for (size_t at = 0; at <= n; at++)
                        failed += !check_row(row + so, dst + doff, n, at, bads[b]), rows++;
    for (int b = 0; b < 4; b++)
        for (size_t at = 0; at <= frame_row; at += at < 64 || at > frame_row - 64 ? 1 : 97)
            failed += !check_row(row, dst, frame_row, at, bads[b]), rows++;
    CHECK_MSG(failed == 0, "%d of %d rows counted or copied wrong", failed, rows);
    /* every value of a row bad: the count is the row's length */
    for (size_t i = 0; i < 37; i++) row[i] = bads[i % 4];
    CHECK(atmos__copy_not_finite(dst, row, 37) == 37);
    CHECK(atmos__copy_not_finite(NULL, row, 37) == 37);
    free(row);
    free(dst);
    return test_summary("finite_copy");
}
