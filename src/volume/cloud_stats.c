/* The clouds of a projected cloud mask: connected pixels (4 or 8 neighbours, optionally
 * wrapping round), each cloud's area, two perimeters and its base's flatness
 * (include/atmos/cloudstats.h, docs/clouds.md "Shape statistics").
 *
 * Perimeters. The crack perimeter counts the pixel edges between the cloud and clear pixels:
 * for a large smooth shape it is the outline's length times 4/pi on average over directions
 * (a straight edge at angle t to the grid is counted as |cos t| + |sin t| per unit length).
 * The marching-squares perimeter joins the midpoints of those pixel edges round each corner
 * (segments of length 1 or sqrt(2)/2 through the 2 x 2 cells of pixel centres); a straight
 * edge at t in [0, 45 deg] then measures cos t + (sqrt 2 - 1) sin t per unit length, on
 * average over directions 8 (sqrt 2 - 1) / pi = 1.0548 times the true length. Neither factor
 * changes the perimeter-area dimension of shapes much larger than a pixel. */
#include "atmos/cloudstats.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define HALF_DIAG 0.70710678118654752

static int find(int *parent, int x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

static void join(int *parent, int a, int b)
{
    a = find(parent, a), b = find(parent, b);
    if (a < b) parent[b] = a;
    else if (b < a) parent[a] = b;
}

typedef struct {
    int nx, ny, periodic;
    const int *label;
} grid;

/* The label at (i, j), -1 for clear or outside the grid (wrapped when periodic). */
static int at(const grid *g, int i, int j)
{
    if (g->periodic) {
        i = (i % g->nx + g->nx) % g->nx;
        j = (j % g->ny + g->ny) % g->ny;
    } else if (i < 0 || j < 0 || i >= g->nx || j >= g->ny) {
        return -1;
    }
    return g->label[(size_t)j * g->nx + i];
}

/* Labels the cloudy pixels by union-find, numbered in the order of their first pixel. */
static int label_clouds(const atmos_cloud_columns *c, double tau0, int conn8, int periodic, int *parent, int *label)
{
    int nx = c->nx, ny = c->ny, n = nx * ny;
    for (int p = 0; p < n; p++) parent[p] = c->tau[p] >= tau0 ? p : -1;
    static const int off4[2][2] = {{1, 0}, {0, 1}}, off8[4][2] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            int p = j * nx + i;
            if (parent[p] < 0) continue;
            for (int o = 0; o < (conn8 ? 4 : 2); o++) {
                int di = conn8 ? off8[o][0] : off4[o][0], dj = conn8 ? off8[o][1] : off4[o][1];
                int a = i + di, b = j + dj;
                if (periodic) a = (a + nx) % nx, b = b % ny;
                else if (a < 0 || a >= nx || b >= ny) continue;
                int q = b * nx + a;
                if (parent[q] >= 0) join(parent, p, q);
            }
        }
    int count = 0;
    for (int p = 0; p < n; p++) label[p] = -1;
    for (int p = 0; p < n; p++) {
        if (parent[p] < 0) continue;
        int r = find(parent, p);
        if (label[r] < 0) label[r] = count++;
        label[p] = label[r];
    }
    return count;
}

/* Marching squares over the 2 x 2 cells of pixel centres: each segment's length goes to the
 * cloud of an inside corner (a saddle's two segments each to its own corner's cloud). */
static void outline(const grid *g, atmos_cloud *cl)
{
    int lo = g->periodic ? 0 : -1;
    for (int j = lo; j < g->ny; j++)
        for (int i = lo; i < g->nx; i++) {
            int k[4] = {at(g, i, j), at(g, i + 1, j), at(g, i + 1, j + 1), at(g, i, j + 1)}; /* round the cell */
            int in = (k[0] >= 0) + (k[1] >= 0) + (k[2] >= 0) + (k[3] >= 0);
            if (in == 0 || in == 4) continue;
            if (in == 2 && (k[0] >= 0) == (k[2] >= 0)) { /* a saddle */
                for (int m = 0; m < 4; m++)
                    if (k[m] >= 0) cl[k[m]].perimeter_m += HALF_DIAG;
                continue;
            }
            int first = 0;
            while (k[first] < 0) first++;
            cl[k[first]].perimeter_m += in == 2 ? 1.0 : HALF_DIAG;
        }
}

/* Area, crack perimeter, edge flag and the bases' mean, spread and depth per cloud;
 * low/top/nb are work arrays of ncl entries. */
static void per_cloud(const grid *g, const atmos_cloud_columns *c, atmos_cloud *cl, int ncl, double *low, double *top,
                      int *nb)
{
    for (int m = 0; m < ncl; m++) top[m] = -INFINITY, low[m] = INFINITY, nb[m] = 0;
    for (int j = 0; j < g->ny; j++)
        for (int i = 0; i < g->nx; i++) {
            size_t p = (size_t)j * g->nx + i;
            int k = g->label[p];
            if (k < 0) continue;
            atmos_cloud *a = &cl[k];
            a->pixels++;
            a->crack_perimeter_m += (at(g, i - 1, j) < 0) + (at(g, i + 1, j) < 0) + (at(g, i, j - 1) < 0) + (at(g, i, j + 1) < 0);
            if (!g->periodic && (i == 0 || j == 0 || i == g->nx - 1 || j == g->ny - 1)) a->edge = 1;
            double b = c->base_m[p];
            if (!isfinite(b)) continue;
            a->base_mean_m += b;
            nb[k]++;
            if (b < low[k]) low[k] = b;
            if (c->top_m[p] > top[k]) top[k] = c->top_m[p];
        }
    for (int m = 0; m < ncl; m++) cl[m].base_mean_m = nb[m] ? cl[m].base_mean_m / nb[m] : NAN;
    for (size_t p = 0; p < (size_t)g->nx * g->ny; p++) {
        int k = g->label[p];
        double b = c->base_m[p];
        if (k >= 0 && isfinite(b)) cl[k].base_sd_m += (b - cl[k].base_mean_m) * (b - cl[k].base_mean_m);
    }
    double dx = c->dx_m;
    for (int m = 0; m < ncl; m++) {
        atmos_cloud *a = &cl[m];
        a->area_m2 = a->pixels * dx * dx;
        a->perimeter_m *= dx;
        a->crack_perimeter_m *= dx;
        a->diameter_m = sqrt(4 * a->area_m2 / ATMOS_PI);
        a->base_sd_m = nb[m] ? sqrt(a->base_sd_m / nb[m]) : NAN;
        a->depth_m = nb[m] ? top[m] - low[m] : NAN;
    }
}

atmos_status atmos_cloud_stats_measure(atmos_context *ctx, const atmos_cloud_columns *cols,
                                       const atmos_cloud_stats_desc *desc, atmos_cloud_stats *out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "cloud stats: no output");
    memset(out, 0, sizeof *out);
    if (!cols || !cols->tau || !cols->base_m || !cols->top_m || cols->nx < 1 || cols->ny < 1 ||
        (long long)cols->nx * cols->ny > (1LL << 30) || !(cols->dx_m > 0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "cloud stats: no columns");
    atmos_cloud_stats_desc d = desc ? *desc : (atmos_cloud_stats_desc){0};
    if (d.tau_threshold == 0) d.tau_threshold = 1;
    if (d.connectivity == 0) d.connectivity = 4;
    if (!(d.tau_threshold > 0 && isfinite(d.tau_threshold)) || (d.connectivity != 4 && d.connectivity != 8) ||
        !(d.fit_min_pixels >= 0) || !(d.size_min_m >= 0) || !(d.size_max_m >= 0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "cloud stats: threshold %g (expected > 0), connectivity %d (4 or 8), fit ranges must be >= 0",
                            d.tau_threshold, d.connectivity);
    int n = cols->nx * cols->ny;
    int *parent = malloc((size_t)n * sizeof *parent);
    out->label = malloc((size_t)n * sizeof *out->label);
    if (!parent || !out->label) {
        free(parent);
        atmos_cloud_stats_free(out);
        return atmos__error(ctx, ATMOS_E_NOMEM, "cloud stats: out of memory");
    }
    int ncl = label_clouds(cols, d.tau_threshold, d.connectivity == 8, d.periodic != 0, parent, out->label);
    out->clouds = calloc((size_t)(ncl ? ncl : 1), sizeof *out->clouds);
    double *work = malloc((size_t)(ncl ? ncl : 1) * 2 * sizeof *work);
    if (!out->clouds || !work) {
        free(parent);
        free(work);
        atmos_cloud_stats_free(out);
        return atmos__error(ctx, ATMOS_E_NOMEM, "cloud stats: out of memory for %d clouds", ncl);
    }
    out->nclouds = ncl;
    grid g = {cols->nx, cols->ny, d.periodic != 0, out->label};
    outline(&g, out->clouds);
    per_cloud(&g, cols, out->clouds, ncl, work, work + ncl, parent); /* parent reused as counts */
    free(parent);
    free(work);
    out->pixels = n;
    for (int p = 0; p < n; p++) out->cloudy_pixels += out->label[p] >= 0;
    atmos_cloud_stats_fit(out->clouds, ncl, out->cloudy_pixels, out->pixels, cols->dx_m, &d, &out->fit);
    return ATMOS_OK;
}

void atmos_cloud_stats_free(atmos_cloud_stats *s)
{
    if (!s) return;
    free(s->clouds);
    free(s->label);
    memset(s, 0, sizeof *s);
}
