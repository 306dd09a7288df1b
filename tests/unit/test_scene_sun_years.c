/* A scene's sun given by time, and its animation's time_end, outside the years the solar position
 * algorithm takes (ATMOS_SUN_YEAR_MIN..MAX, 1800-2200: atmos_sun_position_compute refuses the
 * others) are refused when the scene is read or validated, naming the scene and the key, as any
 * value out of range. They were accepted there, and the render failed later with "sun position:
 * year 2300 out of range", naming neither the file nor the key. The years at the ends are taken. */
#include "test.h"

#include <stdio.h>
#include <string.h>

/* Parses a scene whose sun is at time `sun` and whose animation (when `end`) ends at `end`. */
static atmos_status parse(atmos_context *ctx, const char *sun, const char *end, atmos_scene *out)
{
    char json[512];
    snprintf(json, sizeof json,
             "{\"sun\": {\"time\": \"%s\", \"latitude_deg\": 48, \"longitude_deg\": 11}%s%s%s}", sun,
             end ? ", \"animation\": {\"frames\": 3, \"time_end\": \"" : "", end ? end : "", end ? "\"}" : "");
    return atmos_scene_parse(ctx, json, strlen(json), "years.json", out);
}

static int says(atmos_context *ctx, const char *what)
{
    const char *m = atmos_context_error(ctx);
    const int ok = strstr(m, what) != NULL;
    if (!ok) printf("  expected \"%s\" in \"%s\"\n", what, m);
    return ok;
}

int main(void)
{
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    CHECK(ATMOS_SUN_YEAR_MIN == 1800 && ATMOS_SUN_YEAR_MAX == 2200);
    atmos_scene s;
    const char *bad[] = {"1799-12-31T23:59:59Z", "2201-01-01T00:00:00Z", "0001-01-01T00:00:00Z", "9999-06-21T12:00:00Z"};
    for (int i = 0; i < 4; i++) {
        CHECK(parse(ctx, bad[i], NULL, &s) == ATMOS_E_INVALID_ARG);
        CHECK(says(ctx, "years.json: /sun/time:") && says(ctx, "[1800, 2200]"));
        CHECK(parse(ctx, "2026-06-21T12:00:00Z", bad[i], &s) == ATMOS_E_INVALID_ARG);
        CHECK(says(ctx, "years.json: /animation/time_end:") && says(ctx, "[1800, 2200]"));
    }
    /* the ends of the range, and a scene rendered from them */
    CHECK_OK(parse(ctx, "1800-01-01T00:00:00Z", "2200-12-31T23:59:59Z", &s));
    atmos_sun_position p;
    CHECK_OK(atmos_sun_position_compute(ctx, &s.sun.time, 48, 11, 1, &p));
    CHECK_OK(atmos_sun_position_compute(ctx, &s.animation.time_end, 48, 11, 1, &p));
    /* a scene made in code: atmos_scene_validate says the same */
    atmos_scene_defaults(&s);
    s.sun.from_time = 1, s.sun.latitude_deg = 40, s.sun.longitude_deg = -105;
    CHECK_OK(atmos_parse_utc_time(ctx, "2300-06-21T19:00:00Z", &s.sun.time));
    CHECK(atmos_scene_validate(ctx, &s, "mine") == ATMOS_E_INVALID_ARG);
    CHECK(says(ctx, "mine: /sun/time:") && says(ctx, "year 2300"));
    atmos_image *img = NULL;
    CHECK(atmos_render_scene(ctx, &s, NULL, &img, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(img == NULL && says(ctx, "/sun/time"));
    atmos_context_destroy(ctx);
    return test_summary("test_scene_sun_years");
}
