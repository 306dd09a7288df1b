/* The generator presets (docs/volumes.md "Generators").
 *
 * Metaball clouds follow Nishita et al. 1996 §4: a few large balls give the basic
 * shape, fractal refinement adds smaller balls on the isosurface. The field value F
 * (sum of Wyvill falloffs) becomes a number density:
 *
 *   eta = eta_peak * clamp((F - iso) / 0.6, 0, 1) * (0.35 + 0.65 * clamp((y - base) / H, 0, 1))
 *
 * zero outside the isosurface F = iso, rising inward over a soft edge, and growing
 * with height above the base like the adiabatic liquid water content of a cumulus
 * (which rises roughly linearly with height above the condensation level). The
 * base itself is a horizontal cut at the condensation level: below it there is no
 * cloud (the refinement's downward-triangle rule keeps balls from growing there).
 *
 * Peak number densities, chosen so that the extinction with the optics presets'
 * cross-sections (cloud 6.28e-10, ice 1.82e-6, rain 6.28e-6 m^2; Riley Table 2) is
 * typical: cloud droplets 1e8 m^-3 (100 cm^-3; 63 km^-1). The layer clouds (cirrus,
 * stratocumulus) are in generate_cirrus.c and generate_stratocumulus.c, the storm presets
 * (cumulonimbus, storm, rain_shaft, virga) in generate_storm.c.
 */
#include "volume/generate_job.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ETA_CLOUD 1e8
#define ISO 0.3f
/* The field's domes are this much wider (and as much flatter) than their footprints
 * (generate_footprint.c), so that the rough outline cut from a dome rarely meets its rim. */
#define WIDE 1.4
/* The share of a cut column's depth over which its top fades out. */
#define FADE 0.4



/* The basic shape of one cumulus of diameter W on a base at height `base`: tiers
 * of balls, wide at the bottom and narrowing upward (a dome). Top of the
 * isosurface at about base + 0.75 W / squash before refinement (squash > 1: the balls
 * oblate and the tiers closer, a dome squash times wider than it is tall). */
static int cumulus_balls(gen_job *job, gen_balls *bl, double cx, double cz, double base, double w, double squash)
{
    static const struct {
        int n;
        double rfac, yoff, disc;
    } tiers[] = {{6, 1.0, 0.35, 1.0}, {4, 0.8, 1.10, 0.6}, {2, 0.6, 1.70, 0.35}, {1, 0.45, 2.2, 0.1}};
    double r0 = 0.30 * w, d = 0.2 * w;
    for (int t = 0; t < 4; t++)
        for (int n = 0; n < tiers[t].n; n++) {
            double ang = gen_range(&job->rng, 0, 2 * ATMOS_PI), rad = sqrt(gen_u01(&job->rng)) * d * tiers[t].disc;
            double y = base + (tiers[t].yoff + gen_range(&job->rng, -0.05, 0.05)) * r0 / squash;
            double r = tiers[t].rfac * r0 * gen_range(&job->rng, 0.85, 1.15);
            if (!atmos__gen_balls_add(bl, cx + rad * cos(ang), y, cz + rad * sin(ang), r, 1, squash)) return 0;
        }
    return 1;
}

/* F -> eta in place (see the top comment); rows below floor_j become 0, and with `top` (one
 * height per column, x fastest) the voxels above the column's top fade out over one voxel. */
static void cloud_density(gen_job *job, gen_grid *g, double base, double height, double eta, int floor_j,
                          const float *top)
{
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++) {
            float *row = g->v + ((size_t)k * g->n[1] + j) * g->n[0];
            double h = 0.35 + 0.65 * gen_clamp01((gen_vox(job, j, 1) - base) / height);
            const float *tc = top ? top + (size_t)k * g->n[0] : NULL;
            const double y = gen_vox(job, j, 1);
            for (int i = 0; i < g->n[0]; i++) {
                double cut = 1;
                if (tc && isfinite(tc[i])) { /* a soft top, fading over FADE of its depth (a voxel at least) */
                    double f = gen_clamp01((tc[i] - y) / fmax(g->voxel, FADE * (tc[i] - base)) + 0.5);
                    cut = f * f * (3 - 2 * f);
                }
                row[i] = j < floor_j ? 0.0f : (float)(eta * gen_clamp01((row[i] - ISO) / 0.6) * h * cut);
            }
        }
}

static atmos_status refine(gen_job *job, gen_grid *g, double r0, int levels, int floor_j, int fringe)
{
    gen_refine p = {.levels = levels, .r0 = r0, .ratio = 0.5, .coverage = 1.5, .iso = ISO,
                    .floor_j = floor_j, .max_balls = 20000, .fringe = fringe, .ctx = job->ctx};
    return atmos__gen_refine(g, &job->balls, &p, &job->rng, job->threads) ? ATMOS_OK : gen_nomem(job);
}

static atmos_status cumulus(gen_job *job)
{
    const double s = job->scale, base = 1000, w = 1500 * s;
    job->voxel = job->voxel_override ? job->voxel_override : 10 * s;
    job->ngrids = 1;
    job->field_name[0] = "cloud";
    double lo[3] = {-1000 * s, base - 20 * s, -1000 * s}, hi[3] = {1000 * s, base + 1550 * s, 1000 * s};
    atmos_status st = atmos__gen_grid_init(job, lo, hi);
    if (st != ATMOS_OK) return st;
    if (!cumulus_balls(job, &job->balls, 0, 0, base, w, 1)) return gen_nomem(job);
    atmos__gen_accumulate(&job->grid[0], &job->balls, 0, job->threads);
    int fj = atmos__gen_floor_j(job, base);
    if ((st = refine(job, &job->grid[0], 0.075 * w, 3, fj, 1)) != ATMOS_OK) return st;
    cloud_density(job, &job->grid[0], base, 0.8 * w, ETA_CLOUD, fj, NULL);
    return ATMOS_OK;
}

static atmos_status cumulus_field(gen_job *job)
{
    const double s = job->scale, base = 1000, half = 5500 * s;
    job->voxel = job->voxel_override ? job->voxel_override : 40 * s;
    job->ngrids = 1;
    job->field_name[0] = "cloud";
    double lo[3] = {-half, base - 40 * s, -half}, hi[3] = {half, base + 1500 * s, half};
    atmos_status st = atmos__gen_grid_init(job, lo, hi);
    if (st != ATMOS_OK) return st;
    /* NF fair-weather cumuli, diameters drawn from a power law n(w) ~ w^-1.7 (the cloud size
     * density of shallow cumulus, Neggers et al. 2003) over 250..1600 m, then placed largest
     * first by dart throwing, kept apart by 0.6 x the sum of their diameters (a cloud that finds
     * no place in 200 throws is left out: drawing a new size instead would favour small ones).
     * Each is a dome of metaballs WIDE times its width, cut down to a fractal footprint of its
     * width (generate_footprint.c). */
    enum { NF = 64 };
    double cx[NF], cz[NF], cw[NF], wd[NF];
    const double b = 1.7, w0 = pow(250, 1 - b), w1 = pow(1600, 1 - b);
    for (int m = 0; m < NF; m++) wd[m] = pow(w0 + gen_u01(&job->rng) * (w1 - w0), 1 / (1 - b)) * s;
    for (int m = 1; m < NF; m++) /* largest first (insertion sort) */
        for (int q = m; q > 0 && wd[q] > wd[q - 1]; q--) {
            double t = wd[q];
            wd[q] = wd[q - 1], wd[q - 1] = t;
        }
    int n = 0;
    for (int m = 0; m < NF; m++) {
        double w = wd[m], lim = half - 0.7 * w - 300 * s;
        for (int attempt = 0; attempt < 200; attempt++) {
            double x = gen_range(&job->rng, -lim, lim), z = gen_range(&job->rng, -lim, lim);
            int ok = 1;
            for (int q = 0; q < n && ok; q++)
                if (hypot(x - cx[q], z - cz[q]) < 0.6 * (w + cw[q])) ok = 0;
            if (!ok) continue;
            cx[n] = x, cz[n] = z, cw[n] = w;
            if (!cumulus_balls(job, &job->balls, x, z, base, WIDE * w, WIDE)) return gen_nomem(job);
            n++;
            break;
        }
    }
    atmos__gen_accumulate(&job->grid[0], &job->balls, 0, job->threads);
    int fj = atmos__gen_floor_j(job, base);
    if ((st = refine(job, &job->grid[0], 110 * s, 2, fj, 0)) != ATMOS_OK) return st;
    float *top = atmos__gen_fractal_tops(job, n, cx, cz, cw, base, 0.8);
    if (!top) return gen_nomem(job);
    cloud_density(job, &job->grid[0], base, 900 * s, ETA_CLOUD, fj, top);
    free(top);
    return ATMOS_OK;
}

atmos_status atmos__gen_preset(gen_job *job, int which)
{
    switch (which) {
    case 0: return cumulus(job);
    case 1: return atmos__gen_cumulonimbus(job, 0);
    case 2: return cumulus_field(job);
    case 3: return atmos__gen_cirrus(job);
    case 4: return atmos__gen_rain_shaft(job, 0);
    case 5: return atmos__gen_cumulonimbus(job, 1);
    case 6: return atmos__gen_stratocumulus(job);
    case 7: return atmos__gen_rain_shaft(job, 1);
    default: return atmos__error(job->ctx, ATMOS_E_INVALID_ARG, "generate: no preset %d", which);
    }
}
