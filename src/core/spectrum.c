/* Wavelength sets and colour conversion (CIE 1931 2° observer, linear sRGB). */
#include "core/internal.h"
#include "core/spectral_data.h"

#include <math.h>
#include <string.h>

/* Luminous efficacy of monochromatic 555 nm radiation, lm/W: turns spectral
 * radiance (W m^-2 sr^-1 nm^-1) integrated against ybar into cd m^-2. */
#define ATMOS_KM 683.0

/* Riley et al. 2004, Table 3: the three channels' wavelengths. */
static const double rgb_nm[3] = {680.0, 550.0, 440.0};

static double table_lerp(const double *v, int stride, double nm)
{
    double t = nm - ATMOS__SPECTRAL_DATA_LO_NM;
    if (!(t >= 0.0) || t > (double)(ATMOS__SPECTRAL_DATA_COUNT - 1)) return 0.0;
    int i = (int)t;
    if (i >= ATMOS__SPECTRAL_DATA_COUNT - 1) return v[(ATMOS__SPECTRAL_DATA_COUNT - 1) * stride];
    double f = t - i;
    return v[i * stride] * (1.0 - f) + v[(i + 1) * stride] * f;
}

void atmos_cie_xyz_cmf(double nm, double xyz[3])
{
    for (int c = 0; c < 3; c++) xyz[c] = table_lerp(&atmos__cie_xyz[0][c], 3, nm);
}

double atmos_solar_irradiance(double nm) { return table_lerp(atmos__solar_etr, 1, nm); }

/* Integrates f over [lo, hi] with the midpoint rule at 0.05 nm: the tables are
 * piecewise linear at 1 nm, so this is accurate to ~1e-6 relative. */
static double integrate(double (*f)(double, int), int c, double lo, double hi)
{
    if (!(hi > lo)) return 0.0;
    int n = (int)ceil((hi - lo) / 0.05);
    double h = (hi - lo) / n, s = 0.0;
    for (int i = 0; i < n; i++) s += f(lo + (i + 0.5) * h, c);
    return s * h;
}

static double cmf_component(double nm, int c)
{
    double xyz[3];
    atmos_cie_xyz_cmf(nm, xyz);
    return xyz[c];
}

static double solar_component(double nm, int c)
{
    (void)c;
    return atmos_solar_irradiance(nm);
}

double atmos_solar_irradiance_mean(double lo_nm, double hi_nm)
{
    if (!(hi_nm > lo_nm)) return atmos_solar_irradiance(lo_nm);
    return integrate(solar_component, 0, lo_nm, hi_nm) / (hi_nm - lo_nm);
}

/* IEC 61966-2-1 (sRGB) matrices, D65 white. */
static const double M_xyz_to_srgb[3][3] = {
    {3.2404542, -1.5371385, -0.4985314},
    {-0.9692660, 1.8760108, 0.0415560},
    {0.0556434, -0.2040259, 1.0572252},
};
static const double M_srgb_to_xyz[3][3] = {
    {0.4124564, 0.3575761, 0.1804375},
    {0.2126729, 0.7151522, 0.0721750},
    {0.0193339, 0.1191920, 0.9503041},
};

static void mat3_apply(const double m[3][3], const double in[3], double out[3])
{
    double r[3];
    for (int i = 0; i < 3; i++) r[i] = m[i][0] * in[0] + m[i][1] * in[1] + m[i][2] * in[2];
    memcpy(out, r, sizeof r);
}

void atmos_xyz_to_srgb(const double xyz[3], double rgb[3]) { mat3_apply(M_xyz_to_srgb, xyz, rgb); }
void atmos_srgb_to_xyz(const double rgb[3], double xyz[3]) { mat3_apply(M_srgb_to_xyz, rgb, xyz); }

/* XYZ of the extraterrestrial solar spectrum seen as
 * a radiance: 683 * integral E(l) cmf(l) dl over the CIE table. */
static void solar_xyz(double xyz[3])
{
    for (int c = 0; c < 3; c++) {
        double s = 0.0;
        for (int i = 0; i < ATMOS__SPECTRAL_DATA_COUNT; i++) s += atmos__solar_etr[i] * atmos__cie_xyz[i][c];
        xyz[c] = ATMOS_KM * s; /* 1 nm spacing */
    }
}

void atmos_wavelengths_rgb(atmos_wavelengths *out)
{
    memset(out, 0, sizeof *out);
    out->mode = ATMOS_WAVELENGTHS_RGB;
    out->count = 3;
    double sun_xyz[3], sun_rgb[3];
    solar_xyz(sun_xyz);
    atmos_xyz_to_srgb(sun_xyz, sun_rgb);
    for (int i = 0; i < 3; i++) {
        out->nm[i] = rgb_nm[i];
        out->width_nm[i] = 10.0;
        out->sun_irradiance[i] = atmos_solar_irradiance_mean(rgb_nm[i] - 5.0, rgb_nm[i] + 5.0);
        /* Channel i's radiance relative to the sun at its wavelength, times the sun's
         * true colour in that sRGB channel: sunlight itself maps exactly to its colour. */
        double rgb[3] = {0, 0, 0};
        rgb[i] = sun_rgb[i] / out->sun_irradiance[i];
        for (int c = 0; c < 3; c++) out->to_srgb[i][c] = rgb[c];
        atmos_srgb_to_xyz(rgb, out->to_xyz[i]);
    }
}

atmos_status atmos_wavelengths_spectral(int n, atmos_wavelengths *out)
{
    if (n < 1 || n > ATMOS_MAX_WAVELENGTHS) return ATMOS_E_INVALID_ARG;
    memset(out, 0, sizeof *out);
    out->mode = ATMOS_WAVELENGTHS_SPECTRAL;
    out->count = n;
    double w = (ATMOS_SPECTRAL_MAX_NM - ATMOS_SPECTRAL_MIN_NM) / n;
    for (int i = 0; i < n; i++) {
        double lo = ATMOS_SPECTRAL_MIN_NM + i * w, hi = lo + w;
        out->nm[i] = 0.5 * (lo + hi);
        out->width_nm[i] = w;
        out->sun_irradiance[i] = atmos_solar_irradiance_mean(lo, hi);
        /* Box-filter reconstruction: the sample stands for its whole bin. */
        for (int c = 0; c < 3; c++) out->to_xyz[i][c] = ATMOS_KM * integrate(cmf_component, c, lo, hi);
        atmos_xyz_to_srgb(out->to_xyz[i], out->to_srgb[i]);
    }
    return ATMOS_OK;
}
