/* The check that a frame holds no NaN and no infinity (DESIGN §5), shared by the plan's check of a
 * rendered frame and the display pass that checks it while reading it. */
#ifndef ATMOS_CORE_FINITE_H
#define ATMOS_CORE_FINITE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* 1 for a NaN or an infinity: all exponent bits set (integer operations, so that a loop over a
 * row vectorises: isfinite's did not). */
static inline unsigned atmos__not_finite(float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    return (u & 0x7f800000u) == 0x7f800000u;
}

/* The index of the first NaN or infinity among row[0 .. n), or n when there is none. */
static inline size_t atmos__first_not_finite(const float *row, size_t n)
{
    size_t i = 0;
    while (i < n && !atmos__not_finite(row[i])) i++;
    return i;
}

/* The number of NaNs and infinities among src[0 .. n); with dst, src copied there in the same
 * pass (the plan's kept frame). One load a value: the row's greatest |bits| against the
 * exponent's, counted value by value only in a row that holds one (finite.c). */
size_t atmos__copy_not_finite(float *restrict dst, const float *restrict src, size_t n);

#endif
