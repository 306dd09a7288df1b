/* Volume core: trilinear sampling, optical depth (Riley et al. 2004 Eq. 4) against
 * analytic and brute-force references, empty-space skipping, sparse memory, limits,
 * input validation, the raw+JSON round trip and the raw-format crashers. */
#define _POSIX_C_SOURCE 200809L
#include "atmos/atmos.h"
#include "test.h"
#include "volume/volume_grid.h"

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static uint64_t rng_state = 0x1234567ull;
static double urand(void)
{
    /* xorshift64*: test-local randomness, fixed seed */
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

static void rot_axis_angle(double ax, double ay, double az, double deg, double r[9])
{
    double n = sqrt(ax * ax + ay * ay + az * az);
    ax /= n, ay /= n, az /= n;
    double c = cos(deg * ATMOS_PI / 180), s = sin(deg * ATMOS_PI / 180), t = 1 - c;
    double m[9] = {t * ax * ax + c,      t * ax * ay - s * az, t * ax * az + s * ay,
                   t * ax * ay + s * az, t * ay * ay + c,      t * ay * az - s * ax,
                   t * ax * az - s * ay, t * ay * az + s * ax, t * az * az + c};
    memcpy(r, m, sizeof m);
}

/* world = origin + R (index * voxel) */
static void index_to_world(const atmos_volume_desc *d, const double q[3], double p[3])
{
    for (int a = 0; a < 3; a++)
        p[a] = d->origin_m[a] + d->voxel_size_m * (d->rotation[3 * a] * q[0] + d->rotation[3 * a + 1] * q[1] +
                                                   d->rotation[3 * a + 2] * q[2]);
}

static atmos_volume *random_volume(atmos_context *ctx, const int dims[3], const double rot[9], double fill, int nfields)
{
    atmos_volume_desc d = {.dims = {dims[0], dims[1], dims[2]}, .voxel_size_m = 2.5, .origin_m = {100, -20, 7}};
    if (rot) memcpy(d.rotation, rot, sizeof d.rotation);
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &d, &v));
    static const char *names[] = {"cloud", "rain", "ice"};
    for (int f = 0; f < nfields; f++) {
        int idx;
        CHECK_OK(atmos_volume_add_field(ctx, v, names[f], NULL, &idx));
        for (int k = 0; k < dims[2]; k++)
            for (int j = 0; j < dims[1]; j++)
                for (int i = 0; i < dims[0]; i++)
                    if (urand() < fill) atmos_volume_set(ctx, v, f, i, j, k, (float)(urand() * 1000));
    }
    CHECK_OK(atmos_volume_finalize(ctx, v));
    return v;
}

static void test_sampling(atmos_context *ctx)
{
    const int dims[3] = {13, 9, 11};
    double rot[9];
    rot_axis_angle(0.3, 1, -0.5, 37, rot);
    for (int r = 0; r < 2; r++) {
        atmos_volume *v = random_volume(ctx, dims, r ? rot : NULL, 0.7, 1);
        const atmos_volume_desc *d = atmos_volume_get_desc(v);
        int bad = 0;
        double maxerr = 0;
        for (int k = 0; k < dims[2]; k++)
            for (int j = 0; j < dims[1]; j++)
                for (int i = 0; i < dims[0]; i++) {
                    double q[3] = {i + 0.5, j + 0.5, k + 0.5}, p[3];
                    index_to_world(d, q, p);
                    double want = vol_voxel(v, &v->field[0], i, j, k), got = atmos_volume_sample(v, 0, p);
                    double e = fabs(got - want);
                    if (e > 1e-9 * (1 + want)) bad++;
                    if (e > maxerr) maxerr = e;
                }
        CHECK_MSG(bad == 0, "%d voxel centres not reproduced (max err %g, rotation %d)", bad, maxerr, r);
        /* Linear along each axis between neighbouring centres, and trilinear inside a cell. */
        for (int n = 0; n < 200; n++) {
            int i = (int)(urand() * (dims[0] - 1)), j = (int)(urand() * (dims[1] - 1)), k = (int)(urand() * (dims[2] - 1));
            double fx = urand(), fy = urand(), fz = urand();
            double c[8];
            for (int c8 = 0; c8 < 8; c8++)
                c[c8] = vol_voxel(v, &v->field[0], i + (c8 & 1), j + (c8 >> 1 & 1), k + (c8 >> 2 & 1));
            double want = 0;
            for (int c8 = 0; c8 < 8; c8++)
                want += c[c8] * (c8 & 1 ? fx : 1 - fx) * (c8 & 2 ? fy : 1 - fy) * (c8 & 4 ? fz : 1 - fz);
            double q[3] = {i + 0.5 + fx, j + 0.5 + fy, k + 0.5 + fz}, p[3];
            index_to_world(d, q, p);
            CHECK_NEAR(atmos_volume_sample(v, 0, p), want, 1e-9 * (1 + want));
        }
        /* Outside the grid box: 0. */
        double q[3] = {-0.01, 3, 3}, p[3];
        index_to_world(d, q, p);
        CHECK(atmos_volume_sample(v, 0, p) == 0);
        atmos_volume_destroy(v);
    }
}

/* Length of the chord of the index box [0,n] cut by o + t dir, t in [t0, t1], in world metres. */
static double chord_world(const atmos_volume_desc *d, const double o[3], const double dir[3], double t0, double t1)
{
    /* Independent of the library: bisection for entry/exit on a fine scan. */
    double q0[3], dq[3];
    for (int a = 0; a < 3; a++) {
        double po = o[a] - d->origin_m[a];
        q0[a] = 0;
        dq[a] = 0;
        for (int b = 0; b < 3; b++) {
            q0[a] += d->rotation[3 * b + a] * (o[b] - d->origin_m[b]) / d->voxel_size_m;
            dq[a] += d->rotation[3 * b + a] * dir[b] / d->voxel_size_m;
        }
        (void)po;
    }
    double lo = t0, hi = t1;
    for (int a = 0; a < 3; a++) {
        if (dq[a] == 0) {
            if (q0[a] < 0 || q0[a] > d->dims[a]) return 0;
            continue;
        }
        double ta = -q0[a] / dq[a], tb = (d->dims[a] - q0[a]) / dq[a];
        if (ta > tb) { double x = ta; ta = tb; tb = x; }
        lo = fmax(lo, ta);
        hi = fmin(hi, tb);
    }
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    return hi > lo ? (hi - lo) * len : 0;
}

static void test_constant_box(atmos_context *ctx)
{
    const double eta = 350.0, sigma[1] = {2.2e-3};
    double rot[9];
    for (int r = 0; r < 3; r++) {
        atmos_volume_desc d = {.dims = {20, 30, 25}, .voxel_size_m = 1.7, .origin_m = {-5, 3, 11}};
        if (r == 1) rot_axis_angle(0, 1, 0, 30, d.rotation);
        if (r == 2) rot_axis_angle(1, -2, 0.7, 113, d.rotation);
        memcpy(rot, d.rotation, sizeof rot);
        atmos_volume *v = NULL;
        CHECK_OK(atmos_volume_create(ctx, &d, &v));
        CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "cloud", NULL));
        float *vals = malloc(sizeof(float) * 20 * 30 * 25);
        for (int n = 0; n < 20 * 30 * 25; n++) vals[n] = (float)eta;
        int off[3] = {0, 0, 0};
        CHECK_OK(atmos_volume_set_dense(ctx, v, 0, off, d.dims, vals, 1.0f));
        free(vals);
        CHECK_OK(atmos_volume_finalize(ctx, v));
        const atmos_volume_desc *rd = atmos_volume_get_desc(v);
        double centre[3], qc[3] = {10, 15, 12.5};
        index_to_world(rd, qc, centre);
        double worst = 0;
        for (int n = 0; n < 100; n++) {
            /* A direction at a random angle through a random point of the box's middle. */
            double th = acos(2 * urand() - 1), ph = 2 * ATMOS_PI * urand();
            double dir[3] = {sin(th) * cos(ph), cos(th), sin(th) * sin(ph)};
            double scale = n % 2 ? 1.0 : 3.7; /* non-unit directions too */
            double o[3];
            for (int a = 0; a < 3; a++) {
                dir[a] *= scale;
                o[a] = centre[a] + (urand() - 0.5) * 10 - dir[a] * 100 / scale;
            }
            double t0 = n % 3 == 0 ? 30 / scale : 0, t1 = n % 5 == 0 ? 110 / scale : INFINITY;
            double want = eta * sigma[0] * chord_world(rd, o, dir, t0, t1);
            double got = atmos_volume_optical_depth(v, sigma, o, dir, t0, t1);
            double e = fabs(got - want) / fmax(want, 1e-300);
            if (want > 0 && e > worst) worst = e;
            CHECK_REL(got, want, 1e-10);
        }
        printf("constant box (rotation %d): worst relative error %.2e over 100 rays\n", r, worst);
        atmos_volume_destroy(v);
    }
    (void)rot;
}

/* A random sparse two-field volume: a few blobs of occupied bricks. */
static double blob_centre[8][3];
static atmos_volume *sparse_volume(atmos_context *ctx, const double *rot)
{
    atmos_volume_desc d = {.dims = {48, 40, 56}, .voxel_size_m = 3.0, .origin_m = {10, 1000, -50}};
    if (rot) memcpy(d.rotation, rot, sizeof d.rotation);
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &d, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", NULL, NULL));
    CHECK_OK(atmos_volume_add_field(ctx, v, "rain", NULL, NULL));
    for (int b = 0; b < 8; b++) {
        int c[3] = {(int)(urand() * 48), (int)(urand() * 40), (int)(urand() * 56)};
        int rad = 2 + (int)(urand() * 6), f = b % 2;
        double q[3] = {c[0] + 0.5, c[1] + 0.5, c[2] + 0.5};
        index_to_world(atmos_volume_get_desc(v), q, blob_centre[b]);
        for (int k = c[2] - rad; k <= c[2] + rad; k++)
            for (int j = c[1] - rad; j <= c[1] + rad; j++)
                for (int i = c[0] - rad; i <= c[0] + rad; i++)
                    if (i >= 0 && j >= 0 && k >= 0 && i < 48 && j < 40 && k < 56 && urand() < 0.8)
                        atmos_volume_set(ctx, v, f, i, j, k, (float)(50 + 900 * urand()));
    }
    CHECK_OK(atmos_volume_finalize(ctx, v));
    return v;
}

static void test_dda_vs_quadrature(atmos_context *ctx)
{
    double rot[9];
    rot_axis_angle(1, 1, 0.2, 21, rot);
    const double sigma[2] = {1.3e-3, 4e-4};
    for (int r = 0; r < 2; r++) {
        atmos_volume *v = sparse_volume(ctx, r ? rot : NULL);
        double lo[3], hi[3];
        atmos_volume_bounds(v, lo, hi);
        double worst = 0;
        int identical = 1, nonzero = 0;
        for (int n = 0; n < 24; n++) {
            /* Through a blob centre (most rays) or between random points. */
            double a[3], b[3], dir[3];
            const double *c = blob_centre[n % 8];
            double u = urand();
            for (int k = 0; k < 3; k++) {
                a[k] = lo[k] + (hi[k] - lo[k]) * (urand() * 1.4 - 0.2);
                b[k] = n % 4 == 3 ? lo[k] + (hi[k] - lo[k]) * (urand() * 1.4 - 0.2) : c[k] + (c[k] - a[k]) * u;
                dir[k] = b[k] - a[k];
            }
            /* Brute force: midpoint rule on 100k steps of the point extinction. */
            const int N = getenv("ATMOS_QN") ? atoi(getenv("ATMOS_QN")) : 100000;
            double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]), sum = 0;
            for (int s = 0; s < N; s++) {
                double t = (s + 0.5) / N, p[3] = {a[0] + t * dir[0], a[1] + t * dir[1], a[2] + t * dir[2]};
                sum += atmos_volume_extinction(v, sigma, p);
            }
            double brute = sum * len / N;
            double got = atmos_volume_optical_depth(v, sigma, a, dir, 0, 1);
            double noskip = atmos__volume_optical_depth_ex(v, sigma, a, dir, 0, 1, 0);
            if (got != noskip) identical = 0;
            if (brute > 0) {
                nonzero++;
                double e = fabs(got - brute) / brute;
                if (e > worst) worst = e;
                CHECK_REL(got, brute, 1e-4);
            } else {
                CHECK(got == 0);
            }
        }
        printf("DDA vs 100k-step quadrature (rotation %d): %d non-empty rays, worst relative error %.2e\n", r, nonzero,
               worst);
        CHECK(nonzero >= 10);
        CHECK_MSG(identical, "empty-space skipping changed the optical depth");
        atmos_volume_destroy(v);
    }
}

static void test_sparse_memory(atmos_context *ctx)
{
    atmos_volume_desc d = {.dims = {1024, 1024, 1024}, .voxel_size_m = 10};
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &d, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", NULL, NULL));
    uint64_t before = atmos_volume_memory(v);
    CHECK_OK(atmos_volume_set(ctx, v, 0, 500, 600, 700, 1.0f));
    CHECK_OK(atmos_volume_set(ctx, v, 0, 501, 600, 700, 2.0f)); /* same brick */
    uint64_t one = atmos_volume_memory(v);
    CHECK_OK(atmos_volume_set(ctx, v, 0, 10, 10, 10, 3.0f));
    uint64_t two = atmos_volume_memory(v);
    CHECK_OK(atmos_volume_finalize(ctx, v));
    uint64_t tables = 128ull * 128 * 128 * 4; /* brick table; the per-brick bounds index is the same size */
    uint64_t brick = 512 * 4;
    /* The brick pool grows by doubling: the first brick pays for a growth of at most 16
     * bricks, the second fits in it. */
    CHECK_MSG(one - before >= brick && one - before <= 16 * brick, "first brick cost %llu bytes",
              (unsigned long long)(one - before));
    CHECK_MSG(two == one, "second brick cost %llu bytes", (unsigned long long)(two - one));
    uint64_t total = atmos_volume_memory(v);
    printf("1024^3 grid with 2 occupied bricks: %llu bytes (dense float32 would be %llu)\n", (unsigned long long)total,
           1024ull * 1024 * 1024 * 4);
    /* finalize trims the pool to the zero brick and the two bricks */
    CHECK(total <= 2 * tables + 3 * brick + 4096);
    atmos_volume_field_stats s;
    CHECK_OK(atmos_volume_field_stats_get(ctx, v, 0, &s));
    CHECK(s.active_voxels == 3);
    CHECK(s.min == 1 && s.max == 3);
    CHECK_NEAR(s.bounds_m[0][0], 100, 1e-9);
    CHECK_NEAR(s.bounds_m[1][0], 5020, 1e-9);
    CHECK_NEAR(s.bounds_m[1][2], 7010, 1e-9);
    atmos_volume_destroy(v);
}

static void test_limits_and_errors(atmos_context *ctx)
{
    atmos_volume *v = NULL;
    atmos_volume_desc d = {.dims = {1024, 1024, 1024}, .voxel_size_m = 1, .max_memory = 1 << 20};
    CHECK_OK(atmos_volume_create(ctx, &d, &v));
    CHECK(atmos_volume_add_field(ctx, v, "cloud", NULL, NULL) == ATMOS_E_LIMIT);
    CHECK(strstr(atmos_context_error(ctx), "bytes") != NULL);
    atmos_volume_destroy(v);

    /* A small table fits but a dense block's bricks do not. */
    atmos_volume_desc d2 = {.dims = {64, 64, 64}, .voxel_size_m = 1, .max_memory = 64 * 1024};
    CHECK_OK(atmos_volume_create(ctx, &d2, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", NULL, NULL));
    float *vals = malloc(sizeof(float) * 64 * 64 * 64);
    for (int n = 0; n < 64 * 64 * 64; n++) vals[n] = 1;
    int off[3] = {0, 0, 0};
    CHECK(atmos_volume_set_dense(ctx, v, 0, off, d2.dims, vals, 1) == ATMOS_E_LIMIT);
    CHECK(strstr(atmos_context_error(ctx), "brick") != NULL);
    CHECK(atmos_volume_memory(v) <= 64 * 1024);
    atmos_volume_destroy(v);

    /* Invalid descriptions name the field. */
    atmos_volume_desc bad = {.dims = {4, 0, 4}, .voxel_size_m = 1};
    CHECK(atmos_volume_create(ctx, &bad, &v) == ATMOS_E_INVALID_ARG && v == NULL);
    CHECK(strstr(atmos_context_error(ctx), "dims[1]") != NULL);
    bad.dims[1] = ATMOS_VOLUME_MAX_DIM + 1;
    CHECK(atmos_volume_create(ctx, &bad, &v) == ATMOS_E_INVALID_ARG);
    bad.dims[1] = 4;
    bad.voxel_size_m = -2;
    CHECK(atmos_volume_create(ctx, &bad, &v) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "voxel_size_m") != NULL);
    bad.voxel_size_m = NAN;
    CHECK(atmos_volume_create(ctx, &bad, &v) == ATMOS_E_INVALID_ARG);
    bad.voxel_size_m = 1;
    bad.rotation[0] = 2;
    CHECK(atmos_volume_create(ctx, &bad, &v) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "rotation") != NULL);
    bad.origin_m[2] = INFINITY;
    bad.rotation[0] = 0;
    CHECK(atmos_volume_create(ctx, &bad, &v) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "origin_m[2]") != NULL);

    /* Bad densities name the voxel and leave the volume unchanged. */
    atmos_volume_desc d3 = {.dims = {8, 8, 8}, .voxel_size_m = 1};
    CHECK_OK(atmos_volume_create(ctx, &d3, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", NULL, NULL));
    CHECK(atmos_volume_add_field(ctx, v, "cloud", NULL, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_volume_set(ctx, v, 0, 1, 2, 3, NAN) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "(1, 2, 3)") != NULL);
    CHECK(atmos_volume_set(ctx, v, 0, 1, 2, 3, -1.0f) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_volume_set(ctx, v, 0, 8, 0, 0, 1.0f) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_volume_set(ctx, v, 1, 0, 0, 0, 1.0f) == ATMOS_E_INVALID_ARG);
    for (int n = 0; n < 64; n++) vals[n] = 1;
    vals[2 * 16 + 3 * 4 + 1] = -5; /* block index (1, 3, 2) */
    int off2[3] = {2, 2, 2}, sz[3] = {4, 4, 4};
    CHECK(atmos_volume_set_dense(ctx, v, 0, off2, sz, vals, 1) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "voxel 3, 5, 4") != NULL);
    vals[2 * 16 + 3 * 4 + 1] = INFINITY;
    CHECK(atmos_volume_set_dense(ctx, v, 0, off2, sz, vals, 1) == ATMOS_E_INVALID_ARG);
    vals[2 * 16 + 3 * 4 + 1] = 3e38f;
    CHECK(atmos_volume_set_dense(ctx, v, 0, off2, sz, vals, 10) == ATMOS_E_INVALID_ARG); /* overflows */
    int off3[3] = {6, 0, 0};
    CHECK(atmos_volume_set_dense(ctx, v, 0, off3, sz, vals, 1) == ATMOS_E_INVALID_ARG); /* out of the grid */
    CHECK_OK(atmos_volume_finalize(ctx, v));
    atmos_volume_field_stats s;
    CHECK_OK(atmos_volume_field_stats_get(ctx, v, 0, &s));
    CHECK(s.active_voxels == 0 && s.min == 0 && s.max == 0);
    CHECK(atmos_volume_set(ctx, v, 0, 0, 0, 0, 1.0f) == ATMOS_E_INVALID_ARG); /* after finalize */
    /* An empty volume: zero everywhere, optical depth 0, no NaN. */
    double sig[1] = {1}, o[3] = {-1, 4, 4}, dir[3] = {1, 0, 0};
    CHECK(atmos_volume_optical_depth(v, sig, o, dir, 0, INFINITY) == 0);
    double zero[3] = {0, 0, 0};
    CHECK(atmos_volume_optical_depth(v, sig, o, zero, 0, 1) == 0);
    atmos_volume_destroy(v);
    free(vals);
    atmos_volume_destroy(NULL);
}

/* Staged files left by a write that was killed before renaming them (their names: the file's
 * + ".staged"): a later write of the same set removes them first, so that even when it fails
 * (here at the third field, whose staged name is a folder that cannot be replaced) none is
 * left. */
static void test_raw_stale_staged(atmos_context *ctx)
{
    const int dims[3] = {5, 4, 3};
    double rot[9];
    rot_axis_angle(0, 0, 1, 0, rot);
    atmos_volume *v = random_volume(ctx, dims, rot, 0.4, 3);
    if (!v) return;
    char json[1024], staged_json[1100], raw0[1100], dir2[1100], inner[1200];
    test_tmp_path(json, sizeof json, "stale.json");
    const size_t stem = strlen(json) - 5;
    snprintf(staged_json, sizeof staged_json, "%s.staged", json);
    snprintf(raw0, sizeof raw0, "%.*s.%s.raw.staged", (int)stem, json, atmos_volume_field_name(v, 0));
    snprintf(dir2, sizeof dir2, "%.*s.%s.raw.staged", (int)stem, json, atmos_volume_field_name(v, 2));
    snprintf(inner, sizeof inner, "%s/x", dir2);
    FILE *f;
    if ((f = fopen(staged_json, "wb"))) fputs("{\"killed\": true}\n", f), fclose(f);
    if ((f = fopen(raw0, "wb"))) fputs("partial", f), fclose(f);
    mkdir(dir2, 0755);
    if ((f = fopen(inner, "wb"))) fclose(f);
    CHECK(atmos_volume_write_raw(ctx, v, json) != ATMOS_OK);
    CHECK_MSG(access(staged_json, F_OK) != 0, "%s left behind", staged_json);
    CHECK_MSG(access(raw0, F_OK) != 0, "%s left behind", raw0);
    CHECK_MSG(access(json, F_OK) != 0, "%s written by a failed write", json);
    remove(inner), rmdir(dir2);
    atmos_volume_destroy(v);
}

static void test_raw_roundtrip(atmos_context *ctx)
{
    const int dims[3] = {19, 7, 12};
    double rot[9];
    rot_axis_angle(0.2, 0.9, 0.1, 63, rot);
    atmos_volume *v = random_volume(ctx, dims, rot, 0.4, 3);
    char path[1024];
    test_tmp_path(path, sizeof path, "roundtrip.json");
    CHECK_OK(atmos_volume_write_raw(ctx, v, path));
    atmos_volume *w = NULL;
    CHECK_OK(atmos_volume_load(ctx, path, NULL, &w));
    if (!w) {
        atmos_volume_destroy(v);
        return;
    }
    const atmos_volume_desc *a = atmos_volume_get_desc(v), *b = atmos_volume_get_desc(w);
    CHECK(!memcmp(a->dims, b->dims, sizeof a->dims));
    CHECK(a->voxel_size_m == b->voxel_size_m);
    CHECK(!memcmp(a->origin_m, b->origin_m, sizeof a->origin_m));
    CHECK(!memcmp(a->rotation, b->rotation, sizeof a->rotation));
    CHECK(atmos_volume_field_count(w) == 3);
    int diff = 0;
    for (int f = 0; f < 3; f++) {
        CHECK(!strcmp(atmos_volume_field_name(v, f), atmos_volume_field_name(w, f)));
        CHECK(!strcmp(atmos_volume_field_particle(v, f), atmos_volume_field_particle(w, f)));
        for (int k = 0; k < dims[2]; k++)
            for (int j = 0; j < dims[1]; j++)
                for (int i = 0; i < dims[0]; i++)
                    if (vol_voxel(v, &v->field[f], i, j, k) != vol_voxel(w, &w->field[f], i, j, k)) diff++;
        atmos_volume_field_stats s1, s2;
        atmos_volume_field_stats_get(ctx, v, f, &s1);
        atmos_volume_field_stats_get(ctx, w, f, &s2);
        CHECK(s1.active_voxels == s2.active_voxels && s1.max == s2.max);
    }
    CHECK_MSG(diff == 0, "%d voxels differ after the round trip", diff);
    atmos_volume_destroy(w);

    /* The single-field sidecar form, with a scale and a field name override. */
    char json[1024], raw[1024];
    test_tmp_path(json, sizeof json, "single.json");
    test_tmp_path(raw, sizeof raw, "single.raw");
    float vals[8] = {0, 1, 2, 3, 4, 5, 6, 0.5f};
    FILE *f = fopen(raw, "wb");
    fwrite(vals, 4, 8, f); /* the test machines are little-endian */
    fclose(f);
    f = fopen(json, "w");
    fprintf(f, "{\"file\": \"single.raw\", \"dims\": [2, 2, 2], \"voxel_size_m\": 4, \"origin_m\": [1, 2, 3], "
               "\"field\": \"rain\", \"scale\": 1000}\n");
    fclose(f);
    CHECK_OK(atmos_volume_load(ctx, json, NULL, &w));
    if (w) {
        CHECK(!strcmp(atmos_volume_field_name(w, 0), "rain"));
        double p[3] = {1 + 4 * 1.5, 2 + 4 * 0.5, 3 + 4 * 1.5}; /* centre of voxel (1, 0, 1) = value 5 */
        CHECK_NEAR(atmos_volume_sample(w, 0, p), 5000, 1e-9);
        atmos_volume_destroy(w);
    }
    atmos_volume_load_desc ld = {.field = "snow", .density_scale = 2};
    CHECK_OK(atmos_volume_load(ctx, json, &ld, &w));
    if (w) {
        CHECK(!strcmp(atmos_volume_field_name(w, 0), "snow"));
        atmos_volume_field_stats s;
        atmos_volume_field_stats_get(ctx, w, 0, &s);
        CHECK(s.max == 12000 && s.active_voxels == 7);
        atmos_volume_destroy(w);
    }
    atmos_volume_destroy(v);
    /* Missing file: I/O error; not a volume: format error. */
    CHECK(atmos_volume_load(ctx, "/nonexistent/x.json", NULL, &w) == ATMOS_E_IO);
    f = fopen(raw, "wb");
    fputs("hello", f);
    fclose(f);
    CHECK(atmos_volume_load(ctx, raw, NULL, &w) == ATMOS_E_FORMAT && w == NULL);
}

static void test_crashers(atmos_context *ctx)
{
    const char *src = getenv("ATMOS_SOURCE_DIR");
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/tests/crashers/volume", src && *src ? src : "..");
    DIR *dp = opendir(dir);
    CHECK_MSG(dp != NULL, "cannot open %s", dir);
    if (!dp) return;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(dp))) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 5, ".json")) continue;
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        atmos_volume *v = (atmos_volume *)(uintptr_t)1;
        atmos_status st = atmos_volume_load(ctx, path, NULL, &v);
        CHECK_MSG(st == ATMOS_E_FORMAT, "%s: got %s (%s)", e->d_name, atmos_status_string(st), atmos_context_error(ctx));
        CHECK_MSG(v == NULL, "%s: out not cleared", e->d_name);
        CHECK_MSG(strstr(atmos_context_error(ctx), e->d_name) != NULL, "%s: message does not name the file: %s",
                  e->d_name, atmos_context_error(ctx));
        if (st == ATMOS_E_FORMAT && getenv("ATMOS_VERBOSE")) printf("  %s\n", atmos_context_error(ctx));
        if (st != ATMOS_E_FORMAT) atmos_volume_destroy(v);
        n++;
    }
    closedir(dp);
    printf("%d volume crashers rejected\n", n);
    CHECK(n >= 30);
}

/* A scene's volume: generator, placement by position_m (bottom-face centre) and by
 * default in front of the camera, and the optical-depth image of a constant box
 * (tau = sigma eta L along the axis, 0 beside it). */
static void test_scene_volume(atmos_context *ctx)
{
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.width = 33, s.height = 33;
    s.camera.position[0] = 0, s.camera.position[1] = 1000, s.camera.position[2] = 0;
    s.camera.look_at[0] = 0, s.camera.look_at[1] = 1000, s.camera.look_at[2] = -1000; /* north */
    s.camera.fov_deg = 10;
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = vd.dims[1] = vd.dims[2] = 20;
    vd.voxel_size_m = 10;
    atmos_volume *v = NULL;
    int f = -1;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "cloud", &f));
    static float ones[20 * 20 * 20];
    for (int i = 0; i < 20 * 20 * 20; i++) ones[i] = 1e8f;
    int off[3] = {0, 0, 0}, size[3] = {20, 20, 20};
    CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, ones, 1.0f));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    /* Box [0,200]^3 moved so its bottom-face centre is at (0, 900, -3000): the camera's
     * axis at y = 1000 crosses it from z = -3100 to -2900. */
    double offset[3] = {0 - 100, 900 - 0, -3000 - 100};
    double sigma[1] = {2e-11}; /* 2e-11 m^2 * 1e8 m^-3 = 2e-3 m^-1; tau = 0.4 over 200 m */
    atmos_image *img = NULL;
    CHECK_OK(atmos_render_optical_depth(ctx, &s, v, sigma, offset, &img));
    if (img) {
        CHECK_REL(img->pixels[16 * 33 + 16], 0.4, 1e-4);
        CHECK(img->pixels[0] == 0.0f && img->pixels[33 * 33 - 1] == 0.0f);
    }
    atmos_image_destroy(img);
    atmos_volume_destroy(v);

    snprintf(s.volume.source, sizeof s.volume.source, "generate:cirrus");
    s.volume.seed = 1, s.volume.scale = 0.3;
    s.volume.placed = 1;
    s.volume.position_m[0] = 10, s.volume.position_m[1] = 8000, s.volume.position_m[2] = -20;
    double o[3], lo[3], hi[3];
    CHECK_OK(atmos_scene_load_volume(ctx, &s, &v, o));
    if (v) {
        atmos_volume_bounds(v, lo, hi);
        CHECK_NEAR(0.5 * (lo[0] + hi[0]) + o[0], 10, 1e-6);
        CHECK_NEAR(lo[1] + o[1], 8000, 1e-6);
        CHECK_NEAR(0.5 * (lo[2] + hi[2]) + o[2], -20, 1e-6);
    }
    s.volume.placed = 0;
    double o2[3];
    atmos_volume_destroy(v);
    v = NULL;
    CHECK_OK(atmos_scene_load_volume(ctx, &s, &v, o2));
    if (v) {
        /* In front (north) of the camera, at least 4 km away, at its own altitude. */
        double cz = 0.5 * (lo[2] + hi[2]) + o2[2], cx = 0.5 * (lo[0] + hi[0]) + o2[0];
        CHECK(cz <= -4000 + 1e-6 && fabs(cx) < 1e-6 && o2[1] == 0);
    }
    atmos_volume_destroy(v);
    snprintf(s.volume.source, sizeof s.volume.source, "generate:nope");
    v = NULL;
    CHECK(atmos_scene_load_volume(ctx, &s, &v, o) == ATMOS_E_INVALID_ARG && v == NULL);
}

int main(void)
{
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) return 1;
    test_sampling(ctx);
    test_constant_box(ctx);
    test_dda_vs_quadrature(ctx);
    test_sparse_memory(ctx);
    test_limits_and_errors(ctx);
    test_raw_roundtrip(ctx);
    test_raw_stale_staged(ctx);
    test_crashers(ctx);
    test_scene_volume(ctx);
    atmos_context_destroy(ctx);
    return test_summary("test_volume");
}
