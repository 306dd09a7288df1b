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
 * typical: cloud droplets 1e8 m^-3 (100 cm^-3; 63 km^-1), anvil ice 3e3 m^-3
 * (5.5 km^-1, a dense anvil), rain drops 2e3 m^-3 (moderate rain of ~1 mm drops; 13 km^-1).
 * The layer clouds (cirrus, stratocumulus) are in generate_cirrus.c and generate_stratocumulus.c.
 */
#include "volume/generate_job.h"

#include <math.h>
#include <string.h>

#define ETA_CLOUD 1e8
#define ETA_ICE_ANVIL 3e3
#define ETA_RAIN 2e3
#define ISO 0.3f

static double clamp01(double x) { return x < 0 ? 0 : (x > 1 ? 1 : x); }
static double smoothstep(double a, double b, double x)
{
    double t = clamp01((x - a) / (b - a));
    return t * t * (3 - 2 * t);
}

static double vox_y(const gen_job *job, int j) { return job->origin[1] + (j + 0.5) * job->voxel; }
static double vox_x(const gen_job *job, int i, int a) { return job->origin[a] + (i + 0.5) * job->voxel; }

static atmos_status nomem(gen_job *job) { return atmos__error(job->ctx, ATMOS_E_NOMEM, "generate %s: out of memory", job->preset); }

/* The basic shape of one cumulus of diameter W on a base at height `base`: tiers
 * of balls, wide at the bottom and narrowing upward (a dome). Top of the
 * isosurface at about base + 0.75 W before refinement. */
static int cumulus_balls(gen_job *job, gen_balls *bl, double cx, double cz, double base, double w)
{
    static const struct {
        int n;
        double rfac, yoff, disc;
    } tiers[] = {{6, 1.0, 0.35, 1.0}, {4, 0.8, 1.10, 0.6}, {2, 0.6, 1.70, 0.35}, {1, 0.45, 2.2, 0.1}};
    double r0 = 0.30 * w, d = 0.2 * w;
    for (int t = 0; t < 4; t++)
        for (int n = 0; n < tiers[t].n; n++) {
            double ang = gen_range(&job->rng, 0, 2 * ATMOS_PI), rad = sqrt(gen_u01(&job->rng)) * d * tiers[t].disc;
            double y = base + (tiers[t].yoff + gen_range(&job->rng, -0.05, 0.05)) * r0;
            double r = tiers[t].rfac * r0 * gen_range(&job->rng, 0.85, 1.15);
            if (!atmos__gen_balls_add(bl, cx + rad * cos(ang), y, cz + rad * sin(ang), r, 1, 1)) return 0;
        }
    return 1;
}

/* F -> eta in place (see the top comment); rows below floor_j become 0. */
static void cloud_density(gen_job *job, gen_grid *g, double base, double height, double eta, int floor_j)
{
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++) {
            float *row = g->v + ((size_t)k * g->n[1] + j) * g->n[0];
            double h = 0.35 + 0.65 * clamp01((vox_y(job, j) - base) / height);
            for (int i = 0; i < g->n[0]; i++)
                row[i] = j < floor_j ? 0.0f : (float)(eta * clamp01((row[i] - ISO) / 0.6) * h);
        }
}

static atmos_status refine(gen_job *job, gen_grid *g, double r0, int levels, int floor_j, int fringe)
{
    gen_refine p = {.levels = levels, .r0 = r0, .ratio = 0.5, .coverage = 1.5, .iso = ISO,
                    .floor_j = floor_j, .max_balls = 20000, .fringe = fringe, .ctx = job->ctx};
    return atmos__gen_refine(g, &job->balls, &p, &job->rng, job->threads) ? ATMOS_OK : nomem(job);
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
    if (!cumulus_balls(job, &job->balls, 0, 0, base, w)) return nomem(job);
    atmos__gen_accumulate(&job->grid[0], &job->balls, 0, job->threads);
    int fj = atmos__gen_floor_j(job, base);
    if ((st = refine(job, &job->grid[0], 0.075 * w, 3, fj, 1)) != ATMOS_OK) return st;
    cloud_density(job, &job->grid[0], base, 0.8 * w, ETA_CLOUD, fj);
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
     * no place in 200 throws is left out: drawing a new size instead would favour small ones). */
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
            if (!cumulus_balls(job, &job->balls, x, z, base, w)) return nomem(job);
            n++;
            break;
        }
    }
    atmos__gen_accumulate(&job->grid[0], &job->balls, 0, job->threads);
    int fj = atmos__gen_floor_j(job, base);
    if ((st = refine(job, &job->grid[0], 110 * s, 2, fj, 0)) != ATMOS_OK) return st;
    cloud_density(job, &job->grid[0], base, 900 * s, ETA_CLOUD, fj);
    return ATMOS_OK;
}

/* Rain under (and in the lower part of) a cloud: a shaft of radius R around an axis
 * that drifts downwind (+x) as the drops fall, thinning towards the ground by
 * evaporation and modulated by value noise. cloud_f is the cloud's field F (the
 * rain inside the cloud only where F > iso). */
static void rain_shaft(gen_job *job, gen_grid *rain, const gen_grid *cloud_f, double base, double radius,
                       double depth_in_cloud, uint64_t seed)
{
    const double s = job->scale;
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < rain->n[2]; k++)
        for (int j = 0; j < rain->n[1]; j++) {
            double y = vox_y(job, j);
            if (y > base + depth_in_cloud) continue;
            double ax = 0.15 * (base - y);
            double vert = y < base ? 0.7 + 0.3 * y / base : 1 - (y - base) / depth_in_cloud;
            size_t row = ((size_t)k * rain->n[1] + j) * rain->n[0];
            for (int i = 0; i < rain->n[0]; i++) {
                double x = vox_x(job, i, 0), z = vox_x(job, k, 2);
                double r2 = ((x - ax) * (x - ax) + z * z) / (radius * radius);
                if (r2 >= 1) continue;
                if (y >= base && !(cloud_f->v[row + i] > ISO)) continue;
                double nz = atmos__gen_fbm3(seed, x / (400 * s), y / (800 * s), z / (400 * s), 4, 0.5);
                rain->v[row + i] = (float)(ETA_RAIN * (1 - r2) * (1 - r2) * (0.4 + 0.6 * nz) * vert);
            }
        }
}

static atmos_status rain_shaft_preset(gen_job *job)
{
    const double s = job->scale, base = 1200, w = 3000 * s;
    job->voxel = job->voxel_override ? job->voxel_override : 25 * s;
    job->ngrids = 2;
    job->field_name[0] = "cloud";
    job->field_name[1] = "rain";
    double lo[3] = {-2100 * s, 0, -2100 * s}, hi[3] = {2100 * s, base + 2900 * s, 2100 * s};
    atmos_status st = atmos__gen_grid_init(job, lo, hi);
    if (st != ATMOS_OK) return st;
    if (!cumulus_balls(job, &job->balls, 0, 0, base, w)) return nomem(job);
    atmos__gen_accumulate(&job->grid[0], &job->balls, 0, job->threads);
    int fj = atmos__gen_floor_j(job, base);
    if ((st = refine(job, &job->grid[0], 0.075 * w, 2, fj, 1)) != ATMOS_OK) return st;
    rain_shaft(job, &job->grid[1], &job->grid[0], base, 0.25 * w, 400 * s, atmos__splitmix64(&job->rng.s));
    cloud_density(job, &job->grid[0], base, 0.8 * w, ETA_CLOUD, fj);
    return ATMOS_OK;
}

/* A cumulonimbus: a tower of metaballs from the base to ~10 km, glaciating above
 * ~6-7.5 km above the base, under an anvil of ice: oblate balls spreading
 * downwind (+x) at the top, as the outflow at the tropopause does. With rain:
 * the "storm" preset (cloud + rain + ice, the inputs of Riley et al. Figs. 5, 6, 9, 14). */
static atmos_status cumulonimbus(gen_job *job, int with_rain)
{
    const double s = job->scale, base = 1000, tower_r = 1400 * s;
    job->voxel = job->voxel_override ? job->voxel_override : 80 * s;
    job->ngrids = with_rain ? 3 : 2;
    job->field_name[0] = "cloud";
    job->field_name[1] = "ice";
    job->field_name[2] = "rain";
    double lo[3] = {-4500 * s, with_rain ? 0 : base - 80 * s, -7000 * s},
           hi[3] = {13000 * s, base + 11500 * s, 7000 * s};
    atmos_status st = atmos__gen_grid_init(job, lo, hi);
    if (st != ATMOS_OK) return st;
    double top = base + 9300 * s;
    for (double y = base + 0.35 * tower_r; y < top; y += 0.7 * tower_r) {
        double grow = y > top - 1.5 * tower_r ? 1.2 : 1.0; /* the dome spreads under the anvil */
        for (int n = 0; n < 3; n++) {
            double ang = gen_range(&job->rng, 0, 2 * ATMOS_PI), rad = sqrt(gen_u01(&job->rng)) * 0.5 * tower_r;
            if (!atmos__gen_balls_add(&job->balls, rad * cos(ang), y, rad * sin(ang),
                                      grow * tower_r * gen_range(&job->rng, 0.85, 1.1), 1, 1))
                return nomem(job);
        }
    }
    atmos__gen_accumulate(&job->grid[0], &job->balls, 0, job->threads);
    int fj = atmos__gen_floor_j(job, base);
    if ((st = refine(job, &job->grid[0], 0.35 * tower_r, 2, fj, 1)) != ATMOS_OK) return st;
    /* The anvil: oblate balls (vertical extent a third of the horizontal). */
    gen_balls anvil = {0};
    double ya = base + 9500 * s;
    for (int n = 0; n < 40; n++) {
        double x = (-0.15 + 1.15 * gen_u01(&job->rng)) * 9000 * s;
        double zh = 1500 * s + 0.45 * fmax(x, 0);
        double z = gen_range(&job->rng, -0.8, 0.8) * zh;
        if (!atmos__gen_balls_add(&anvil, x, ya + gen_range(&job->rng, -300, 300) * s, z,
                                  gen_range(&job->rng, 1800, 2600) * s, 1, 3)) {
            atmos__gen_balls_free(&anvil);
            return nomem(job);
        }
    }
    atmos__gen_accumulate(&job->grid[1], &anvil, 0, job->threads);
    atmos__gen_balls_free(&anvil);
    uint64_t seed_anvil = atmos__splitmix64(&job->rng.s), seed_rain = atmos__splitmix64(&job->rng.s);
    if (with_rain) rain_shaft(job, &job->grid[2], &job->grid[0], base, 2200 * s, 1200 * s, seed_rain);
    /* Split the tower into liquid and ice by height (glaciation), add the anvil. */
    const double yg0 = base + 6000 * s, yg1 = base + 7500 * s;
    gen_grid *cl = &job->grid[0], *ice = &job->grid[1];
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < cl->n[2]; k++)
        for (int j = 0; j < cl->n[1]; j++) {
            double y = vox_y(job, j), fi = smoothstep(yg0, yg1, y);
            double h = 0.35 + 0.65 * clamp01((y - base) / (6000 * s));
            size_t row = ((size_t)k * cl->n[1] + j) * cl->n[0];
            for (int i = 0; i < cl->n[0]; i++) {
                double st_ = j < fj ? 0 : clamp01((cl->v[row + i] - ISO) / 0.6);
                double sa = clamp01((ice->v[row + i] - ISO) / 0.6);
                if (sa > 0)
                    sa *= 0.5 + 0.5 * atmos__gen_fbm3(seed_anvil, vox_x(job, i, 0) / (2000 * s), y / (600 * s),
                                                       vox_x(job, k, 2) / (2000 * s), 4, 0.5);
                cl->v[row + i] = (float)(ETA_CLOUD * st_ * h * (1 - fi));
                ice->v[row + i] = (float)(ETA_ICE_ANVIL * fmax(st_ * fi, sa));
            }
        }
    return ATMOS_OK;
}

atmos_status atmos__gen_preset(gen_job *job, int which)
{
    switch (which) {
    case 0: return cumulus(job);
    case 1: return cumulonimbus(job, 0);
    case 2: return cumulus_field(job);
    case 3: return atmos__gen_cirrus(job);
    case 4: return rain_shaft_preset(job);
    case 5: return cumulonimbus(job, 1);
    case 6: return atmos__gen_stratocumulus(job);
    default: return atmos__error(job->ctx, ATMOS_E_INVALID_ARG, "generate: no preset %d", which);
    }
}
