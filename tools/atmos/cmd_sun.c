/* `atmos sun`: where the sun is for a UTC instant and a place.
 * Turns the options into atmos_parse_utc_time + atmos_sun_position_compute and
 * prints the result; the astronomy lives in src/sky/sunpos.c. */
#include "cli.h"

#include <stdio.h>
#include <string.h>

static const char *const SUN_CMD = "sun";

static void sun_usage(FILE *f)
{
    fputs("Usage: atmos sun --time TIME --lat DEG --lon DEG [--no-refraction] [--json]\n"
          "\n"
          "Prints the sun's position (NOAA solar calculator algorithm, after Meeus).\n"
          "\n"
          "  --time TIME       ISO 8601 instant, YYYY-MM-DDTHH:MM[:SS[.fff]] followed by Z\n"
          "                    or an offset +HH:MM/-HH:MM (years 1800-2200)\n"
          "  --lat DEG         latitude, degrees north, in [-90, 90]\n"
          "  --lon DEG         longitude, degrees east, in [-180, 180]\n"
          "  --no-refraction   report the geometric elevation (no atmospheric refraction)\n"
          "  --json            print one JSON object: elevation_deg, azimuth_deg,\n"
          "                    declination_deg, equation_of_time_min\n"
          "  -h, --help        show this help\n"
          "\n"
          "Azimuth is measured clockwise from north (east = 90).\n",
          f);
    fputs(CLI_HELP_EXIT, f);
}

int cli_cmd_sun(int argc, char **argv)
{
    const char *time_text = NULL, *lat_text = NULL, *lon_text = NULL;
    int refraction = 1, json = 0;

    /* Hand-rolled parsing: eight options do not need getopt_long's global state. */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            sun_usage(stdout);
            return CLI_EXIT_OK;
        } else if (strcmp(a, "--no-refraction") == 0) {
            refraction = 0;
        } else if (strcmp(a, "--json") == 0) {
            json = 1;
        } else if (cli_take_value(argc, argv, &i, "--time", &v)) {
            if (!v) return cli_usage_error(SUN_CMD, "--time: missing value");
            time_text = v;
        } else if (cli_take_value(argc, argv, &i, "--lat", &v)) {
            if (!v) return cli_usage_error(SUN_CMD, "--lat: missing value");
            lat_text = v;
        } else if (cli_take_value(argc, argv, &i, "--lon", &v)) {
            if (!v) return cli_usage_error(SUN_CMD, "--lon: missing value");
            lon_text = v;
        } else if (a[0] == '-') {
            return cli_usage_error(SUN_CMD, "unknown option '%s'", a);
        } else {
            return cli_usage_error(SUN_CMD, "unexpected argument '%s'", a);
        }
    }
    if (!time_text) return cli_usage_error(SUN_CMD, "--time is required");
    if (!lat_text) return cli_usage_error(SUN_CMD, "--lat is required");
    if (!lon_text) return cli_usage_error(SUN_CMD, "--lon is required");

    double lat, lon;
    if (!cli_parse_double(SUN_CMD, "--lat", lat_text, &lat)) return CLI_EXIT_USAGE;
    if (!cli_parse_double(SUN_CMD, "--lon", lon_text, &lon)) return CLI_EXIT_USAGE;

    atmos_context *ctx = cli_context(1, 1);
    if (!ctx) return cli_runtime_error(SUN_CMD, NULL, ATMOS_E_NOMEM);

    int rc = CLI_EXIT_OK;
    atmos_utc_time t;
    atmos_sun_position pos;
    atmos_status st = atmos_parse_utc_time(ctx, time_text, &t);
    if (st == ATMOS_OK) st = atmos_sun_position_compute(ctx, &t, lat, lon, refraction, &pos);
    if (st == ATMOS_E_INVALID_ARG) {
        /* Every input here came from an option, so a rejected value is a usage
         * error (exit 2) carrying the library's message, which names the range. */
        rc = cli_usage_error(SUN_CMD, "%s", atmos_context_error(ctx));
    } else if (st != ATMOS_OK) {
        rc = cli_runtime_error(SUN_CMD, ctx, st);
    } else if (json) {
        printf("{\"elevation_deg\": %.9g, \"azimuth_deg\": %.9g, \"declination_deg\": %.9g, "
               "\"equation_of_time_min\": %.9g}\n",
               pos.elevation_deg, pos.azimuth_deg, pos.declination_deg, pos.equation_of_time_min);
    } else {
        printf("time (UTC):        %04d-%02d-%02dT%02d:%02d:%06.3fZ\n", t.year, t.month, t.day,
               t.hour, t.minute, t.second);
        printf("elevation:         %.4f deg (%s)\n", pos.elevation_deg,
               refraction ? "with refraction" : "geometric");
        printf("azimuth:           %.4f deg (clockwise from north)\n", pos.azimuth_deg);
        printf("declination:       %.4f deg\n", pos.declination_deg);
        printf("equation of time:  %.2f min\n", pos.equation_of_time_min);
    }
    if (fflush(stdout) != 0 && rc == CLI_EXIT_OK) {
        fprintf(stderr, "atmos %s: cannot write to standard output\n", SUN_CMD);
        rc = CLI_EXIT_RUNTIME;
    }
    atmos_context_destroy(ctx);
    return rc;
}
