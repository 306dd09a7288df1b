/* Cloud generators: determinism (seed, thread count) and the shape claims of
 * docs/volumes.md: a flat cumulus base, a bumpy top, a spreading anvil, rain
 * below the cloud base. Coarse voxels keep it fast. */
#include "atmos/atmos.h"
#include "test.h"
#include "volume/volume_grid.h"

/* Number of voxels that differ between two volumes of the same grid. */
static long count_diff(const atmos_volume *a, const atmos_volume *b)
{
    const int *n = a->desc.dims;
    if (memcmp(n, b->desc.dims, sizeof a->desc.dims) || a->nfields != b->nfields) return -1;
    long d = 0;
    for (int f = 0; f < a->nfields; f++)
        for (int k = 0; k < n[2]; k++)
            for (int j = 0; j < n[1]; j++)
                for (int i = 0; i < n[0]; i++)
                    if (vol_voxel(a, &a->field[f], i, j, k) != vol_voxel(b, &b->field[f], i, j, k)) d++;
    return d;
}

static void test_determinism(void)
{
    atmos_context *c1 = test_context(1, NULL), *c3 = test_context(3, NULL);
    static const char *presets[] = {"cumulus", "cirrus", "rain_shaft"};
    static const double voxels[] = {40, 250, 80};
    for (int p = 0; p < 3; p++) {
        atmos_volume *a = test_generate(c1, presets[p], 7, voxels[p]), *b = test_generate(c3, presets[p], 7, voxels[p]);
        atmos_volume *c = test_generate(c3, presets[p], 8, voxels[p]);
        if (a && b && c) {
            CHECK_MSG(count_diff(a, b) == 0, "%s: 1 vs 3 threads differ in %ld voxels", presets[p], count_diff(a, b));
            long d = count_diff(a, c);
            CHECK_MSG(d > 0, "%s: seeds 7 and 8 give the same volume", presets[p]);
        }
        atmos_volume_destroy(a);
        atmos_volume_destroy(b);
        atmos_volume_destroy(c);
    }
    atmos_context_destroy(c1);
    atmos_context_destroy(c3);
}

/* Active voxels per horizontal layer j of field f. */
static void layer_areas(const atmos_volume *v, int f, long *area)
{
    const int *n = v->desc.dims;
    for (int j = 0; j < n[1]; j++) {
        area[j] = 0;
        for (int k = 0; k < n[2]; k++)
            for (int i = 0; i < n[0]; i++) area[j] += vol_voxel(v, &v->field[f], i, j, k) > 0;
    }
}

/* Flat base and bumpy top of a single cumulus, over several seeds. */
static void test_cumulus_shape(atmos_context *ctx)
{
    for (uint64_t seed = 1; seed <= 3; seed++) {
        atmos_volume *v = test_generate(ctx, "cumulus", seed, 20);
        if (!v) continue;
        const int *n = v->desc.dims;
        long *area = calloc((size_t)n[1], sizeof *area);
        layer_areas(v, 0, area);
        int jb = -1, jt = -1;
        long amax = 0;
        for (int j = 0; j < n[1]; j++)
            if (area[j]) {
                if (jb < 0) jb = j;
                jt = j;
                if (area[j] > amax) amax = area[j];
            }
        CHECK(jb >= 0);
        if (jb < 0) {
            free(area);
            atmos_volume_destroy(v);
            continue;
        }
        /* Flat base: the cross-section 10 % of the vertical extent above the base already
         * covers >= 50 % of the widest one (a sphere gives 36 %, a cone far less). */
        int j10 = jb + (int)lround(0.1 * (jt - jb + 1));
        double ratio = (double)area[j10] / amax;
        printf("cumulus seed %llu: base j=%d top j=%d, area(10%% up)/max area = %.2f\n", (unsigned long long)seed, jb, jt,
               ratio);
        CHECK_MSG(ratio >= 0.5, "seed %llu: base not flat: %.2f", (unsigned long long)seed, ratio);
        /* The base is a plane: every column's lowest active voxel is the base layer or
         * within 2 voxels of it for >= 90 % of the columns under the widest layer. */
        long cols = 0, flat = 0;
        double sum = 0, sum2 = 0, rough = 0;
        long rough_n = 0;
        int *top = malloc(sizeof(int) * (size_t)n[0] * n[2]);
        for (int k = 0; k < n[2]; k++)
            for (int i = 0; i < n[0]; i++) {
                int lo = -1, hi = -1;
                for (int j = 0; j < n[1]; j++)
                    if (vol_voxel(v, &v->field[0], i, j, k) > 0) {
                        if (lo < 0) lo = j;
                        hi = j;
                    }
                top[k * n[0] + i] = hi;
                if (hi < 0) continue;
                cols++;
                flat += lo <= jb + 2;
                sum += hi;
                sum2 += (double)hi * hi;
            }
        /* Bumpy top: the top height differs from the mean of its 3x3 neighbours (small-scale
         * relief added by the fractal refinement). */
        for (int k = 1; k + 1 < n[2]; k++)
            for (int i = 1; i + 1 < n[0]; i++) {
                int h = top[k * n[0] + i], ok = h >= 0;
                double m = 0;
                for (int dk = -1; dk <= 1 && ok; dk++)
                    for (int di = -1; di <= 1; di++) {
                        int hh = top[(k + dk) * n[0] + i + di];
                        if (hh < 0) ok = 0;
                        m += hh;
                    }
                if (!ok) continue;
                rough += fabs(h - m / 9);
                rough_n++;
            }
        double mean = sum / cols, sd = sqrt(fmax(0, sum2 / cols - mean * mean));
        double relief = rough / (double)(rough_n ? rough_n : 1);
        printf("  columns with base within 2 voxels of the lowest layer: %.0f %%; top height sd %.1f voxels "
               "(%.0f %% of extent), mean |top - 3x3 mean| %.2f voxels\n",
               100.0 * flat / cols, sd, 100 * sd / (jt - jb + 1), relief);
        CHECK(flat >= 0.6 * cols);
        CHECK_MSG(sd > 0.15 * (jt - jb + 1), "top height sd %.1f", sd);
        /* Unrefined metaballs (levels = 0) measure 0.41-0.50 voxels here; refined 1.17-1.41. */
        CHECK_MSG(relief > 0.8, "top relief %.2f voxels", relief);
        free(top);
        free(area);
        atmos_volume_destroy(v);
    }
}

static int layer_of(const atmos_volume *v, double y)
{
    return (int)floor((y - v->desc.origin_m[1]) / v->desc.voxel_size_m);
}

/* The cumulonimbus's anvil and base: tests/unit/test_generate_storm.c. */

static void test_rain(atmos_context *ctx)
{
    static const char *presets[] = {"rain_shaft", "storm"};
    static const double voxels[] = {60, 200};
    for (int p = 0; p < 2; p++) {
        atmos_volume *v = test_generate(ctx, presets[p], 5, voxels[p]);
        if (!v) continue;
        int fc = test_field_index(v, "cloud"), fr = test_field_index(v, "rain");
        CHECK(fc >= 0 && fr >= 0);
        atmos_volume_field_stats sc, sr;
        atmos_volume_field_stats_get(ctx, v, fc, &sc);
        atmos_volume_field_stats_get(ctx, v, fr, &sr);
        /* Most rain lies below the cloud base and it reaches the ground (y = 0). */
        long below = 0, total = 0;
        const int *n = v->desc.dims;
        int jbase = layer_of(v, sc.bounds_m[0][1]);
        for (int k = 0; k < n[2]; k++)
            for (int j = 0; j < n[1]; j++)
                for (int i = 0; i < n[0]; i++)
                    if (vol_voxel(v, &v->field[fr], i, j, k) > 0) {
                        total++;
                        below += j < jbase;
                    }
        printf("%s: cloud base %.0f m, rain from %.0f m, %.0f %% of rain voxels below the base\n", presets[p],
               sc.bounds_m[0][1], sr.bounds_m[0][1], 100.0 * below / (total ? total : 1));
        CHECK(total > 0);
        CHECK(sr.bounds_m[0][1] <= v->desc.voxel_size_m);
        CHECK(below > total / 2);
        atmos_volume_destroy(v);
    }
}

static void test_presets_and_errors(atmos_context *ctx)
{
    const char *const *names = atmos_volume_generator_names();
    int n = 0;
    for (; names[n]; n++) {
        atmos_volume *v = test_generate(ctx, names[n], 1, 250);
        if (!v) continue;
        for (int f = 0; f < atmos_volume_field_count(v); f++) {
            atmos_volume_field_stats s;
            atmos_volume_field_stats_get(ctx, v, f, &s);
            CHECK_MSG(s.active_voxels > 0 && isfinite(s.max) && s.max > 0, "%s: field %s empty", names[n],
                      atmos_volume_field_name(v, f));
        }
        atmos_volume_destroy(v);
    }
    CHECK(n == 8);
    atmos_volume *v = NULL;
    atmos_volume_generate_desc g = {.seed = 1};
    CHECK(atmos_volume_generate(ctx, "nimbostratus", &g, &v) == ATMOS_E_INVALID_ARG && !v);
    CHECK(strstr(atmos_context_error(ctx), "cumulonimbus") != NULL); /* lists the known ones */
    g.voxel_size_m = 0.01;
    CHECK(atmos_volume_generate(ctx, "cumulus", &g, &v) == ATMOS_E_INVALID_ARG && !v);
    g.voxel_size_m = 50;
    g.max_memory = 1000;
    CHECK(atmos_volume_generate(ctx, "cumulus", &g, &v) == ATMOS_E_LIMIT && !v);
    g.max_memory = 0;
    g.scale = -1;
    CHECK(atmos_volume_generate(ctx, "cumulus", &g, &v) == ATMOS_E_INVALID_ARG && !v);
}

int main(void)
{
    atmos_context *ctx = test_context(0, NULL);
    test_determinism();
    test_cumulus_shape(ctx);
    test_rain(ctx);
    test_presets_and_errors(ctx);
    atmos_context_destroy(ctx);
    return test_summary("test_generate");
}
