/* Solar position from a UTC instant and a place.
 *
 * The algorithm is the NOAA Global Monitoring Division solar calculator
 * (NOAA_Solar_Calculations_day.xls), which is the low-accuracy solar theory of
 * Meeus, Astronomical Algorithms, 2nd ed. (1998): ch. 7 (Julian day), ch. 22
 * (mean obliquity, Eq. 22.2), ch. 25 (geometric mean longitude, mean anomaly,
 * equation of centre, apparent longitude, Eqs. 25.2-25.8), ch. 28 (equation of
 * time, Eq. 28.3 after Smart) and ch. 13 (equatorial to horizontal, Eqs.
 * 13.5-13.6). Accuracy is about 0.01 degree for 1800-2200, the range we accept.
 *
 * Like NOAA we feed UT where the theory wants dynamical time (TD): the ~1 minute
 * of Delta T moves the sun by ~0.001 degree in longitude, below the method's own
 * error. Positions are geocentric: we omit the solar parallax, at most
 * 8.794"/R = 0.0025 degree (Meeus ch. 40).
 */
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Accepted years: the polynomials of Meeus ch. 25 are fits around J2000, and
 * feeding UT for TD (see above) costs more than the 0.01 degree budget once
 * |Delta T| grows past ~15 minutes, i.e. centuries away from now. 1800-2200
 * keeps us well inside both (ATMOS_SUN_YEAR_MIN, ATMOS_SUN_YEAR_MAX in atmos/sun.h). */

static int is_leap_year(int y)
{
    return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
}

static int days_in_month(int y, int m)
{
    static const int days[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
    if (m < 1 || m > 12) return 0;
    return m == 2 && is_leap_year(y) ? 29 : days[m - 1];
}

static double deg_sin(double d) { return sin(d * ATMOS_DEG2RAD); }
static double deg_cos(double d) { return cos(d * ATMOS_DEG2RAD); }

/* Reduces an angle to [0, 360). fmod keeps the sign of its argument, and a tiny
 * negative value plus 360 can round to exactly 360, hence the second test. */
static double wrap360(double d)
{
    double r = fmod(d, 360.0);
    if (r < 0) r += 360.0;
    if (r >= 360.0) r = 0.0;
    return r;
}

/* asin/acos of a value that rounding may have pushed just outside [-1, 1]
 * (sun at the zenith or nadir, observer at a pole): clamp instead of NaN. */
static double clamp_unit(double x)
{
    return x > 1.0 ? 1.0 : x < -1.0 ? -1.0 : x;
}

/* ---- ISO 8601 parsing ---------------------------------------------------- */

/* Reads exactly n decimal digits; returns 0 if any is missing. */
static int read_digits(const char **p, int n, int *out)
{
    int v = 0;
    for (int i = 0; i < n; i++) {
        char c = (*p)[i];
        if (c < '0' || c > '9') return 0;
        v = v * 10 + (c - '0');
    }
    *p += n;
    *out = v;
    return 1;
}

#define TIME_FORMAT_HINT "expected YYYY-MM-DDTHH:MM[:SS[.fff]] followed by Z or +HH:MM/-HH:MM"

atmos_status atmos_parse_utc_time(atmos_context *ctx, const char *text, atmos_utc_time *out)
{
    if (!text || !out)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "time: text and out must not be NULL");
    const char *p = text;
    int year, month, day, hour, minute, isec = 0;
    double second = 0.0;

    /* Quote at most 64 characters of the input in messages. */
#define BAD_FORMAT(what)                                                                    \
    atmos__error(ctx, ATMOS_E_INVALID_ARG, "time '%.64s': %s; " TIME_FORMAT_HINT, text, what)

    if (!read_digits(&p, 4, &year) || *p++ != '-') return BAD_FORMAT("bad date");
    if (!read_digits(&p, 2, &month) || *p++ != '-') return BAD_FORMAT("bad date");
    if (!read_digits(&p, 2, &day)) return BAD_FORMAT("bad date");
    if (*p++ != 'T') return BAD_FORMAT("missing 'T' between date and time");
    if (!read_digits(&p, 2, &hour) || *p++ != ':' || !read_digits(&p, 2, &minute))
        return BAD_FORMAT("bad time of day");
    if (*p == ':') {
        p++;
        if (!read_digits(&p, 2, &isec)) return BAD_FORMAT("bad seconds");
        second = isec;
        if (*p == '.') {
            /* At most 9 fractional digits (nanoseconds): enough for any use and
             * keeps the loop bounded. */
            p++;
            double scale = 0.1;
            int ndig = 0;
            while (*p >= '0' && *p <= '9') {
                if (++ndig > 9) return BAD_FORMAT("more than 9 fractional second digits");
                second += (*p - '0') * scale;
                scale *= 0.1;
                p++;
            }
            if (ndig == 0) return BAD_FORMAT("no digits after the decimal point");
        }
    }

    int offset_min = 0;
    if (*p == 'Z') {
        p++;
    } else if (*p == '+' || *p == '-') {
        int sign = *p++ == '-' ? -1 : 1, oh, om;
        if (!read_digits(&p, 2, &oh) || *p++ != ':' || !read_digits(&p, 2, &om))
            return BAD_FORMAT("bad time zone offset");
        if (oh > 23 || om > 59)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "time '%.64s': time zone offset %c%02d:%02d out of range "
                                "(hours 00-23, minutes 00-59)", text, sign < 0 ? '-' : '+', oh, om);
        offset_min = sign * (oh * 60 + om);
    } else {
        return BAD_FORMAT("missing time zone (Z or +HH:MM/-HH:MM)");
    }
    if (*p != '\0') return BAD_FORMAT("unexpected characters after the time zone");
#undef BAD_FORMAT

    if (month < 1 || month > 12)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "time '%.64s': month %d out of range [1, 12]",
                            text, month);
    int dim = days_in_month(year, month);
    if (day < 1 || day > dim)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "time '%.64s': day %d out of range [1, %d] for %04d-%02d", text, day, dim,
                            year, month);
    if (hour > 23 || minute > 59 || isec > 59)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "time '%.64s': time of day out of range (hours 00-23, minutes 00-59, "
                            "seconds 00-59)", text);

    /* Local time minus offset is UTC. The shift is under a day, so at most one
     * day of rollover, which may carry into the month and the year. */
    int minutes = hour * 60 + minute - offset_min;
    if (minutes < 0) {
        minutes += 1440;
        if (--day < 1) {
            if (--month < 1) { month = 12; year--; }
            day = days_in_month(year, month);
        }
    } else if (minutes >= 1440) {
        minutes -= 1440;
        if (++day > days_in_month(year, month)) {
            day = 1;
            if (++month > 12) { month = 1; year++; }
        }
    }
    out->year = year;
    out->month = month;
    out->day = day;
    out->hour = minutes / 60;
    out->minute = minutes % 60;
    out->second = second;
    return ATMOS_OK;
}

/* ---- Solar position ------------------------------------------------------ */

/* Julian day number of 0h UT on a Gregorian date (Meeus Eq. 7.1; B from the
 * Gregorian reform, valid for all our years). Kept separate from the time of day
 * so Julian centuries can be formed without losing the day fraction's precision. */
static double julian_day_0h(int year, int month, int day)
{
    if (month <= 2) { year -= 1; month += 12; }
    int a = year / 100; /* year > 0 here, so truncation is floor */
    int b = 2 - a + a / 4;
    return floor(365.25 * (year + 4716)) + floor(30.6001 * (month + 1)) + day + b - 1524.5;
}

static atmos_status validate_time(atmos_context *ctx, const atmos_utc_time *t)
{
    if (t->year < ATMOS_SUN_YEAR_MIN || t->year > ATMOS_SUN_YEAR_MAX)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "sun position: year %d out of range [%d, %d] of the NOAA/Meeus algorithm",
                            t->year, ATMOS_SUN_YEAR_MIN, ATMOS_SUN_YEAR_MAX);
    if (t->month < 1 || t->month > 12)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "sun position: month %d out of range [1, 12]",
                            t->month);
    int dim = days_in_month(t->year, t->month);
    if (t->day < 1 || t->day > dim)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "sun position: day %d out of range [1, %d] for %04d-%02d", t->day, dim,
                            t->year, t->month);
    if (t->hour < 0 || t->hour > 23)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "sun position: hour %d out of range [0, 23]",
                            t->hour);
    if (t->minute < 0 || t->minute > 59)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "sun position: minute %d out of range [0, 59]",
                            t->minute);
    if (!isfinite(t->second) || t->second < 0.0 || t->second >= 60.0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "sun position: second %g out of range [0, 60)",
                            t->second);
    return ATMOS_OK;
}

/* The NOAA solar calculator's refraction approximation for a standard
 * atmosphere, piecewise in the geometric elevation e (degrees): 0.48 degree at
 * the horizon, zero above 85 degrees. Returns the correction in degrees to add. */
static double noaa_refraction_deg(double e)
{
    double arcsec;
    if (e > 85.0) {
        arcsec = 0.0;
    } else if (e > 5.0) {
        double te = tan(e * ATMOS_DEG2RAD);
        arcsec = 58.1 / te - 0.07 / (te * te * te) + 0.000086 / (te * te * te * te * te);
    } else if (e > -0.575) {
        arcsec = 1735.0 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)));
    } else {
        /* Below the horizon: NOAA's -20.774/tan(e) fades to 0 at the nadir
         * (tan(-90 deg) is huge but finite in floating point). */
        arcsec = -20.774 / tan(e * ATMOS_DEG2RAD);
    }
    return arcsec / 3600.0;
}

/* Julian day number (the day starting at noon UT on the given civil date's noon) of a
 * Gregorian date (Meeus, Astronomical Algorithms, ch. 7), and its inverse. */
static long julian_day_number(int y, int m, int d)
{
    if (m <= 2) y -= 1, m += 12;
    long a = y / 100, b = 2 - a + a / 4;
    return (long)floor(365.25 * (y + 4716)) + (long)floor(30.6001 * (m + 1)) + d + b - 1524;
}

static void civil_from_julian_day_number(long z, int *y, int *m, int *d)
{
    long alpha = (long)floor((z - 1867216.25) / 36524.25);
    long a = z + 1 + alpha - alpha / 4, b = a + 1524;
    long c = (long)floor((b - 122.1) / 365.25), dd = (long)floor(365.25 * c);
    long e = (long)floor((b - dd) / 30.6001);
    *d = (int)(b - dd - (long)floor(30.6001 * e));
    *m = (int)(e < 14 ? e - 1 : e - 13);
    *y = (int)(*m > 2 ? c - 4716 : c - 4715);
}

/* Seconds since the start of Julian day number 0's civil date, and back. Doubles hold
 * whole seconds of any year 1..9999 exactly and leave ~1e-5 s for fractions. */
double atmos_utc_time_seconds(const atmos_utc_time *t)
{
    return (double)julian_day_number(t->year, t->month, t->day) * 86400.0 + t->hour * 3600.0 + t->minute * 60.0 +
           t->second;
}

void atmos_utc_time_from_seconds(double s, atmos_utc_time *t)
{
    double day = floor(s / 86400.0), sod = s - day * 86400.0;
    if (sod < 0) sod = 0;
    civil_from_julian_day_number((long)day, &t->year, &t->month, &t->day);
    t->hour = (int)(sod / 3600.0);
    if (t->hour > 23) t->hour = 23;
    sod -= t->hour * 3600.0;
    t->minute = (int)(sod / 60.0);
    if (t->minute > 59) t->minute = 59;
    t->second = sod - t->minute * 60.0;
    if (t->second < 0) t->second = 0;
}

atmos_status atmos_sun_position_compute(atmos_context *ctx, const atmos_utc_time *t,
                                        double latitude_deg, double longitude_deg,
                                        int refraction, atmos_sun_position *out)
{
    if (!t || !out)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "sun position: time and out must not be NULL");
    if (!isfinite(latitude_deg) || latitude_deg < -90.0 || latitude_deg > 90.0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "sun position: latitude %g out of range [-90, 90] degrees", latitude_deg);
    if (!isfinite(longitude_deg) || longitude_deg < -180.0 || longitude_deg > 180.0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "sun position: longitude %g out of range [-180, 180] degrees",
                            longitude_deg);
    atmos_status st = validate_time(ctx, t);
    if (st != ATMOS_OK) return st;

    double jd0 = julian_day_0h(t->year, t->month, t->day);
    double day_min = t->hour * 60.0 + t->minute + t->second / 60.0; /* minutes past 0h UT */
    double day_frac = day_min / 1440.0;
    /* Julian centuries from J2000.0 (JD 2451545.0); the integer-ish part and the
     * fraction are added after the subtraction to keep sub-second resolution. */
    double T = ((jd0 - 2451545.0) + day_frac) / 36525.0;

    /* Meeus Eqs. 25.2-25.4: geometric mean longitude L0, mean anomaly M,
     * eccentricity of Earth's orbit e. */
    double L0 = wrap360(280.46646 + T * (36000.76983 + T * 0.0003032));
    double M = 357.52911 + T * (35999.05029 - T * 0.0001537);
    double ecc = 0.016708634 - T * (0.000042037 + T * 0.0000001267);
    /* Equation of the centre C; true longitude = L0 + C. */
    double C = deg_sin(M) * (1.914602 - T * (0.004817 + T * 0.000014)) +
               deg_sin(2.0 * M) * (0.019993 - T * 0.000101) + deg_sin(3.0 * M) * 0.000289;
    double true_long = L0 + C;
    /* Apparent longitude (Meeus 25.8 note): nutation and aberration through the
     * longitude of the Moon's ascending node Omega. */
    double omega = 125.04 - 1934.136 * T;
    double lambda = true_long - 0.00569 - 0.00478 * deg_sin(omega);
    /* Mean obliquity (Meeus Eq. 22.2, arcseconds) and the correction for the
     * apparent position (Meeus ch. 25: epsilon + 0.00256 cos Omega). */
    double eps0 = 23.0 + (26.0 + (21.448 - T * (46.815 + T * (0.00059 - T * 0.001813))) / 60.0) / 60.0;
    double eps = eps0 + 0.00256 * deg_cos(omega);

    /* Meeus Eqs. 25.6-25.7: apparent right ascension and declination. */
    double alpha = wrap360(atan2(deg_cos(eps) * deg_sin(lambda), deg_cos(lambda)) * ATMOS_RAD2DEG);
    double decl = asin(clamp_unit(deg_sin(eps) * deg_sin(lambda))) * ATMOS_RAD2DEG;

    /* Equation of time (Meeus Eq. 28.3, W. M. Smart), in minutes (4 min/degree). */
    double y = tan(eps * ATMOS_DEG2RAD / 2.0);
    y *= y;
    double L0r = L0 * ATMOS_DEG2RAD, Mr = M * ATMOS_DEG2RAD;
    double eot_rad = y * sin(2.0 * L0r) - 2.0 * ecc * sin(Mr) +
                     4.0 * ecc * y * sin(Mr) * cos(2.0 * L0r) - 0.5 * y * y * sin(4.0 * L0r) -
                     1.25 * ecc * ecc * sin(2.0 * Mr);
    double eot_min = 4.0 * eot_rad * ATMOS_RAD2DEG;

    /* True solar time and hour angle (NOAA): the hour angle is 0 at local
     * apparent noon, positive in the afternoon (west). */
    double tst = fmod(day_min + eot_min + 4.0 * longitude_deg, 1440.0);
    if (tst < 0) tst += 1440.0;
    double H = tst / 4.0 - 180.0;

    /* Horizontal coordinates (Meeus Eqs. 13.5-13.6). The elevation from asin of a
     * clamped sine and the azimuth from atan2 (north = 0, clockwise) stay finite
     * at the poles and at the zenith, where acos-based forms divide by zero. */
    double sphi = deg_sin(latitude_deg), cphi = deg_cos(latitude_deg);
    double sdec = deg_sin(decl), cdec = deg_cos(decl);
    double cH = deg_cos(H), sH = deg_sin(H);
    double sin_elev = clamp_unit(sphi * sdec + cphi * cdec * cH);
    double elev = asin(sin_elev) * ATMOS_RAD2DEG;
    double east = -cdec * sH;                      /* horizontal component toward east */
    double north = cphi * sdec - sphi * cdec * cH; /* horizontal component toward north */
    double az;
    if (hypot(east, north) < 1e-12) {
        /* Sun at the zenith or nadir: azimuth is undefined; report south. */
        az = 180.0;
    } else {
        az = wrap360(atan2(east, north) * ATMOS_RAD2DEG);
    }

    double app = elev;
    if (refraction) {
        app = elev + noaa_refraction_deg(elev);
        if (app > 90.0) app = 90.0;
    }

    out->elevation_deg = app;
    out->azimuth_deg = az;
    out->geometric_elevation_deg = elev;
    out->declination_deg = decl;
    out->right_ascension_deg = alpha;
    out->equation_of_time_min = eot_min;
    out->julian_day = jd0 + day_frac;
    return ATMOS_OK;
}
