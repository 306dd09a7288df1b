/* The storm generators (docs/volumes.md "Generated storms"): the cumulonimbus, the storm
 * (the cumulonimbus with its rain), rain_shaft (a shower under a cumulus congestus) and
 * virga (rain that evaporates before it reaches the ground).
 *
 * Shapes follow photographs of mature cumulonimbus and the textbook picture of one (e.g.
 * Houze, "Cloud Dynamics", 2nd ed. 2014, ch. 8): a broad, flat base at the condensation
 * level; a tower of big convective cells with smaller ones on their surfaces (Nishita's
 * metaball hierarchy: big balls in tiers, refined by smaller balls on the isosurface,
 * which grow only up and sideways); an anvil, a thin sheet of ice whose top is flat at the
 * tropopause, spreading far downwind (+x, the shear) and little upwind, thinner and
 * fibrous towards its edges, with an overshooting dome above the updraft. The rain falls
 * from the base under the downwind half of the tower, drifts downwind as it falls and
 * fades smoothly to zero at its edges; virga thins downward to nothing above the ground.
 *
 * Peak number densities with the optics presets' cross-sections (cloud 6.28e-10, ice
 * 1.82e-6, rain 6.28e-6 m^2; Riley Table 2): cloud droplets 1e8 m^-3 (63 km^-1), the
 * glaciated tower 1e4 m^-3 of ice (18 km^-1), the anvil 2e3 m^-3 next to the tower (3.6
 * km^-1) thinning downwind, rain 5e2 m^-3 (3.1 km^-1: moderate rain, in which one sees
 * 1-2 km).
 */
#include "volume/generate_job.h"

#include <math.h>

#define ISO 0.3f
#define ETA_CLOUD 1e8
#define ETA_ICE_TOWER 1e4
#define ETA_ICE_ANVIL 2e3
#define ETA_RAIN 5e2


/* A convective tower: the radius of its isosurface goes from r_base at the base through
 * r_mid half-way up to r_top at the top; the axis leans downwind by `lean` m per m. */
typedef struct {
    double x, z, base, top, r_base, r_mid, r_top, ball, lean;
} tower_shape;

static double tower_radius(const tower_shape *t, double y)
{
    double u = gen_clamp01((y - t->base) / (t->top - t->base));
    return u < 0.5 ? t->r_base + (t->r_mid - t->r_base) * gen_smoothstep(0, 0.5, u)
                   : t->r_mid + (t->r_top - t->r_mid) * gen_smoothstep(0.5, 1, u);
}

static double tower_axis(const tower_shape *t, double y) { return t->x + t->lean * (y - t->base); }

/* The big cells: tiers 0.55 ball apart, each a disc filled with concentric rings of balls
 * so that the isosurface (~0.85 ball outside the outer ring) has the tower's radius. The
 * lowest tier is centred just above the base: the cut at the base goes through the cells'
 * widest part, a broad flat base. */
static int tower_balls(gen_job *job, gen_balls *bl, const tower_shape *t)
{
    const double b = t->ball;
    for (double y = t->base + 0.15 * b; y <= t->top - 0.6 * b; y += 0.55 * b) {
        double ax = tower_axis(t, y), ring = tower_radius(t, y) - 0.85 * b;
        if (!atmos__gen_balls_add(bl, ax + gen_range(&job->rng, -0.1, 0.1) * b, y, t->z + gen_range(&job->rng, -0.1, 0.1) * b,
                                  b * gen_range(&job->rng, 0.9, 1.1), 1, 1))
            return 0;
        for (double rr = ring; rr > 0.4 * b; rr -= 0.8 * b) {
            int m = (int)ceil(2 * ATMOS_PI * rr / (0.8 * b));
            double phase = gen_range(&job->rng, 0, 2 * ATMOS_PI);
            for (int n = 0; n < m; n++) {
                double a = phase + 2 * ATMOS_PI * (n + gen_range(&job->rng, -0.2, 0.2)) / m;
                double r = rr * gen_range(&job->rng, 0.9, 1.05);
                if (!atmos__gen_balls_add(bl, ax + r * cos(a), y + gen_range(&job->rng, -0.1, 0.1) * b,
                                          t->z + r * sin(a), b * gen_range(&job->rng, 0.75, 1.05), 1, 1))
                    return 0;
            }
        }
    }
    return 1;
}

/* Balls -> field F, then Nishita's refinement: three levels of smaller cells on the
 * surface, none on downward faces (the base stays flat), so the top grows cauliflower. */
static atmos_status tower_field(gen_job *job, gen_grid *g, const tower_shape *t, int levels, int floor_j)
{
    atmos__gen_accumulate(g, &job->balls, 0, job->threads);
    gen_refine p = {.levels = levels, .r0 = 0.4 * t->ball, .ratio = 0.5, .coverage = 1.5, .iso = ISO,
                    .floor_j = floor_j, .max_balls = 20000, .fringe = 0, .ctx = job->ctx};
    return atmos__gen_refine(g, &job->balls, &p, &job->rng, job->threads) ? ATMOS_OK : gen_nomem(job);
}

/* F -> number densities: liquid below the glaciation band [yg0, yg1], ice above it; the
 * liquid grows with height above the base (adiabatic water content) to its peak hlw above
 * it. Rows below floor_j are 0. ice may be NULL (no glaciation: yg0 above the grid). */
static void tower_density(gen_job *job, gen_grid *cl, gen_grid *ice, double base, double hlw, double yg0, double yg1,
                          int floor_j)
{
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < cl->n[2]; k++)
        for (int j = 0; j < cl->n[1]; j++) {
            double y = gen_vox(job, j, 1), fi = ice ? gen_smoothstep(yg0, yg1, y) : 0;
            double h = 0.35 + 0.65 * gen_clamp01((y - base) / hlw);
            size_t row = ((size_t)k * cl->n[1] + j) * cl->n[0];
            for (int i = 0; i < cl->n[0]; i++) {
                double s = j < floor_j ? 0 : gen_clamp01((cl->v[row + i] - ISO) / 0.6);
                cl->v[row + i] = (float)(ETA_CLOUD * s * h * (1 - fi));
                if (ice) ice->v[row + i] = (float)(ETA_ICE_TOWER * s * fi);
            }
        }
}

/* The anvil: a sheet whose top is flat at y_top, from lu upwind of the axis x0 to ld
 * downwind (a rounded outline), its half-width w0 across the wind at the axis growing by
 * 0.2 m per m downwind, its thickness th0 next to the tower thinning downwind; edges eaten
 * by noise stretched along the wind (fibres).
 * Written as max(ice, anvil). */
static void anvil(gen_job *job, gen_grid *ice, double x0, double y_top, double lu, double ld, double w0, double th0,
                  uint64_t seed)
{
    const double s = job->scale;
    uint64_t s_edge = seed, s_th = seed ^ 0x5bd1e995ull, s_fine = seed ^ 0x27d4eb2full;
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < ice->n[2]; k++)
        for (int i = 0; i < ice->n[0]; i++) {
            double x = gen_vox(job, i, 0), z = gen_vox(job, k, 2), d = x - x0;
            double fib = atmos__gen_fbm3(s_edge, x / (5000 * s), 0.3, z / (700 * s), 4, 0.55) - 0.5;
            double along = d < 0 ? -d / lu : d / ld, across = fabs(z) / (w0 + 0.2 * fmax(d, 0));
            double e = cbrt(across * across * across + along * along * along) * (1 + 0.5 * fib);
            double edge = 1 - gen_smoothstep(0.55, 1.0, e);
            if (edge <= 0) continue;
            double dd = fmax(d, 0), fall = atmos__gen_fbm3(s_th, x / (3000 * s), 0.6, z / (3000 * s), 3, 0.5);
            double th = th0 * (0.3 + 0.7 * exp(-dd / (4000 * s))) * (0.6 + 0.8 * fall) * sqrt(edge);
            double thin = ETA_ICE_ANVIL * (0.3 + 0.7 * exp(-dd / (6000 * s))) * edge;
            for (int j = 0; j < ice->n[1]; j++) {
                double y = gen_vox(job, j, 1), t = (y_top - y) / th;
                if (t <= -0.05 || t >= 1) continue;
                double vert = gen_smoothstep(-0.05, 0.12, t) * (1 - gen_smoothstep(0.5, 1, t));
                double fine = gen_smoothstep(0.2, 0.8, atmos__gen_fbm3(s_fine, x / (3000 * s), y / (200 * s), z / (400 * s), 5, 0.55));
                float v = (float)(thin * vert * (0.15 + 0.85 * fine));
                float *p = ice->v + ((size_t)k * ice->n[1] + j) * ice->n[0] + i;
                if (v > *p) *p = v;
            }
        }
}

/* Rain from the cloud base down: around an axis that starts at (x0, z0) at the base and
 * drifts downwind by `slant` m per m of fall; the density fades from the axis to zero at a
 * noisy radius ~R (no walls), is streaked along the fall, and thins towards the ground by
 * evaporation; with y_end > 0 (virga) it falls to zero at y_end. Zero at and above the base. */
typedef struct {
    double x0, z0, base, radius, slant, y_end, eta;
} rain_shape;

static void rain(gen_job *job, gen_grid *g, const rain_shape *r, uint64_t seed)
{
    const double s = job->scale, ramp = fmax(job->voxel, 100 * s);
    uint64_t s_edge = seed, s_streak = seed ^ 0x9e3779b97f4a7c15ull;
#pragma omp parallel for schedule(static) num_threads(job->threads)
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++) {
            double y = gen_vox(job, j, 1), fall = r->base - y;
            if (fall <= 0 || y <= r->y_end) continue;
            double vert = gen_smoothstep(0, ramp, fall);
            vert *= r->y_end > 0 ? gen_smoothstep(r->y_end, r->y_end + 0.8 * (r->base - r->y_end), y) : 0.7 + 0.3 * y / r->base;
            double ax = r->x0 + r->slant * fall;
            float *row = g->v + ((size_t)k * g->n[1] + j) * g->n[0];
            for (int i = 0; i < g->n[0]; i++) {
                double x = gen_vox(job, i, 0), z = gen_vox(job, k, 2);
                double q = hypot(x - ax, z - r->z0) / r->radius;
                if (q > 1.6) continue;
                double wob = atmos__gen_fbm3(s_edge, x / r->radius, y / (4 * r->radius), z / r->radius, 3, 0.5);
                double radial = 1 - gen_smoothstep(0.25, 1.0, q * (0.7 + 0.6 * wob));
                if (radial <= 0) continue;
                double streak = atmos__gen_fbm3(s_streak, x / (300 * s), y / (3000 * s), z / (300 * s), 3, 0.5);
                row[i] = (float)(r->eta * radial * vert * (0.5 + 0.5 * streak));
            }
        }
}

/* cumulonimbus (cloud, ice) and storm (cloud, ice, rain). */
atmos_status atmos__gen_cumulonimbus(gen_job *job, int with_rain)
{
    const double s = job->scale, base = 1000, y_top = base + 9300 * s;
    job->voxel = job->voxel_override ? job->voxel_override : 80 * s;
    job->ngrids = with_rain ? 3 : 2;
    job->field_name[0] = "cloud";
    job->field_name[1] = "ice";
    job->field_name[2] = "rain";
    double lo[3] = {-4500 * s, with_rain ? 0 : base - 80 * s, -7000 * s}, hi[3] = {13000 * s, base + 11000 * s, 7000 * s};
    atmos_status st = atmos__gen_grid_init(job, lo, hi);
    if (st != ATMOS_OK) return st;
    tower_shape t = {.x = 0, .z = 0, .base = base, .top = y_top - 200 * s, .r_base = 2900 * s, .r_mid = 2000 * s,
                     .r_top = 2600 * s, .ball = 1500 * s, .lean = 0.06};
    if (!tower_balls(job, &job->balls, &t)) return gen_nomem(job);
    /* The overshooting top: a dome over the updraft, ~1 km above the anvil after refinement. */
    double xo = tower_axis(&t, y_top);
    for (int n = 0; n < 3; n++) {
        double dx = gen_range(&job->rng, -500, 500) * s, dy = gen_range(&job->rng, -600, -400) * s;
        double z = gen_range(&job->rng, -500, 500) * s, r = 1300 * s * gen_range(&job->rng, 0.9, 1.1);
        if (!atmos__gen_balls_add(&job->balls, xo + dx, y_top + dy, z, r, 1, 1)) return gen_nomem(job);
    }
    int fj = atmos__gen_floor_j(job, base);
    if ((st = tower_field(job, &job->grid[0], &t, 3, fj)) != ATMOS_OK) return st;
    uint64_t seed_anvil = atmos__splitmix64(&job->rng.s), seed_rain = atmos__splitmix64(&job->rng.s);
    tower_density(job, &job->grid[0], &job->grid[1], base, 6000 * s, base + 6000 * s, base + 7500 * s, fj);
    /* Noise stretches the edge by up to 1/0.75, rarely beyond 1/0.8: the anvil ends inside the grid. */
    anvil(job, &job->grid[1], xo, y_top, 1.25 * t.r_top, 0.8 * (12900 * s - xo), 1.1 * t.r_top, 2400 * s, seed_anvil);
    if (with_rain) {
        rain_shape r = {.x0 = 0.3 * t.r_base, .z0 = 0, .base = base, .radius = 0.75 * t.r_base, .slant = 0.2, .y_end = 0,
                        .eta = ETA_RAIN};
        rain(job, &job->grid[2], &r, seed_rain);
    }
    return ATMOS_OK;
}

/* rain_shaft: a cumulus congestus (base 1.2 km) raining to the ground; virga: a high-based
 * cumulus (base 2.5 km) whose rain evaporates ~0.8 km above the ground. */
atmos_status atmos__gen_rain_shaft(gen_job *job, int virga)
{
    const double s = job->scale, base = virga ? 2500 : 1200;
    job->voxel = job->voxel_override ? job->voxel_override : 25 * s;
    job->ngrids = 2;
    job->field_name[0] = "cloud";
    job->field_name[1] = "rain";
    double lo[3] = {-2100 * s, 0, -2100 * s}, hi[3] = {2100 * s, base + 3300 * s, 2100 * s};
    atmos_status st = atmos__gen_grid_init(job, lo, hi);
    if (st != ATMOS_OK) return st;
    tower_shape t = {.x = -300 * s, .z = 0, .base = base, .top = base + 2500 * s, .r_base = 1500 * s, .r_mid = 1250 * s,
                     .r_top = 800 * s, .ball = 700 * s, .lean = 0.05};
    if (!tower_balls(job, &job->balls, &t)) return gen_nomem(job);
    int fj = atmos__gen_floor_j(job, base);
    if ((st = tower_field(job, &job->grid[0], &t, 3, fj)) != ATMOS_OK) return st;
    uint64_t seed_rain = atmos__splitmix64(&job->rng.s);
    tower_density(job, &job->grid[0], NULL, base, 0.8 * (t.top - base), 1e30, 1e30, fj);
    rain_shape r = {.x0 = 0, .z0 = 0, .base = base, .radius = 900 * s, .slant = virga ? 0.12 : 0.15,
                    .y_end = virga ? 800 : 0, .eta = 2 * ETA_RAIN};
    rain(job, &job->grid[1], &r, seed_rain);
    return ATMOS_OK;
}
