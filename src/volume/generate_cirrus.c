/* The cirrus preset: fibrous, sheared cirrus (uncinus and fibratus) with fall streaks.
 *
 * Cirrus grows in generating cells near the top of a moist layer; their ice crystals fall at
 * v_f ~ 0.5-1.5 m/s into air whose wind differs from the heads' by the shear S (typically
 * 5-20 m/s per km). A crystal that has fallen a depth d has been carried d^2 S / (2 v_f)
 * downwind of its head (relative velocity S d' at depth d', time d / v_f), so the streak below
 * a head is a parabola in the plane of the wind, steep under the head and bending towards
 * the horizontal further down: the hook of cirrus uncinus. Everything here lives in the
 * sheared frame: a voxel at depth d below the generating level reads its ice from the point
 * x0 = x - d^2 / (2 L) of the heads' pattern, L = v_f / S = 180 m (x scale), so the whole
 * field drifts downwind (+x) with depth.
 *
 *  - Heads: tufts on a jittered lattice (2.5 km, 60 % of the sites), each an ellipse
 *    200-450 m across and 2x longer along the wind, 250 m deep, over a streak that spreads
 *    (1 + 0.6 d / D) and thins to nothing at the depth D (600-1500 m) where the crystals
 *    have sublimated. Each head and its streak is cut to a fractal outline
 *    (atmos__gen_fractal_phi, the cumulus field's) fixed on the ground, so that seen from above
 *    the swept streak's outline is rough at every scale: perimeter-area dimension 1.33, Kuo et
 *    al. 1988 measured 1.3-1.4 on cirrus (smooth ellipses: 1.05).
 *  - Fibratus: a sheet of streaks between the heads whose coverage is fractal noise stretched
 *    8:1 along the wind.
 *  - Fibres: everything is multiplied by ridged fractal noise sampled at scales 2.5 km along
 *    the wind and 180 m across (14:1), its across-wind coordinate warped by 500 m of smooth
 *    noise so the filaments wander; squared, so the ice gathers in thin strands.
 *
 * Peak number density ETA_CIRRUS m^-3 (with the 'ice' preset's 1.82e-6 m^2, 3.6 km^-1 in a
 * head); the column optical depths come out 0.1-2 (docs/clouds.md "Generated clouds").
 * All lengths scale with the preset's scale. The wind blows along +x. */
#include "volume/generate_job.h"

#include <math.h>
#include <stdlib.h>

#define ETA_CIRRUS 4000.0

typedef struct {
    double x, z, r, depth, w;
    uint64_t seed; /* its fractal outline's */
} cirrus_head;

/* A head's dome is this much wider than its fractal outline (atmos__gen_fractal_phi), so that
 * the rough outline cut from it rarely meets the dome's smooth rim. */
#define WIDE 1.5
/* Their outlines' roughness, of the cumulus field's (atmos__gen_fractal_phi): D 1.33 for 0.6
 * (Kuo et al. 1988: 1.3-1.4; 1.0 gave 1.38, 0.5 1.28; docs/clouds.md "Against observations") */
#define ROUGH 0.6


/* Ridged fractal noise in [0, 1]: 1 - |2n - 1| per octave, high on thin sheets. */
static double ridged(uint64_t seed, double x, double y, double z, int octaves)
{
    double sum = 0, amp = 1, norm = 0;
    for (int o = 0; o < octaves; o++) {
        double n = atmos__gen_noise3(seed + (uint64_t)o * 0x632BE59BD9B4E019ull, x, y, z);
        double r = 1 - fabs(2 * n - 1);
        sum += amp * r * r;
        norm += amp;
        amp *= 0.5;
        x = 2 * x + 0.37, y = 2 * y + 0.71, z = 2 * z + 0.13;
    }
    return sum / norm;
}

/* The heads on a jittered lattice of spacing `sp` over [-half, half]^2. */
static int place_heads(gen_job *job, double half, double sp, cirrus_head **out)
{
    const double s = job->scale;
    int m = (int)ceil(2 * half / sp), n = 0;
    cirrus_head *h = malloc(sizeof *h * (size_t)(m * m > 0 ? m * m : 1));
    if (!h) return -1;
    for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++) {
            double x = -half + (a + gen_range(&job->rng, 0.1, 0.9)) * sp;
            double z = -half + (b + gen_range(&job->rng, 0.1, 0.9)) * sp;
            double r = gen_range(&job->rng, 200, 450) * s, depth = gen_range(&job->rng, 600, 1500) * s;
            double w = gen_range(&job->rng, 0.6, 1.0);
            if (gen_u01(&job->rng) < 0.6) h[n++] = (cirrus_head){x, z, r, depth, w, 0};
        }
    *out = h;
    return n;
}

/* The heads' and streaks' ice (0..1) at the sheared-frame point (x0, z), depth d below the
 * generating level. */
static double heads_at(const cirrus_head *h, int nh, double x0, double shift, double z, double d, double hh,
                       double voxel)
{
    double best = 0;
    for (int q = 0; q < nh; q++) {
        if (d > h[q].depth || d < -0.5 * hh) continue;
        double spread = 1 + 0.6 * fmax(d, 0) / h[q].depth, rz = h[q].r * spread, rx = 2 * rz;
        double ex = (x0 - h[q].x) / rx, ez = (z - h[q].z) / rz, e2 = ex * ex + ez * ez;
        if (e2 >= WIDE * WIDE) continue;
        double vert = d < hh ? 1 : 0.8 * (1 - (d - hh) / (h[q].depth - hh)) / spread;
        double top = d < 0 ? 1 - d / (-0.5 * hh) : 1; /* the head's rounded top */
        double dome = 1 - e2 / (WIDE * WIDE), v = h[q].w * dome * dome * vert * top;
        if (v <= best) continue;
        /* the outline: noise fixed on the ground (x = x0 + shift), in units of the head's
         * width each way, so that seen from above the streak's outline is one level set */
        double phi = atmos__gen_fractal_phi(h[q].seed, (x0 + shift - h[q].x) / (4 * h[q].r), (z - h[q].z) / (2 * h[q].r),
                                            1 - e2, atmos__gen_fractal_octaves(2 * h[q].r, voxel), ROUGH);
        v *= gen_clamp01(phi / 0.1);
        if (v > best) best = v;
    }
    return best;
}

atmos_status atmos__gen_cirrus(gen_job *job)
{
    const double s = job->scale, half = 10000 * s;
    job->voxel = job->voxel_override ? job->voxel_override : 80 * s;
    job->ngrids = 1;
    job->field_name[0] = "ice";
    double lo[3] = {-half, 8000, -half}, hi[3] = {half, 8000 + 2000 * s, half};
    atmos_status st = atmos__gen_grid_init(job, lo, hi);
    if (st != ATMOS_OK) return st;
    uint64_t s_cov = atmos__splitmix64(&job->rng.s), s_fib = atmos__splitmix64(&job->rng.s),
             s_warp = atmos__splitmix64(&job->rng.s), s_sheet = atmos__splitmix64(&job->rng.s);
    cirrus_head *heads = NULL;
    /* heads over a margin upwind: their streaks drift downwind into the box */
    int nh = place_heads(job, half + 3000 * s, 2500 * s, &heads);
    if (nh < 0) return atmos__error(job->ctx, ATMOS_E_NOMEM, "generate %s: out of memory", job->preset);
    /* drawn after the heads, which stay where they were before the outlines were fractal */
    const uint64_t s_outline = atmos__splitmix64(&job->rng.s);
    for (int q = 0; q < nh; q++) {
        uint64_t t = s_outline + (uint64_t)q;
        heads[q].seed = atmos__splitmix64(&t);
    }
    const double ygen = 8000 + 1650 * s, hh = 250 * s, L = 180 * s;
    gen_grid *g = &job->grid[0];
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++) {
            double y = gen_vox(job, j, 1), d = ygen - y, dd = fmax(d, 0);
            float *row = g->v + ((size_t)k * g->n[1] + j) * g->n[0];
            for (int i = 0; i < g->n[0]; i++) {
                double x = gen_vox(job, i, 0), z = gen_vox(job, k, 2);
                double x0 = x - dd * dd / (2 * L);
                double ice = heads_at(heads, nh, x0, x - x0, z, d, hh, job->voxel);
                /* the fibratus sheet: 100..900 m below the generating level */
                double sheet_v = gen_smoothstep(-50 * s, 150 * s, d) * (1 - gen_smoothstep(500 * s, 900 * s, d));
                if (sheet_v > 0) {
                    double cov = atmos__gen_fbm3(s_cov, x0 / (9000 * s), 0.5, z / (1100 * s), 4, 0.5);
                    ice = fmax(ice, 0.55 * gen_smoothstep(0.5, 0.68, cov) * sheet_v *
                                        (0.6 + 0.4 * atmos__gen_noise3(s_sheet, x0 / (4000 * s), d / (300 * s), 0.3)));
                }
                if (ice <= 0) continue;
                double zw = z + 500 * s * (atmos__gen_fbm3(s_warp, x0 / (6000 * s), 0.5, z / (3000 * s), 3, 0.5) - 0.5);
                double fib = ridged(s_fib, x0 / (2500 * s), d / (500 * s), zw / (180 * s), 4);
                row[i] = (float)(ETA_CIRRUS * ice * (0.08 + 0.92 * fib * fib));
            }
        }
    free(heads);
    return ATMOS_OK;
}
