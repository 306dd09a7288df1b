/* The angle-table reader (src/optics/angle_table.h) against independent references: a
 * linear scan for the interval of an angle, on the library's two grids and on a random grid
 * with angles on and one ulp beside the lookup's bin edges; the slice renderer's per-pixel
 * lookup (atmos__angle_locate) against its former implementation, a hinted bisection, kept
 * here as the reference; the weights of the sampled density; the path tracer's copies of a
 * table's density (exact single-precision copies, and the truncated tables' sampler against
 * their evaluation). */
#include "atmos/atmos.h"
#include "optics/angle_table.h"
#include "render/path_phase.h"
#include "render/slice_tables.h"
#include "test.h"

#include <stdint.h>

#define PI 3.14159265358979323846

static uint64_t rng_state = 77;
static double uniform(void)
{
    return test_uniform_from(&rng_state);
}

/* ---- references */

/* The interval of x by a linear scan: the last i <= n - 2 with deg[i] <= x; 0 at or below
 * the first angle and for NaN. */
static int scan_find(const double *deg, int n, double x)
{
    if (!(x > deg[0])) return 0;
    int i = 0;
    for (int j = 0; j + 1 < n; j++)
        if (deg[j] <= x) i = j;
    return i;
}

/* atmos__angle_locate as it was before the angle-table reader: the hint and its
 * neighbours, then a bisection of the whole grid. */
static void old_locate(const double *grid, int ng, double theta_deg, int *a, float *w)
{
    int lo = 0, hi = ng - 1;
    for (int g = *a - 1; g <= *a + 1; g++)
        if (g >= 0 && g < ng - 1 && grid[g] < theta_deg && theta_deg < grid[g + 1]) {
            *a = g;
            *w = (float)((theta_deg - grid[g]) / (grid[g + 1] - grid[g]));
            return;
        }
    if (theta_deg <= grid[0]) {
        *a = 0, *w = 0;
        return;
    }
    if (theta_deg >= grid[ng - 1]) {
        *a = ng - 2, *w = 1;
        return;
    }
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (grid[mid] <= theta_deg) lo = mid;
        else hi = mid;
    }
    *a = lo;
    *w = (float)((theta_deg - grid[lo]) / (grid[lo + 1] - grid[lo]));
}

/* ---- test angles: every grid angle, its neighbours one ulp away, the midpoints, every
 * bin edge of the lookup (j / 20 and j * 0.05, which round differently) and its
 * neighbours, random angles over the range and near 0°, the ends and beyond, NaN. */
typedef struct {
    double *x;
    int n, cap;
} angles;

static void add(angles *a, double x)
{
    if (a->n == a->cap) {
        a->cap = a->cap ? 2 * a->cap : 4096;
        a->x = realloc(a->x, sizeof(double) * (size_t)a->cap);
        if (!a->x) exit(1);
    }
    a->x[a->n++] = x;
}

static void add_near(angles *a, double x)
{
    add(a, x);
    add(a, nextafter(x, -INFINITY));
    add(a, nextafter(x, INFINITY));
}

static angles test_angles(const double *deg, int n)
{
    angles a = {0};
    for (int i = 0; i < n; i++) {
        add_near(&a, deg[i]);
        if (i + 1 < n) add(&a, 0.5 * (deg[i] + deg[i + 1]));
    }
    for (int j = 0; j <= ATMOS__ANGLE_LUT; j++) {
        add_near(&a, j / ATMOS__ANGLE_BINS_PER_DEG);
        add_near(&a, j * 0.05);
    }
    for (int i = 0; i < 200000; i++) add(&a, 180 * uniform());
    for (int i = 0; i < 50000; i++) add(&a, pow(10, -8 + 9 * uniform())); /* 1e-8 .. 10 degrees */
    const double special[] = {0.0, -0.0, -1e-300, -5.0, 180.0, 180.0 + 1e-13, 1e300, INFINITY, -INFINITY, NAN};
    for (size_t i = 0; i < sizeof special / sizeof *special; i++) add(&a, special[i]);
    return a;
}

/* ---- the reader */

static void check_reader(const char *name, const atmos__angle_grid *g)
{
    angles a = test_angles(g->deg, g->n);
    long bad_find = 0, bad_lerp = 0;
    for (int q = 0; q < a.n; q++) {
        const double x = a.x[q];
        const int ref = scan_find(g->deg, g->n, x);
        if (atmos__angle_find(g, x) != ref) {
            if (bad_find++ < 5) fprintf(stderr, "%s: find(%.17g) = %d, scan %d\n", name, x, atmos__angle_find(g, x), ref);
        }
        /* lerp: the interval above, the fraction linear in degrees, clamped at the ends */
        double f, fr;
        const int i = atmos__angle_lerp(g, x, &f);
        if (!(x > 0)) fr = 0;
        else if (x >= 180) fr = 1;
        else fr = (x - g->deg[ref]) / (g->deg[ref + 1] - g->deg[ref]);
        if (i != ref || memcmp(&f, &fr, sizeof f) != 0) bad_lerp++;
    }
    CHECK_MSG(bad_find == 0, "%s: %ld of %d angles in the wrong interval", name, bad_find, a.n);
    CHECK_MSG(bad_lerp == 0, "%s: %ld of %d lerp results differ", name, bad_lerp, a.n);
    printf("%s: %d angles, reader = linear scan\n", name, a.n);
    free(a.x);
}

/* A grid of random angles, dense near 0°, with angles exactly on lookup bin edges and
 * pairs one ulp apart, built through atmos__angle_grid_init. */
static void check_random_grid(atmos__angle_grid *g)
{
    enum { N = 5000 };
    static double d[N];
    int n = 0;
    d[n++] = 0.0;
    for (int i = 1; i < N - 1; i++) {
        double r = uniform();
        if (i % 7 == 0) d[i] = (int)(3600 * uniform()) * 0.05;
        else if (i % 11 == 0) d[i] = (int)(3600 * uniform()) / 20.0;
        else if (i % 3 == 0) d[i] = pow(10, -6 + 8 * r);
        else d[i] = 180 * r;
        if (i % 13 == 0) d[i] = nextafter(d[i - 1], INFINITY);
    }
    /* sort, keep distinct angles inside (0, 180) */
    for (int i = 1; i < N - 1; i++) {
        double v = d[i];
        int j = i - 1;
        while (j >= 1 && d[j] > v) d[j + 1] = d[j], j--;
        d[j + 1] = v;
    }
    for (int i = 1; i < N - 1; i++)
        if (d[i] > d[n - 1] && d[i] < 180.0) d[n++] = d[i];
    d[n++] = 180.0;
    CHECK(atmos__angle_grid_init(g, d, n));
    check_reader("random grid", g);

    /* and the slice renderer's lookup on a grid that is not one of the library's (the
     * fallback bisection) */
    angles a = test_angles(g->deg, g->n);
    long bad = 0;
    int hint = 0;
    for (int q = 0; q < a.n; q++) {
        int a1 = q % 5 == 0 ? (int)(uniform() * n) : hint, a2 = a1;
        float w1, w2;
        old_locate(g->deg, g->n, a.x[q], &a1, &w1);
        atmos__angle_locate(g->deg, g->n, a.x[q], &a2, &w2);
        if (a1 != a2 || memcmp(&w1, &w2, sizeof w1) != 0) bad++;
        hint = a1;
    }
    CHECK_MSG(bad == 0, "atmos__angle_locate on a random grid: %ld of %d differ from the former lookup", bad, a.n);
    free(a.x);

    /* not grids */
    const double bad1[] = {0, 10, 10, 180}, bad2[] = {0.1, 10, 180}, bad3[] = {0, NAN, 180}, bad4[] = {0, 10, 179};
    CHECK(!atmos__angle_grid_init(g, bad1, 4) && !atmos__angle_grid_init(g, bad2, 3));
    CHECK(!atmos__angle_grid_init(g, bad3, 3) && !atmos__angle_grid_init(g, bad4, 3));
    CHECK(!atmos__angle_grid_init(g, d, 1) && !atmos__angle_grid_init(g, d, ATMOS__ANGLE_MAX + 1));
}

/* The library's grids: sizes and landmarks (docs/phase-tables.md, docs/msphase.md), the
 * public pointers, and the lookup by pointer. */
static void check_grids(void)
{
    const atmos__angle_grid *pg = atmos__phase_angle_grid(), *mg = atmos__msphase_angle_grid();
    const double *theta;
    CHECK(atmos_phase_grid(&theta) == 4951 && theta == pg->deg && pg->n == 4951);
    CHECK(pg->deg[200] == 0.1 && pg->deg[650] == 1.0 && pg->deg[1550] == 10.0 && pg->deg[4950] == 180.0);
    CHECK(fabs(pg->deg[1551] - 10.05) < 1e-12 && fabs(pg->deg[201] - 0.102) < 1e-15);
    CHECK(mg->n == 200 + 400 + 150 + 360 + 1600 + 1);
    CHECK(mg->deg[600] == 0.5 && mg->deg[750] == 2.0 && mg->deg[1110] == 20.0 && mg->deg[mg->n - 1] == 180.0);
    int inc = 1;
    for (int i = 0; i + 1 < pg->n; i++) inc &= pg->deg[i] < pg->deg[i + 1] && pg->sin[i] == sin(pg->rad[i]);
    for (int i = 0; i + 1 < mg->n; i++) inc &= mg->deg[i] < mg->deg[i + 1];
    CHECK(inc);
    CHECK(atmos__angle_grid_known(pg->deg, pg->n) == pg && atmos__angle_grid_known(mg->deg, mg->n) == mg);
    CHECK(atmos__angle_grid_known(pg->deg, pg->n - 1) == NULL && atmos__angle_grid_known(theta + 1, pg->n) == NULL);
    check_reader("phase grid", pg);
    check_reader("Ams grid", mg);

    /* The slice renderer's per-pixel lookup on the Ams grid: (a, w) bit for bit as before,
     * whatever the hint (the neighbouring pixel's, a random one, or garbage). */
    angles a = test_angles(mg->deg, mg->n);
    long bad = 0;
    int hint = 0;
    for (int q = 0; q < a.n; q++) {
        int a1 = q % 3 == 0 ? (int)(uniform() * (mg->n + 20)) - 10 : hint, a2 = a1;
        float w1, w2;
        old_locate(mg->deg, mg->n, a.x[q], &a1, &w1);
        atmos__angle_locate(mg->deg, mg->n, a.x[q], &a2, &w2);
        if (a1 != a2 || memcmp(&w1, &w2, sizeof w1) != 0) {
            if (bad++ < 5) fprintf(stderr, "locate(%.17g): (%d, %.9g) former (%d, %.9g)\n", a.x[q], a2, w2, a1, w1);
        }
        hint = a1;
    }
    CHECK_MSG(bad == 0, "atmos__angle_locate on the Ams grid: %ld of %d differ from the former lookup", bad, a.n);
    free(a.x);
}

/* ---- the weights of the sampled density, against the formulas of angle_table.h with the
 * interval from the linear scan; and their meaning: with f_i = sin(theta_i) (P = 1), the
 * density is the interpolant of sin over sin, 1 at the grid angles. */
static void check_weights(void)
{
    const atmos__angle_grid *g = atmos__phase_angle_grid();
    long bad = 0;
    double worst = 0;
    for (int q = 0; q < 400000; q++) {
        double mu;
        if (q < g->n) mu = cos(g->rad[q]);
        else if (q < 2 * g->n) mu = nextafter(cos(g->rad[q - g->n]), q % 2 ? 2 : -2);
        else if (q % 4 == 0) mu = cos(1e-4 * uniform());
        else mu = 2 * uniform() - 1;
        if (q == 0) mu = 1;
        if (q == 1) mu = -1;
        if (q == 2) mu = 1.5;
        if (q == 3) mu = NAN;
        atmos__angle_weights w;
        atmos__angle_density_weights(g, mu, &w);
        double m = isnan(mu) || mu < -1 ? -1 : mu > 1 ? 1 : mu;
        const double th = acos(m);
        const int i = scan_find(g->deg, g->n, th * (180.0 / PI));
        const double h = g->rad[i + 1] - g->rad[i];
        double s = (th - g->rad[i]) / h;
        s = s < 0 ? 0 : s > 1 ? 1 : s;
        double w0, w1;
        if (i == 0) w0 = 0, w1 = (th > 1e-12 ? th / sin(th) : 1.0) / h;
        else if (i == g->n - 2) w0 = ((PI - th) > 1e-12 ? (PI - th) / sin(th) : 1.0) / h, w1 = 0;
        else w0 = (1 - s) * (1.0 / sin(th)), w1 = s * (1.0 / sin(th));
        if (w.i != i || w.s != s || w.w0 != w0 || w.w1 != w1) bad++;
        /* P = 1: p = w0 sin_i + w1 sin_{i+1}, within the interpolation error of sin */
        const double p = w.w0 * g->sin[w.i] + w.w1 * g->sin[w.i + 1];
        if (fabs(p - 1) > worst) worst = fabs(p - 1);
    }
    CHECK_MSG(bad == 0, "%ld density weights differ from the reference", bad);
    CHECK_MSG(worst < 1e-5, "isotropic density: max |p - 1| = %g", worst);
    printf("density weights: isotropic table reads back as 1 to %.2g\n", worst);
}

/* ---- the path tracer's copies: untruncated, f_i in single precision exactly; truncated,
 * a density (integral 1) that its sampler draws (CDF at a sampled angle = u). */
static double path_integral(const path_phase *p, int f, int k, double lo_rad, double hi_rad)
{
    const atmos__angle_grid *g = p->grid;
    double s = 0;
    for (int i = 0; i + 1 < g->n; i++) {
        double a = fmax(g->rad[i], lo_rad), b = fmin(g->rad[i + 1], hi_rad);
        if (!(b > a)) continue;
        /* the density times sin is linear in theta inside an interval: two Gauss points are exact */
        const double c = 0.5 * (a + b), r = 0.5 * (b - a) / sqrt(3.0);
        path_angle w1, w2;
        atmos__path_angle(p, cos(c - r), &w1);
        atmos__path_angle(p, cos(c + r), &w2);
        s += 0.5 * (b - a) * (atmos__path_phase_eval(p, f, k, &w1) * sin(c - r) + atmos__path_phase_eval(p, f, k, &w2) * sin(c + r));
    }
    return 2 * PI * s;
}

static void check_path_phase(void)
{
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_particle_desc pd;
    memset(&pd, 0, sizeof pd);
    snprintf(pd.name, sizeof pd.name, "hg");
    pd.kind = ATMOS_PARTICLE_ANALYTIC;
    pd.analytic.count = 2;
    pd.analytic.kind[0] = ATMOS_PHASE_HG, pd.analytic.g[0] = 0.98, pd.analytic.weight[0] = 0.7;
    pd.analytic.kind[1] = ATMOS_PHASE_HG, pd.analytic.g[1] = 0.3, pd.analytic.weight[1] = 0.3;
    atmos_phase_table *t = NULL;
    atmos_phase_table_desc td = {1};
    CHECK_OK(atmos_phase_table_build(NULL, &pd, &wl, &td, &t));
    if (!t) return;
    atmos_volume_optics o;
    memset(&o, 0, sizeof o);
    o.count = 1;
    o.phase[0] = t;
    path_phase p;
    CHECK_OK(atmos__path_phase_build(NULL, &o, 3, 0, &p));
    const int n = p.ng;
    long bad = 0;
    for (int k = 0; k < 3; k++) {
        const double *v = atmos_phase_table_values(t, k), F = atmos__phase_table_total(t, k);
        for (int i = 0; i < n; i++) bad += p.fv[0][(size_t)k * n + i] != (float)(v[i] * sin(p.grid->rad[i]) / F);
        CHECK_NEAR(F, 1.0, 1e-12);
    }
    CHECK_MSG(bad == 0, "%ld single-precision densities are not the table's", bad);
    double worst = 0;
    for (int q = 0; q < 20000; q++) {
        double mu = q % 2 ? 2 * uniform() - 1 : cos(0.1 * uniform());
        path_angle a;
        atmos__path_angle(&p, mu, &a);
        double e = atmos_phase_table_eval(t, 1, mu), r = fabs(atmos__path_phase_eval(&p, 0, 1, &a) - e) / e;
        if (r > worst) worst = r;
    }
    CHECK_MSG(worst < 1e-6, "path evaluation vs atmos_phase_table_eval: %g", worst);
    CHECK(atmos__path_phase_sample(&p, 0, 1, 0.3) == atmos_phase_table_sample(t, 1, 0.3));
    atmos__path_phase_free(&p);

    /* truncated at 3°: the fraction removed, a normalised density, and its sampler */
    CHECK_OK(atmos__path_phase_build(NULL, &o, 3, 3.0, &p));
    CHECK(p.ic > 0 && fabs(p.cut_deg - 3.0) < 1e-9);
    CHECK_MSG(p.trunc[0][1] > 0.3 && p.trunc[0][1] < 0.7, "truncated fraction %g", p.trunc[0][1]);
    CHECK_NEAR(path_integral(&p, 0, 1, 0, PI), 1.0, 1e-6);
    double werr = 0;
    for (int q = 0; q < 500; q++) {
        const double u = (q + 0.5) / 500;
        const double th = acos(atmos__path_phase_sample(&p, 0, 1, u));
        werr = fmax(werr, fabs(path_integral(&p, 0, 1, 0, th) - u));
    }
    CHECK_MSG(werr < 1e-6, "truncated sampler vs its density: CDF at a sample differs from u by %g", werr);
    /* below the cut the truncated density is flat in P (P(theta_c)), above it the table's */
    path_angle a0, a1, a2;
    atmos__path_angle(&p, cos(0.5 * PI / 180), &a0);
    atmos__path_angle(&p, cos(2.9 * PI / 180), &a1);
    atmos__path_angle(&p, cos(20 * PI / 180), &a2);
    CHECK_REL(atmos__path_phase_eval(&p, 0, 1, &a0), atmos__path_phase_eval(&p, 0, 1, &a1), 1e-3);
    CHECK_REL(atmos__path_phase_eval(&p, 0, 1, &a2) * (1 - p.trunc[0][1]), atmos_phase_table_eval(t, 1, cos(20 * PI / 180)), 1e-6);
    printf("path phase: exact copies, eval within %.2g of the table's; truncated at 3 deg removes %.4f, sampler within %.2g\n",
           worst, p.trunc[0][1], werr);
    atmos__path_phase_free(&p);
    atmos_phase_table_destroy(t);
}

int main(void)
{
    check_grids();
    atmos__angle_grid *g = malloc(sizeof *g);
    if (g) check_random_grid(g);
    free(g);
    check_weights();
    check_path_phase();
    return test_summary("test_angle_table");
}
