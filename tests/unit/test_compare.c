/* atmos_image_compare against statistics computed by hand on constructed images. */
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>

static int cmp_float(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

int main(void)
{
    atmos_image *ref = NULL, *img = NULL, *heat = NULL;
    CHECK_OK(atmos_image_create(NULL, 40, 20, 4, &ref));
    CHECK_OK(atmos_image_create(NULL, 40, 20, 4, &img));
    if (!ref || !img) return test_summary("test_compare");
    /* reference: R = 2, G = 4, B = 6 everywhere; image: R + 1 everywhere (bias 1, rmse 1),
     * G exact, B off by 3 in one pixel at (33, 17); alpha differs and must be ignored */
    for (int p = 0; p < 800; p++) {
        float *r = ref->pixels + p * 4, *a = img->pixels + p * 4;
        r[0] = 2, r[1] = 4, r[2] = 6, r[3] = 1;
        a[0] = 3, a[1] = 4, a[2] = 6, a[3] = 0;
    }
    img->pixels[(17 * 40 + 33) * 4 + 2] = 9;
    atmos_image_diff d;
    CHECK_OK(atmos_image_compare(NULL, img, ref, &d, &heat));
    CHECK(d.channels == 3);
    CHECK_NEAR(d.rmse[0], 1.0, 1e-12);
    CHECK_NEAR(d.bias[0], 1.0, 1e-12);
    CHECK_NEAR(d.rel_rmse[0], 0.5, 1e-12);
    CHECK_NEAR(d.rmse[1], 0.0, 0);
    CHECK_NEAR(d.rmse[2], sqrt(9.0 / 800), 1e-12);
    CHECK_NEAR(d.bias[2], 3.0 / 800, 1e-12);
    CHECK_NEAR(d.rmse_all, sqrt((800 + 9.0) / 2400), 1e-12);
    CHECK_NEAR(d.rel_rmse_all, sqrt((800 + 9.0) / 2400) / 4.0, 1e-12);
    /* the worst 16x16 tile holds the bad pixel: tile x 32..39 (clipped), y 16..19 */
    CHECK(d.worst_x == 32 && d.worst_y == 16 && d.worst_w == 8 && d.worst_h == 4);
    CHECK(heat && heat->channels == 3 && heat->width == 40);
    if (heat) {
        const float *hot = heat->pixels + (17 * 40 + 33) * 3, *cold = heat->pixels;
        CHECK(hot[0] == 1.0f && hot[1] == 1.0f && hot[2] == 1.0f); /* the maximum is white */
        CHECK(cold[0] < hot[0]);
    }
    /* identical images: zero everything */
    CHECK_OK(atmos_image_compare(NULL, ref, ref, &d, NULL));
    CHECK(d.rmse_all == 0 && d.bias[0] == 0 && d.rel_rmse_all == 0);
    /* non-finite samples are skipped, not counted as perfect matches: image = 2, ref = 1,
     * half the samples NaN -> rmse over the rest is exactly 1 */
    atmos_image *x = NULL, *y = NULL;
    CHECK_OK(atmos_image_create(NULL, 4, 4, 3, &x));
    CHECK_OK(atmos_image_create(NULL, 4, 4, 3, &y));
    for (int i = 0; i < 48; i++) x->pixels[i] = i % 2 ? NAN : 2.0f, y->pixels[i] = 1.0f;
    CHECK_OK(atmos_image_compare(NULL, x, y, &d, NULL));
    CHECK_NEAR(d.rmse_all, 1.0, 1e-12);
    CHECK_NEAR(d.bias[0], 1.0, 1e-12);
    CHECK(d.nonfinite == 24 && d.nonfinite_image == 24 && d.nonfinite_reference == 0);
    /* An all-NaN image has no finite sample: its statistics are NaN, not a perfect 0,
     * and every sample is counted against the image, none against the reference. */
    for (int i = 0; i < 48; i++) x->pixels[i] = NAN;
    y->pixels[5] = INFINITY;
    CHECK_OK(atmos_image_compare(NULL, x, y, &d, NULL));
    CHECK(isnan(d.rmse_all) && isnan(d.rel_rmse_all) && isnan(d.rmse[0]) && isnan(d.bias[2]));
    CHECK(d.nonfinite == 48 && d.nonfinite_image == 48 && d.nonfinite_reference == 1);
    atmos_image_destroy(x);
    atmos_image_destroy(y);
    /* the heat map's white: 10 times the 99th percentile of the pixels' differences when the
     * largest is farther off (five outliers), the percentile found here by sorting */
    {
        enum { W = 300, H = 200, N = W * H };
        atmos_image *r3 = NULL, *i3 = NULL, *h3 = NULL;
        float *sorted = malloc(sizeof(float) * N);
        CHECK_OK(atmos_image_create(NULL, W, H, 3, &r3));
        CHECK_OK(atmos_image_create(NULL, W, H, 3, &i3));
        if (r3 && i3 && sorted) {
            for (int p = 0; p < N; p++)
                for (int c = 0; c < 3; c++) {
                    r3->pixels[p * 3 + c] = 1;
                    i3->pixels[p * 3 + c] = 1 + (float)((p * 7919) % 1000) * 1e-5f + (p % 9973 == 5 ? 1000 : 0);
                }
            for (int p = 0; p < N; p++) {
                const double dd = fabs((double)i3->pixels[p * 3] - 1.0);
                sorted[p] = (float)((dd + dd + dd) / 3);
            }
            qsort(sorted, N, sizeof *sorted, cmp_float);
            const double p99 = sorted[(size_t)floor(0.99 * (N - 1))];
            CHECK_OK(atmos_image_compare(NULL, i3, r3, &d, &h3));
            CHECK_MSG(d.heat_scale == 10 * p99, "heat scale %.9g, 10 x the sorted 99th percentile %.9g", d.heat_scale,
                      10 * p99);
        }
        free(sorted);
        atmos_image_destroy(h3);
        atmos_image_destroy(i3);
        atmos_image_destroy(r3);
    }
    /* size mismatch is an error, not a crash */
    atmos_image *small = NULL;
    CHECK_OK(atmos_image_create(NULL, 4, 4, 4, &small));
    CHECK(atmos_image_compare(NULL, small, ref, &d, NULL) == ATMOS_E_INVALID_ARG);
    atmos_image_destroy(small);
    atmos_image_destroy(heat);
    atmos_image_destroy(ref);
    atmos_image_destroy(img);
    /* Binned by a key: left half key 1 (image = ref * 1.1), right half key 5 (exact),
     * one pixel with key 100 outside the edges. */
    {
        atmos_image *r2 = NULL, *i2 = NULL, *key = NULL;
        CHECK_OK(atmos_image_create(NULL, 10, 4, 3, &r2));
        CHECK_OK(atmos_image_create(NULL, 10, 4, 3, &i2));
        CHECK_OK(atmos_image_create(NULL, 10, 4, 1, &key));
        for (int p = 0; r2 && i2 && key && p < 40; p++) {
            int left = p % 10 < 5;
            for (int c = 0; c < 3; c++) r2->pixels[p * 3 + c] = (float)(c + 1), i2->pixels[p * 3 + c] = (float)((c + 1) * (left ? 1.1 : 1.0));
            key->pixels[p] = left ? 1.0f : 5.0f;
        }
        if (key) key->pixels[39] = 100.0f;
        double edges[] = {0, 2, 10, 20};
        atmos_image_bins bins;
        CHECK_OK(atmos_image_compare_binned(NULL, i2, r2, key, edges, 4, &bins));
        CHECK(bins.bins == 3 && bins.count[0] == 20 && bins.count[1] == 19 && bins.count[2] == 0);
        /* left: differences 0.1, 0.2, 0.3 over |ref| 1, 2, 3: rmse sqrt(0.14/3), mean ref 2 */
        CHECK_REL(bins.rel_rmse[0], sqrt(0.14 / 3) / 2, 1e-5);
        CHECK_REL(bins.rel_bias[0], 0.2 / 2, 1e-5);
        CHECK(bins.rel_rmse[1] == 0 && bins.rel_bias[1] == 0 && isnan(bins.rel_rmse[2]));
        double bad[] = {0, 2, 2};
        CHECK(atmos_image_compare_binned(NULL, i2, r2, key, bad, 3, &bins) == ATMOS_E_INVALID_ARG);
        atmos_image_destroy(r2);
        atmos_image_destroy(i2);
        atmos_image_destroy(key);
    }
    return test_summary("test_compare");
}
