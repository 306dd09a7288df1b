/* The plan's one pass over a rendered frame: its check for NaNs and infinities and its kept copy
 * (finite.h). */
#include "core/finite.h"

#if defined(__SSE2__)
#  include <emmintrin.h>
#endif

/* A value is not finite when its bits without the sign are above the largest float's: each row is
 * first tested as a whole, with no count (the SSE2 path: four values a vector, an and, a compare
 * and an or; their copy stored from the same register with streaming stores, which do not read
 * the kept frame's lines into the cache, nor push the renderer's tables out of it: the copy is read
 * again only by a later call of the same view). A row that holds one is counted again value by
 * value (a renderer bug, refused by the caller: not a path worth its speed). */
size_t atmos__copy_not_finite(float *restrict dst, const float *restrict src, size_t n)
{
    uint32_t any = 0;
    size_t i = 0;
#if defined(__SSE2__)
    if (dst)
        for (; i < n && ((uintptr_t)(dst + i) & 15u); i++) {
            uint32_t u;
            memcpy(&u, src + i, sizeof u);
            dst[i] = src[i];
            any |= (u & 0x7fffffffu) > 0x7f7fffffu;
        }
    const __m128i mask = _mm_set1_epi32(0x7fffffff), top = _mm_set1_epi32(0x7f7fffff);
    __m128i acc = _mm_setzero_si128();
    if (dst)
        for (; i + 4 <= n; i += 4) {
            const __m128 v = _mm_loadu_ps(src + i);
            _mm_stream_ps(dst + i, v);
            acc = _mm_or_si128(acc, _mm_cmpgt_epi32(_mm_and_si128(_mm_castps_si128(v), mask), top));
        }
    else
        for (; i + 4 <= n; i += 4) {
            const __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(src + i));
            acc = _mm_or_si128(acc, _mm_cmpgt_epi32(_mm_and_si128(v, mask), top));
        }
    if (dst) _mm_sfence(); /* the streamed copy ordered before what follows */
    any |= (uint32_t)_mm_movemask_epi8(acc);
#endif
    for (; i < n; i++) {
        uint32_t u;
        memcpy(&u, src + i, sizeof u);
        if (dst) dst[i] = src[i];
        any |= (u & 0x7fffffffu) > 0x7f7fffffu;
    }
    if (!any) return 0;
    size_t bad = 0;
    for (i = 0; i < n; i++) bad += atmos__not_finite(src[i]);
    return bad;
}
