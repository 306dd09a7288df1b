/* Cloud shape statistics (include/atmos/cloudstats.h) on shapes with known answers: digitised
 * discs and squares (areas, perimeters, D = 1 for smooth shapes), a seeded field of discs with
 * a known number and a known power-law size distribution, a flat-based and a tilted block,
 * clouds on the edge, periodic wrap, bad input. */
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#define PI 3.14159265358979323846

static atmos_context *ctx;

/* Marks the pixels whose centres lie within r of (cx, cy) (pixel (i, j) has its centre at
 * (i, j)) with optical depth 5; wraps round when periodic. */
static void disc(atmos_cloud_columns *c, double cx, double cy, double r, int periodic)
{
    for (int j = (int)floor(cy - r) - 1; j <= (int)ceil(cy + r) + 1; j++)
        for (int i = (int)floor(cx - r) - 1; i <= (int)ceil(cx + r) + 1; i++) {
            if ((i - cx) * (i - cx) + (j - cy) * (j - cy) > r * r) continue;
            int a = i, b = j;
            if (periodic) a = (a % c->nx + c->nx) % c->nx, b = (b % c->ny + c->ny) % c->ny;
            if (a < 0 || b < 0 || a >= c->nx || b >= c->ny) continue;
            c->tau[(size_t)b * c->nx + a] = 5;
        }
}

static void test_disc(void)
{
    static const double radii[] = {5.3, 10.7, 20.2, 40.6, 80.45};
    for (int t = 0; t < 5; t++) {
        double r = radii[t], h = sqrt(0.5);
        atmos_cloud_columns c;
        CHECK_OK(atmos_cloud_columns_create(ctx, 200, 200, 1.0, &c));
        disc(&c, 99.37, 100.21, r, 0);
        atmos_cloud_stats s;
        CHECK_OK(atmos_cloud_stats_measure(ctx, &c, NULL, &s));
        CHECK(s.nclouds == 1);
        const atmos_cloud *k = &s.clouds[0];
        /* Area: the pixels with centres in the disc cover the disc of radius r - sqrt(2)/2 and lie
         * in the disc of radius r + sqrt(2)/2. */
        CHECK_MSG(k->area_m2 >= PI * (r - h) * (r - h) && k->area_m2 <= PI * (r + h) * (r + h), "r %g area %g", r,
                  k->area_m2);
        /* Crack perimeter of a digitised disc (orthogonally convex): 2 (W + H), each width between
         * 2 sqrt(r^2 - 1/4) - 1 and 2 r + 1 pixels. */
        double lo = 4 * (2 * sqrt(r * r - 0.25) - 1), hi = 4 * (2 * r + 1);
        CHECK_MSG(k->crack_perimeter_m >= lo && k->crack_perimeter_m <= hi, "r %g crack %g not in [%g, %g]", r,
                  k->crack_perimeter_m, lo, hi);
        /* Marching squares: between 1 and 1.0824 times the length along every direction (the
         * factor cos t + (sqrt 2 - 1) sin t), on average 8 (sqrt 2 - 1) / pi = 1.0548. The corners
         * of the digitisation add at most a pixel's diagonal per octant. */
        double ms = k->perimeter_m, c2 = 2 * PI * r;
        CHECK_MSG(ms >= c2 * 1.0 - 8 * h && ms <= c2 * 1.0824 + 8 * h, "r %g ms %g circle %g", r, ms, c2);
        if (r > 40) CHECK_REL(ms / c2, 8 * (sqrt(2.0) - 1) / PI, 0.01);
        CHECK(k->edge == 0);
        CHECK_NEAR(s.fit.cloud_fraction, k->pixels / 40000.0, 1e-12);
        atmos_cloud_stats_free(&s);
        atmos_cloud_columns_free(&c);
    }
}

static void test_square(void)
{
    atmos_cloud_columns c;
    CHECK_OK(atmos_cloud_columns_create(ctx, 64, 64, 25.0, &c));
    for (int j = 10; j < 10 + 17; j++)
        for (int i = 20; i < 20 + 17; i++) c.tau[j * 64 + i] = 1.0f; /* at the threshold: cloudy */
    c.tau[0 * 64 + 40] = 0.999f;                                      /* below: clear */
    atmos_cloud_stats s;
    CHECK_OK(atmos_cloud_stats_measure(ctx, &c, NULL, &s));
    CHECK(s.nclouds == 1);
    CHECK_NEAR(s.clouds[0].area_m2, 17 * 17 * 625.0, 1e-9);
    CHECK_NEAR(s.clouds[0].crack_perimeter_m, 4 * 17 * 25.0, 1e-9);
    /* the outline through the edge midpoints: 4 (s - 1) straight cells and 4 corner diagonals */
    CHECK_NEAR(s.clouds[0].perimeter_m, (4 * 16 + 4 * sqrt(0.5)) * 25.0, 1e-9);
    atmos_cloud_stats_free(&s);
    atmos_cloud_columns_free(&c);
}

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double u01(void)
{
    rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
    return (rng_state >> 11) * (1.0 / 9007199254740992.0);
}

/* Smooth shapes of many sizes: D = 1; and a field with a known number of clouds whose
 * diameters follow n(d) ~ d^-b on [dmin, dmax]. */
static void test_field(int conn)
{
    enum { N = 1024, NCL = 500 };
    const double b = 2.0, dmin = 5, dmax = 60;
    atmos_cloud_columns c;
    CHECK_OK(atmos_cloud_columns_create(ctx, N, N, 10.0, &c));
    double cx[NCL], cy[NCL], rr[NCL];
    rng_state = 12345;
    for (int n = 0; n < NCL; n++) {
        /* inverse CDF of the truncated power law */
        double u = u01(), a1 = pow(dmin, 1 - b), a2 = pow(dmax, 1 - b);
        double d = pow(a1 + u * (a2 - a1), 1 / (1 - b)), r = d / 2;
        for (int tries = 0; tries < 10000; tries++) {
            double x = r + 2 + u01() * (N - 2 * r - 5), y = r + 2 + u01() * (N - 2 * r - 5);
            int ok = 1;
            for (int m = 0; m < n && ok; m++) ok = hypot(x - cx[m], y - cy[m]) > r + rr[m] + 3;
            if (ok) {
                cx[n] = x, cy[n] = y, rr[n] = r;
                break;
            }
        }
        disc(&c, cx[n], cy[n], r, 0);
    }
    atmos_cloud_stats_desc d = {.connectivity = conn, .size_min_m = 10 * (dmin + 1), .size_max_m = 10 * (dmax - 1)};
    atmos_cloud_stats s;
    CHECK_OK(atmos_cloud_stats_measure(ctx, &c, &d, &s));
    CHECK_MSG(s.nclouds == NCL, "%d clouds", s.nclouds);
    CHECK(s.fit.edge_clouds == 0);
    CHECK_NEAR(s.fit.d, 1.0, 0.03);
    CHECK_NEAR(s.fit.d_crack, 1.0, 0.03);
    CHECK(s.fit.d_se < 0.02);
    CHECK_MSG(fabs(s.fit.size_slope - b) < 3 * s.fit.size_slope_se + 0.05, "MLE slope %g +- %g (n %d)", s.fit.size_slope,
              s.fit.size_slope_se, s.fit.size_n);
    CHECK_MSG(s.fit.size_slope_se > 0.02 && s.fit.size_slope_se < 0.2, "se %g", s.fit.size_slope_se);
    CHECK_MSG(fabs(s.fit.size_slope_hist - b) < 3 * s.fit.size_slope_hist_se + 0.1, "histogram slope %g +- %g",
              s.fit.size_slope_hist, s.fit.size_slope_hist_se);
    printf("field (%d-conn): %d clouds, D %.3f +- %.3f, crack %.3f, size slope %.3f +- %.3f (hist %.3f +- %.3f, n %d)\n", conn,
           s.nclouds, s.fit.d, s.fit.d_se, s.fit.d_crack, s.fit.size_slope, s.fit.size_slope_se, s.fit.size_slope_hist,
           s.fit.size_slope_hist_se, s.fit.size_n);
    atmos_cloud_stats_free(&s);
    atmos_cloud_columns_free(&c);
}

/* A rough shape has D > 1: the union of random discs along a random walk. */
static void test_rough(void)
{
    atmos_cloud_columns c;
    CHECK_OK(atmos_cloud_columns_create(ctx, 512, 512, 1.0, &c));
    rng_state = 777;
    for (int n = 0; n < 60; n++) {
        double x = 40 + 430 * u01(), y = 40 + 430 * u01(), r = 1.5;
        int steps = (int)(5 + 400 * pow(u01(), 2));
        for (int s = 0; s < steps; s++) {
            disc(&c, x, y, r + 2 * u01(), 0);
            x += 3 * (u01() - 0.5), y += 3 * (u01() - 0.5);
            x = fmin(fmax(x, 8), 503), y = fmin(fmax(y, 8), 503);
        }
    }
    atmos_cloud_stats s;
    CHECK_OK(atmos_cloud_stats_measure(ctx, &c, NULL, &s));
    CHECK_MSG(s.fit.d > 1.1, "D of random-walk blobs %g", s.fit.d);
    atmos_cloud_stats_free(&s);
    atmos_cloud_columns_free(&c);
}

static void test_edges(void)
{
    atmos_cloud_columns c;
    CHECK_OK(atmos_cloud_columns_create(ctx, 100, 80, 1.0, &c));
    disc(&c, 2.4, 40.3, 10.2, 1); /* across the left edge: wrapped to the right one */
    disc(&c, 50.2, 40.1, 8.3, 1);
    atmos_cloud_stats s;
    CHECK_OK(atmos_cloud_stats_measure(ctx, &c, NULL, &s));
    CHECK(s.nclouds == 3 && s.fit.edge_clouds == 2 && s.fit.fitted == 1);
    atmos_cloud_stats_free(&s);
    atmos_cloud_stats_desc d = {.periodic = 1};
    CHECK_OK(atmos_cloud_stats_measure(ctx, &c, &d, &s));
    CHECK(s.nclouds == 2 && s.fit.edge_clouds == 0);
    /* the wrapped disc measures as the whole disc */
    atmos_cloud_columns w;
    CHECK_OK(atmos_cloud_columns_create(ctx, 100, 80, 1.0, &w));
    disc(&w, 40.4, 40.3, 10.2, 0);
    atmos_cloud_stats sw;
    CHECK_OK(atmos_cloud_stats_measure(ctx, &w, NULL, &sw));
    CHECK(sw.nclouds == 1 && s.clouds[0].pixels == sw.clouds[0].pixels);
    CHECK_NEAR(s.clouds[0].perimeter_m, sw.clouds[0].perimeter_m, 1e-9);
    CHECK_NEAR(s.clouds[0].crack_perimeter_m, sw.clouds[0].crack_perimeter_m, 1e-9);
    atmos_cloud_stats_free(&sw);
    atmos_cloud_columns_free(&w);
    atmos_cloud_stats_free(&s);
    /* two pixels touching at a corner: two clouds with 4 neighbours, one with 8 */
    atmos_cloud_columns_free(&c);
    CHECK_OK(atmos_cloud_columns_create(ctx, 10, 10, 1.0, &c));
    c.tau[3 * 10 + 3] = c.tau[4 * 10 + 4] = 2;
    CHECK_OK(atmos_cloud_stats_measure(ctx, &c, NULL, &s));
    CHECK(s.nclouds == 2);
    CHECK_NEAR(s.clouds[0].perimeter_m + s.clouds[1].perimeter_m, 8 * sqrt(0.5), 1e-12);
    atmos_cloud_stats_free(&s);
    d = (atmos_cloud_stats_desc){.connectivity = 8};
    CHECK_OK(atmos_cloud_stats_measure(ctx, &c, &d, &s));
    CHECK(s.nclouds == 1 && s.clouds[0].pixels == 2);
    CHECK_NEAR(s.clouds[0].crack_perimeter_m, 8, 1e-12);
    atmos_cloud_stats_free(&s);
    atmos_cloud_columns_free(&c);
}

/* A block of uniform cloud, 20 x 12 columns of 50 m voxels, its base flat at voxel 10 or
 * rising one voxel per column along x; top at voxel 30. */
static void test_flatness(void)
{
    for (int tilted = 0; tilted < 2; tilted++) {
        atmos_volume_desc vd = {.dims = {40, 40, 30}, .voxel_size_m = 50, .origin_m = {-1000, 0, -750}};
        atmos_volume *v = NULL;
        int f = -1;
        CHECK_OK(atmos_volume_create(ctx, &vd, &v));
        CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "cloud", &f));
        for (int k = 5; k < 17; k++)
            for (int i = 5; i < 25; i++)
                for (int j = 10 + (tilted ? i - 5 : 0); j < 30; j++) CHECK_OK(atmos_volume_set(ctx, v, f, i, j, k, 1e8f));
        CHECK_OK(atmos_volume_finalize(ctx, v));
        double sigma = 6.28e-10; /* 62.8 km^-1: 3.14 per voxel */
        atmos_cloud_columns c;
        CHECK_OK(atmos_cloud_columns_from_volume(ctx, v, &sigma, 0.1, &c));
        CHECK(c.nx == 40 && c.ny == 30 && c.dx_m == 50);
        CHECK_REL(c.tau[10 * 40 + 5], (tilted ? 20 : 20) * 50 * 6.28e-10 * 1e8, 1e-6);
        /* the base 0.1 optical depths above the block's bottom: 0.1 / 3.14 of a voxel */
        CHECK_NEAR(c.base_m[10 * 40 + 5], 500 + 50 * 0.1 / 3.14, 1e-3);
        CHECK_NEAR(c.top_m[10 * 40 + 5], 1500 - 50 * 0.1 / 3.14, 1e-3);
        atmos_cloud_stats s;
        CHECK_OK(atmos_cloud_stats_measure(ctx, &c, NULL, &s));
        CHECK(s.nclouds == 1 && s.clouds[0].pixels == 240);
        /* tilted: bases 50 m i apart over 20 columns, sd = 50 sqrt((20^2 - 1) / 12) */
        double sd = tilted ? 50 * sqrt((400 - 1) / 12.0) : 0, depth = tilted ? 1000 - 0.1 / 3.14 * 100 : 1000 - 0.1 / 3.14 * 100;
        CHECK_NEAR(s.clouds[0].base_sd_m, sd, 1e-3);
        if (!tilted) CHECK_NEAR(s.clouds[0].depth_m, depth, 1e-3);
        CHECK_NEAR(s.fit.flatness_median, sd / s.clouds[0].depth_m, 1e-6);
        if (tilted) CHECK(s.fit.flatness_median > 0.2);
        else CHECK(s.fit.flatness_median < 1e-6);
        atmos_cloud_stats_free(&s);
        atmos_cloud_columns_free(&c);
        atmos_volume_destroy(v);
    }
}

static void test_bad_input(void)
{
    atmos_cloud_columns c;
    CHECK(atmos_cloud_columns_create(ctx, 0, 10, 1, &c) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_cloud_columns_create(ctx, 10, 10, NAN, &c) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_cloud_columns_create(ctx, 65536, 65536, 1, &c) == ATMOS_E_INVALID_ARG);
    CHECK_OK(atmos_cloud_columns_create(ctx, 10, 10, 1, &c));
    atmos_cloud_stats s;
    atmos_cloud_stats_desc d = {.tau_threshold = -1};
    CHECK(atmos_cloud_stats_measure(ctx, &c, &d, &s) == ATMOS_E_INVALID_ARG && !s.clouds);
    d = (atmos_cloud_stats_desc){.connectivity = 6};
    CHECK(atmos_cloud_stats_measure(ctx, &c, &d, &s) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_cloud_stats_measure(ctx, NULL, NULL, &s) == ATMOS_E_INVALID_ARG);
    CHECK_OK(atmos_cloud_stats_measure(ctx, &c, NULL, &s)); /* clear sky: no clouds, fits NAN */
    CHECK(s.nclouds == 0 && s.fit.cloud_fraction == 0 && isnan(s.fit.d) && isnan(s.fit.size_slope));
    CHECK(s.fit.size_n == 0 && isnan(s.fit.size_min_m) && isnan(s.fit.size_max_m)); /* no range, not an inverted one */
    atmos_cloud_stats_free(&s);
    atmos_cloud_columns_free(&c);
    atmos_volume_desc vd = {.dims = {8, 8, 8}, .voxel_size_m = 10, .rotation = {0, 0, 1, 0, 1, 0, -1, 0, 0}};
    atmos_volume *v = NULL;
    int f;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "cloud", &f));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    double sigma = 1e-9;
    CHECK(atmos_cloud_columns_from_volume(ctx, v, &sigma, 0.1, &c) == ATMOS_E_INVALID_ARG);
    atmos_volume_destroy(v);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_disc();
    test_square();
    test_field(4);
    test_field(8);
    test_rough();
    test_edges();
    test_flatness();
    test_bad_input();
    atmos_context_destroy(ctx);
    return test_summary("test_cloud_stats");
}
