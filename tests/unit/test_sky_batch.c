/* The renderer's fast float sky evaluator against the double-precision library
 * functions (which are themselves checked against quadrature in test_sky). */
#include "atmos/atmos.h"
#include "atmosphere/riley_batch.h"
#include "test.h"

static void compare(const atmos_wavelengths *wl, double albedo, double eye_y, double *max_err, int *n_bad)
{
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.ground_albedo = albedo;
    ad.hide_sun_disk = 1; /* the batch evaluator leaves the disk to the caller */
    atmos_sky *sky = NULL;
    CHECK_OK(atmos_sky_create(NULL, &ad, wl, &sky));
    enum { N = 2000 };
    static float dx[N], dy[N], dz[N], w[N], out[N * ATMOS_MAX_WAVELENGTHS], scratch[N * ATMOS__SKY_BATCH_SCRATCH];
    double L[ATMOS_MAX_WAVELENGTHS];
    const double sun_el[] = {-3, 0.05, 0.5, 2, 10, 35, 70, 90};
    for (int s = 0; s < 8; s++) {
        double sun[3], eye[3] = {0, eye_y, 0};
        atmos_direction_from_angles(sun_el[s], 250, sun);
        atmos__sky_batch b;
        atmos__sky_batch_init(&b, sky, eye_y, sun);
        for (int i = 0; i < N; i++) {
            double d[3];
            /* Elevations cluster near the horizon, where the closed form is most delicate. */
            double t = (i + 0.5) / N * 2 - 1;
            double el = 90.0 * t * t * t;
            atmos_direction_from_angles(el, 37.0 * i, d);
            dx[i] = (float)d[0], dy[i] = (float)d[1], dz[i] = (float)d[2], w[i] = 1;
        }
        memset(out, 0, sizeof out);
        atmos__sky_batch_eval(&b, N, dx, dy, dz, w, out, scratch);
        for (int i = 0; i < N; i++) {
            double d[3] = {dx[i], dy[i], dz[i]};
            atmos_sky_radiance(sky, eye, d, sun, L, NULL);
            for (int k = 0; k < wl->count; k++) {
                double ref = L[k], got = out[k * N + i];
                /* float evaluation of the same formula: 1e-4 relative, with a floor at
                 * 1e-6 of a typical daylight sky radiance (~0.1 W m^-2 sr^-1 nm^-1) */
                double err = fabs(got - ref) / fmax(fabs(ref), 1e-7);
                if (err > *max_err) *max_err = err;
                if (!(err <= 1e-4) || !isfinite(got)) {
                    if (*n_bad < 10)
                        fprintf(stderr, "sun %g eye %g dir el %.6g: batch %.8g, reference %.8g\n", sun_el[s], eye_y,
                                asin(d[1]) * 57.29577951308232, got, ref);
                    (*n_bad)++;
                }
            }
        }
    }
    atmos_sky_destroy(sky);
}

int main(void)
{
    atmos_wavelengths wl;
    double max_err = 0;
    int bad = 0;
    atmos_wavelengths_rgb(&wl);
    compare(&wl, 0.3, 2.0, &max_err, &bad);
    compare(&wl, 0.0, 0.0, &max_err, &bad);
    compare(&wl, 1.0, 10000.0, &max_err, &bad);
    atmos_wavelengths_spectral(16, &wl);
    compare(&wl, 0.2, 50000.0, &max_err, &bad);
    printf("batch vs double: max relative error %.3e\n", max_err);
    CHECK(bad == 0);
    /* the fast exponential itself */
    double emax = 0;
    for (float x = -87.0f; x <= 88.0f; x += 0.001f) {
        double e = fabs(atmos__expf_fast(x) / exp((double)x) - 1.0);
        if (e > emax) emax = e;
    }
    printf("expf_fast: max relative error %.3e\n", emax);
    CHECK(emax < 1e-6);
    CHECK(atmos__expf_fast(-1000.0f) == 0.0f);
    return test_summary("test_sky_batch");
}
