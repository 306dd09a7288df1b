/* The volume accessor (src/volume/volume_access.h) against references written here from
 * scratch: the pooled brick layout (one allocation, 32-bit brick indices, its memory figure
 * and limits), the world <-> index transform of a rotated, moved volume, the float and
 * double trilinear samplers against brute-force trilinear interpolation of a dense copy of
 * the voxels, the per-brick bounds against the interpolant, the brick DDA against the
 * bricks a ray crosses found by slab tests, the occupied-brick iterator and boxes, and the
 * optical depth against an independent exact quadrature and against values printed by the
 * implementation that preceded the accessor. */
#include "atmos/atmos.h"
#include "test.h"
#include "volume/volume_access.h"

#include <float.h>
#include <stdint.h>

static uint64_t rng_state = 0x2545f4914f6cdd1dull;
static double urand(void)
{
    /* xorshift64*: test-local randomness, fixed seed */
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}
static int irand(int n) { return (int)(urand() * n); }

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

/* A random sparse volume and a dense copy of its voxels (dense[f][(k*ny + j)*nx + i]):
 * each brick position of each field is occupied with probability p, and an occupied
 * brick's voxels are 0 (a third) or random in (0, 1000). */
typedef struct {
    atmos_volume *v;
    int n[3], nf;
    float *dense[ATMOS_VOLUME_MAX_FIELDS];
} rvol;

static float dval(const rvol *r, int f, int i, int j, int k)
{
    return r->dense[f][((size_t)k * r->n[1] + j) * r->n[0] + i];
}

static void rvol_make(atmos_context *ctx, rvol *r, const int dims[3], int nf, double p, const double *rot)
{
    memset(r, 0, sizeof *r);
    atmos_volume_desc d = {.dims = {dims[0], dims[1], dims[2]}, .voxel_size_m = 0.5 + 3 * urand(),
                           .origin_m = {1000 * (urand() - 0.5), 2000 * urand(), 1000 * (urand() - 0.5)}};
    if (rot) memcpy(d.rotation, rot, sizeof d.rotation);
    CHECK_OK(atmos_volume_create(ctx, &d, &r->v));
    memcpy(r->n, dims, sizeof r->n);
    r->nf = nf;
    static const char *names[] = {"cloud", "rain", "ice", "snow"};
    const size_t nv = (size_t)dims[0] * dims[1] * dims[2];
    for (int f = 0; f < nf; f++) {
        CHECK_OK(atmos_volume_add_field(ctx, r->v, names[f], NULL, NULL));
        r->dense[f] = calloc(nv, sizeof(float));
        for (int bz = 0; bz < (dims[2] + 7) / 8; bz++)
            for (int by = 0; by < (dims[1] + 7) / 8; by++)
                for (int bx = 0; bx < (dims[0] + 7) / 8; bx++) {
                    if (urand() >= p) continue;
                    for (int k = bz * 8; k < bz * 8 + 8 && k < dims[2]; k++)
                        for (int j = by * 8; j < by * 8 + 8 && j < dims[1]; j++)
                            for (int i = bx * 8; i < bx * 8 + 8 && i < dims[0]; i++) {
                                float x = urand() < 1.0 / 3 ? 0.0f : (float)(1000 * urand());
                                r->dense[f][((size_t)k * dims[1] + j) * dims[0] + i] = x;
                                CHECK_OK(atmos_volume_set(ctx, r->v, f, i, j, k, x));
                            }
                }
    }
    CHECK_OK(atmos_volume_finalize(ctx, r->v));
}

static void rvol_free(rvol *r)
{
    atmos_volume_destroy(r->v);
    for (int f = 0; f < r->nf; f++) free(r->dense[f]);
}

static void random_dims(int dims[3], int lo, int hi)
{
    for (int a = 0; a < 3; a++) dims[a] = lo + irand(hi - lo + 1);
}

/* ------------------------------------------------------------------ pooled layout */

/* Brute force: does the region of brick c (its voxels and the one-voxel ring, clamped)
 * hold a nonzero voxel of some field? Also its min and max per field. */
static int region_minmax(const rvol *r, const int c[3], int f, float *mn, float *mx)
{
    int lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = c[a] * 8 - 1 < 0 ? 0 : c[a] * 8 - 1;
        hi[a] = c[a] * 8 + 8 > r->n[a] - 1 ? r->n[a] - 1 : c[a] * 8 + 8;
    }
    *mn = INFINITY, *mx = 0;
    for (int k = lo[2]; k <= hi[2]; k++)
        for (int j = lo[1]; j <= hi[1]; j++)
            for (int i = lo[0]; i <= hi[0]; i++) {
                float x = dval(r, f, i, j, k);
                if (x < *mn) *mn = x;
                if (x > *mx) *mx = x;
            }
    if (!(*mn > 0)) *mn = 0;
    return *mx > 0;
}

static void test_pool_layout(atmos_context *ctx)
{
    const int dims[3] = {40, 24, 17};
    atmos_volume_desc d = {.dims = {40, 24, 17}, .voxel_size_m = 1};
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &d, &v));
    const uint64_t header = sizeof(atmos_volume), brick = 2048, nb = 5 * 3 * 3;
    CHECK_MSG(atmos_volume_memory(v) == header + brick, "new volume holds %llu bytes",
              (unsigned long long)atmos_volume_memory(v));
    atmos_volume_destroy(v);

    /* The same layout filled at random, against a dense copy. */
    rvol r;
    rng_state = 77;
    rvol_make(ctx, &r, dims, 3, 0.4, NULL);
    v = r.v;
    CHECK(v->nbricks == nb);
    uint32_t seen_total = 0;
    unsigned char *seen = calloc(v->pool_used, 1);
    int bad_index = 0, shared = 0, bad_value = 0;
    for (int f = 0; f < 3; f++) {
        uint32_t count = 0;
        for (uint64_t b = 0; b < nb; b++) {
            uint32_t s = v->field[f].table[b];
            if (!s) continue;
            count++;
            if (s >= v->pool_used) {
                bad_index++;
                continue;
            }
            if (seen[s]++) shared++;
        }
        CHECK(count == v->field[f].count);
        seen_total += count;
        for (int k = 0; k < dims[2]; k++)
            for (int j = 0; j < dims[1]; j++)
                for (int i = 0; i < dims[0]; i++)
                    if (atmos__vol_voxel(v, f, i, j, k) != dval(&r, f, i, j, k)) bad_value++;
    }
    free(seen);
    CHECK_MSG(bad_index == 0 && shared == 0, "%d brick indices outside the pool, %d shared", bad_index, shared);
    CHECK_MSG(bad_value == 0, "%d voxels differ from the written values", bad_value);
    /* One pool: the zero brick and exactly the occupied bricks, trimmed at finalize. */
    CHECK(v->pool_used == 1 + seen_total && v->pool_cap == v->pool_used);
    int nonzero = 0;
    for (int n = 0; n < 512; n++) nonzero += vol_brick_data(v, 0)[n] != 0;
    CHECK(nonzero == 0);
    /* Bounds: one entry per position some field's interpolant reaches, plus the zeros. */
    uint64_t reached = 0;
    for (uint64_t b = 0; b < nb; b++) {
        int c[3] = {(int)(b % 5), (int)(b / 5 % 3), (int)(b / 15)}, any = 0;
        float mn, mx;
        for (int f = 0; f < 3; f++) any |= region_minmax(&r, c, f, &mn, &mx);
        reached += any;
        CHECK((v->cell[b] != 0) == any);
    }
    CHECK(v->nrange == 1 + reached);
    const uint64_t want = header + 3 * nb * 4 + (uint64_t)v->pool_used * brick + nb * 4 + (1 + reached) * 3 * 8;
    CHECK_MSG(atmos_volume_memory(v) == want, "memory %llu, layout says %llu", (unsigned long long)atmos_volume_memory(v),
              (unsigned long long)want);
    printf("pool: %u bricks of %llu positions x 3 fields in one allocation; %llu bytes\n", seen_total,
           (unsigned long long)nb, (unsigned long long)want);
    rvol_free(&r);
}

static void test_pool_limits(atmos_context *ctx)
{
    const uint64_t header = sizeof(atmos_volume), brick = 2048, table = 512 * 4;
    atmos_volume *v = NULL;
    /* Below the header and the zero brick: refused before allocating. */
    atmos_volume_desc d = {.dims = {64, 64, 64}, .voxel_size_m = 1, .max_memory = header + brick - 1};
    CHECK(atmos_volume_create(ctx, &d, &v) == ATMOS_E_LIMIT && v == NULL);
    /* Room for exactly ten bricks: the pool grows up to the limit, not past it. */
    d.max_memory = header + brick + table + 10 * brick;
    CHECK_OK(atmos_volume_create(ctx, &d, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", NULL, NULL));
    for (int n = 0; n < 10; n++) CHECK_OK(atmos_volume_set(ctx, v, 0, 8 * n % 64, 8 * (n / 8), 5, 1.0f + n));
    CHECK(atmos_volume_memory(v) <= d.max_memory);
    CHECK(atmos_volume_set(ctx, v, 0, 0, 40, 40, 1.0f) == ATMOS_E_LIMIT);
    CHECK(strstr(atmos_context_error(ctx), "brick") != NULL);
    CHECK(atmos_volume_memory(v) <= d.max_memory);
    int bad = 0;
    for (int n = 0; n < 10; n++) bad += atmos__vol_voxel(v, 0, 8 * n % 64, 8 * (n / 8), 5) != 1.0f + n;
    CHECK_MSG(bad == 0, "%d bricks lost by the refused growth", bad);
    /* Finalize needs the per-brick bounds: refused too, the volume stays unfinalized. */
    CHECK(atmos_volume_finalize(ctx, v) == ATMOS_E_LIMIT);
    CHECK(strstr(atmos_context_error(ctx), "bounds") != NULL);
    atmos_volume_field_stats s;
    CHECK(atmos_volume_field_stats_get(ctx, v, 0, &s) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "not finalized") != NULL);
    atmos_volume_destroy(v);
    /* With room for the bounds it finalizes within the limit. */
    d.max_memory = header + brick + table + 10 * brick + table + (1 + 27 * 10) * 8;
    CHECK_OK(atmos_volume_create(ctx, &d, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", NULL, NULL));
    for (int n = 0; n < 10; n++) CHECK_OK(atmos_volume_set(ctx, v, 0, 8 * n % 64, 8 * (n / 8), 5, 1.0f + n));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    CHECK(atmos_volume_memory(v) <= d.max_memory);
    CHECK_OK(atmos_volume_field_stats_get(ctx, v, 0, &s));
    CHECK(s.active_voxels == 10 && s.max == 10);
    /* Field statistics name what is wrong. */
    CHECK(atmos_volume_field_stats_get(ctx, v, 3, &s) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "field index 3") != NULL);
    CHECK(atmos_volume_field_stats_get(ctx, NULL, 0, &s) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_volume_field_stats_get(NULL, v, 0, NULL) == ATMOS_E_INVALID_ARG);
    atmos_volume_destroy(v);
}

/* ------------------------------------------------------------------ transform */

static void test_transform(atmos_context *ctx)
{
    double rot[9];
    rot_axis_angle(0.4, -1, 0.3, 73, rot);
    atmos_volume_desc d = {.dims = {20, 30, 40}, .voxel_size_m = 2.75, .origin_m = {-310, 1250, 77}};
    memcpy(d.rotation, rot, sizeof rot);
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &d, &v));
    const double off[3] = {15.5, -400, 3};
    atmos__vol_xform x;
    atmos__vol_xform_init(v, off, &x);
    const atmos__vol_xform *x0 = atmos__vol_xform_of(v);
    CHECK(!memcmp(x0->org, d.origin_m, sizeof d.origin_m) && x0->vs == 2.75);
    double worst_p = 0, worst_q = 0, worst_ref = 0, worst_d = 0;
    int frame = 0;
    for (int n = 0; n < 1000; n++) {
        double q[3] = {60 * urand() - 10, 60 * urand() - 10, 60 * urand() - 10}, p[3], q2[3], ref[3];
        atmos__vol_index_to_point(&x, q, p);
        atmos__vol_point_to_index(&x, p, q2);
        for (int a = 0; a < 3; a++) {
            /* world = origin + offset + R (q vs), written out here */
            ref[a] = d.origin_m[a] + off[a];
            for (int b = 0; b < 3; b++) ref[a] += rot[3 * a + b] * q[b] * d.voxel_size_m;
            worst_q = fmax(worst_q, fabs(q2[a] - q[a]));
            worst_ref = fmax(worst_ref, fabs(p[a] - ref[a]));
        }
        double p2[3], dw[3] = {urand() - 0.5, urand() - 0.5, urand() - 0.5}, dq[3], dw2[3], g[3];
        atmos__vol_point_to_index(&x, ref, q2);
        atmos__vol_index_to_point(&x, q2, p2);
        for (int a = 0; a < 3; a++) worst_p = fmax(worst_p, fabs(p2[a] - ref[a]));
        atmos__vol_dir_to_index(&x, dw, dq);
        atmos__vol_index_to_dir(&x, dq, dw2);
        atmos__vol_dir_to_frame(&x, dw, g);
        for (int a = 0; a < 3; a++) {
            worst_d = fmax(worst_d, fabs(dw2[a] - dw[a]));
            frame += g[a] * x.inv_vs != dq[a]; /* index = frame / voxel size, the same arithmetic */
        }
    }
    printf("transform round trips: index %.2e voxels, world %.2e m, direction %.2e; against R(q vs): %.2e m\n", worst_q,
           worst_p, worst_d, worst_ref);
    CHECK(worst_q < 1e-11 && worst_p < 1e-9 && worst_d < 1e-14 && worst_ref < 1e-9);
    CHECK(frame == 0);
    atmos_volume_destroy(v);
}

/* ------------------------------------------------------------------ samplers */

/* Brute-force trilinear interpolation of the dense copy at index point q (in the box):
 * the sum over the eight corners of their weights times their values, indices clamped. */
static long double brute_trilinear(const rvol *r, int f, const double q[3])
{
    int i0[3], i1[3];
    long double w[3];
    for (int a = 0; a < 3; a++) {
        double x = q[a] - 0.5, fl = floor(x);
        w[a] = x - fl;
        i0[a] = (int)fl, i1[a] = (int)fl + 1;
        if (i0[a] < 0) i0[a] = 0;
        if (i0[a] > r->n[a] - 1) i0[a] = r->n[a] - 1;
        if (i1[a] > r->n[a] - 1) i1[a] = r->n[a] - 1;
    }
    long double s = 0;
    for (int c = 0; c < 8; c++)
        s += (long double)dval(r, f, c & 1 ? i1[0] : i0[0], c & 2 ? i1[1] : i0[1], c & 4 ? i1[2] : i0[2]) *
             (c & 1 ? w[0] : 1 - w[0]) * (c & 2 ? w[1] : 1 - w[1]) * (c & 4 ? w[2] : 1 - w[2]);
    return s;
}

/* A point of the box: mostly uniform, sometimes on a face, an edge, a brick boundary or a
 * voxel centre (where the gather crosses bricks or the clamping acts). */
static void box_point(const int n[3], double q[3])
{
    for (int a = 0; a < 3; a++) {
        double u = urand();
        q[a] = n[a] * urand();
        if (u < 0.1) q[a] = urand() < 0.5 ? 0 : n[a];
        else if (u < 0.2) q[a] = 8 * irand(n[a] / 8 + 1) + (urand() - 0.5) * 1e-3;
        else if (u < 0.3) q[a] = irand(n[a]) + 0.5;
        if (q[a] < 0) q[a] = 0;
        if (q[a] > n[a]) q[a] = n[a];
    }
}

/* x rounded to float. Through a volatile: GCC 12.2's SLP vectorizer at -O2 was seen to drop
 * the rounding of {(float)q[0], (float)q[1], (float)q[2]} converted back to double. */
static double round_to_float(double x)
{
    volatile float f = (float)x;
    return f;
}

static void test_samplers(atmos_context *ctx)
{
    double worst_d = 0, worst_f = 0, worst_fq = 0;
    int exact_d = 0, exact_f = 0, total = 0, outside_bad = 0, public_bad = 0, weights_bad = 0;
    for (int vol = 0; vol < 6; vol++) {
        rvol r;
        int dims[3];
        random_dims(dims, 1, 30);
        rvol_make(ctx, &r, dims, 3, 0.6, NULL);
        const atmos_volume *v = r.v;
        for (int n = 0; n < 4000; n++) {
            double q[3], wd[3], p[3];
            float wf[3];
            box_point(dims, q);
            atmos__vol_corners cd, cf;
            atmos__vol_setup_d(v, q, &cd, wd);
            atmos__vol_setup_f(v, q, &cf, wf);
            atmos__vol_index_to_point(atmos__vol_xform_of(v), q, p);
            /* the float sampler sees q rounded to float, its weights are exact there */
            const double qf[3] = {round_to_float(q[0]), round_to_float(q[1]), round_to_float(q[2])};
            for (int a = 0; a < 3; a++) {
                volatile float xf = (float)qf[a] - 0.5f, fl = floorf(xf); /* each step rounded to float */
                weights_bad += wf[a] != xf - fl;
            }
            for (int f = 0; f < 3; f++) {
                const long double ref = brute_trilinear(&r, f, q), reff = brute_trilinear(&r, f, qf);
                const double gd = atmos__vol_sample_d(v, f, &cd, wd);
                const float gf = atmos__vol_sample_f(v, f, &cf, wf);
                worst_d = fmax(worst_d, (double)fabsl(gd - ref) / 1000);
                worst_fq = fmax(worst_fq, (double)fabsl(gf - ref) / 1000);
                worst_f = fmax(worst_f, (double)fabsl(gf - reff) / 1000);
                /* The renderers' images depend on this exact arithmetic: x, then y, then z,
                 * in the sampler's precision, on the clamped corners. */
                float c[8];
                for (int k = 0; k < 8; k++)
                    c[k] = dval(&r, f, k & 1 ? cd.i1[0] : cd.i0[0], k & 2 ? cd.i1[1] : cd.i0[1], k & 4 ? cd.i1[2] : cd.i0[2]);
                double dx0 = c[0] + wd[0] * ((double)c[1] - c[0]), dx1 = c[2] + wd[0] * ((double)c[3] - c[2]);
                double dx2 = c[4] + wd[0] * ((double)c[5] - c[4]), dx3 = c[6] + wd[0] * ((double)c[7] - c[6]);
                double dy0 = dx0 + wd[1] * (dx1 - dx0), dy1 = dx2 + wd[1] * (dx3 - dx2);
                exact_d += gd == dy0 + wd[2] * (dy1 - dy0);
                float fx0 = c[0] + wf[0] * (c[1] - c[0]), fx1 = c[2] + wf[0] * (c[3] - c[2]);
                float fx2 = c[4] + wf[0] * (c[5] - c[4]), fx3 = c[6] + wf[0] * (c[7] - c[6]);
                float fy0 = fx0 + wf[1] * (fx1 - fx0), fy1 = fx2 + wf[1] * (fx3 - fx2);
                exact_f += gf == fy0 + wf[2] * (fy1 - fy0);
                /* the public call from the world point (its round trip may leave the box at a face) */
                int face = 0;
                for (int a = 0; a < 3; a++) face |= q[a] < 1e-6 || q[a] > dims[a] - 1e-6;
                public_bad += !face && fabs(atmos_volume_sample(v, f, p) - gd) > 1e-9 * 1000;
                total++;
            }
            /* Outside the box: exactly 0. */
            double qo[3] = {q[0], q[1], q[2]};
            qo[irand(3)] = urand() < 0.5 ? -0.01 - urand() : dims[0] + dims[1] + dims[2] + 0.01;
            atmos__vol_index_to_point(atmos__vol_xform_of(v), qo, p);
            outside_bad += atmos__vol_inside(v, qo) || atmos_volume_sample(v, 0, p) != 0;
        }
        rvol_free(&r);
    }
    printf("samplers vs brute-force trilinear (%d samples, values < 1000, errors relative to 1000): double %.2e, "
           "float %.2e (%.2e at q itself, not rounded to float)\n",
           total, worst_d, worst_f, worst_fq);
    CHECK(worst_d < 1e-15 * 64 && worst_f < 1e-6 && worst_fq < 1e-5);
    CHECK_MSG(exact_d == total && exact_f == total, "x-y-z lerp order: double %d, float %d of %d", exact_d, exact_f, total);
    CHECK_MSG(outside_bad == 0 && public_bad == 0 && weights_bad == 0, "outside %d, public call %d, float weights %d",
              outside_bad, public_bad, weights_bad);
}

/* ------------------------------------------------------------------ bounds */

static void test_bounds(atmos_context *ctx)
{
    int wrong_range = 0, outside = 0, outside_f = 0, checked = 0, empty_nonzero = 0;
    const float scales[3] = {1.0f, 1e8f, 3.7e-3f};
    for (int vol = 0; vol < 5; vol++) {
        rvol r;
        int dims[3];
        random_dims(dims, 3, 45);
        rvol_make(ctx, &r, dims, 3, 0.35, NULL);
        const atmos_volume *v = r.v;
        /* Every position's bounds are the region's min and max (brute force). */
        for (uint64_t b = 0; b < v->nbricks; b++) {
            int c[3] = {(int)(b % (uint64_t)v->nb[0]), (int)(b / (uint64_t)v->nb[0] % (uint64_t)v->nb[1]),
                        (int)(b / ((uint64_t)v->nb[0] * v->nb[1]))};
            const float *rg = atmos__vol_range(v, b);
            for (int f = 0; f < 3; f++) {
                float mn, mx;
                region_minmax(&r, c, f, &mn, &mx);
                wrong_range += rg[2 * f] != mn || rg[2 * f + 1] != mx;
            }
        }
        /* Random points of random bricks: the interpolant stays inside, in both precisions. */
        for (int n = 0; n < 300; n++) {
            int c[3];
            for (int a = 0; a < 3; a++) c[a] = irand(v->nb[a]);
            const uint64_t b = ((uint64_t)c[2] * v->nb[1] + c[1]) * v->nb[0] + c[0];
            const float *rg = atmos__vol_range(v, b);
            for (int s = 0; s < 40; s++) {
                double q[3], wd[3];
                float wf[3];
                for (int a = 0; a < 3; a++) {
                    double hi = c[a] * 8 + 8 < dims[a] ? c[a] * 8 + 8 : dims[a];
                    q[a] = s < 8 ? (s >> a & 1 ? hi : c[a] * 8) : c[a] * 8 + (hi - c[a] * 8) * urand();
                }
                atmos__vol_corners cd, cf;
                atmos__vol_setup_d(v, q, &cd, wd);
                atmos__vol_setup_f(v, q, &cf, wf);
                for (int f = 0; f < 3; f++) {
                    /* (up to the double lerp's own rounding) */
                    const double x = atmos__vol_sample_d(v, f, &cd, wd);
                    outside += !(x >= rg[2 * f] * (1 - 1e-14) && x <= rg[2 * f + 1] * (1 + 1e-14));
                    if (v->cell[b] == 0) empty_nonzero += x != 0;
                    for (int k = 0; k < 3; k++) {
                        /* the path tracer's scaled, rounded-out bounds of its float densities */
                        const float sc = scales[k], y = atmos__vol_sample_f(v, f, &cf, wf) * sc;
                        const float lo = rg[2 * f] * sc * 0.99999f, hi = rg[2 * f + 1] * sc * 1.00001f;
                        outside_f += !((y > 0 ? y : 0) >= lo && (y > 0 ? y : 0) <= hi);
                    }
                    checked++;
                }
            }
        }
        rvol_free(&r);
    }
    printf("bounds: %d interpolant values checked against their brick's (min, max)\n", checked);
    CHECK_MSG(wrong_range == 0, "%d bounds differ from the region's min/max", wrong_range);
    CHECK_MSG(outside == 0 && outside_f == 0, "interpolant outside its bounds: %d double, %d float", outside, outside_f);
    CHECK(empty_nonzero == 0);
}

/* ------------------------------------------------------------------ DDA */

/* [ta, tb] of the ray q + t qd inside the box lo..hi; 0 if it misses. */
static int slab(const double q[3], const double qd[3], const double lo[3], const double hi[3], double *ta, double *tb)
{
    double a0 = -INFINITY, a1 = INFINITY;
    for (int a = 0; a < 3; a++) {
        if (qd[a] == 0) {
            if (q[a] < lo[a] || q[a] > hi[a]) return 0;
            continue;
        }
        double u = (lo[a] - q[a]) / qd[a], w = (hi[a] - q[a]) / qd[a];
        if (u > w) {
            double x = u;
            u = w, w = x;
        }
        a0 = fmax(a0, u), a1 = fmin(a1, w);
    }
    *ta = a0, *tb = a1;
    return a0 <= a1;
}

static void test_dda(atmos_context *ctx)
{
    int rays = 0, missing = 0, extra = 0, badt = 0, badorder = 0, visited = 0;
    for (int vol = 0; vol < 6; vol++) {
        int dims[3];
        random_dims(dims, 1, 70);
        atmos_volume_desc d = {.dims = {dims[0], dims[1], dims[2]}, .voxel_size_m = 1};
        atmos_volume *v = NULL;
        CHECK_OK(atmos_volume_create(ctx, &d, &v));
        CHECK_OK(atmos_volume_finalize(ctx, v));
        const double box_lo[3] = {0, 0, 0}, box_hi[3] = {dims[0], dims[1], dims[2]};
        unsigned char *hit = calloc(v->nbricks, 1);
        for (int n = 0; n < 500; n++) {
            double q[3], qd[3], t0, t1;
            for (int a = 0; a < 3; a++) {
                q[a] = (dims[a] + 20) * urand() - 10;
                qd[a] = urand() - 0.5;
                if (n % 7 == a) qd[a] = 0; /* parallel to a face */
            }
            if (!slab(q, qd, box_lo, box_hi, &t0, &t1) || !(t1 > t0)) continue;
            rays++;
            memset(hit, 0, v->nbricks);
            atmos__vol_dda g;
            atmos__vol_dda_init(v, q, qd, t0, &g);
            double t = t0;
            for (;;) {
                double te = atmos__vol_dda_tend(&g);
                if (te > t1) te = t1;
                if (te < t) badorder++;
                const uint64_t idx = ((uint64_t)g.c[2] * v->nb[1] + g.c[1]) * v->nb[0] + g.c[0];
                if (idx != g.idx) badorder++;
                if (te > t) {
                    /* the brick's own interval along the ray must be this one */
                    double lo[3] = {g.c[0] * 8.0, g.c[1] * 8.0, g.c[2] * 8.0}, hi[3], ta, tb;
                    for (int a = 0; a < 3; a++) hi[a] = lo[a] + 8;
                    if (!slab(q, qd, lo, hi, &ta, &tb)) ta = tb = NAN;
                    ta = fmax(ta, t0), tb = fmin(tb, t1);
                    const double tol = 1e-9 * (1 + fabs(t1 - t0));
                    if (!(fabs(ta - t) <= tol && fabs(tb - te) <= tol)) badt++;
                    if (te - t > tol) hit[g.idx] = 1, visited++;
                }
                if (te >= t1) break;
                t = te;
                if (!atmos__vol_dda_step(v, &g)) break;
            }
            /* Brute force: every brick whose box the clipped ray crosses for a positive length. */
            for (uint64_t b = 0; b < v->nbricks; b++) {
                int c[3] = {(int)(b % (uint64_t)v->nb[0]), (int)(b / (uint64_t)v->nb[0] % (uint64_t)v->nb[1]),
                            (int)(b / ((uint64_t)v->nb[0] * v->nb[1]))};
                double lo[3], hi[3], ta, tb;
                for (int a = 0; a < 3; a++) lo[a] = c[a] * 8.0, hi[a] = fmin(lo[a] + 8, dims[a]);
                int crossed = slab(q, qd, lo, hi, &ta, &tb) && fmin(tb, t1) - fmax(ta, t0) > 1e-9 * (1 + fabs(t1 - t0));
                if (crossed && !hit[b]) missing++;
                if (!crossed && hit[b]) extra++;
            }
        }
        free(hit);
        atmos_volume_destroy(v);
    }
    printf("DDA: %d rays, %d brick crossings, against slab tests on every brick\n", rays, visited);
    CHECK(rays > 1000);
    CHECK_MSG(missing == 0 && extra == 0, "bricks missed %d, visited but not crossed %d", missing, extra);
    CHECK_MSG(badt == 0 && badorder == 0, "interval mismatches %d, order/index errors %d", badt, badorder);
}

/* ------------------------------------------------------------------ occupied bricks */

static void test_iterator_and_boxes(atmos_context *ctx)
{
    for (int vol = 0; vol < 4; vol++) {
        rvol r;
        int dims[3];
        random_dims(dims, 1, 50);
        rvol_make(ctx, &r, dims, 2, vol == 3 ? 0.0 : 0.15, NULL);
        const atmos_volume *v = r.v;
        int olo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, ohi[3] = {-1, -1, -1}, rlo[3], rhi[3], glo[3], ghi[3];
        memcpy(rlo, olo, sizeof rlo), memcpy(rhi, ohi, sizeof rhi);
        int order_bad = 0;
        for (int f = 0; f < 2; f++) {
            atmos__vol_brick_it it = {0};
            uint64_t b = 0;
            int n = 0;
            while (atmos__vol_next_brick(v, f, &it)) {
                while (b < v->nbricks && !v->field[f].table[b]) b++; /* the table scan it replaces */
                const int c[3] = {(int)(b % (uint64_t)v->nb[0]), (int)(b / (uint64_t)v->nb[0] % (uint64_t)v->nb[1]),
                                  (int)(b / ((uint64_t)v->nb[0] * v->nb[1]))};
                order_bad += b >= v->nbricks || it.o[0] != 8 * c[0] || it.o[1] != 8 * c[1] || it.o[2] != 8 * c[2] ||
                             it.data != vol_brick_data(v, v->field[f].table[b]);
                for (int a = 0; a < 3; a++) olo[a] = c[a] < olo[a] ? c[a] : olo[a], ohi[a] = c[a] > ohi[a] ? c[a] : ohi[a];
                b++, n++;
            }
            CHECK((uint32_t)n == v->field[f].count);
        }
        CHECK(order_bad == 0);
        for (uint64_t b = 0; b < v->nbricks; b++) {
            int c[3] = {(int)(b % (uint64_t)v->nb[0]), (int)(b / (uint64_t)v->nb[0] % (uint64_t)v->nb[1]),
                        (int)(b / ((uint64_t)v->nb[0] * v->nb[1]))}, any = 0;
            float mn, mx;
            for (int f = 0; f < 2; f++) any |= region_minmax(&r, c, f, &mn, &mx);
            if (any)
                for (int a = 0; a < 3; a++) rlo[a] = c[a] < rlo[a] ? c[a] : rlo[a], rhi[a] = c[a] > rhi[a] ? c[a] : rhi[a];
        }
        const int occ = atmos__vol_occupied_box(v, glo, ghi);
        CHECK(occ == (ohi[0] >= 0));
        if (occ) CHECK(!memcmp(glo, olo, sizeof glo) && !memcmp(ghi, ohi, sizeof ghi));
        const int rng = atmos__vol_range_box(v, glo, ghi);
        CHECK(rng == (rhi[0] >= 0));
        if (rng) CHECK(!memcmp(glo, rlo, sizeof glo) && !memcmp(ghi, rhi, sizeof ghi));
        rvol_free(&r);
    }
}

/* ------------------------------------------------------------------ optical depth */

/* Exact optical depth of the dense copy along q + t qd, t in [t0, t1] (index space, inside
 * the box), in units of t: Simpson's rule between consecutive voxel-centre planes, where
 * the interpolant is a cubic in t. Written without bricks. */
static double brute_tau(const rvol *r, const double *sigma, const double q[3], const double qd[3], double t0, double t1)
{
    double cuts[4096];
    int nc = 0;
    cuts[nc++] = t0;
    for (int a = 0; a < 3; a++) {
        if (qd[a] == 0) continue;
        for (int k = 0; k < r->n[a] && nc < 4095; k++) {
            double t = (k + 0.5 - q[a]) / qd[a];
            if (t > t0 && t < t1) cuts[nc++] = t;
        }
    }
    cuts[nc++] = t1;
    for (int i = 1; i < nc; i++) /* insertion sort: few hundred cuts */
        for (int j = i; j > 0 && cuts[j] < cuts[j - 1]; j--) {
            double x = cuts[j];
            cuts[j] = cuts[j - 1], cuts[j - 1] = x;
        }
    double tau = 0;
    for (int i = 0; i + 1 < nc; i++) {
        double s[3] = {cuts[i], 0.5 * (cuts[i] + cuts[i + 1]), cuts[i + 1]}, e[3];
        for (int k = 0; k < 3; k++) {
            double p[3];
            for (int a = 0; a < 3; a++) {
                p[a] = q[a] + s[k] * qd[a];
                p[a] = p[a] < 0 ? 0 : (p[a] > r->n[a] ? r->n[a] : p[a]);
            }
            e[k] = 0;
            for (int f = 0; f < r->nf; f++) e[k] += sigma[f] * (double)brute_trilinear(r, f, p);
        }
        tau += (s[2] - s[0]) * (e[0] + 4 * e[1] + e[2]) / 6;
    }
    return tau;
}

static void test_optical_depth_exact(atmos_context *ctx)
{
    double worst = 0;
    int nonzero = 0;
    double rot[9];
    rot_axis_angle(1, 0.2, -0.7, 29, rot);
    for (int vol = 0; vol < 4; vol++) {
        rvol r;
        int dims[3];
        random_dims(dims, 5, 40);
        rvol_make(ctx, &r, dims, 2, 0.3, vol % 2 ? rot : NULL);
        const double sigma[2] = {1.3e-3, 4e-4};
        const atmos__vol_xform *x = atmos__vol_xform_of(r.v);
        const double box_lo[3] = {0, 0, 0}, box_hi[3] = {dims[0], dims[1], dims[2]};
        for (int n = 0; n < 40; n++) {
            double qa[3], qb[3], a[3], b[3], dir[3], q[3], qd[3], t0, t1;
            for (int k = 0; k < 3; k++) qa[k] = (dims[k] + 10) * urand() - 5, qb[k] = (dims[k] + 10) * urand() - 5;
            atmos__vol_index_to_point(x, qa, a);
            atmos__vol_index_to_point(x, qb, b);
            for (int k = 0; k < 3; k++) dir[k] = b[k] - a[k];
            const double got = atmos_volume_optical_depth(r.v, sigma, a, dir, 0, 1);
            atmos__vol_point_to_index(x, a, q);
            atmos__vol_dir_to_index(x, dir, qd);
            double want = 0;
            if (slab(q, qd, box_lo, box_hi, &t0, &t1) && fmin(t1, 1) > fmax(t0, 0))
                want = brute_tau(&r, sigma, q, qd, fmax(t0, 0), fmin(t1, 1)) *
                       sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
            if (want > 0) nonzero++;
            const double e = fabs(got - want) / fmax(want, 1e-300);
            if (want > 0 && e > worst) worst = e;
            CHECK_REL(got, want, 1e-11);
        }
        rvol_free(&r);
    }
    printf("optical depth vs exact Simpson on the dense copy: %d non-empty rays, worst relative error %.2e\n", nonzero,
           worst);
    CHECK(nonzero >= 40);
}

/* Values printed by the optical depth before the accessor (per-cell majorant grid, its own
 * DDA recomputing every brick boundary) for this volume and these rays. The accessor's DDA
 * steps the boundaries incrementally: agreement to rounding (observed <= 4e-16 relative). */
static const double golden_tau[48] = {
    11.173246829126173,  5.4782981620035942,  7.1583528110649786, 0.12546821119192827, 7.7598168206916975,
    0,                   6.2536902559990377,  0,                  13.749270738242785,  4.6587701816646243,
    12.005754183764511,  0,                   0,                  1.4251003448865585,  9.9912484663771295,
    0,                   5.8312625591475449,  1.8691351701758199, 14.579321276151733,  3.3931523369855778,
    1.0594810340802481,  2.2098893752454334,  0.21406329146586292, 0,                  20.440269419478451,
    7.2333706463854721,  8.7500574096977015,  4.1099905804182217, 0,                   4.0446781282950148,
    10.423122261124364,  0,                   0,                  1.4498645094509628,  4.2261352948508861,
    1.2198585973466702,  0,                   12.000193996615693, 9.006107940741936,   2.3508979835802539,
    8.8321364568492697,  0,                   4.6681665638302157, 7.2393190025334215,  5.400906391982943,
    9.5128546516977757,  5.5701966753682184,  0.29056950490261713};

static void test_optical_depth_unchanged(void)
{
    rng_state = 0x9e3779b97f4a7c15ull;
    atmos_volume_desc d = {.dims = {37, 29, 45}, .voxel_size_m = 2.0, .origin_m = {-30, 500, 12}};
    double m[9];
    rot_axis_angle(1, 2, 2, 40, m); /* 40 degrees about (1, 2, 2)/3 */
    memcpy(d.rotation, m, sizeof m);
    atmos_volume *v;
    CHECK_OK(atmos_volume_create(NULL, &d, &v));
    CHECK_OK(atmos_volume_add_field(NULL, v, "cloud", NULL, NULL));
    CHECK_OK(atmos_volume_add_field(NULL, v, "rain", NULL, NULL));
    int ctr[10][3];
    for (int b = 0; b < 10; b++) {
        int cc[3] = {(int)(urand() * 37), (int)(urand() * 29), (int)(urand() * 45)}, r = 2 + (int)(urand() * 7), f = b % 2;
        memcpy(ctr[b], cc, sizeof cc);
        for (int k = cc[2] - r; k <= cc[2] + r; k++)
            for (int j = cc[1] - r; j <= cc[1] + r; j++)
                for (int i = cc[0] - r; i <= cc[0] + r; i++)
                    if (i >= 0 && j >= 0 && k >= 0 && i < 37 && j < 29 && k < 45 && urand() < 0.85)
                        atmos_volume_set(NULL, v, f, i, j, k, (float)(10 + 990 * urand()));
    }
    CHECK_OK(atmos_volume_finalize(NULL, v));
    double lo[3], hi[3], sigma[2] = {1.1e-3, 3e-4}, worst = 0;
    atmos_volume_bounds(v, lo, hi);
    for (int n = 0; n < 48; n++) {
        double a[3], e[3], dir[3], q[3] = {ctr[n % 10][0] + 0.5, ctr[n % 10][1] + 0.5, ctr[n % 10][2] + 0.5};
        for (int k = 0; k < 3; k++) {
            double w = d.origin_m[k];
            for (int j = 0; j < 3; j++) w += m[3 * k + j] * q[j] * d.voxel_size_m;
            a[k] = lo[k] + (hi[k] - lo[k]) * (urand() * 1.6 - 0.3);
            e[k] = n % 8 == 7 ? lo[k] + (hi[k] - lo[k]) * (urand() * 1.6 - 0.3) : w + (w - a[k]) * urand();
            dir[k] = e[k] - a[k];
        }
        if (n % 6 == 5) dir[n % 3] = 0; /* in a plane of the world axes */
        double t0 = n % 4 == 1 ? 0.25 : 0, t1 = n % 4 == 2 ? 0.8 : (n % 4 == 3 ? INFINITY : 1);
        const double got = atmos_volume_optical_depth(v, sigma, a, dir, t0, t1), want = golden_tau[n];
        if (want > 0) worst = fmax(worst, fabs(got - want) / want);
        CHECK_REL(got, want, 1e-14);
    }
    printf("optical depth vs the implementation before the accessor: worst relative difference %.1e\n", worst);
    atmos_volume_destroy(v);
}

int main(void)
{
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) return 1;
    test_pool_layout(ctx);
    test_pool_limits(ctx);
    test_transform(ctx);
    test_samplers(ctx);
    test_bounds(ctx);
    test_dda(ctx);
    test_iterator_and_boxes(ctx);
    test_optical_depth_exact(ctx);
    test_optical_depth_unchanged();
    atmos_context_destroy(ctx);
    return test_summary("test_volume_access");
}
