/* Trilinear samples at rows of departure points (the semi-Lagrangian advection's inner loop,
 * sim_advect.c): one field, or four fields packed per cell. Positions are in the field's
 * index space, x and y wrap, z clamps to [0, nz_f - 1]. On x86-64 CPUs with AVX2 the
 * corners and weights of eight points are found at once and the corners fetched by
 * gathers, or, where the points' corners lie side by side in one grid row (most points of a
 * row in a smooth wind), by plain loads of the row; every lane does the scalar code's operations in the same order and precision
 * (single-precision positions, weights and interpolation, no fused multiply-adds), so both paths
 * give the same bits. A weight is the exact fraction of its float position (x - floor x has no
 * rounding where x >= 0), so the positions' single precision costs about half an ulp of x:
 * 3e-5 of a cell at 512 cells, 4e-6 at 64. Points far outside the grid (more than one domain
 * away) or NaN take the scalar path. */
#include "sim/sim_internal.h"

#include <string.h>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define SIM_AVX2 1
#include <immintrin.h>
#define AVX2 __attribute__((target("avx2")))
#define AVX2_INLINE static inline __attribute__((target("avx2"), always_inline))
#endif

/* The eight corners and weights of one sample (the scalar path). */
typedef struct {
    size_t c[4]; /* offsets of the corners (i0, j, k) of rows j0/j1 at levels k0/k1 */
    int i0, i1;
    float ax, ay, az;
} tri;

static inline void tri_setup(const atmos_sim *s, int nz_f, float x, float y, float z, tri *t)
{
    const int nx = s->nx, ny = s->ny;
    if (z < 0) z = 0;
    if (z > nz_f - 1) z = (float)(nz_f - 1);
    const int fx0 = sim_ifloor(x), fy0 = sim_ifloor(y), fz0 = sim_ifloor(z);
    t->ax = x - (float)fx0, t->ay = y - (float)fy0, t->az = z - (float)fz0;
    const int i0 = sim_wrap(fx0, nx), j0 = sim_wrap(fy0, ny), k0 = fz0;
    const int j1 = j0 + 1 == ny ? 0 : j0 + 1, k1 = k0 + 1 < nz_f ? k0 + 1 : k0;
    t->i0 = i0, t->i1 = i0 + 1 == nx ? 0 : i0 + 1;
    const size_t l0 = (size_t)k0 * nx * ny, l1 = (size_t)k1 * nx * ny;
    t->c[0] = l0 + (size_t)j0 * nx, t->c[1] = l0 + (size_t)j1 * nx;
    t->c[2] = l1 + (size_t)j0 * nx, t->c[3] = l1 + (size_t)j1 * nx;
}

static inline float tri_eval(const float *f, const tri *t)
{
    const int i0 = t->i0, i1 = t->i1;
    const float c00 = f[t->c[0] + i0] + t->ax * (f[t->c[0] + i1] - f[t->c[0] + i0]);
    const float c01 = f[t->c[1] + i0] + t->ax * (f[t->c[1] + i1] - f[t->c[1] + i0]);
    const float c10 = f[t->c[2] + i0] + t->ax * (f[t->c[2] + i1] - f[t->c[2] + i0]);
    const float c11 = f[t->c[3] + i0] + t->ax * (f[t->c[3] + i1] - f[t->c[3] + i0]);
    const float c0 = c00 + t->ay * (c01 - c00), c1 = c10 + t->ay * (c11 - c10);
    return c0 + t->az * (c1 - c0);
}

/* Four fields packed per cell (16 bytes a cell): tri_eval's arithmetic on each of them. */
typedef float v4f __attribute__((vector_size(16)));

static inline v4f ld4(const float *p)
{
    v4f v;
    memcpy(&v, p, sizeof v);
    return v;
}

static inline v4f tri_eval4(const float *f4, const tri *t)
{
    const size_t i0 = 4 * (size_t)t->i0, i1 = 4 * (size_t)t->i1;
    v4f c[4];
    for (int r = 0; r < 4; r++) {
        const v4f a = ld4(f4 + 4 * t->c[r] + i0), b = ld4(f4 + 4 * t->c[r] + i1);
        c[r] = a + t->ax * (b - a);
    }
    const v4f c0 = c[0] + t->ay * (c[1] - c[0]), c1 = c[2] + t->ay * (c[3] - c[2]);
    return c0 + t->az * (c1 - c0);
}

static void sample_scalar(const atmos_sim *s, const float *f, int nz_f, const float *x, const float *y,
                          const float *z, float *out, int a, int b)
{
    for (int m = a; m < b; m++) {
        tri t;
        tri_setup(s, nz_f, x[m], y[m], z[m], &t);
        out[m] = tri_eval(f, &t);
    }
}

static void sample4_scalar(const atmos_sim *s, const float *f4, int nz_f, const float *x, const float *y,
                           const float *z, float *out4, int a, int b)
{
    for (int m = a; m < b; m++) {
        tri t;
        tri_setup(s, nz_f, x[m], y[m], z[m], &t);
        const v4f q = tri_eval4(f4, &t);
        memcpy(out4 + 4 * m, &q, sizeof q);
    }
}

#ifdef SIM_AVX2
/* Corners and weights of eight points: i0, i1 (wrapped), the offsets of the four rows
 * (j0/j1 at k0/k1), the weights; and the same for four of them (a half). 0 if a point is
 * outside [-n, 2n) along x or y, or NaN. */
typedef struct {
    __m256i i0, i1, r[4];
    __m256 ax, ay, az;
} lanes8;
typedef struct {
    __m128i i0, i1, r[4];
    __m128 ax, ay, az;
} lanes4;

AVX2_INLINE __m256i wrap8(__m256i i, int n)
{
    const __m256i vn = _mm256_set1_epi32(n);
    const __m256i lo = _mm256_cmpgt_epi32(_mm256_setzero_si256(), i);
    const __m256i hi = _mm256_cmpgt_epi32(i, _mm256_set1_epi32(n - 1));
    return _mm256_sub_epi32(_mm256_add_epi32(i, _mm256_and_si256(lo, vn)), _mm256_and_si256(hi, vn));
}

AVX2_INLINE __m256i next8(__m256i i, int n) /* i + 1, n -> 0 */
{
    const __m256i p = _mm256_add_epi32(i, _mm256_set1_epi32(1));
    return _mm256_andnot_si256(_mm256_cmpeq_epi32(p, _mm256_set1_epi32(n)), p);
}

AVX2_INLINE __m256i outside8(__m256i i, int lo, int hi) /* lanes not in [lo, hi] */
{
    return _mm256_or_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(lo), i), _mm256_cmpgt_epi32(i, _mm256_set1_epi32(hi)));
}

AVX2_INLINE int setup8(const atmos_sim *s, int nz_f, const float *x, const float *y, const float *z, lanes8 *o)
{
    const int nx = s->nx, ny = s->ny;
    const __m256 X = _mm256_loadu_ps(x), Y = _mm256_loadu_ps(y);
    /* z < 0 -> 0, z > nz_f - 1 -> nz_f - 1, else z itself (a -0 or a NaN kept, as the scalar code) */
    const __m256 Z =
        _mm256_min_ps(_mm256_set1_ps((float)(nz_f - 1)), _mm256_max_ps(_mm256_setzero_ps(), _mm256_loadu_ps(z)));
    /* floor through int (the scalar sim_ifloor: -0 gives +0); out of range and NaN give INT_MIN */
    const __m256i ix = _mm256_cvttps_epi32(_mm256_floor_ps(X)), iy = _mm256_cvttps_epi32(_mm256_floor_ps(Y));
    const __m256i iz = _mm256_cvttps_epi32(_mm256_floor_ps(Z));
    const __m256i bad = _mm256_or_si256(_mm256_or_si256(outside8(ix, -nx, 2 * nx - 1), outside8(iy, -ny, 2 * ny - 1)),
                                        outside8(iz, 0, nz_f - 1));
    if (!_mm256_testz_si256(bad, bad)) return 0;
    o->ax = _mm256_sub_ps(X, _mm256_cvtepi32_ps(ix));
    o->ay = _mm256_sub_ps(Y, _mm256_cvtepi32_ps(iy));
    o->az = _mm256_sub_ps(Z, _mm256_cvtepi32_ps(iz));
    o->i0 = wrap8(ix, nx);
    o->i1 = next8(o->i0, nx);
    const __m256i j0 = wrap8(iy, ny), j1 = next8(j0, ny);
    const __m256i k1 = _mm256_min_epi32(_mm256_add_epi32(iz, _mm256_set1_epi32(1)), _mm256_set1_epi32(nz_f - 1));
    const __m256i vny = _mm256_set1_epi32(ny), vnx = _mm256_set1_epi32(nx);
    const __m256i l0 = _mm256_mullo_epi32(iz, vny), l1 = _mm256_mullo_epi32(k1, vny);
    o->r[0] = _mm256_mullo_epi32(_mm256_add_epi32(l0, j0), vnx);
    o->r[1] = _mm256_mullo_epi32(_mm256_add_epi32(l0, j1), vnx);
    o->r[2] = _mm256_mullo_epi32(_mm256_add_epi32(l1, j0), vnx);
    o->r[3] = _mm256_mullo_epi32(_mm256_add_epi32(l1, j1), vnx);
    return 1;
}

/* Points 0..3 (h = 0) or 4..7 (h = 1) of eight. */
AVX2_INLINE __m128i half_i(__m256i v, int h)
{
    return h ? _mm256_extracti128_si256(v, 1) : _mm256_castsi256_si128(v);
}

AVX2_INLINE __m128 half_f(__m256 v, int h)
{
    return h ? _mm256_extractf128_ps(v, 1) : _mm256_castps256_ps128(v);
}

AVX2_INLINE void half4(const lanes8 *e, int h, lanes4 *o)
{
    o->i0 = half_i(e->i0, h), o->i1 = half_i(e->i1, h);
    for (int q = 0; q < 4; q++) o->r[q] = half_i(e->r[q], h);
    o->ax = half_f(e->ax, h), o->ay = half_f(e->ay, h), o->az = half_f(e->az, h);
}

AVX2_INLINE __m256 lerp8(__m256 a, __m256 b, __m256 t) /* a + t (b - a) */
{
    return _mm256_add_ps(a, _mm256_mul_ps(t, _mm256_sub_ps(b, a)));
}

/* Whether eight points' corners lie side by side: the same rows (j0 and k0, so row 0's offset,
 * the same in every lane) and i0 = i0[0] + lane, none of the second corners wrapping (i0[0] + 8
 * < nx). Then i0[0], else -1. Points along a row of the grid in a smooth wind are mostly so: the
 * corners are then read by two unaligned loads a row instead of two gathers. */
AVX2_INLINE int run8(__m256i i0, __m256i row0, int nx)
{
    const __m256i d = _mm256_sub_epi32(i0, _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    const __m256i same = _mm256_and_si256(_mm256_cmpeq_epi32(d, _mm256_broadcastd_epi32(_mm256_castsi256_si128(d))),
                                          _mm256_cmpeq_epi32(row0, _mm256_broadcastd_epi32(_mm256_castsi256_si128(row0))));
    const int first = _mm256_cvtsi256_si32(i0);
    return _mm256_movemask_epi8(same) == -1 && first + 8 < nx ? first : -1;
}

/* Eight points of one field. */
AVX2 static void sample_avx2(const atmos_sim *s, const float *f, int nz_f, const float *x, const float *y,
                             const float *z, float *out, int n)
{
    int m = 0;
    for (; m + 8 <= n; m += 8) {
        lanes8 a;
        if (!setup8(s, nz_f, x + m, y + m, z + m, &a)) {
            sample_scalar(s, f, nz_f, x, y, z, out, m, m + 8);
            continue;
        }
        const int first = run8(a.i0, a.r[0], s->nx);
        __m256 c[4];
        for (int r = 0; r < 4; r++) {
            __m256 lo, hi;
            if (first >= 0) { /* the same corners as the gathers below, read in a row */
                const float *p = f + (size_t)_mm256_cvtsi256_si32(a.r[r]) + first;
                lo = _mm256_loadu_ps(p), hi = _mm256_loadu_ps(p + 1);
            } else {
                lo = _mm256_i32gather_ps(f, _mm256_add_epi32(a.r[r], a.i0), 4);
                hi = _mm256_i32gather_ps(f, _mm256_add_epi32(a.r[r], a.i1), 4);
            }
            c[r] = lerp8(lo, hi, a.ax);
        }
        _mm256_storeu_ps(out + m, lerp8(lerp8(c[0], c[1], a.ay), lerp8(c[2], c[3], a.ay), a.az));
    }
    sample_scalar(s, f, nz_f, x, y, z, out, m, n);
}

/* Four points of four packed fields, two points a 256-bit register. */
AVX2_INLINE __m256 load_pair(const float *f4, int p, int q)
{
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f4 + 4 * (size_t)p)), _mm_loadu_ps(f4 + 4 * (size_t)q),
                                1);
}

AVX2_INLINE __m256 spread_pair(__m128 w, int p) /* lanes p, p + 1 of w, each four times */
{
    const __m256i sel = _mm256_setr_epi32(p, p, p, p, p + 1, p + 1, p + 1, p + 1);
    return _mm256_permutevar8x32_ps(_mm256_castps128_ps256(w), sel);
}

/* run8's test for four points. */
AVX2_INLINE int run4(__m128i i0, __m128i row0, int nx)
{
    const __m128i d = _mm_sub_epi32(i0, _mm_setr_epi32(0, 1, 2, 3));
    const __m128i same = _mm_and_si128(_mm_cmpeq_epi32(d, _mm_shuffle_epi32(d, 0)), _mm_cmpeq_epi32(row0, _mm_shuffle_epi32(row0, 0)));
    const int first = _mm_cvtsi128_si32(i0);
    return _mm_movemask_epi8(same) == 0xffff && first + 4 < nx ? first : -1;
}

/* Four points of four packed fields (their corners and weights a), into out4[0..16). */
AVX2_INLINE void block4(const float *f4, int nx, const lanes4 *a, float *out4)
{
    const int first = run4(a->i0, a->r[0], nx);
    if (first >= 0) { /* point p's corners at first + p and first + p + 1 of each row */
        for (int p = 0; p < 4; p += 2) {
            const __m256 ax = spread_pair(a->ax, p), ay = spread_pair(a->ay, p), az = spread_pair(a->az, p);
            __m256 c[4];
            for (int q = 0; q < 4; q++) {
                const float *row = f4 + 4 * ((size_t)_mm_cvtsi128_si32(a->r[q]) + first + p);
                c[q] = lerp8(_mm256_loadu_ps(row), _mm256_loadu_ps(row + 4), ax);
            }
            _mm256_storeu_ps(out4 + 4 * p, lerp8(lerp8(c[0], c[1], ay), lerp8(c[2], c[3], ay), az));
        }
        return;
    }
    int i0[4], i1[4], r[4][4];
    _mm_storeu_si128((__m128i *)i0, a->i0);
    _mm_storeu_si128((__m128i *)i1, a->i1);
    for (int q = 0; q < 4; q++) _mm_storeu_si128((__m128i *)r[q], a->r[q]);
    for (int p = 0; p < 4; p += 2) {
        const __m256 ax = spread_pair(a->ax, p), ay = spread_pair(a->ay, p), az = spread_pair(a->az, p);
        __m256 c[4];
        const int whole = i1[p] && i1[p + 1]; /* no wrap: the corners i0, i0 + 1 side by side */
        for (int q = 0; q < 4; q++) {
            __m256 lo, hi;
            if (whole) {
                const __m256 dp = _mm256_loadu_ps(f4 + 4 * (size_t)(r[q][p] + i0[p]));
                const __m256 dq = _mm256_loadu_ps(f4 + 4 * (size_t)(r[q][p + 1] + i0[p + 1]));
                lo = _mm256_permute2f128_ps(dp, dq, 0x20), hi = _mm256_permute2f128_ps(dp, dq, 0x31);
            } else {
                lo = load_pair(f4, r[q][p] + i0[p], r[q][p + 1] + i0[p + 1]);
                hi = load_pair(f4, r[q][p] + i1[p], r[q][p + 1] + i1[p + 1]);
            }
            c[q] = lerp8(lo, hi, ax);
        }
        _mm256_storeu_ps(out4 + 4 * p, lerp8(lerp8(c[0], c[1], ay), lerp8(c[2], c[3], ay), az));
    }
}

/* Eight points' corners and weights found at once, then two blocks of four. */
AVX2 static void sample4_avx2(const atmos_sim *s, const float *f4, int nz_f, const float *x, const float *y,
                              const float *z, float *out4, int n)
{
    int m = 0;
    for (; m + 8 <= n; m += 8) {
        lanes8 e;
        if (!setup8(s, nz_f, x + m, y + m, z + m, &e)) {
            sample4_scalar(s, f4, nz_f, x, y, z, out4, m, m + 8);
            continue;
        }
        lanes4 a;
        half4(&e, 0, &a);
        block4(f4, s->nx, &a, out4 + 4 * (size_t)m);
        half4(&e, 1, &a);
        block4(f4, s->nx, &a, out4 + 4 * (size_t)(m + 4));
    }
    sample4_scalar(s, f4, nz_f, x, y, z, out4, m, n);
}

static int have_avx2(void)
{
    return __builtin_cpu_supports("avx2");
}
#endif

void atmos__sim_sample_row(const atmos_sim *s, const float *f, int nz_f, const float *x, const float *y,
                           const float *z, float *out, int n)
{
#ifdef SIM_AVX2
    if (have_avx2()) {
        sample_avx2(s, f, nz_f, x, y, z, out, n);
        return;
    }
#endif
    sample_scalar(s, f, nz_f, x, y, z, out, 0, n);
}

void atmos__sim_sample4_row(const atmos_sim *s, const float *f4, int nz_f, const float *x, const float *y,
                            const float *z, float *out4, int n)
{
#ifdef SIM_AVX2
    if (have_avx2()) {
        sample4_avx2(s, f4, nz_f, x, y, z, out4, n);
        return;
    }
#endif
    sample4_scalar(s, f4, nz_f, x, y, z, out4, 0, n);
}

void atmos__sim_sample_row_scalar(const atmos_sim *s, const float *f, int nz_f, const float *x, const float *y,
                                  const float *z, float *out, int n)
{
    sample_scalar(s, f, nz_f, x, y, z, out, 0, n);
}

void atmos__sim_sample4_row_scalar(const atmos_sim *s, const float *f4, int nz_f, const float *x, const float *y,
                                   const float *z, float *out4, int n)
{
    sample4_scalar(s, f4, nz_f, x, y, z, out4, 0, n);
}
