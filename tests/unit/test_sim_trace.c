/* The semi-Lagrangian advection's trilinear samples (src/sim/sim_trace.c): against a
 * trilinear interpolation written out here in double precision (x and y periodic, z clamped),
 * at random points and at the edge cases (a row's last cell, where the second corner wraps to
 * the first; -0; the top level; integer points, which give the grid value exactly; points
 * more than a domain away, which the vectorised path hands to the scalar code); and the
 * vectorised path (AVX2, where the CPU has it) against the scalar one, bit for bit. */
#include "atmos/atmos.h"
#include "sim/sim_internal.h"
#include "test.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { NX = 13, NY = 7, NZF = 6, NP = 67 };

static uint64_t rng = 0x9e3779b97f4a7c15ULL;
static double u01(void)
{
    rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static int wrap(long i, int n)
{
    const long m = i % n;
    return (int)(m < 0 ? m + n : m);
}

/* The reference: field g of nx * ny * NZF cells (stride `stride` floats a cell, component c)
 * at (x, y, z). */
static double reference(const float *g, int nx, int ny, int stride, int c, double x, double y, double z)
{
    z = fmin(fmax(z, 0.0), NZF - 1.0);
    const double fx = floor(x), fy = floor(y), fz = floor(z);
    const double ax = x - fx, ay = y - fy, az = z - fz;
    const int i0 = wrap((long)fx, nx), i1 = wrap((long)fx + 1, nx), j0 = wrap((long)fy, ny), j1 = wrap((long)fy + 1, ny);
    const int k0 = (int)fz, k1 = k0 + 1 < NZF ? k0 + 1 : k0;
    const int ii[2] = {i0, i1}, jj[2] = {j0, j1}, kk[2] = {k0, k1};
    const double wx[2] = {1 - ax, ax}, wy[2] = {1 - ay, ay}, wz[2] = {1 - az, az};
    double v = 0;
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++)
            for (int d = 0; d < 2; d++)
                v += wx[a] * wy[b] * wz[d] * g[stride * (((size_t)kk[d] * ny + jj[b]) * nx + ii[a]) + c];
    return v;
}

/* Rows of departure points as the advection makes them (point i of a row near i - shift, its
 * y and z near the row's): a shift the same along the row, whose corners lie side by side
 * (read in a row by the vectorised path), one that varies so that some points' corners do not,
 * one lane in another grid row or level, and the row's end, where the second corner wraps.
 * Against the reference and the scalar code, bit for bit. */
enum { RX = 40, RN = 4 * RX };
static void test_rows(atmos_context *ctx)
{
    atmos_sim *s = NULL;
    CHECK_OK(atmos__sim_create_env(ctx, atmos__sim_preset("towering_cumulus"), RX, NY, NZF - 1, 100.0, 1, &s));
    if (!s) return;
    const size_t cells = (size_t)RX * NY * NZF;
    float *f = malloc(cells * sizeof *f), *f4 = malloc(4 * cells * sizeof *f4);
    for (size_t n = 0; n < cells; n++) f[n] = (float)(u01() * 20.0 - 10.0);
    for (size_t n = 0; n < 4 * cells; n++) f4[n] = (float)(u01() * 2.0 - 1.0);
    static float x[RN], y[RN], z[RN];
    static float out[RN], ref_out[RN], out4[4 * RN], ref_out4[4 * RN];
    const double shift[4] = {0.3, -1.45, 0.6, 0.05};
    for (int r = 0; r < 4; r++)
        for (int i = 0; i < RX; i++) {
            const int m = r * RX + i;
            const double wobble = r == 2 ? 0.5 * sin(0.7 * i) : 0.0; /* floors that change along the row */
            x[m] = (float)(i - shift[r] + wobble);
            y[m] = (float)(3 + 0.4 * u01()), z[m] = (float)(2 + 0.9 * u01());
        }
    y[3 * RX + 13] = 4.2f; /* one lane in the next grid row */
    z[3 * RX + 21] = 3.1f; /* one lane a level up */
    atmos__sim_sample_row(s, f, NZF, x, y, z, out, RN);
    atmos__sim_sample_row_scalar(s, f, NZF, x, y, z, ref_out, RN);
    atmos__sim_sample4_row(s, f4, NZF, x, y, z, out4, RN);
    atmos__sim_sample4_row_scalar(s, f4, NZF, x, y, z, ref_out4, RN);
    int bad = 0, bad4 = 0;
    for (int m = 0; m < RN; m++) {
        bad += fabs(out[m] - reference(f, RX, NY, 1, 0, x[m], y[m], z[m])) > 1e-4;
        for (int c = 0; c < 4; c++) bad4 += fabs(out4[4 * m + c] - reference(f4, RX, NY, 4, c, x[m], y[m], z[m])) > 1e-5;
    }
    CHECK_MSG(bad == 0, "rows: %d samples off the reference", bad);
    CHECK_MSG(bad4 == 0, "rows: %d packed samples off the reference", bad4);
    CHECK_MSG(!memcmp(out, ref_out, sizeof out), "rows: the vectorised samples differ from the scalar code's");
    CHECK_MSG(!memcmp(out4, ref_out4, sizeof out4), "rows: the vectorised packed samples differ from the scalar code's");
    free(f);
    free(f4);
    atmos_sim_destroy(s);
}

int main(void)
{
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.threads = 1;
    cd.log = NULL;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    atmos_sim *s = NULL;
    CHECK_OK(atmos__sim_create_env(ctx, atmos__sim_preset("towering_cumulus"), NX, NY, NZF - 1, 100.0, 1, &s));
    if (!s) return test_summary("test_sim_trace");
    const size_t cells = (size_t)NX * NY * NZF;
    float *f = malloc(cells * sizeof *f), *f4 = malloc(4 * cells * sizeof *f4);
    for (size_t n = 0; n < cells; n++) f[n] = (float)(u01() * 20.0 - 10.0);
    for (size_t n = 0; n < 4 * cells; n++) f4[n] = (float)(u01() * 2.0 - 1.0);
    float x[NP], y[NP], z[NP];
    for (int m = 0; m < NP; m++) {
        x[m] = (float)(-NX + 3.0 * NX * u01());
        y[m] = (float)(-NY + 3.0 * NY * u01());
        z[m] = (float)(-1.5 + (NZF + 2.0) * u01());
    }
    x[0] = NX - 0.25f, y[0] = NY - 0.75f, z[0] = 1.5f;      /* both second corners wrap to 0 */
    x[1] = -0.0f, y[1] = -0.0f, z[1] = -0.0f;               /* negative zeros */
    x[2] = 2.5f, y[2] = 3.25f, z[2] = NZF - 1;              /* the top level */
    x[3] = 4, y[3] = 5, z[3] = 2;                           /* a grid point */
    x[4] = 3.5f * NX, y[4] = 1.5f, z[4] = 1;                /* beyond 2 NX: the scalar path */
    x[5] = -NX - 0.5f, y[5] = 1.5f, z[5] = 1;               /* below -NX: the scalar path */
    x[6] = 2.0f * NX - 0.01f, y[6] = -NY + 0.01f, z[6] = 40; /* far side of the range, clamped z */
    x[9] = 5.5f, y[9] = 9.0f * NY, z[9] = 0.5f;             /* y beyond: the scalar path */
    float out[NP], ref_out[NP], out4[4 * NP], ref_out4[4 * NP];
    atmos__sim_sample_row(s, f, NZF, x, y, z, out, NP);
    atmos__sim_sample_row_scalar(s, f, NZF, x, y, z, ref_out, NP);
    atmos__sim_sample4_row(s, f4, NZF, x, y, z, out4, NP);
    atmos__sim_sample4_row_scalar(s, f4, NZF, x, y, z, ref_out4, NP);
    int bad = 0, bad4 = 0;
    double worst = 0;
    for (int m = 0; m < NP; m++) {
        const double r = reference(f, NX, NY, 1, 0, x[m], y[m], z[m]);
        worst = fmax(worst, fabs(out[m] - r));
        bad += fabs(out[m] - r) > 1e-5 * 10;
        for (int c = 0; c < 4; c++) {
            const double r4 = reference(f4, NX, NY, 4, c, x[m], y[m], z[m]);
            worst = fmax(worst, fabs(out4[4 * m + c] - r4) * 10);
            bad4 += fabs(out4[4 * m + c] - r4) > 1e-5;
        }
    }
    printf("  %d points, worst error %.2g (of values up to 10)\n", NP, worst);
    CHECK_MSG(bad == 0, "%d samples off the reference", bad);
    CHECK_MSG(bad4 == 0, "%d packed samples off the reference", bad4);
    CHECK_MSG(out[3] == f[(2 * NY + 5) * NX + 4], "a grid point: %g, the grid value %g", out[3], f[(2 * NY + 5) * NX + 4]);
    CHECK_MSG(!memcmp(out, ref_out, sizeof out), "the vectorised samples differ from the scalar code's");
    CHECK_MSG(!memcmp(out4, ref_out4, sizeof out4), "the vectorised packed samples differ from the scalar code's");
    free(f);
    free(f4);
    atmos_sim_destroy(s);
    test_rows(ctx);
    atmos_context_destroy(ctx);
    return test_summary("test_sim_trace");
}
