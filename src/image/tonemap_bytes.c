/* A frame's 8-bit display values straight from the exposure-scaled linear value x = v scale, by
 * a table per tone curve (the window's frames, which need no float display values): the byte
 * that the curve, the sRGB table (atmos__tonemap_row) and the PNG's rounding give is a function
 * of x alone, and it steps by at most one level within 1/256 of an octave of x. So the table
 * holds, for each 1/256 octave of x (the float's exponent and first 8 mantissa bits), the byte at
 * its start and the first of its other 15 mantissa bits where the byte is one level higher: a
 * table read and a comparison a value instead of the curve's division and two reads of the sRGB
 * table. The table is made by evaluating that very path (each interval's ends and a bisection
 * between them); where the path's roundings step back and forth about a step (v 255 + 1/2 within
 * a few ulps of a whole number), its interval is marked and its values take the path itself. The
 * same bytes as the path (test_display compares the two over every 5th float from 2^-17 to 2^11,
 * the table's range and an octave either side; every float of it with ATMOS_TEST_EXHAUSTIVE=1). */
#include "core/internal.h"
#include "image/display_internal.h"

#include <stdatomic.h>
#include <stdint.h>
#include <string.h>

#define BYTE_SEG_BITS 8                                   /* 256 intervals an octave */
#define BYTE_LOW_BITS (23 - BYTE_SEG_BITS)                /* the mantissa bits within one */
#define BYTE_LO_EXP (-16)                                 /* from x = 2^-16 (byte 0 below) */
#define BYTE_OCTAVES 26                                   /* to 2^10 (byte 255 above) */
#define BYTE_LUT (BYTE_OCTAVES << BYTE_SEG_BITS)
#define BYTE_FIRST ((uint32_t)(127 + BYTE_LO_EXP) << 23) /* the float bits of 2^BYTE_LO_EXP */
#define BYTE_NEVER (1u << BYTE_LOW_BITS)                  /* no step within the interval */

/* entry: the interval's first byte << 16 | the low bits from which it is one more */
static uint32_t byte_lut[3][BYTE_LUT];
static _Atomic int byte_lut_state[3]; /* 0 not made, 1 made, 2 not usable (the path steps by more) */

/* The byte of a display value v (the PNG's rounding). */
static int byte_of(float v) { return !(v > 0) ? 0 : v >= 1 ? 255 : (int)(unsigned char)(v * 255.0f + 0.5f); }

/* The bytes of the float display path at the floats with bits from `bits`, n of them (scale 1:
 * x 1 = x). */
#define BYTE_WINDOW 256 /* floats checked at each end of an interval and about its step */

static void bytes_at(atmos_tone_curve curve, uint32_t bits, int n, int *out)
{
    float x[2 * BYTE_WINDOW] = {0}, v[2 * BYTE_WINDOW];
    for (int i = 0; i < n; i++) {
        const uint32_t u = bits + (uint32_t)i;
        memcpy(&x[i], &u, sizeof x[i]);
    }
    atmos__tonemap_row(curve, x, v, (size_t)n, 1, 1.0f);
    for (int i = 0; i < n; i++) out[i] = byte_of(v[i]);
}

/* The byte of one float (without bytes_at's window and its 2 KB zeroing). */
static int byte_at(atmos_tone_curve curve, uint32_t bits)
{
    float x, v;
    memcpy(&x, &bits, sizeof x);
    atmos__tonemap_row(curve, &x, &v, 1, 1, 1.0f);
    return byte_of(v);
}

/* 1 when the floats [from, from + n) of interval lo's give the bytes entry e says (the path's
 * roundings may step back and forth where v 255 + 1/2 is within a few of its ulps of a whole
 * number: near the step, and at the interval's ends, next to another's step). */
static int entry_holds(atmos_tone_curve curve, uint32_t lo, uint32_t e, uint32_t from, int n)
{
    int b[2 * BYTE_WINDOW];
    bytes_at(curve, from, n, b);
    for (int i = 0; i < n; i++)
        if (b[i] != (int)((e >> 16) & 0xffu) + ((from + (uint32_t)i - lo) >= (e & 0xffffu))) return 0;
    return 1;
}

/* Curve's table; 0 when the path steps by more than a level within an interval or is not
 * constant below and above the table's range. An interval where the path's bytes do not follow
 * its entry next to the step or at its ends is marked BYTE_EXACT: its values take the path. */
#define BYTE_EXACT 0x80000000u
static int make_table(atmos_tone_curve curve, uint32_t *lut)
{
    const uint32_t top = BYTE_FIRST + ((uint32_t)BYTE_LUT << BYTE_LOW_BITS);
    if (byte_at(curve, 0) != byte_at(curve, BYTE_FIRST + BYTE_NEVER - 1) ||
        byte_at(curve, top - BYTE_NEVER) != byte_at(curve, 0x7f800000u))
        return 0;
    for (int i = 0; i < BYTE_LUT; i++) {
        const uint32_t lo = BYTE_FIRST + ((uint32_t)i << BYTE_LOW_BITS), hi = lo + BYTE_NEVER - 1;
        const int b0 = byte_at(curve, lo), b1 = byte_at(curve, hi);
        if (b1 != b0 && b1 != b0 + 1) return 0;
        uint32_t a = lo, b = hi; /* the first bits with b1: in (a, b] */
        if (b1 == b0) b = lo + BYTE_NEVER;
        else
            while (b - a > 1) {
                const uint32_t m = a + (b - a) / 2;
                if (byte_at(curve, m) == b1) b = m;
                else a = m;
            }
        uint32_t e = (uint32_t)b0 << 16 | (b - lo);
        const uint32_t c = b - lo < BYTE_WINDOW ? lo : b - lo > BYTE_NEVER - BYTE_WINDOW ? hi + 1 - 2 * BYTE_WINDOW : b - BYTE_WINDOW;
        if (!entry_holds(curve, lo, e, lo, BYTE_WINDOW) || !entry_holds(curve, lo, e, hi + 1 - BYTE_WINDOW, BYTE_WINDOW) ||
            !entry_holds(curve, lo, e, c, 2 * BYTE_WINDOW))
            e |= BYTE_EXACT;
        lut[i] = e;
    }
    return 1;
}

const uint32_t *atmos__tonemap_byte_table(atmos_tone_curve curve)
{
    if ((unsigned)curve > 2u) return NULL;
    int st = atomic_load_explicit(&byte_lut_state[curve], memory_order_acquire);
    if (!st) {
#pragma omp critical(atmos_byte_lut)
        {
            st = atomic_load_explicit(&byte_lut_state[curve], memory_order_relaxed);
            if (!st) {
                st = make_table(curve, byte_lut[curve]) ? 1 : 2;
                atomic_store_explicit(&byte_lut_state[curve], st, memory_order_release);
            }
        }
    }
    return st == 1 ? byte_lut[curve] : NULL;
}

/* The table's interval of the float with bits u (clamped to the first and the last). */
static inline int interval_of(uint32_t u)
{
    const int k = (int)(u >> BYTE_LOW_BITS) - (int)(BYTE_FIRST >> BYTE_LOW_BITS);
    return k < 0 ? 0 : k < BYTE_LUT ? k : BYTE_LUT - 1;
}

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__SANITIZE_ADDRESS__) && !defined(__clang__)
#include <immintrin.h>
#define BYTES_AVX2 1
/* The table's bytes of a chunk's m values (m a multiple of 8) with AVX2 (GCC vectorises the
 * portable loop with 64-bit gather indices, two gathers of four where one of eight will do):
 * q as the portable loop makes it; returns the BYTE_EXACT marks of the colours OR-ed. */
__attribute__((target("avx2"))) static uint32_t table_bytes_avx2(const uint32_t *lut, const float *s, uint32_t *q, int m,
                                                                  float scale)
{
    const __m256 sc = _mm256_set1_ps(scale), zero = _mm256_setzero_ps();
    const __m256i first = _mm256_set1_epi32((int)(BYTE_FIRST >> BYTE_LOW_BITS)), last = _mm256_set1_epi32(BYTE_LUT - 1),
                  low = _mm256_set1_epi32(BYTE_NEVER - 1), ff = _mm256_set1_epi32(0xff), ffff = _mm256_set1_epi32(0xffff),
                  mark = _mm256_set1_epi32((int)BYTE_EXACT), colours = _mm256_setr_epi32(-1, -1, -1, 0, -1, -1, -1, 0);
    __m256i exact = _mm256_setzero_si256();
    for (int j = 0; j < m; j += 8) {
        const __m256 x = _mm256_max_ps(_mm256_mul_ps(_mm256_loadu_ps(s + j), sc), zero); /* NaN: 0 */
        const __m256i u = _mm256_castps_si256(x);
        __m256i k = _mm256_sub_epi32(_mm256_srli_epi32(u, BYTE_LOW_BITS), first);
        k = _mm256_min_epi32(_mm256_max_epi32(k, _mm256_setzero_si256()), last);
        const __m256i e = _mm256_i32gather_epi32((const int *)lut, k, 4);
        const __m256i t = _mm256_and_si256(u, low), thr = _mm256_and_si256(e, ffff);
        /* t >= thr (both below 2^16): 1 where max(t, thr) == t */
        const __m256i step = _mm256_srli_epi32(_mm256_cmpeq_epi32(_mm256_max_epi32(t, thr), t), 31);
        const __m256i b = _mm256_add_epi32(_mm256_and_si256(_mm256_srli_epi32(e, 16), ff), step);
        const __m256i em = _mm256_and_si256(e, mark);
        _mm256_storeu_si256((__m256i *)(q + j), _mm256_or_si256(b, em));
        exact = _mm256_or_si256(exact, _mm256_and_si256(em, colours));
    }
    uint32_t lane[8], all = 0;
    _mm256_storeu_si256((__m256i *)lane, exact);
    for (int i = 0; i < 8; i++) all |= lane[i];
    return all;
}
#endif

/* Width RGBA pixels of linear sRGB (src) to 8-bit display values, alpha 255: each colour scaled,
 * NaN and negatives 0 (as the curve takes them; x > 0 ? x : 0 and maxps alike), its byte from
 * the table (BYTE_EXACT kept), the values of the intervals marked BYTE_EXACT again by the path.
 * In chunks of three loops (the table's reads; any colour marked; the bytes). */
ATMOS_CLONES void atmos__tonemap_bytes_row(atmos_tone_curve curve, const uint32_t *restrict lut, const float *restrict src,
                                           unsigned char *restrict dst, size_t width, float scale)
{
    enum { CHUNK = 256 }; /* a multiple of 8: a chunk's lane j is channel j & 3 */
    uint32_t q[CHUNK];
    const size_t n = 4 * width;
#ifdef BYTES_AVX2
    const int avx2 = __builtin_cpu_supports("avx2");
#endif
    for (size_t j0 = 0; j0 < n; j0 += CHUNK) {
        const int m = n - j0 < CHUNK ? (int)(n - j0) : CHUNK;
        const float *s = src + j0;
        unsigned char *d = dst + j0;
        uint32_t exact = 0;
        int j = 0;
#ifdef BYTES_AVX2
        if (avx2) exact = table_bytes_avx2(lut, s, q, j = m & ~7, scale);
#endif
        for (; j < m; j++) {
            float x = s[j] * scale;
            x = x > 0 ? x : 0.0f;
            uint32_t u;
            memcpy(&u, &x, sizeof u);
            const uint32_t e = lut[interval_of(u)];
            q[j] = (e & BYTE_EXACT) | (((e >> 16) & 0xffu) + ((u & (BYTE_NEVER - 1)) >= (e & 0xffffu)));
            exact |= (j & 3) == 3 ? 0u : q[j];
        }
        if (exact & BYTE_EXACT) { /* the marked values through the float path, the chunk's at once */
            float x[CHUNK], v[CHUNK];
            int at[CHUNK], ne = 0;
            for (j = 0; j < m; j++)
                if ((j & 3) != 3 && (q[j] & BYTE_EXACT)) {
                    const float y = s[j] * scale;
                    x[ne] = y > 0 ? y : 0.0f, at[ne++] = j;
                }
            atmos__tonemap_row(curve, x, v, (size_t)ne, 1, 1.0f);
            for (int i = 0; i < ne; i++) q[at[i]] = (uint32_t)byte_of(v[i]);
        }
        for (j = 0; j < m; j++) d[j] = (j & 3) == 3 ? 255 : (unsigned char)q[j];
    }
}
