/* A Gaussian blob of cloud droplets for the slice renderer's tests (test_slice_sky,
 * test_slice_angle): 32^3 voxels of 20 m (640 m across) centred 1500 m up and 1000 m north of
 * the origin, the density peak exp(-4 r^2) (0.8 - r^2) / 0.8 for r^2 < 0.8 (r in half-widths),
 * 0 outside; peak in m^-3. Header-only. */
#ifndef ATMOS_TEST_BLOB_H
#define ATMOS_TEST_BLOB_H

#include "atmos/atmos.h"
#include "test.h"

#include <math.h>
#include <string.h>

#define TEST_BLOB_N 32
#define TEST_BLOB_VOX 20.0

static atmos_volume *test_blob(atmos_context *ctx, float peak)
{
    enum { N = TEST_BLOB_N };
    static float buf[N * N * N];
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                const double x = (i + 0.5 - N / 2.0) / (N / 2.0), y = (j + 0.5 - N / 2.0) / (N / 2.0),
                             z = (k + 0.5 - N / 2.0) / (N / 2.0), r2 = x * x + y * y + z * z;
                buf[(k * N + j) * N + i] = r2 < 0.8 ? (float)(peak * exp(-4 * r2) * (0.8 - r2) / 0.8) : 0.0f;
            }
    const int dims[3] = {N, N, N};
    const double org[3] = {-N * TEST_BLOB_VOX / 2, 1500 - N * TEST_BLOB_VOX / 2, -1000 - N * TEST_BLOB_VOX / 2};
    return test_dense_volume(ctx, dims, TEST_BLOB_VOX, org, "cloud", "cloud", buf);
}

#endif
