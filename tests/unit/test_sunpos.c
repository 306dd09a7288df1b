/* Solar position (src/sky/sunpos.c) against published reference values, plus
 * physical checks and the ISO 8601 parser.
 *
 * References:
 *  [M]    J. Meeus, Astronomical Algorithms, 2nd ed., Willmann-Bell 1998.
 *         Ex. 7.a (p. 61): 1957 October 4.81 (Sputnik 1) is JD 2436116.31.
 *         Ex. 25.a (p. 165): 1992 October 13.0 TD, JDE 2448908.5: apparent
 *           alpha = 198.38083 deg (13h13m31.4s), delta = -7.78507 deg (-7d47'06").
 *         Ex. 28.a (p. 184): same instant, equation of time E = +13m42.6s
 *           (13.710 min; Eq. 28.3, which NOAA uses, gives 13m42.7s).
 *  [SPA]  I. Reda, A. Andreas, Solar Position Algorithm for Solar Radiation
 *         Applications, NREL/TP-560-34302 (2003, rev. 2008), Table A5.1 for
 *         2003-10-17 12:30:30 local time, UTC-7, lat 39.742476, lon -105.1786,
 *         elevation 1830.14 m, P = 820 mbar, T = 11 degC, Delta T = 67 s:
 *         JD = 2452930.312847; geocentric alpha = 202.22741, delta = -9.31434;
 *         topocentric elevation without refraction e0 = 39.872046; with
 *         refraction e = 39.888378 (zenith 50.111622); azimuth 194.340241.
 *  [USNO] U.S. Naval Observatory, "Earth's Seasons: Equinoxes, Solstices,
 *         Perihelion, and Aphelion", 2024: March equinox 2024-03-20 03:06 UTC,
 *         June solstice 2024-06-20 20:51 UTC.
 */
#include "atmos/atmos.h"
#include "test.h"

static atmos_utc_time parse(const char *s)
{
    atmos_utc_time t;
    memset(&t, 0, sizeof t);
    atmos_status st = atmos_parse_utc_time(NULL, s, &t);
    CHECK_MSG(st == ATMOS_OK, "parse '%s' failed", s);
    return t;
}

static atmos_sun_position sun_at(const char *s, double lat, double lon, int refraction)
{
    atmos_utc_time t = parse(s);
    atmos_sun_position p;
    memset(&p, 0, sizeof p);
    CHECK_OK(atmos_sun_position_compute(NULL, &t, lat, lon, refraction, &p));
    return p;
}

static int finite_position(const atmos_sun_position *p)
{
    return isfinite(p->elevation_deg) && isfinite(p->azimuth_deg) &&
           isfinite(p->geometric_elevation_deg) && isfinite(p->declination_deg) &&
           isfinite(p->right_ascension_deg) && isfinite(p->equation_of_time_min) &&
           p->azimuth_deg >= 0.0 && p->azimuth_deg < 360.0 && p->elevation_deg >= -90.0 &&
           p->elevation_deg <= 90.0;
}

static void test_meeus(void)
{
    /* [M] Ex. 7.a: 1957 Oct 4.81 = 19:26:24 UT. */
    atmos_sun_position p = sun_at("1957-10-04T19:26:24Z", 0, 0, 0);
    CHECK_NEAR(p.julian_day, 2436116.31, 1e-6);

    /* [M] Ex. 25.a is worked in TD; the NOAA method does not distinguish TD
     * from UT, so 0h UTC reproduces the example's JDE 2448908.5 exactly. */
    p = sun_at("1992-10-13T00:00:00Z", 0, 0, 0);
    CHECK_NEAR(p.julian_day, 2448908.5, 1e-9);
    CHECK_NEAR(p.right_ascension_deg, 198.38083, 0.01);
    CHECK_NEAR(p.declination_deg, -7.78507, 0.01);
    /* Same formulas as the book, so we expect far better than 0.01 degree. */
    CHECK_NEAR(p.right_ascension_deg, 198.38083, 1e-4);
    CHECK_NEAR(p.declination_deg, -7.78507, 1e-4);
    /* [M] Ex. 28.a: 13m42.6s; tolerance 1 s (the book rounds to 0.1 s, and
     * Eq. 28.3 itself gives 42.7 s). */
    CHECK_NEAR(p.equation_of_time_min, 13.0 + 42.6 / 60.0, 1.0 / 60.0);
}

static void test_nrel_spa(void)
{
    /* [SPA] Table A5.1. The offset -07:00 exercises the time zone path. */
    atmos_sun_position p = sun_at("2003-10-17T12:30:30-07:00", 39.742476, -105.1786, 0);
    CHECK_NEAR(p.julian_day, 2452930.312847, 1e-6);
    /* SPA's full VSOP87 theory against NOAA's low-accuracy one. */
    CHECK_NEAR(p.right_ascension_deg, 202.22741, 0.01);
    CHECK_NEAR(p.declination_deg, -9.31434, 0.01);
    /* Our geometric elevation is geocentric; SPA's e0 is topocentric (parallax
     * lowers it by xi cos e ~ 0.0019 deg, xi = 0.002451 deg in Table A5.1).
     * e0 is the published value without refraction, so it is the one to
     * compare with; the published zenith 50.111622 includes refraction for
     * 820 mbar / 11 degC, which is not NOAA's standard atmosphere. */
    CHECK_NEAR(p.geometric_elevation_deg, 39.872046, 0.01);
    CHECK_NEAR(p.azimuth_deg, 194.340241, 0.01);

    /* With refraction: NOAA's standard atmosphere (~1010 mbar) refracts more than
     * SPA's 820 mbar, so only a loose comparison with e = 39.888378 makes sense:
     * the correction is positive and of the same order (SPA: 0.016332 deg). */
    atmos_sun_position r = sun_at("2003-10-17T12:30:30-07:00", 39.742476, -105.1786, 1);
    double dr = r.elevation_deg - r.geometric_elevation_deg;
    CHECK(dr > 0.010 && dr < 0.025);
    CHECK_NEAR(r.elevation_deg, 39.888378, 0.01);
    CHECK_NEAR(r.azimuth_deg, p.azimuth_deg, 1e-12); /* refraction does not move azimuth */
}

static void test_usno_seasons(void)
{
    /* [USNO] 2024 March equinox: apparent declination crosses 0. It changes by
     * ~0.016 deg/hour there, so a time given to the minute pins it to ~3e-4. */
    atmos_sun_position p = sun_at("2024-03-20T03:06:00Z", 0, 0, 0);
    CHECK_NEAR(p.declination_deg, 0.0, 0.01);
    CHECK_NEAR(p.right_ascension_deg < 180 ? p.right_ascension_deg : p.right_ascension_deg - 360,
               0.0, 0.02); /* alpha = 0 at the March equinox */
    /* [USNO] 2024 June solstice: declination reaches the obliquity, ~23.44 deg
     * ("as far north as it goes, 23.44 deg"), and is a maximum. */
    p = sun_at("2024-06-20T20:51:00Z", 0, 0, 0);
    CHECK_NEAR(p.declination_deg, 23.44, 0.01);
    CHECK_NEAR(p.right_ascension_deg, 90.0, 0.02);
    atmos_sun_position before = sun_at("2024-06-18T20:51:00Z", 0, 0, 0);
    atmos_sun_position after = sun_at("2024-06-22T20:51:00Z", 0, 0, 0);
    CHECK(p.declination_deg > before.declination_deg && p.declination_deg > after.declination_deg);
}

static void test_declination_over_year(void)
{
    double dmin = 90, dmax = -90;
    int ok = 1;
    for (int doy = 0; doy < 366; doy++) {
        atmos_utc_time t = { 2025, 1, 1, 0, 0, 0.0 };
        /* Walk the days with a simple month table (2025 is not a leap year). */
        static const int dim[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
        int d = doy % 365, m = 0;
        while (d >= dim[m]) d -= dim[m++];
        t.month = m + 1;
        t.day = d + 1;
        for (int h = 0; h < 24; h += 6) {
            t.hour = h;
            atmos_sun_position p;
            if (atmos_sun_position_compute(NULL, &t, 45, 10, 1, &p) != ATMOS_OK || !finite_position(&p))
                ok = 0;
            if (p.declination_deg < dmin) dmin = p.declination_deg;
            if (p.declination_deg > dmax) dmax = p.declination_deg;
        }
    }
    CHECK(ok);
    CHECK(dmax <= 23.45 && dmin >= -23.45);
    CHECK(dmax > 23.42 && dmin < -23.42); /* and it does reach the tropics */
}

/* UTC instant of local apparent noon at longitude lon on 2025-mm-dd: hour angle
 * zero when UT minutes = 720 - 4 lon - EoT; two fixed-point steps converge. */
static atmos_utc_time solar_noon(int month, int day, double lat, double lon)
{
    atmos_utc_time t = { 2025, month, day, 12, 0, 0.0 };
    for (int it = 0; it < 3; it++) {
        atmos_sun_position p;
        atmos_sun_position_compute(NULL, &t, lat, lon, 0, &p);
        double m = 720.0 - 4.0 * lon - p.equation_of_time_min;
        if (m < 0) m += 1440; /* stay on a valid time; the date shifts by a day at most */
        if (m >= 1440) m -= 1440;
        t.hour = (int)(m / 60.0);
        t.minute = (int)(m - t.hour * 60.0);
        t.second = (m - t.hour * 60.0 - t.minute) * 60.0;
        if (t.second >= 60.0) t.second = 59.999;
    }
    return t;
}

static void test_solar_noon(void)
{
    const double lats[] = { 40.0, -33.9, 0.0, 65.0, -80.0, 10.0 };
    const double lons[] = { -105.0, 151.2, 30.0, -20.0, 166.7, 0.0 };
    const int months[] = { 6, 12, 3, 9, 1, 6 };
    for (int i = 0; i < 6; i++) {
        atmos_utc_time t = solar_noon(months[i], 15, lats[i], lons[i]);
        atmos_sun_position p;
        CHECK_OK(atmos_sun_position_compute(NULL, &t, lats[i], lons[i], 0, &p));
        /* Upper culmination: e = 90 - |phi - delta| (Meeus ch. 13, H = 0). */
        CHECK_NEAR(p.geometric_elevation_deg, 90.0 - fabs(lats[i] - p.declination_deg), 0.01);
        /* The sun is due south when we are north of it, due north otherwise. */
        double expect_az = lats[i] > p.declination_deg ? 180.0 : 0.0;
        double daz = fabs(p.azimuth_deg - expect_az);
        if (daz > 180) daz = 360 - daz;
        CHECK_MSG(daz < 0.1, "lat %g: noon azimuth %g, expected %g", lats[i], p.azimuth_deg, expect_az);
    }

    /* Equinox at the equator at solar noon: sun within a hair of the zenith.
     * Choose the longitude where apparent noon falls at the [USNO] equinox
     * instant 03:06 UTC. Azimuth is ill-defined there but must be finite. */
    atmos_sun_position e = sun_at("2024-03-20T03:06:00Z", 0, 0, 0);
    double lon = (720.0 - 186.0 - e.equation_of_time_min) / 4.0;
    atmos_sun_position z = sun_at("2024-03-20T03:06:00Z", 0, lon, 0);
    CHECK(z.geometric_elevation_deg > 89.99);
    CHECK(finite_position(&z));
    atmos_sun_position zr = sun_at("2024-03-20T03:06:00Z", 0, lon, 1);
    CHECK(finite_position(&zr));
    CHECK_NEAR(zr.elevation_deg, z.geometric_elevation_deg, 1e-9); /* no refraction at zenith */

    /* Sun exactly overhead (latitude = declination at apparent noon). */
    atmos_utc_time t = solar_noon(6, 21, 23.4, 0.0);
    atmos_sun_position p;
    CHECK_OK(atmos_sun_position_compute(NULL, &t, 23.4, 0.0, 1, &p));
    CHECK_OK(atmos_sun_position_compute(NULL, &t, p.declination_deg, 0.0, 1, &p));
    CHECK(finite_position(&p));
    CHECK(p.geometric_elevation_deg > 89.99);
}

static void test_refraction(void)
{
    /* Scan a day at 40 N for the geometric sunset and compare refracted and
     * geometric elevation there: ~0.5 deg at the horizon (NOAA: 1735" = 0.48
     * deg at e = 0; the classical horizontal refraction is ~34'). */
    atmos_utc_time t = { 2025, 6, 15, 0, 0, 0.0 };
    double best = 1e9, refr_at_best = 0;
    int ok = 1;
    for (int m = 0; m < 1440; m++) {
        t.hour = m / 60;
        t.minute = m % 60;
        atmos_sun_position a, g;
        if (atmos_sun_position_compute(NULL, &t, 40.0, -105.0, 1, &a) != ATMOS_OK ||
            atmos_sun_position_compute(NULL, &t, 40.0, -105.0, 0, &g) != ATMOS_OK ||
            !finite_position(&a) || !finite_position(&g))
            ok = 0;
        double refr = a.elevation_deg - g.elevation_deg;
        if (refr < 0) ok = 0; /* refraction always raises the sun */
        if (fabs(g.elevation_deg) < best) {
            best = fabs(g.elevation_deg);
            refr_at_best = refr;
        }
    }
    CHECK(ok);
    CHECK(best < 0.3);
    CHECK_MSG(refr_at_best > 0.4 && refr_at_best < 0.6, "horizon refraction %g deg", refr_at_best);

    /* Refraction falls as the sun climbs: scan elevations via latitude at a
     * fixed instant (declination fixed, hour angle fixed). NOAA's pieces meet
     * with small steps (~2" at 5 deg, ~5" at 85 deg), hence the tolerance. */
    double prev_refr = 1e9;
    int monotonic = 1;
    atmos_utc_time noon = solar_noon(3, 20, 0.0, 0.0);
    for (double lat = 89.0; lat >= 0.0; lat -= 1.0) {
        atmos_sun_position a, g;
        atmos_sun_position_compute(NULL, &noon, lat, 0.0, 1, &a);
        atmos_sun_position_compute(NULL, &noon, lat, 0.0, 0, &g);
        double refr = a.elevation_deg - g.elevation_deg;
        if (refr > prev_refr + 1e-3) monotonic = 0;
        prev_refr = refr;
    }
    CHECK(monotonic);
    CHECK(prev_refr < 1e-9); /* near the zenith (lat 0 at equinox noon) */
}

static void test_poles_and_dateline(void)
{
    const char *times[] = { "2025-03-20T09:01:00Z", "2025-06-21T00:00:00Z", "2025-12-21T15:03:00Z",
                            "2025-09-22T18:19:00Z" };
    for (int i = 0; i < 4; i++) {
        for (int s = -1; s <= 1; s += 2) {
            for (int r = 0; r <= 1; r++) {
                atmos_sun_position p = sun_at(times[i], 90.0 * s, 0.0, r);
                CHECK_MSG(finite_position(&p), "pole %+d at %s", s, times[i]);
                /* At a pole the elevation is +-declination (sin e = sin phi sin delta). */
                CHECK_NEAR(p.geometric_elevation_deg, s * p.declination_deg, 1e-6);
            }
        }
        /* The dateline: -180 and +180 are the same meridian. */
        atmos_sun_position w = sun_at(times[i], 12.5, -180.0, 1);
        atmos_sun_position e = sun_at(times[i], 12.5, 180.0, 1);
        CHECK(finite_position(&w) && finite_position(&e));
        CHECK_NEAR(w.elevation_deg, e.elevation_deg, 1e-9);
        CHECK_NEAR(w.azimuth_deg, e.azimuth_deg, 1e-9);
    }
    /* Range ends of the calendar. */
    atmos_sun_position a = sun_at("1800-01-01T00:00:00Z", -90.0, -180.0, 1);
    atmos_sun_position b = sun_at("2200-12-31T23:59:59.999Z", 90.0, 180.0, 1);
    CHECK(finite_position(&a) && finite_position(&b));
}

static void test_invalid_position_args(void)
{
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_utc_time t = parse("2025-06-21T12:00:00Z");
    atmos_sun_position p;
    const double bad_lat[] = { 90.0001, -91.0, NAN, INFINITY };
    for (int i = 0; i < 4; i++) {
        CHECK(atmos_sun_position_compute(ctx, &t, bad_lat[i], 0, 1, &p) == ATMOS_E_INVALID_ARG);
        CHECK(strstr(atmos_context_error(ctx), "latitude") && strstr(atmos_context_error(ctx), "[-90, 90]"));
    }
    const double bad_lon[] = { 180.5, -181.0, NAN, -INFINITY };
    for (int i = 0; i < 4; i++) {
        CHECK(atmos_sun_position_compute(ctx, &t, 0, bad_lon[i], 1, &p) == ATMOS_E_INVALID_ARG);
        CHECK(strstr(atmos_context_error(ctx), "longitude") && strstr(atmos_context_error(ctx), "[-180, 180]"));
    }
    atmos_utc_time y = t;
    y.year = 1799;
    CHECK(atmos_sun_position_compute(ctx, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "[1800, 2200]") != NULL);
    y.year = 2201;
    CHECK(atmos_sun_position_compute(ctx, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    y = t; y.month = 13;
    CHECK(atmos_sun_position_compute(ctx, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    y = t; y.month = 4; y.day = 31;
    CHECK(atmos_sun_position_compute(ctx, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    y = t; y.hour = 24;
    CHECK(atmos_sun_position_compute(ctx, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    y = t; y.minute = -1;
    CHECK(atmos_sun_position_compute(ctx, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    y = t; y.second = 60.0;
    CHECK(atmos_sun_position_compute(ctx, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    y = t; y.second = NAN;
    CHECK(atmos_sun_position_compute(ctx, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_sun_position_compute(ctx, NULL, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_sun_position_compute(ctx, &t, 0, 0, 1, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_sun_position_compute(NULL, &y, 0, 0, 1, &p) == ATMOS_E_INVALID_ARG); /* NULL ctx */
    atmos_context_destroy(ctx);
}

static int same_time(const atmos_utc_time *t, int y, int mo, int d, int h, int mi, double s)
{
    return t->year == y && t->month == mo && t->day == d && t->hour == h && t->minute == mi &&
           fabs(t->second - s) < 1e-9;
}

static void test_parse(void)
{
    atmos_utc_time t;
    t = parse("2026-06-21T12:00:00Z");
    CHECK(same_time(&t, 2026, 6, 21, 12, 0, 0));
    t = parse("2026-06-21T12:34Z"); /* seconds optional */
    CHECK(same_time(&t, 2026, 6, 21, 12, 34, 0));
    t = parse("2003-10-17T19:30:30.25Z");
    CHECK(same_time(&t, 2003, 10, 17, 19, 30, 30.25));
    t = parse("2003-10-17T12:30:30-07:00");
    CHECK(same_time(&t, 2003, 10, 17, 19, 30, 30));
    /* Rollovers through day, month and year, in both directions. */
    t = parse("2026-01-01T01:00:00+02:00");
    CHECK(same_time(&t, 2025, 12, 31, 23, 0, 0));
    t = parse("2025-12-31T23:30-01:00");
    CHECK(same_time(&t, 2026, 1, 1, 0, 30, 0));
    t = parse("2024-02-28T23:00-02:00"); /* into a leap day */
    CHECK(same_time(&t, 2024, 2, 29, 1, 0, 0));
    t = parse("2023-02-28T23:00-02:00"); /* no leap day in 2023 */
    CHECK(same_time(&t, 2023, 3, 1, 1, 0, 0));
    t = parse("2023-03-01T00:30+01:00");
    CHECK(same_time(&t, 2023, 2, 28, 23, 30, 0));
    t = parse("2024-03-01T00:30+05:45");
    CHECK(same_time(&t, 2024, 2, 29, 18, 45, 0));
    t = parse("2025-06-30T20:00-05:00");
    CHECK(same_time(&t, 2025, 7, 1, 1, 0, 0));
    t = parse("2000-02-29T00:00Z"); /* divisible by 400: leap */
    CHECK(same_time(&t, 2000, 2, 29, 0, 0, 0));
    t = parse("2025-06-21T12:00:00-00:00");
    CHECK(same_time(&t, 2025, 6, 21, 12, 0, 0));

    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    const char *bad[] = {
        "2026-02-30T00:00:00Z",     /* impossible date */
        "2026-13-01T00:00Z",        /* month 13 */
        "2026-06-21 12:00",         /* space instead of T, no zone */
        "2026-06-21T12:00",         /* missing zone */
        "garbage",
        "",
        "1900-02-29T00:00Z",        /* divisible by 100, not 400: no leap day */
        "2023-02-29T00:00Z",
        "2026-04-31T00:00Z",
        "2026-00-10T00:00Z",
        "2026-01-00T00:00Z",
        "2026-06-21T24:00Z",
        "2026-06-21T12:60Z",
        "2026-06-21T12:00:60Z",
        "2026-06-21T12:00:00.Z",
        "2026-06-21T12:00:00.1234567891Z",
        "2026-06-21T12:00:00Zjunk",
        "2026-06-21T12:00:00z",
        "2026-06-21T12:00:00+0200",
        "2026-06-21T12:00:00+02",
        "2026-06-21T12:00:00+24:00",
        "2026-06-21T12:00:00+02:60",
        "2026-6-21T12:00Z",
        "26-06-21T12:00Z",
        "2026-06-21T1:00Z",
        "-2026-06-21T12:00Z",
        "2026-06-21T12:00:00Z ",
        " 2026-06-21T12:00:00Z",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        atmos_status st = atmos_parse_utc_time(ctx, bad[i], &t);
        CHECK_MSG(st == ATMOS_E_INVALID_ARG, "'%s' was accepted", bad[i]);
        CHECK_MSG(atmos_context_error(ctx)[0] != '\0', "'%s': no message", bad[i]);
    }
    CHECK(atmos_parse_utc_time(ctx, "2026-02-30T00:00:00Z", &t) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "day 30") && strstr(atmos_context_error(ctx), "[1, 28]"));
    CHECK(atmos_parse_utc_time(ctx, "2026-06-21T12:00", &t) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "time zone") != NULL);
    CHECK(atmos_parse_utc_time(ctx, NULL, &t) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_parse_utc_time(ctx, "2026-06-21T12:00Z", NULL) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_parse_utc_time(NULL, "garbage", &t) == ATMOS_E_INVALID_ARG);
    atmos_context_destroy(ctx);
}

int main(void)
{
    test_meeus();
    test_nrel_spa();
    test_usno_seasons();
    test_declination_over_year();
    test_solar_noon();
    test_refraction();
    test_poles_and_dateline();
    test_invalid_position_args();
    test_parse();
    return test_summary("test_sunpos");
}
