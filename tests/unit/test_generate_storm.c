/* The storm generators (docs/volumes.md "Generated storms"): a cumulonimbus with a broad
 * flat base, an anvil that is a thin flat sheet at the tropopause spreading downwind,
 * optically thinner than the tower, with an overshooting top; rain that starts at the cloud
 * base, has no walls and drifts downwind; virga that is gone before the ground. Coarse
 * voxels keep it fast; the thresholds are physical claims, not snapshots. Also: these and the
 * cumulus field the same voxels for any thread count, another for another seed. */
#include "atmos/atmos.h"
#include "test.h"
#include "volume/volume_grid.h"

static float at(const atmos_volume *v, int f, int i, int j, int k) { return vol_voxel(v, &v->field[f], i, j, k); }
static double wx(const atmos_volume *v, int i, int a) { return v->desc.origin_m[a] + (i + 0.5) * v->desc.voxel_size_m; }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Lowest (dir = +1) or highest (dir = -1) layer of column (i, k) where field f > 0; -1 if none. */
static int column_end(const atmos_volume *v, int f, int i, int k, int dir)
{
    const int ny = v->desc.dims[1];
    for (int n = 0; n < ny; n++) {
        int j = dir > 0 ? n : ny - 1 - n;
        if (at(v, f, i, j, k) > 0) return j;
    }
    return -1;
}

/* Mean x of field f's active voxels in layers [j0, j1] (weighted by density). */
static double centroid_x(const atmos_volume *v, int f, int j0, int j1)
{
    double sw = 0, sx = 0;
    for (int k = 0; k < v->desc.dims[2]; k++)
        for (int j = j0; j <= j1; j++)
            for (int i = 0; i < v->desc.dims[0]; i++) {
                double d = at(v, f, i, j, k);
                sw += d, sx += d * wx(v, i, 0);
            }
    return sw > 0 ? sx / sw : 0;
}

/* The base: every column within 2 km of the tower's axis has its lowest cloud in the same
 * layer (±1), and the lowest cloudy layer is at least 5 km wide. */
static void test_broad_flat_base(atmos_context *ctx)
{
    atmos_volume *v = test_generate(ctx, "cumulonimbus", 3, 160);
    if (!v) return;
    const int *n = v->desc.dims, fc = test_field_index(v, "cloud");
    int jmin = n[1], jmax = -1, missing = 0, cols = 0;
    for (int k = 0; k < n[2]; k++)
        for (int i = 0; i < n[0]; i++) {
            if (hypot(wx(v, i, 0), wx(v, k, 2)) > 2000) continue;
            int j = column_end(v, fc, i, k, 1);
            cols++;
            if (j < 0) {
                missing++;
                continue;
            }
            if (j < jmin) jmin = j;
            if (j > jmax) jmax = j;
        }
    int lo = n[0], hi = -1;
    for (int k = 0; k < n[2]; k++)
        for (int i = 0; i < n[0]; i++)
            if (at(v, fc, i, jmin, k) > 0) lo = i < lo ? i : lo, hi = i > hi ? i : hi;
    double width = (hi - lo + 1) * v->desc.voxel_size_m;
    printf("cumulonimbus base: %d columns within 2 km of the axis, %d without cloud, lowest cloud in layers %d..%d; "
           "base %.0f m wide\n", cols, missing, jmin, jmax, width);
    CHECK(cols > 100 && missing == 0);
    CHECK_MSG(jmax - jmin <= 1, "base varies over %d layers", jmax - jmin + 1);
    CHECK_MSG(width >= 5000, "base only %.0f m wide", width);
    atmos_volume_destroy(v);
}

/* The anvil: columns more than 4.5 km from the tower's axis hold only anvil ice. Its top is
 * flat (≥ 80 % of those columns end within one layer of their median top), it is thin (median
 * thickness ≤ 2.5 km), wide (x extent in its top 600 m ≥ 2.5 × the tower's width at
 * mid-height), spreads downwind (downwind reach ≥ 2 × upwind), is optically thinner than the
 * tower (its largest density ≤ half the tower's), and the overshooting top rises ≥ 450 m
 * above it. */
static void test_anvil(atmos_context *ctx)
{
    atmos_volume *v = test_generate(ctx, "cumulonimbus", 3, 160);
    if (!v) return;
    const int *n = v->desc.dims, fc = test_field_index(v, "cloud"), fi = test_field_index(v, "ice");
    const double vox = v->desc.voxel_size_m;
    atmos_volume_field_stats sc, si;
    atmos_volume_field_stats_get(ctx, v, fc, &sc);
    atmos_volume_field_stats_get(ctx, v, fi, &si);
    int jm = (int)((0.5 * (sc.bounds_m[0][1] + sc.bounds_m[1][1]) - v->desc.origin_m[1]) / vox);
    double axis = centroid_x(v, fc, jm, jm);
    int lo = n[0], hi = -1;
    for (int k = 0; k < n[2]; k++)
        for (int i = 0; i < n[0]; i++)
            if (at(v, fc, i, jm, k) > 0) lo = i < lo ? i : lo, hi = i > hi ? i : hi;
    double tower = (hi - lo + 1) * vox;
    /* Anvil columns: tops histogram, thickness, largest density. */
    int hist[1024] = {0}, ncol = 0;
    double anvil_max = 0;
    static double thick[200000];
    for (int k = 0; k < n[2]; k++)
        for (int i = 0; i < n[0]; i++) {
            if (hypot(wx(v, i, 0) - axis, wx(v, k, 2)) < 4500) continue;
            int jt = column_end(v, fi, i, k, -1), jb = column_end(v, fi, i, k, 1);
            if (jt < 0 || jt >= 1024 || ncol >= 200000) continue;
            hist[jt]++;
            thick[ncol++] = (jt - jb + 1) * vox;
            for (int j = jb; j <= jt; j++) anvil_max = fmax(anvil_max, at(v, fi, i, j, k));
        }
    int med = 0;
    for (int c = 0, j = 0; j < 1024; j++)
        if ((c += hist[j]) * 2 >= ncol) {
            med = j;
            break;
        }
    int near = hist[med] + (med > 0 ? hist[med - 1] : 0) + hist[med + 1];
    qsort(thick, (size_t)ncol, sizeof *thick, cmp_double);
    double thick_med = ncol ? thick[ncol / 2] : 0;
    /* Extent in the anvil's top 600 m; the overshoot: the highest ice of all. */
    int ax0 = n[0], ax1 = -1, jtop = -1;
    for (int k = 0; k < n[2]; k++)
        for (int i = 0; i < n[0]; i++) {
            int jt = column_end(v, fi, i, k, -1);
            if (jt > jtop) jtop = jt;
            for (int j = med - (int)(600 / vox); j <= med && j >= 0; j++)
                if (at(v, fi, i, j, k) > 0) ax0 = i < ax0 ? i : ax0, ax1 = i > ax1 ? i : ax1;
        }
    double xmin = wx(v, ax0, 0), xmax = wx(v, ax1, 0), width = xmax - xmin;
    double flat = ncol ? (double)near / ncol : 0;
    printf("anvil: %d columns, top at %.0f m (%.0f %% within one layer), median thickness %.0f m; x %.0f..%.0f m "
           "(%.1f x the tower's %.0f m; downwind %.0f, upwind %.0f m from the axis at %.0f m); density max %.3g vs "
           "tower ice %.3g; overshoot %.0f m above the anvil top\n",
           ncol, wx(v, med, 1), 100 * flat, thick_med, xmin, xmax, width / tower, tower, xmax - axis, axis - xmin, axis,
           anvil_max, si.max, (jtop - med) * vox);
    CHECK(ncol > 500);
    CHECK_MSG(flat >= 0.8, "anvil top not flat: %.0f %% of columns within one layer", 100 * flat);
    CHECK_MSG(thick_med <= 2500, "anvil %.0f m thick", thick_med);
    CHECK_MSG(width >= 2.5 * tower, "anvil %.0f m vs tower %.0f m", width, tower);
    CHECK_MSG(xmax - axis >= 2 * (axis - xmin), "downwind %.0f vs upwind %.0f m", xmax - axis, axis - xmin);
    CHECK_MSG(anvil_max <= 0.5 * si.max, "anvil %.3g vs tower %.3g", anvil_max, si.max);
    CHECK_MSG((jtop - med) * vox >= 450, "overshoot %.0f m", (jtop - med) * vox);
    CHECK(si.bounds_m[0][1] > sc.bounds_m[0][1] + 3000); /* ice only aloft */
    atmos_volume_destroy(v);
}

/* Rain: none at or above the cloud base; no walls (neighbouring voxels across the shaft
 * differ by at most max_step of the largest density); drifts downwind (+x) as it falls;
 * reaches the ground (rain) or stops ≥ 500 m above it, thinning downward (virga). */
static void check_rain(atmos_context *ctx, const char *preset, double voxel, double max_step, int virga)
{
    atmos_volume *v = test_generate(ctx, preset, 5, voxel);
    if (!v) return;
    const int *n = v->desc.dims, fc = test_field_index(v, "cloud"), fr = test_field_index(v, "rain");
    atmos_volume_field_stats sc, sr;
    atmos_volume_field_stats_get(ctx, v, fc, &sc);
    atmos_volume_field_stats_get(ctx, v, fr, &sr);
    int jb = (int)((sc.bounds_m[0][1] - v->desc.origin_m[1]) / voxel + 0.5);
    long above = 0;
    double step = 0;
    for (int k = 0; k < n[2]; k++)
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++) {
                float r = at(v, fr, i, j, k);
                above += j >= jb && r > 0;
                if (i + 1 < n[0]) step = fmax(step, fabs(r - at(v, fr, i + 1, j, k)));
                if (k + 1 < n[2]) step = fmax(step, fabs(r - at(v, fr, i, j, k + 1)));
            }
    int jr0 = (int)((sr.bounds_m[0][1] - v->desc.origin_m[1]) / voxel + 0.5), jr1 = jb - 1;
    int q = (jr1 - jr0 + 1) / 4;
    double x_top = centroid_x(v, fr, jr1 - q, jr1), x_bot = centroid_x(v, fr, jr0, jr0 + q);
    double fall = (jr1 - jr0) * voxel * 0.75;
    double max_low = 0, max_high = 0; /* largest density in the lowest and highest quarter */
    for (int k = 0; k < n[2]; k++)
        for (int i = 0; i < n[0]; i++) {
            for (int j = jr0; j <= jr0 + q; j++) max_low = fmax(max_low, at(v, fr, i, j, k));
            for (int j = jr1 - q; j <= jr1; j++) max_high = fmax(max_high, at(v, fr, i, j, k));
        }
    printf("%s: cloud base %.0f m, rain %.0f..%.0f m, %ld rain voxels at or above the base; largest neighbour step "
           "%.2f of the peak; drift %.0f m over %.0f m of fall; lowest quarter's peak %.2f of the highest's\n",
           preset, sc.bounds_m[0][1], sr.bounds_m[0][1], sr.bounds_m[1][1], above, step / sr.max, x_bot - x_top, fall,
           max_low / max_high);
    CHECK_MSG(above == 0, "%s: %ld rain voxels at or above the cloud base", preset, above);
    CHECK_MSG(step <= max_step * sr.max, "%s: step %.2f of the peak", preset, step / sr.max);
    CHECK_MSG(x_bot - x_top >= 0.05 * fall, "%s: drift %.0f m", preset, x_bot - x_top);
    if (virga) {
        CHECK_MSG(sr.bounds_m[0][1] >= 500, "virga reaches %.0f m", sr.bounds_m[0][1]);
        CHECK_MSG(max_low <= 0.3 * max_high, "virga's lowest quarter %.2f of the top", max_low / max_high);
    } else {
        CHECK_MSG(sr.bounds_m[0][1] <= voxel, "%s: rain ends at %.0f m", preset, sr.bounds_m[0][1]);
    }
    atmos_volume_destroy(v);
}

static void test_determinism(void)
{
    atmos_context *c1 = test_context(1, NULL), *c3 = test_context(3, NULL);
    static const char *presets[] = {"storm", "virga", "cumulus_field"};
    static const double voxels[] = {200, 80, 80};
    for (int p = 0; p < 3; p++) {
        atmos_volume *a = test_generate(c1, presets[p], 7, voxels[p]), *b = test_generate(c3, presets[p], 7, voxels[p]);
        atmos_volume *c = test_generate(c3, presets[p], 8, voxels[p]);
        if (a && b && c) {
            long same = 0, diff = 0;
            for (int f = 0; f < a->nfields; f++)
                for (int k = 0; k < a->desc.dims[2]; k++)
                    for (int j = 0; j < a->desc.dims[1]; j++)
                        for (int i = 0; i < a->desc.dims[0]; i++) {
                            same += at(a, f, i, j, k) != at(b, f, i, j, k);
                            diff += at(a, f, i, j, k) != at(c, f, i, j, k);
                        }
            CHECK_MSG(same == 0, "%s: 1 vs 3 threads differ in %ld voxels", presets[p], same);
            CHECK_MSG(diff > 0, "%s: seeds 7 and 8 give the same volume", presets[p]);
        }
        atmos_volume_destroy(a);
        atmos_volume_destroy(b);
        atmos_volume_destroy(c);
    }
    atmos_context_destroy(c1);
    atmos_context_destroy(c3);
}

int main(void)
{
    atmos_context *ctx = test_context(0, NULL);
    test_broad_flat_base(ctx);
    test_anvil(ctx);
    check_rain(ctx, "storm", 160, 0.35, 0);
    check_rain(ctx, "rain_shaft", 60, 0.35, 0);
    check_rain(ctx, "virga", 60, 0.35, 1);
    test_determinism();
    atmos_context_destroy(ctx);
    return test_summary("test_generate_storm");
}
