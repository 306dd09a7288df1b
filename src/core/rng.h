/* The library's random numbers. All are deterministic functions of explicit seeds, so
 * results never depend on which thread runs what.
 *
 *  - SplitMix64 (Steele, Lea & Flood, OOPSLA 2014): atmos__splitmix64 steps a 64-bit state;
 *    atmos__mix64 is its output function, used to derive independent seeds by hashing.
 *  - atmos__stream: a SplitMix64 stream seeded from (seed, pixel, sample), one per sample
 *    of a Monte Carlo renderer (counter-based: no state is shared between samples).
 *  - atmos__rng: xoshiro256** (Blackman & Vigna, ACM TOMS 47(4), 2021) seeded through
 *    SplitMix64 as the authors recommend, for long streams (ray tracing of crystals). */
#ifndef ATMOS_CORE_RNG_H
#define ATMOS_CORE_RNG_H

#include <stdint.h>

static inline uint64_t atmos__mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static inline uint64_t atmos__splitmix64(uint64_t *state)
{
    return atmos__mix64(*state += 0x9e3779b97f4a7c15ULL);
}

/* The top 53 bits of x as a double uniform in [0, 1). */
static inline double atmos__u01(uint64_t x) { return (double)(x >> 11) * 0x1.0p-53; }

typedef struct {
    uint64_t s;
} atmos__stream;

static inline void atmos__stream_seed(atmos__stream *r, uint64_t seed, uint64_t pixel, uint64_t sample)
{
    r->s = atmos__mix64(atmos__mix64(seed + 0x9e3779b97f4a7c15ULL) ^ (pixel * 0xd1b54a32d192ed03ULL)) ^
           atmos__mix64(sample + 0x632be59bd9b4e019ULL);
}

/* Uniform in [0, 1) with 53 bits. */
static inline double atmos__stream_u(atmos__stream *r) { return atmos__u01(atmos__splitmix64(&r->s)); }

typedef struct atmos__rng {
    uint64_t s[4];
} atmos__rng;

static inline void atmos__rng_seed(atmos__rng *r, uint64_t seed)
{
    for (int i = 0; i < 4; i++) r->s[i] = atmos__splitmix64(&seed);
}

static inline uint64_t atmos__rng_rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static inline uint64_t atmos__rng_next(atmos__rng *r)
{
    uint64_t *s = r->s;
    uint64_t out = atmos__rng_rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = atmos__rng_rotl(s[3], 45);
    return out;
}

/* Uniform in [0, 1) with 53 random bits. */
static inline double atmos__rng_uniform(atmos__rng *r) { return atmos__u01(atmos__rng_next(r)); }

#endif
