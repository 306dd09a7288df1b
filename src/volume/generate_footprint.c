/* Fractal footprints for the generated cumulus field (docs/clouds.md "Against observations");
 * the outline (atmos__gen_fractal_phi) also cuts the cirrus's generating heads (generate_cirrus.c).
 *
 * Each cloud m (centre cx, cz, footprint diameter w) owns the columns where its smooth envelope
 * e = 1 - rho^2, rho = distance / (w / 2), is the largest of all clouds'. In those columns
 *
 *   phi = e + SIGMA (N - 1/2) - T,
 *
 * N a fractional Brownian value noise (atmos__gen_fbm3, octave gain 2^-H) measured in units of
 * the cloud's own width, from one width down to half a voxel: the outline phi = 0 is rough at
 * every scale between the voxel and the cloud, and a small cloud is a scaled copy of a large one
 * (statistically), which is what a perimeter-area law across sizes asks for. A single contour
 * loop of a rough surface of Hurst exponent H has the dimension (3 - H) / 2 (Kondev & Henley
 * 1995, Phys. Rev. Lett. 74, 4580), not the 2 - H of the whole level set; H = 0.15 (gain 0.90)
 * with the noise about 1.2 times the envelope's unit (SIGMA x the noise's standard deviation of
 * 0.076) measured D = 1.33 on the field (8 seeds), the observed value.
 *
 * The column's cloud is cut above  base + clamp(phi / 0.1, 0, 1) max(HMIN, depth w clamp(phi_s /
 * RAMP, 0, 1)):  outside the outline nothing; inside it at least a thin layer HMIN deep on the
 * flat base, rising towards the core as phi_s, the same sum over its first LOW octaves only (the
 * cloud-sized undulations), grows; where phi_s reaches RAMP (and phi EDGE) there is no cut at
 * all. The metaball dome is kept where it is lower than the cut: the rough outline is a skirt of
 * thin cloud round a cauliflower core, not a cookie-cutter wall. (With RAMP 1.5 the cut ran
 * through most cores and gave them flat tops, mesas seen from the side; at 0.25 the core keeps
 * its rounded dome and D is the same.) */
#include "volume/generate_job.h"

#include <math.h>
#include <stdlib.h>

#define HURST 0.15
#define SIGMA 16.0
#define T 0.2
#define RAMP 0.25
#define EDGE 0.1
#define LOW 2
#define HMIN 120.0

int atmos__gen_fractal_octaves(double width, double finest)
{
    const int oct = (int)ceil(log2(width / (0.5 * finest)));
    return oct < 1 ? 1 : oct;
}

double atmos__gen_fractal_phi(uint64_t seed, double u, double v, double e, int octaves, double rough)
{
    return e + rough * SIGMA * (atmos__gen_fbm3(seed, u, 0.5, v, octaves, pow(2, -HURST)) - 0.5) - T;
}

/* The cut height (m) of the column at (x, z) owned by the cloud at (cx, cz) of width w; infinite
 * in the core (no cut). */
static double column_top(const gen_job *job, uint64_t seed, double x, double z, double cx, double cz, double w,
                         double e, double base, double depth)
{
    const double gain = pow(2, -HURST), u = (x - cx) / w, v = (z - cz) / w;
    const int oct = atmos__gen_fractal_octaves(w, job->voxel);
    const int low = oct < LOW ? oct : LOW;
    /* atmos__gen_fbm3 divides the sum by its amplitudes' total: the low octaves' sum on the
     * full sum's scale is the low octaves' mean times their share of the total. */
    const double share = (1 - pow(gain, low)) / (1 - pow(gain, oct));
    const double phi = atmos__gen_fractal_phi(seed, u, v, e, oct, 1.0);
    const double phi_s = e + SIGMA * share * (atmos__gen_fbm3(seed, u, 0.5, v, low, gain) - 0.5) - T;
    if (phi_s >= RAMP && phi >= EDGE) return HUGE_VAL; /* the core: the dome uncut */
    return base + gen_clamp01(phi / EDGE) * fmax(HMIN * job->scale, depth * w * gen_clamp01(phi_s / RAMP));
}

float *atmos__gen_fractal_tops(gen_job *job, int n, const double *cx, const double *cz, const double *cw,
                               double base, double depth)
{
    const int nx = job->dims[0], nz = job->dims[2];
    float *top = malloc((size_t)nx * nz * sizeof *top);
    uint64_t *seed = malloc((size_t)(n > 0 ? n : 1) * sizeof *seed);
    if (!top || !seed) {
        free(top);
        free(seed);
        return NULL;
    }
    for (int m = 0; m < n; m++) seed[m] = atmos__splitmix64(&job->rng.s);
    /* Each column depends on its position and the clouds only: any thread count, same tops. */
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < nz; k++)
        for (int i = 0; i < nx; i++) {
            const double x = gen_vox(job, i, 0), z = gen_vox(job, k, 2);
            int own = -1;
            double e = -INFINITY;
            for (int m = 0; m < n; m++) {
                const double r = 2 * hypot(x - cx[m], z - cz[m]) / cw[m], em = 1 - r * r;
                if (em > e) e = em, own = m;
            }
            top[(size_t)k * nx + i] =
                (float)(own >= 0 ? column_top(job, seed[own], x, z, cx[own], cz[own], cw[own], e, base, depth) : base);
        }
    free(seed);
    return top;
}
