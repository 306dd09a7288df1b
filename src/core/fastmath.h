/* Branch-free float exponential and select for the renderers' vectorised loops; ln(1 + x)
 * without the library's log1p; atan2 without the library's. */
#ifndef ATMOS_FASTMATH_H
#define ATMOS_FASTMATH_H

#include <math.h>
#include <stdint.h>
#include <string.h>

/* c ? a : b (c 0 or 1) by the bits: a and b are both computed by the caller, so that GCC's
 * vectoriser sees no branch. Written as c ? a : b, an operation on one side (a division, a
 * product) is moved into a branch that, floating point operations being allowed to trap, the
 * loop cannot be vectorised with; the bits chosen are the same. */
static inline float atmos__select_f(int c, float a, float b)
{
    int32_t ia, ib;
    memcpy(&ia, &a, sizeof ia), memcpy(&ib, &b, sizeof ib);
    const int32_t mk = -(int32_t)c, r = (ia & mk) | (ib & ~mk);
    float f;
    memcpy(&f, &r, sizeof f);
    return f;
}

/* e^x by range reduction x = n ln2 + r, |r| <= ln2/2, and a degree-6 Taylor polynomial
 * for e^r (truncation error < 2e-8), 2^n assembled in the exponent bits; x is clamped to
 * [-87, 88] (e^-87 < 2e-38 stands for anything smaller). No branches or calls, so loops
 * over it vectorise (its clamps by atmos__select_f: written as c ? a : b, GCC 12 at -O2 without
 * -fno-trapping-math left such loops scalar). */
static inline float atmos__expf_poly(float x)
{
    x = atmos__select_f(x < -87.0f, -87.0f, x);
    x = atmos__select_f(x > 88.0f, 88.0f, x);
    float t = x * 1.44269504088896341f;
    float nf = (t + 12582912.0f) - 12582912.0f; /* round to nearest by the 1.5*2^23 trick */
    /* nf is in [-126, 127] for any number; a NaN argument (which the clamps above let
     * through) becomes -126 here so that the conversion and shift below stay defined,
     * while p, and so the result, stays NaN for the caller's checks to see. */
    nf = atmos__select_f(nf > -126.0f, nf, -126.0f);
    float r = x - nf * 0.693145751953125f;      /* ln2 split: hi exactly representable */
    r = r - nf * 1.428606765330187045e-06f;     /* ln2 lo */
    float p = 1.0f / 720.0f;
    p = p * r + 1.0f / 120.0f;
    p = p * r + 1.0f / 24.0f;
    p = p * r + 1.0f / 6.0f;
    p = p * r + 0.5f;
    p = p * r + 1.0f;
    p = p * r + 1.0f;
    union {
        int32_t i;
        float f;
    } s;
    s.i = (int32_t)((uint32_t)((int32_t)nf + 127) << 23); /* nf + 127 in [1, 254]: exact */
    return p * s.f;
}

/* exp(x) with the polynomial above, 0 below -87 (relative error < 2e-7 over [-87, 88]). */
static inline float atmos__expf_fast(float x) { return x < -87.0f ? 0.0f : atmos__expf_poly(x); }
/* v[j] = atmos__expf_fast(v[j]) for j < count, vectorised (fastmath_array.c). */
void atmos__expf_fast_array(float *v, int count);

/* ln(1 + x) for x > -1 by one call of log, which takes fewer instructions than the C
 * library's log1p: with u = 1 + x rounded, ln(1 + x) = x ln(u) / (u - 1), x itself where
 * u = 1 (Goldberg 1991, "What every computer scientist should know about floating-point
 * arithmetic", Theorem 4: a relative error of at most 5 epsilon for 0 <= x < 3/4 with log
 * within half an ulp; u - 1 is exact and ln(u) / (u - 1) varies slowly, so the rounding of
 * u cancels). test_beams_sun measures it against log1p over (-1, 10]: 3.7e-16 at worst. */
static inline double atmos__log1p_fast(double x)
{
    const double u = 1 + x;
    return u == 1 ? x : log(u) * (x / (u - 1));
}

/* atan(z) for 0 <= z <= 1 by Abramowitz & Stegun 4.4.49 (|error| <= 2e-8 rad), the polynomial
 * in z^2 = Z evaluated in type T; double and float versions. */
#define ATMOS__ATAN_C1 -0.3333314528
#define ATMOS__ATAN_C2 0.1999355085
#define ATMOS__ATAN_C3 -0.1420889944
#define ATMOS__ATAN_C4 0.1065626393
#define ATMOS__ATAN_C5 -0.0752896400
#define ATMOS__ATAN_C6 0.0429096138
#define ATMOS__ATAN_C7 -0.0161657367
#define ATMOS__ATAN_C8 0.0028662257
#define ATMOS__ATAN_POLY(T, Z)                                                                           \
    ((((((((T)ATMOS__ATAN_C8 * (Z) + (T)ATMOS__ATAN_C7) * (Z) + (T)ATMOS__ATAN_C6) * (Z) +              \
          (T)ATMOS__ATAN_C5) * (Z) + (T)ATMOS__ATAN_C4) * (Z) + (T)ATMOS__ATAN_C3) * (Z) +               \
       (T)ATMOS__ATAN_C2) * (Z) + (T)ATMOS__ATAN_C1)
static inline double atmos__atan_unit(double z)
{
    /* the same polynomial by Estrin's scheme: four independent pairs, then two levels, so
     * its latency is about half of Horner's eight dependent steps (the texture look-ups of
     * the clouds wait on it) */
    const double Z = z * z, Z2 = Z * Z, Z4 = Z2 * Z2;
    const double p01 = ATMOS__ATAN_C1 + ATMOS__ATAN_C2 * Z, p23 = ATMOS__ATAN_C3 + ATMOS__ATAN_C4 * Z;
    const double p45 = ATMOS__ATAN_C5 + ATMOS__ATAN_C6 * Z, p67 = ATMOS__ATAN_C7 + ATMOS__ATAN_C8 * Z;
    const double q = (p01 + p23 * Z2) + Z4 * (p45 + p67 * Z2);
    return z * (1.0 + q * Z);
}
static inline float atmos__atan_unitf(float z)
{
    const float z2 = z * z;
    return z * (1.0f + ATMOS__ATAN_POLY(float, z2) * z2);
}

/* atan2(y, x) in (-pi, pi] from atmos__atan_unit of the smaller over the larger of |y|
 * and |x| (the same 2e-8 rad); 0 at the origin. */
static inline double atmos__atan2_fast(double y, double x)
{
    /* selects rather than fmax / fmin, which are library calls without -ffinite-math-only */
    const double ax = fabs(x), ay = fabs(y), hi = ay > ax ? ay : ax, lo = ay > ax ? ax : ay;
    /* 0 at the origin; a select, not a branch, so that loops of it can be vectorised */
    double a = atmos__atan_unit(hi > 0 ? lo / hi : 0.0);
    a = ay > ax ? 1.57079632679489662 - a : a;
    a = x < 0 ? 3.14159265358979324 - a : a;
    return y < 0 ? -a : a;
}

#endif
