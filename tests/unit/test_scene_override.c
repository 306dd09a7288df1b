/* Scene keys set from outside the file (atmos_scene_parse_with, atmos render -D): dotted
 * paths and JSON pointers, values as JSON or bare words, objects made on the way, array
 * items replaced, and every value read with the file's rules. */
#include "atmos/atmos.h"
#include "test.h"

#include <string.h>

static atmos_context *ctx;

static atmos_status parse(const char *json, const char *const *ov, int n, atmos_scene *s)
{
    return atmos_scene_parse_with(ctx, json, strlen(json), "t.json", ov, n, s);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_scene s;
    /* dotted and pointer paths, numbers, arrays, a bare word; objects made as needed */
    const char *a[] = {"camera.fov_deg=35", "/image/width=64", "name=plain word", "camera.position_m=[1, 900, 2]",
                       "camera.position_m.1=950"};
    CHECK_OK(parse("{\"image\": {\"height\": 32}}", a, 5, &s));
    CHECK(s.camera.fov_deg == 35 && s.width == 64 && s.height == 32 && !strcmp(s.name, "plain word"));
    CHECK(s.camera.position[0] == 1 && s.camera.position[1] == 950 && s.camera.position[2] == 2);
    CHECK(s.camera_given);
    /* a later override wins over an earlier one and over the file */
    const char *b[] = {"image.width=10", "image.width=20"};
    CHECK_OK(parse("{\"image\": {\"width\": 5}}", b, 2, &s));
    CHECK(s.width == 20);
    /* "~1" is "/" in a pointer token: the key "a/b" (unknown), named back as "/a~1b" */
    const char *c[] = {"/a~1b=1"};
    CHECK(parse("{}", c, 1, &s) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "/a~1b: unknown key") != NULL);
    /* the file's rules and JSON pointers in the messages */
    const char *d[] = {"camera.fov_deg=500"};
    CHECK(parse("{}", d, 1, &s) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "/camera/fov_deg") != NULL);
    /* paths that lead nowhere: through a number, past an array's end, an empty token */
    const char *e[] = {"image.width.x=1", "camera.position_m.7=1", "camera..fov_deg=1", "=1", "nothing"};
    for (int i = 0; i < 5; i++) CHECK_MSG(parse("{}", &e[i], 1, &s) == ATMOS_E_INVALID_ARG, "override %s", e[i]);
    /* no overrides: the plain parse */
    CHECK_OK(parse("{\"name\": \"x\"}", NULL, 0, &s));
    CHECK(!strcmp(s.name, "x") && !s.camera_given);
    /* the fog's density is an extinction or a visibility: an override of one replaces the other */
    const char *f[] = {"fog.visibility_m=391.2"}, *g[] = {"fog.extinction_per_m=0.02"};
    CHECK_OK(parse("{\"fog\": {\"extinction_per_m\": 0.05}}", f, 1, &s));
    CHECK(fabs(s.fog.extinction_per_m - 0.01) < 1e-12 && s.fog.visibility_m == 391.2);
    CHECK_OK(parse("{\"fog\": {\"visibility_m\": 100}}", g, 1, &s));
    CHECK(s.fog.extinction_per_m == 0.02 && s.fog.visibility_m == 0);
    /* two overrides naming volume sources of two kinds: refused, as the two keys in a file are
     * (the last no longer drops the first without a word); one kind twice: the last holds */
    const char *h[] = {"volume.file=x.vdb", "volume.generate=cumulus"},
               *i[] = {"volume={\"file\": \"x.vdb\"}", "/volume/simulate={\"preset\": \"stratocumulus\"}"},
               *j[] = {"volume.generate=cumulus", "volume.generate=storm"};
    CHECK(parse("{}", h, 2, &s) == ATMOS_E_INVALID_ARG);
    CHECK_MSG(strstr(atmos_context_error(ctx), "-D volume.file=x.vdb and -D volume.generate=cumulus: /volume: \"file\" "
                                               "and \"generate\" exclude each other") != NULL,
              "%s", atmos_context_error(ctx));
    CHECK(parse("{}", i, 2, &s) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "\"file\" and \"simulate\" exclude each other") != NULL);
    CHECK_OK(parse("{\"volume\": {\"file\": \"d.vdb\"}}", j, 2, &s));
    CHECK(!strcmp(s.volume.source, "generate:storm"));
    /* an error at /volume that a source override causes names the override, not the file */
    const char *k[] = {"volume.generate=cumulus", "volume.time_index=2"};
    CHECK(parse("{\"volume\": {\"file\": \"d.vdb\"}}", k, 2, &s) == ATMOS_E_INVALID_ARG);
    CHECK_MSG(!strncmp(atmos_context_error(ctx), "-D volume.generate=cumulus (on t.json): /volume: \"time_index\"", 60),
              "%s", atmos_context_error(ctx));
    /* the whole value is JSON or it is a bare word: text after a JSON value makes the value a
     * string, not the JSON before it (a time is not the number 2026, 30abc is not 30) */
    const char *l[] = {"sun.time=2026-06-21T12:00:00Z", "sun.latitude_deg=40 ", "sun.longitude_deg=-105"};
    CHECK_MSG(parse("{}", l, 3, &s) == ATMOS_OK, "%s", atmos_context_error(ctx));
    CHECK(s.sun.from_time && s.sun.latitude_deg == 40 && s.sun.longitude_deg == -105);
    const char *m[] = {"name=2026abc"};
    CHECK_OK(parse("{}", m, 1, &s));
    CHECK(!strcmp(s.name, "2026abc"));
    const char *bad_numbers[] = {"camera.fov_deg=30abc", "camera.fov_deg=30, 50", "/image/width=64 px"};
    for (int q = 0; q < 3; q++) {
        CHECK_MSG(parse("{}", &bad_numbers[q], 1, &s) == ATMOS_E_INVALID_ARG, "override %s", bad_numbers[q]);
        CHECK_MSG(strstr(atmos_context_error(ctx), "expected") != NULL, "%s", atmos_context_error(ctx));
    }
    const char *v[] = {"volume={\"generate\": \"cumulus\"} x"};
    CHECK(parse("{}", v, 1, &s) == ATMOS_E_INVALID_ARG);
    atmos_context_destroy(ctx);
    return test_summary("test_scene_override");
}
