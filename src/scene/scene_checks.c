/* The rules every scene value is checked by: the ranges of docs/scene-format.md, the message
 * format, vector helpers. Used by the parser and the validators (scene_validate.c,
 * scene_lights.c) alike. */
#include "scene/scene_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The ranges of docs/scene-format.md. */
const atmos__range atmos__r_dim = {1, ATMOS_SCENE_MAX_DIM, 0, 0};
const atmos__range atmos__r_spp = {1, 256, 0, 0};
const atmos__range atmos__r_altitude = {0, 1e8, 0, 0};
const atmos__range atmos__r_pos = {-ATMOS__SCENE_MAX_POS, ATMOS__SCENE_MAX_POS, 0, 0};
const atmos__range atmos__r_look = {-ATMOS__SCENE_MAX_LOOK, ATMOS__SCENE_MAX_LOOK, 0, 0};
const atmos__range atmos__r_fov_pinhole = {0, 180, 1, 1};
const atmos__range atmos__r_fov_fisheye = {0, 360, 1, 0};
const atmos__range atmos__r_elevation = {-90, 90, 0, 0};
const atmos__range atmos__r_azimuth = {0, 360, 0, 1};
const atmos__range atmos__r_latitude = {-90, 90, 0, 0};
const atmos__range atmos__r_longitude = {-180, 180, 0, 0};
const atmos__range atmos__r_beta = {0, 0.01, 1, 0};
const atmos__range atmos__r_scale_height = {100, 100000, 0, 0};
const atmos__range atmos__r_albedo = {0, 1, 0, 0};
const atmos__range atmos__r_sun_diameter = {0, 20, 1, 0};
const atmos__range atmos__r_sun_scale = {0, 1e6, 0, 0};
const atmos__range atmos__r_thickness = {1, 1e6, 0, 0};
const atmos__range atmos__r_radiance = {0, 1e6, 0, 0};
const atmos__range atmos__r_samples = {1, ATMOS_MAX_WAVELENGTHS, 0, 0};
const atmos__range atmos__r_manual_ev = {-20, 40, 0, 0};
const atmos__range atmos__r_compensation = {-20, 20, 0, 0};
const atmos__range atmos__r_planet_radius = {1e3, 1e8, 0, 0};
const atmos__range atmos__r_top = {60e3, 1e6, 0, 0};
const atmos__range atmos__r_visibility = {0.5, 1000, 0, 0};
const atmos__range atmos__r_turbidity = {1, 50, 0, 0};
const atmos__range atmos__r_ozone = {0, 1000, 0, 0};
const atmos__range atmos__r_dobashi_ambient = {0, 1, 0, 0};

atmos_status atmos__scene_fail(atmos_context *ctx, atmos_status status, const char *source,
                               const char *path, const char *fmt, ...)
{
    char what[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return atmos__error(ctx, status, "%s: %s: %s", source ? source : "scene", path, what);
}

void atmos__scene_fmt_num(char *buf, size_t cap, double v)
{
    if (isnan(v)) {
        snprintf(buf, cap, "nan");
        return;
    }
    if (isinf(v)) {
        snprintf(buf, cap, v < 0 ? "-inf" : "inf");
        return;
    }
    /* 15 digits reads well ("0.1", not "0.10000000000000001"); fall back to 17
     * when that would hide the difference from a boundary ("got 0.01" for a
     * value that is actually just above 0.01 would be a baffling message). */
    snprintf(buf, cap, "%.15g", v);
    if (strtod(buf, NULL) != v) snprintf(buf, cap, "%.17g", v);
}

atmos_status atmos__scene_check_range(atmos_context *ctx, const char *source, const char *path,
                                      double v, const atmos__range *r, const char *extra)
{
    char got[40], lo[40], hi[40];
    atmos__scene_fmt_num(got, sizeof got, v);
    if (!isfinite(v))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path,
                                 "must be a finite number, got %s", got);
    int ok = (r->lo_open ? v > r->lo : v >= r->lo) && (r->hi_open ? v < r->hi : v <= r->hi);
    if (ok) return ATMOS_OK;
    atmos__scene_fmt_num(lo, sizeof lo, r->lo);
    atmos__scene_fmt_num(hi, sizeof hi, r->hi);
    return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path, "must be in %c%s, %s%c%s, got %s",
                             r->lo_open ? '(' : '[', lo, hi, r->hi_open ? ')' : ']',
                             extra ? extra : "", got);
}

double atmos__scene_norm3(const double v[3])
{
    double m = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
    if (!(m > 0) || !isfinite(m)) return isfinite(m) ? 0.0 : m;
    double a = v[0] / m, b = v[1] / m, c = v[2] / m;
    return m * sqrt(a * a + b * b + c * c);
}

double atmos__scene_sin_angle(const double a[3], const double b[3])
{
    double na = atmos__scene_norm3(a), nb = atmos__scene_norm3(b);
    if (!(na > 0) || !(nb > 0) || !isfinite(na) || !isfinite(nb)) return -1.0;
    double u[3] = {a[0] / na, a[1] / na, a[2] / na}, w[3] = {b[0] / nb, b[1] / nb, b[2] / nb};
    double c[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}
