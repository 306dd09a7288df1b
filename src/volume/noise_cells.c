/* Cellular (Worley 1996) noise in the plane: feature points, one per unit lattice cell at a
 * hashed position inside it (jitter 0..1 of the cell), and the distances from a point to the
 * nearest (F1) and second nearest (F2) feature. F2 - F1 is 0 on the cells' borders and largest
 * near their centres: the stratocumulus deck's cells. */
#include "volume/generator.h"

#include <math.h>

static uint64_t cell_hash(uint64_t seed, int64_t i, int64_t k)
{
    uint64_t s = seed ^ ((uint64_t)i * 0x9E3779B97F4A7C15ull) ^ ((uint64_t)k * 0xC2B2AE3D27D4EB4Full);
    return atmos__splitmix64(&s);
}

void atmos__gen_cells2(uint64_t seed, double x, double z, double jitter, gen_cell *out)
{
    double fx = floor(x), fz = floor(z);
    int64_t ix = (int64_t)fx, iz = (int64_t)fz;
    out->f1 = out->f2 = INFINITY;
    out->id = 0;
    for (int64_t dk = -2; dk <= 2; dk++)
        for (int64_t di = -2; di <= 2; di++) {
            uint64_t h = cell_hash(seed, ix + di, iz + dk);
            gen_rng r = {h};
            double px = (double)(ix + di) + 0.5 + jitter * (gen_u01(&r) - 0.5);
            double pz = (double)(iz + dk) + 0.5 + jitter * (gen_u01(&r) - 0.5);
            double d = hypot(x - px, z - pz);
            if (d < out->f1) {
                out->f2 = out->f1;
                out->f1 = d, out->id = h;
            } else if (d < out->f2) {
                out->f2 = d;
            }
        }
}
