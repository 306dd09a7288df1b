/* Value noise for the cirrus sheet and for modulating rain and anvils: random
 * values on the integer lattice (a hash of the lattice point and the seed),
 * interpolated with the quintic fade 6t^5 - 15t^4 + 10t^3 so the sum of octaves
 * has continuous first and second derivatives. */
#include "volume/generator.h"

#include <math.h>

static double lattice(uint64_t seed, int64_t x, int64_t y, int64_t z)
{
    gen_rng r = {seed ^ ((uint64_t)x * 0x8CB92BA72F3D8DD7ull) ^ ((uint64_t)y * 0xD6E8FEB86659FD93ull) ^
                 ((uint64_t)z * 0xA0761D6478BD642Full)};
    return gen_u01(&r);
}

static double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

double atmos__gen_noise3(uint64_t seed, double x, double y, double z)
{
    double fx = floor(x), fy = floor(y), fz = floor(z);
    int64_t ix = (int64_t)fx, iy = (int64_t)fy, iz = (int64_t)fz;
    double u = fade(x - fx), v = fade(y - fy), w = fade(z - fz);
    double c[8];
    for (int k = 0; k < 8; k++) c[k] = lattice(seed, ix + (k & 1), iy + (k >> 1 & 1), iz + (k >> 2 & 1));
    double x00 = c[0] + u * (c[1] - c[0]), x10 = c[2] + u * (c[3] - c[2]);
    double x01 = c[4] + u * (c[5] - c[4]), x11 = c[6] + u * (c[7] - c[6]);
    double y0 = x00 + v * (x10 - x00), y1 = x01 + v * (x11 - x01);
    return y0 + w * (y1 - y0);
}

double atmos__gen_fbm3(uint64_t seed, double x, double y, double z, int octaves, double gain)
{
    double sum = 0, amp = 1, norm = 0;
    for (int o = 0; o < octaves; o++) {
        sum += amp * atmos__gen_noise3(seed + (uint64_t)o * 0x632BE59BD9B4E019ull, x, y, z);
        norm += amp;
        amp *= gain;
        /* an irrational-ish offset per octave hides the lattice alignment */
        x = 2 * x + 0.37;
        y = 2 * y + 0.71;
        z = 2 * z + 0.13;
    }
    return norm > 0 ? sum / norm : 0;
}
