/* Refractive indices of water and ice against the reference table shipped in
 * data/optics/water_ice_n_k_380_780nm.csv (interpolated from the same published
 * sources by a different program) and known values. */
#include "atmos/atmos.h"
#include "test.h"

int main(void)
{
    /* An independent measurement: Hale & Querry 1973 tabulate n = 1.332 at 600 nm (25 °C;
     * water's n falls ~1e-4 per degree, so 20 °C reads slightly higher). */
    CHECK_NEAR(atmos_refractive_index_water(600).re, 1.332, 1.5e-3);
    const char *src = getenv("ATMOS_SOURCE_DIR");
    CHECK_MSG(src && *src, "ATMOS_SOURCE_DIR not set (run through ctest)");
    if (src) {
        char path[1024];
        snprintf(path, sizeof path, "%s/data/optics/water_ice_n_k_380_780nm.csv", src);
        FILE *f = fopen(path, "r");
        CHECK_MSG(f != NULL, "cannot open %s", path);
        if (f) {
            char line[512];
            int rows = 0;
            double max_dn_w = 0, max_dn_i = 0, max_rk_w = 0, max_rk_i = 0;
            if (!fgets(line, sizeof line, f)) line[0] = 0; /* header */
            while (fgets(line, sizeof line, f)) {
                double nm, nd, ns, ks, nh, kh, ni, ki;
                if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &nm, &nd, &ns, &ks, &nh, &kh, &ni, &ki) != 8) continue;
                rows++;
                atmos_complex w = atmos_refractive_index_water(nm), i = atmos_refractive_index_ice(nm);
                max_dn_w = fmax(max_dn_w, fabs(w.re - nd));
                max_dn_i = fmax(max_dn_i, fabs(i.re - ni));
                max_rk_w = fmax(max_rk_w, fabs(-w.im - kh) / kh);
                max_rk_i = fmax(max_rk_i, fabs(-i.im - ki) / ki);
                CHECK(w.im <= 0 && i.im <= 0); /* MIEV0 sign convention */
            }
            fclose(f);
            printf("%d rows: |dn| water %.2e ice %.2e, k rel water %.2e ice %.2e\n", rows, max_dn_w, max_dn_i, max_rk_w, max_rk_i);
            CHECK(rows == 81);
            CHECK(max_dn_w < 2e-5);
            CHECK(max_dn_i < 2e-4);
            CHECK(max_rk_w < 0.1);
            CHECK(max_rk_i < 0.1);
        }
    }
    /* Normal dispersion: n decreases with wavelength across the visible, for both. */
    for (double nm = 380; nm < 780; nm += 10) {
        CHECK(atmos_refractive_index_water(nm + 10).re < atmos_refractive_index_water(nm).re);
        CHECK(atmos_refractive_index_ice(nm + 10).re <= atmos_refractive_index_ice(nm).re);
    }
    /* Ice is optically less dense than water. */
    CHECK(atmos_refractive_index_ice(550).re < atmos_refractive_index_water(550).re);
    /* Out-of-range and NaN wavelengths clamp instead of producing NaN. */
    CHECK(isfinite(atmos_refractive_index_water(NAN).re) && isfinite(atmos_refractive_index_ice(1e9).re));
    return test_summary("test_refractive_index");
}
