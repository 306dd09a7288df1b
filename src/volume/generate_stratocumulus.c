/* The stratocumulus preset: a deck of rounded cells under an inversion.
 *
 * A stratocumulus-topped boundary layer is well mixed below a sharp inversion: the cloud base
 * is flat at the condensation level, the tops are held flat by the inversion, and the deck
 * breaks into convective cells 1-3 km across (about 1.5-2 times the layer's depth of a
 * kilometre or so; cells are drawn here 1.7 km apart) with thinner cloud or clear gaps
 * between them where air sinks. Built as:
 *
 *  - Cells: cellular noise (noise_cells.c) on a 1.7 km lattice, jitter 0.9, its input moved by
 *    350 m of fractal noise so the borders wander. e = (F2 - F1) x 1.7 km is 0 on a border and
 *    grows inward.
 *  - Thickness: h = H c sqrt(1 - (1 - t)^2), t = gen_smoothstep(g, g + 0.25, e / 1.7 km), a dome
 *    with steep rounded sides and a top flattened at the inversion (H = 450 m); c is 1 for
 *    most cells and 0.6-1 for a fifth of them (some cells lower); g (the gap's half width,
 *    0-0.12 of the lattice) from smooth noise, so the gaps are closed in places, open in
 *    others; plus bumps of +-56 m (fractal noise, 450 m) on the tops, all capped at H.
 *  - Density: cloud droplets at ETA_SC x (0.3 + 0.7 (y - base) / H) (liquid water grows with
 *    height above the base, as in cumulus), x 0.75-1 of fractal noise for texture, softened
 *    over the top 120 m of each column, whose top is eroded by up to 100 m of 3-D noise
 *    (180 m) into small turrets and dips. Flat base at 1200 m.
 *
 * Optical depth of a full cell ~ 65 km^-1 x 0.65 x 0.45 km ~ 18 with the 'cloud' preset
 * (6.28e-10 m^2), in the 5-20 of observed decks. */
#include "volume/generate_job.h"

#include <math.h>

#define ETA_SC 1e8


/* The deck's thickness (m) over the point (x, z). */
static double thickness(uint64_t s_cell, uint64_t s_warp, uint64_t s_gap, double x, double z, double sc, double H)
{
    const double lambda = 1700 * sc;
    double wx = x + 700 * sc * (atmos__gen_fbm3(s_warp, x / (2500 * sc), 0.2, z / (2500 * sc), 4, 0.5) - 0.5);
    double wz = z + 700 * sc * (atmos__gen_fbm3(s_warp, x / (2500 * sc), 0.8, z / (2500 * sc), 4, 0.5) - 0.5);
    wx += 250 * sc * (atmos__gen_fbm3(s_warp, x / (500 * sc), 1.4, z / (500 * sc), 3, 0.5) - 0.5);
    wz += 250 * sc * (atmos__gen_fbm3(s_warp, x / (500 * sc), 1.9, z / (500 * sc), 3, 0.5) - 0.5);
    gen_cell c;
    atmos__gen_cells2(s_cell, wx / lambda, wz / lambda, 0.9, &c);
    gen_rng r = {c.id};
    double u = gen_u01(&r), lower = u < 0.2 ? 0.6 + 2 * u : 1;
    double g = 0.12 * gen_smoothstep(0.35, 0.65, atmos__gen_fbm3(s_gap, x / (5000 * sc), 0.5, z / (5000 * sc), 3, 0.5));
    double t = gen_smoothstep(g, g + 0.5, c.f2 - c.f1);
    double bumps = 0.25 * H * (atmos__gen_fbm3(s_gap, x / (450 * sc), 2.5, z / (450 * sc), 4, 0.55) - 0.5);
    return fmin(H, H * lower * fmin(1, 1.25 * (1 - (1 - t) * (1 - t))) + bumps * t);
}

atmos_status atmos__gen_stratocumulus(gen_job *job)
{
    const double s = job->scale, half = 6000 * s, base = 1200, H = 450 * s;
    job->voxel = job->voxel_override ? job->voxel_override : 50 * s;
    job->ngrids = 1;
    job->field_name[0] = "cloud";
    double lo[3] = {-half, base - 50 * s, -half}, hi[3] = {half, base + H + 50 * s, half};
    atmos_status st = atmos__gen_grid_init(job, lo, hi);
    if (st != ATMOS_OK) return st;
    uint64_t s_cell = atmos__splitmix64(&job->rng.s), s_warp = atmos__splitmix64(&job->rng.s),
             s_gap = atmos__splitmix64(&job->rng.s), s_tex = atmos__splitmix64(&job->rng.s);
    gen_grid *g = &job->grid[0];
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < g->n[2]; k++)
        for (int i = 0; i < g->n[0]; i++) {
            double x = gen_vox(job, i, 0), z = gen_vox(job, k, 2);
            double h = thickness(s_cell, s_warp, s_gap, x, z, s, H);
            for (int j = 0; j < g->n[1]; j++) {
                double y = gen_vox(job, j, 1), a = y - base;
                if (a < 0 || a > h) continue;
                /* the tops eroded by small turrets and dips (3-D noise, 180 m, up to 100 m deep) */
                double er = 100 * s * atmos__gen_fbm3(s_tex ^ 0x5C, x / (180 * s), y / (120 * s), z / (180 * s), 3, 0.5);
                if (a > h - er + 50 * s) continue;
                double tex = 0.45 + 0.55 * atmos__gen_fbm3(s_tex, x / (350 * s), y / (200 * s), z / (350 * s), 4, 0.5);
                double soft = gen_smoothstep(0, 120 * s, h - er + 50 * s - a);
                g->v[((size_t)k * g->n[1] + j) * g->n[0] + i] =
                    (float)(ETA_SC * (0.3 + 0.7 * a / H) * tex * (0.15 + 0.85 * soft));
            }
        }
    return ATMOS_OK;
}
