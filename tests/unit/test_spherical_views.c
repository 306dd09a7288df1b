/* The production sky's per-eye tables (src/atmosphere/spherical_batch.c from inside the air,
 * spherical_space.c from above it) against the one-ray radiance (atmos_atmosphere_radiance,
 * which marches each ray), over dense sets of view directions:
 *  - from space (1000 km and 36 000 km, the sun high, on the terminator, behind the planet):
 *    the disk with a sharp checkered ground map and night lights, its edge, the limb
 *    sampled every few metres of impact parameter, the dark side; the rays that miss the air
 *    give exactly nothing; the same bytes on 1 and 2 threads;
 *  - from inside the air (2 m to 60 km): every elevation band, crowded at the horizon.
 * The relative difference of each ray's luminance is taken against max(L, 1e-3 x the view's
 * brightest L), the range an exposed image shows; its largest and rms values are printed. */
#include "atmos/atmos.h"
#include "atmosphere/spherical.h"
#include "core/vec.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

enum { NMAX = 13000 };
static float dx[NMAX], dy[NMAX], dz[NMAX], w[NMAX], out[3 * NMAX], out2[3 * NMAX];
static float scratch[NMAX * ATMOS__ATM_BATCH_SCRATCH];
static double ref[NMAX];

static double lum(const double *c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* A ground map of 2 x 2 degree checks (albedo 0.05 and 0.6) and a night map of lit checks
 * elsewhere: edges far sharper than any table cell. */
static atmos_atmosphere *make(void)
{
    atmos_image *g = NULL, *nt = NULL;
    CHECK_OK(atmos_image_create(NULL, 180, 90, 3, &g));
    CHECK_OK(atmos_image_create(NULL, 180, 90, 1, &nt));
    if (!g || !nt) return NULL;
    for (int y = 0; y < 90; y++)
        for (int x = 0; x < 180; x++) {
            const int on = (x + y) & 1;
            for (int c = 0; c < 3; c++) g->pixels[(y * 180 + x) * 3 + c] = on ? 0.8f : 0.25f;
            nt->pixels[y * 180 + x] = (x % 3 == 0 && y % 2 == 0) ? 1.0f : 0.0f;
        }
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    ad.hide_sun_disk = 1;
    ad.ground_map = g, ad.night_map = nt;
    ad.night_radiance = 2e-4;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, &wl, &a));
    atmos_image_destroy(g);
    atmos_image_destroy(nt);
    return a;
}

static void eval_batch(const atmos_atmosphere *a, const double eye[3], const double sun[3], int n, float *o)
{
    atmos__atm_batch b;
    atmos__atm_batch_init(&b, a, eye, sun, 0);
    memset(o, 0, sizeof(float) * 3 * (size_t)n);
    atmos__atm_batch_eval(&b, n, dx, dy, dz, w, o, scratch);
    atmos__atm_batch_release(&b);
}

/* Compares the batch (out) with the one-ray radiance over the n rays; returns the largest
 * relative difference, adds to the rms sums. */
static double compare(const atmos_atmosphere *a, const double eye[3], const double sun[3], int n, int stride,
                      double *s2, int *cnt, int *at)
{
    double top = 0, worst = 0;
    for (int i = 0; i < n; i++) {
        double d[3] = {dx[i], dy[i], dz[i]}, L[3];
        const double l = sqrt(atmos__dot3(d, d));
        for (int c = 0; c < 3; c++) d[c] /= l;
        atmos_atmosphere_radiance(a, eye, d, sun, L, NULL);
        ref[i] = lum(L);
        top = fmax(top, ref[i]);
    }
    for (int i = 0; i < n; i++) {
        const double got[3] = {out[i], out[stride + i], out[2 * stride + i]};
        double e = fabs(lum(got) - ref[i]) / fmax(ref[i], 1e-3 * top);
        if (!isfinite(e)) e = INFINITY;
        *s2 += e * e, (*cnt)++;
        if (e > worst) worst = e, *at = i;
    }
    return worst;
}

/* Rays from an eye at altitude alt above the origin: impact parameters uniform over the
 * disk and beyond the air, and crowded over the disk's edge and the limb; azimuths off the
 * table's nodes and in the sun's vertical plane (the sun lies in the x = 0 plane). Returns the count; *miss0: the first of the rays that miss the air. */
static int space_rays(const atmos__planet *pl, double alt, int *miss0)
{
    const double r = pl->r_ground + alt, R = pl->r_ground, Rt = pl->r_top;
    int n = 0;
    for (int pass = 0; pass < 2; pass++)
        for (int i = 0; i < (pass ? 10 : 190); i++) {
            double p;
            if (pass) p = Rt + (i + 1) * 2e3; /* outside the air */
            else if (i < 60) p = R * (i + 0.5) / 60;
            else if (i < 90) p = R - 200e3 * pow((90 - i) / 30.0, 2); /* the disk's edge */
            else p = R + (Rt - R) * pow((i - 89.5) / 100.0, 2);      /* the limb */
            if (pass && i == 0) *miss0 = n;
            const double st = p / r, ct = sqrt(1 - st * st);
            for (int j = 0; j < 62; j++) { /* the last two in the sun's vertical plane */
                const double ps = j < 60 ? 2 * ATMOS_PI * (j + 0.37) / 60 : ATMOS_PI * (j == 60 ? 0.5 : 1.5);
                dx[n] = (float)(st * cos(ps)), dy[n] = (float)-ct, dz[n] = (float)(st * sin(ps)), w[n] = 1;
                n++;
            }
        }
    return n;
}

static void from_space(const atmos_atmosphere *a)
{
    const double alts[2] = {1000e3, 36000e3}, els[3] = {30, 0.5, -60};
    double all_worst = 0, s2 = 0;
    int cnt = 0;
    for (int ia = 0; ia < 2; ia++)
        for (int is = 0; is < 3; is++) {
            const double eye[3] = {0, alts[ia], 0};
            double sun[3];
            atmos_direction_from_angles(els[is], 180, sun);
            int miss0 = 0, at = 0;
            const int n = space_rays(a->planet, alts[ia], &miss0);
            eval_batch(a, eye, sun, n, out);
            for (int i = miss0; i < n; i++) CHECK(out[i] == 0 && out[n + i] == 0 && out[2 * n + i] == 0);
            const double worst = compare(a, eye, sun, miss0, n, &s2, &cnt, &at);
            printf("space: eye %.0f km, sun %.1f deg: worst %.3f %% (p row %d, azimuth %d: %.4g vs %.4g)\n",
                   alts[ia] / 1e3, els[is], 100 * worst, at / 62, at % 62,
                   0.2126 * out[at] + 0.7152 * out[n + at] + 0.0722 * out[2 * n + at], ref[at]);
            all_worst = fmax(all_worst, worst);
#ifdef _OPENMP
            if (ia == 1 && is == 1) { /* results independent of the thread count */
                const int saved = omp_get_max_threads();
                omp_set_num_threads(1);
                eval_batch(a, eye, sun, n, out2);
                omp_set_num_threads(2);
                eval_batch(a, eye, sun, n, out);
                omp_set_num_threads(saved);
                CHECK(memcmp(out, out2, sizeof(float) * 3 * (size_t)n) == 0);
            }
#endif
        }
    printf("space table vs one ray: worst %.3f %%, rms %.3f %%\n", 100 * all_worst, 100 * sqrt(s2 / cnt));
    /* (12.5 % and 0.66 %: the worst where the air's light falls off across the terminator,
     * whose logarithm is curved on the scale of a cell; a blurred limb, a lit night side or
     * a ground seen through the table's cells gives errors of order one) */
    CHECK(all_worst < 0.2);
    CHECK(sqrt(s2 / cnt) < 0.01);
}

/* From inside the air: elevations crowded at the horizon (the ground's edge), azimuths off
 * the sky-view table's nodes; with the uniform ground (the table bakes the ground's light in,
 * so a mapped ground is blurred by design: the table serves eyes in the air). */
static void from_air(const atmos_atmosphere *a)
{
    const double alts[4] = {2, 1000, 10e3, 60e3}, els[3] = {45, 5, -3};
    double all_worst = 0, s2 = 0;
    int cnt = 0;
    for (int ia = 0; ia < 4; ia++)
        for (int is = 0; is < 3; is++) {
            const double eye[3] = {0, alts[ia], 0};
            double sun[3];
            atmos_direction_from_angles(els[is], 180, sun);
            int n = 0, at = 0;
            for (int i = 0; i < 200; i++)
                for (int j = 0; j < 48; j++) {
                    const double t = (i + 0.5) / 200 * 2 - 1;
                    double d[3];
                    atmos_direction_from_angles(90 * t * t * t, 360.0 * (j + 0.29) / 48, d);
                    dx[n] = (float)d[0], dy[n] = (float)d[1], dz[n] = (float)d[2], w[n] = 1;
                    n++;
                }
            eval_batch(a, eye, sun, n, out);
            const double worst = compare(a, eye, sun, n, n, &s2, &cnt, &at);
            printf("air: eye %.0f m, sun %.1f deg: worst %.3f %% (elevation row %d, azimuth %d)\n", alts[ia],
                   els[is], 100 * worst, at / 48, at % 48);
            all_worst = fmax(all_worst, worst);
        }
    printf("sky-view table vs one ray: worst %.3f %%, rms %.3f %%\n", 100 * all_worst, 100 * sqrt(s2 / cnt));
    /* (16.6 % and 0.51 %, the worst from 10 km in the twilight; the table of 48 x 32 nodes
     * of 40 steps a piece, interpolated linearly, gave 18.1 % and 0.71 %) */
    CHECK(all_worst < 0.2);
    CHECK(sqrt(s2 / cnt) < 0.006);
}

/* The sky-view table kept between frames (atmos__atm_batch_update): kept while the eye flies
 * level and the sun stands still, built again when either moves beyond its quantum or the
 * ground has maps; a kept table turned toward the new eye gives the very bytes a table built
 * for that eye alone gives (a frame does not depend on the frames before it). */
static void kept_table(const atmos_atmosphere *uniform, const atmos_atmosphere *mapped)
{
    int n = 0;
    for (int i = 0; i < 60; i++)
        for (int j = 0; j < 40; j++) {
            double d[3];
            atmos_direction_from_angles(-30 + i, 360.0 * (j + 0.29) / 40, d);
            dx[n] = (float)d[0], dy[n] = (float)d[1], dz[n] = (float)d[2], w[n] = 1;
            n++;
        }
    double sun[3], sun2[3];
    atmos_direction_from_angles(5, 180, sun);
    atmos_direction_from_angles(5.1, 180, sun2);
    const double e0[3] = {0, 1000, 0}, e1[3] = {40, 1000, 0}, up[3] = {40, 1030, 0};
    atmos__atm_batch b;
    memset(&b, 0, sizeof b);
    CHECK(atmos__atm_batch_update(&b, uniform, e0, sun, 0) == 0);
    CHECK(atmos__atm_batch_update(&b, uniform, e1, sun, 0) == 1); /* 40 m level flight across the sun's vertical */
    memset(out, 0, sizeof(float) * 3 * (size_t)n);
    atmos__atm_batch_eval(&b, n, dx, dy, dz, w, out, scratch);
    eval_batch(uniform, e1, sun, n, out2);
    CHECK(memcmp(out, out2, sizeof(float) * 3 * (size_t)n) == 0);
    CHECK(atmos__atm_batch_update(&b, uniform, up, sun, 0) == 0);  /* 30 m higher */
    CHECK(atmos__atm_batch_update(&b, uniform, up, sun2, 0) == 0); /* the sun 0.1 degree higher */
    CHECK(atmos__atm_batch_update(&b, uniform, up, sun2, 0) == 1);
    CHECK(atmos__atm_batch_update(&b, mapped, up, sun2, 0) == 0);  /* another atmosphere, with maps */
    CHECK(atmos__atm_batch_update(&b, mapped, up, sun2, 0) == 0);
    atmos__atm_batch_release(&b);
}

int main(void)
{
    atmos_atmosphere *a = make();
    if (a) from_space(a);
    atmos_atmosphere_destroy(a);
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    ad.hide_sun_disk = 1;
    ad.ground_albedo = 0.3;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, &wl, &a));
    if (a) from_air(a);
    atmos_atmosphere *m = make();
    if (a && m) kept_table(a, m);
    atmos_atmosphere_destroy(m);
    atmos_atmosphere_destroy(a);
    return test_summary("test_spherical_views");
}
