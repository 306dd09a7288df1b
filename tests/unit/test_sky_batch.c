/* The renderers' single-precision evaluation of many view rays (atmosphere_ops.h: the
 * vectorised closed form for Riley's sky, loops for the other kinds) against the
 * double-precision interface (checked against quadrature in test_sky), for every kind. */
#include "atmos/atmos.h"
#include "atmosphere/atmosphere_ops.h"
#include "core/fastmath.h"
#include "test.h"

static void compare(atmos_atmosphere_kind kind, const atmos_wavelengths *wl, double albedo, double eye_y,
                    double *max_err, int *n_bad)
{
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = kind;
    ad.ground_albedo = albedo;
    ad.background_radiance = 0.125;
    ad.thickness_m = 3000;
    ad.hide_sun_disk = 1; /* the batch evaluator leaves the disk to the caller */
    atmos_atmosphere *sky = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, wl, &sky));
    enum { N = 2000 };
    static float dx[N], dy[N], dz[N], w[N], out[N * ATMOS_MAX_WAVELENGTHS], scratch[N * ATMOS__ATM_BATCH_SCRATCH];
    double L[ATMOS_MAX_WAVELENGTHS];
    const double sun_el[] = {-3, 0.05, 0.5, 2, 10, 35, 70, 90};
    for (int s = 0; s < 8; s++) {
        double sun[3], eye[3] = {0, eye_y, 0};
        atmos_direction_from_angles(sun_el[s], 250, sun);
        atmos__atm_batch b;
        atmos__atm_batch_init(&b, sky, eye, sun, 0);
        for (int i = 0; i < N; i++) {
            double d[3];
            /* Elevations cluster near the horizon, where the closed form is most delicate. */
            double t = (i + 0.5) / N * 2 - 1;
            double el = 90.0 * t * t * t;
            atmos_direction_from_angles(el, 37.0 * i, d);
            dx[i] = (float)d[0], dy[i] = (float)d[1], dz[i] = (float)d[2], w[i] = 1;
        }
        memset(out, 0, sizeof out);
        atmos__atm_batch_eval(&b, N, dx, dy, dz, w, out, scratch);
        for (int i = 0; i < N; i++) {
            double d[3] = {dx[i], dy[i], dz[i]};
            atmos_atmosphere_radiance(sky, eye, d, sun, L, NULL);
            for (int k = 0; k < wl->count; k++) {
                double ref = L[k], got = out[k * N + i];
                /* float evaluation of the same formula: 1e-4 relative, with a floor at
                 * 1e-6 of a typical daylight sky radiance (~0.1 W m^-2 sr^-1 nm^-1) */
                double err = fabs(got - ref) / fmax(fabs(ref), 1e-7);
                if (err > *max_err) *max_err = err;
                if (!(err <= 1e-4) || !isfinite(got)) {
                    if (*n_bad < 10)
                        fprintf(stderr, "kind %d sun %g eye %g dir el %.6g: batch %.8g, reference %.8g\n", (int)kind,
                                sun_el[s], eye_y,
                                asin(d[1]) * 57.29577951308232, got, ref);
                    (*n_bad)++;
                }
            }
        }
    }
    atmos_atmosphere_destroy(sky);
}

int main(void)
{
    atmos_wavelengths wl;
    double max_err = 0;
    int bad = 0;
    atmos_wavelengths_rgb(&wl);
    compare(ATMOS_ATMOSPHERE_RILEY, &wl, 0.3, 2.0, &max_err, &bad);
    compare(ATMOS_ATMOSPHERE_RILEY, &wl, 0.0, 0.0, &max_err, &bad);
    compare(ATMOS_ATMOSPHERE_RILEY, &wl, 1.0, 10000.0, &max_err, &bad);
    compare(ATMOS_ATMOSPHERE_VACUUM, &wl, 0.3, 500.0, &max_err, &bad);
    compare(ATMOS_ATMOSPHERE_HOMOGENEOUS, &wl, 0.3, 500.0, &max_err, &bad);
    compare(ATMOS_ATMOSPHERE_HOMOGENEOUS, &wl, 0.0, 4000.0, &max_err, &bad);
    atmos_wavelengths_spectral(16, &wl);
    compare(ATMOS_ATMOSPHERE_RILEY, &wl, 0.2, 50000.0, &max_err, &bad);
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
