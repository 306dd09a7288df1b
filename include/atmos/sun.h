/* Solar position from a UTC date-time and a place: the NOAA solar calculator
 * algorithm (after Meeus, Astronomical Algorithms, 2nd ed., ch. 25), with
 * atmospheric refraction. Pure functions; thread-safe.
 */
#ifndef ATMOS_SUN_H
#define ATMOS_SUN_H

#include "atmos/base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A UTC instant. Seconds may be fractional. */
typedef struct atmos_utc_time {
    int year, month, day;     /* Gregorian calendar */
    int hour, minute;
    double second;
} atmos_utc_time;

typedef struct atmos_sun_position {
    double elevation_deg;            /* apparent elevation (with refraction unless disabled) */
    double azimuth_deg;              /* clockwise from north, [0, 360) */
    double geometric_elevation_deg;  /* without refraction */
    double declination_deg;
    double right_ascension_deg;      /* apparent, [0, 360) */
    double equation_of_time_min;
    double julian_day;               /* Julian day (UT) of the instant */
} atmos_sun_position;

/* Parses ISO 8601 "YYYY-MM-DDTHH:MM[:SS[.fff]]" followed by "Z" or "+HH:MM" /
 * "-HH:MM" (converted to UTC). Returns ATMOS_E_INVALID_ARG with a message for
 * anything else, including impossible dates (2026-02-30). */
ATMOS_API atmos_status atmos_parse_utc_time(atmos_context *ctx, const char *text, atmos_utc_time *out);

/* Seconds since the start of Julian day number 0's civil date (an instant's place on one
 * clock, for differences and sums: doubles hold whole seconds of any year 1..9999 exactly)
 * and the instant of such a count. */
ATMOS_API double atmos_utc_time_seconds(const atmos_utc_time *t);
ATMOS_API void atmos_utc_time_from_seconds(double seconds, atmos_utc_time *out);

/* The years (UTC) atmos_sun_position_compute takes: the algorithm's polynomials are fits
 * around J2000, within 0.01 degree over these. A scene's sun time and its animation's
 * time_end outside them are refused when the scene is read or validated. */
#define ATMOS_SUN_YEAR_MIN 1800
#define ATMOS_SUN_YEAR_MAX 2200

/* Sun position for latitude (degrees north, [-90, 90]) and longitude (degrees
 * east, [-180, 180]) at a time of the years ATMOS_SUN_YEAR_MIN..ATMOS_SUN_YEAR_MAX.
 * refraction: nonzero to include standard atmospheric refraction in elevation_deg.
 * Errors name the offending value. */
ATMOS_API atmos_status atmos_sun_position_compute(atmos_context *ctx, const atmos_utc_time *t,
                                                  double latitude_deg, double longitude_deg,
                                                  int refraction, atmos_sun_position *out);

#ifdef __cplusplus
}
#endif
#endif
