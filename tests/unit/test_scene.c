/* Scene files: defaults, a full scene read back value by value, absent keys,
 * type-dependent defaults, and a table of bad scenes each of which must fail with
 * the right status and a message naming the right JSON pointer (and range).
 */
#define _POSIX_C_SOURCE 200809L /* opendir */
#include "atmos/atmos.h"
#include "test.h"

#include <dirent.h>
#include <stdlib.h>

static atmos_context *ctx;

static atmos_status parse(const char *json, atmos_scene *s)
{
    return atmos_scene_parse(ctx, json, strlen(json), "scene.json", s);
}

static int contains(const char *hay, const char *needle) { return needle == NULL || strstr(hay, needle) != NULL; }

/* |a - b| for 3-vectors, max norm. */
static double vdiff(const double a[3], const double b[3])
{
    double d = 0;
    for (int i = 0; i < 3; i++) d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

static void test_defaults(void)
{
    atmos_scene s;
    atmos_scene_defaults(&s);
    CHECK(strcmp(s.name, "default") == 0);
    CHECK(s.width == 1280 && s.height == 720 && s.samples_per_pixel == 1);
    CHECK(s.camera.type == ATMOS_CAMERA_PINHOLE);
    double pos[3] = {0, 1000, 0}, up[3] = {0, 1, 0}, dir[3];
    CHECK(vdiff(s.camera.position, pos) == 0);
    CHECK(vdiff(s.camera.up, up) == 0);
    CHECK_NEAR(s.camera.fov_deg, 60, 0);
    /* look_at = position + 1000 m towards elevation 1°, azimuth 200° (SSW: x < 0, z < 0 is north so z > 0). */
    atmos_direction_from_angles(1, 200, dir);
    double look[3] = {1000 * dir[0], 1000 + 1000 * dir[1], 1000 * dir[2]};
    CHECK(vdiff(s.camera.look_at, look) < 1e-9);
    CHECK(s.camera.look_at[0] < 0 && s.camera.look_at[2] > 0);
    CHECK_NEAR(s.camera.look_at[1] - 1000, 1000 * sin(1 * 3.14159265358979323846 / 180), 1e-9);
    CHECK(s.sun.from_time == 0 && s.sun.refraction == 1);
    CHECK_NEAR(s.sun.elevation_deg, 22, 0);
    CHECK_NEAR(s.sun.azimuth_deg, 235, 0);
    CHECK_REL(s.atmosphere.beta_sl_550, 1.35e-5, 1e-12);
    CHECK_NEAR(s.atmosphere.scale_height_m, 8000, 0);
    CHECK_NEAR(s.atmosphere.ground_albedo, 0.1, 1e-15);
    CHECK_NEAR(s.atmosphere.sun_diameter_deg, 0.5, 0);
    CHECK_NEAR(s.atmosphere.sun_scale, 1, 0);
    CHECK(s.atmosphere.hide_sun_disk == 0);
    CHECK(s.wavelengths == ATMOS_WAVELENGTHS_RGB && s.spectral_samples == 16);
    CHECK(s.tonemap.manual_exposure == 0 && s.tonemap.exposure_ev == 0 && s.tonemap.curve == ATMOS_TONE_FILMIC);
    CHECK(s.png_bits == 8 && s.exr_half == 0);
    CHECK_OK(atmos_scene_validate(ctx, &s, "defaults"));
    /* An empty object is the default scene, bit for bit. */
    atmos_scene p;
    CHECK_OK(parse("{}", &p));
    CHECK(memcmp(&p, &s, sizeof s) == 0);
}

static const char *full_scene =
    "{\n"
    "  \"_comment\": \"every key given\",\n"
    "  \"name\": \"clear noon sky\",\n"
    "  \"image\": {\"width\": 1024, \"height\": 512, \"samples_per_pixel\": 4},\n"
    "  \"camera\": {\"type\": \"pinhole\", \"position_m\": [10, 1500, -20], \"look_at_m\": [110, 1600, -20.5],\n"
    "             \"up\": [0, 1, 0.25], \"fov_deg\": 75.5, \"_note\": {\"nested\": [1, 2, {\"x\": null}]}},\n"
    "  \"sun\": {\"elevation_deg\": -4.5, \"azimuth_deg\": 359.75},\n"
    "  \"atmosphere\": {\"beta_sl_550_per_m\": 2e-5, \"scale_height_m\": 7994, \"ground_albedo\": 0.3,\n"
    "                 \"sun_diameter_deg\": 0.53, \"sun_scale\": 2.5, \"sun_disk\": false},\n"
    "  \"wavelengths\": {\"mode\": \"spectral\", \"samples\": 32},\n"
    "  \"output\": {\"exposure\": 14.5, \"tone_curve\": \"reinhard\", \"png_bits\": 16, \"exr_pixel\": \"half\"},\n"
    "  \"renderer\": \"sky\"\n"
    "}\n";

static void test_full_scene(void)
{
    atmos_scene s;
    CHECK_OK(parse(full_scene, &s));
    CHECK(strcmp(s.name, "clear noon sky") == 0);
    CHECK(s.width == 1024 && s.height == 512 && s.samples_per_pixel == 4);
    double pos[3] = {10, 1500, -20}, look[3] = {110, 1600, -20.5}, up[3] = {0, 1, 0.25};
    CHECK(s.camera.type == ATMOS_CAMERA_PINHOLE);
    CHECK(vdiff(s.camera.position, pos) == 0);
    CHECK(vdiff(s.camera.look_at, look) == 0);
    CHECK(vdiff(s.camera.up, up) == 0);
    CHECK(s.camera.fov_deg == 75.5);
    CHECK(s.sun.from_time == 0 && s.sun.elevation_deg == -4.5 && s.sun.azimuth_deg == 359.75);
    CHECK(s.atmosphere.beta_sl_550 == 2e-5 && s.atmosphere.scale_height_m == 7994);
    CHECK(s.atmosphere.ground_albedo == 0.3 && s.atmosphere.sun_diameter_deg == 0.53);
    CHECK(s.atmosphere.sun_scale == 2.5 && s.atmosphere.hide_sun_disk == 1);
    CHECK(s.wavelengths == ATMOS_WAVELENGTHS_SPECTRAL && s.spectral_samples == 32);
    CHECK(s.tonemap.manual_exposure == 1 && s.tonemap.exposure_ev == 14.5);
    CHECK(s.tonemap.curve == ATMOS_TONE_REINHARD);
    CHECK(s.png_bits == 16 && s.exr_half == 1);
    CHECK_OK(atmos_scene_validate(ctx, &s, "full"));

    /* The other spellings of the enumerations. */
    CHECK_OK(parse("{\"output\": {\"exposure\": \"auto\", \"exposure_compensation_ev\": -1.5,"
                   " \"tone_curve\": \"clamp\", \"png_bits\": 8, \"exr_pixel\": \"float\"},"
                   " \"wavelengths\": {\"mode\": \"rgb\"}, \"atmosphere\": {\"sun_disk\": true}}", &s));
    CHECK(s.tonemap.manual_exposure == 0 && s.tonemap.exposure_ev == -1.5 && s.tonemap.curve == ATMOS_TONE_CLAMP);
    CHECK(s.png_bits == 8 && s.exr_half == 0 && s.wavelengths == ATMOS_WAVELENGTHS_RGB);
    CHECK(s.atmosphere.hide_sun_disk == 0);

    /* A sun given by time and place; the parse stores the parsed time. */
    CHECK_OK(parse("{\"sun\": {\"time\": \"2026-06-21T12:00:00Z\", \"latitude_deg\": 40,"
                   " \"longitude_deg\": -105, \"refraction\": false}}", &s));
    CHECK(s.sun.from_time == 1 && s.sun.refraction == 0);
    CHECK(s.sun.time.year == 2026 && s.sun.time.month == 6 && s.sun.time.day == 21);
    CHECK(s.sun.time.hour == 12 && s.sun.time.minute == 0 && s.sun.time.second == 0);
    CHECK(s.sun.latitude_deg == 40 && s.sun.longitude_deg == -105);
    CHECK_OK(atmos_scene_validate(ctx, &s, "time"));

    /* Boundaries that are inside their ranges. */
    CHECK_OK(parse("{\"image\": {\"width\": 16384, \"height\": 1, \"samples_per_pixel\": 256},"
                   " \"camera\": {\"position_m\": [0, 1000000, 0], \"fov_deg\": 179.999},"
                   " \"sun\": {\"elevation_deg\": 90, \"azimuth_deg\": 0},"
                   " \"atmosphere\": {\"beta_sl_550_per_m\": 0.01, \"scale_height_m\": 100, \"ground_albedo\": 1,"
                   " \"sun_diameter_deg\": 20, \"sun_scale\": 0},"
                   " \"wavelengths\": {\"samples\": 128}, \"output\": {\"exposure\": -20}}", &s));
    CHECK(s.width == 16384 && s.camera.position[1] == 1e6 && s.spectral_samples == 128);
    CHECK_OK(parse("{\"camera\": {\"type\": \"fisheye\", \"fov_deg\": 360}, \"output\": {\"exposure\": 40},"
                   " \"atmosphere\": {\"sun_scale\": 1e6, \"scale_height_m\": 1e5}}", &s));
    CHECK(s.camera.fov_deg == 360);
    CHECK_OK(parse("{\"wavelengths\": {\"samples\": 1}, \"sun\": {\"elevation_deg\": -90},"
                   " \"output\": {\"exposure_compensation_ev\": 20}, \"name\": \"\"}", &s));
    CHECK(s.tonemap.manual_exposure == 0 && s.tonemap.exposure_ev == 20 && s.name[0] == '\0');
    /* A name of exactly 127 bytes (UTF-8 counts bytes) fits. */
    char json[512], name[128];
    memset(name, 'n', 127);
    name[127] = '\0';
    snprintf(json, sizeof json, "{\"name\": \"%s\"}", name);
    CHECK_OK(parse(json, &s));
    CHECK(strcmp(s.name, name) == 0);
    CHECK_OK(parse("{\"name\": \"\xc3\xa9t\xc3\xa9 \\\"quoted\\\" \\u00e9\"}", &s));
    CHECK(strcmp(s.name, "\xc3\xa9t\xc3\xa9 \"quoted\" \xc3\xa9") == 0);
    /* A UTF-8 byte order mark and surrounding whitespace are allowed. */
    CHECK_OK(parse("\xef\xbb\xbf \r\n\t{\"name\": \"bom\"}\n\n", &s));
    CHECK(strcmp(s.name, "bom") == 0);
}

static void test_absent_keys(void)
{
    atmos_scene d, s;
    atmos_scene_defaults(&d);

    CHECK_OK(parse("{\"image\": {\"width\": 100}, \"_x\": [[[]]]}", &s));
    CHECK(s.width == 100 && s.height == 720 && s.samples_per_pixel == 1);
    s.width = d.width;
    CHECK(memcmp(&s, &d, sizeof s) == 0);

    /* The simulated volume's form (atmos_sim_desc's refine, detail, ice) */
    CHECK_OK(parse("{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\", \"refine\": 3, \"detail\": 0.5, "
                   "\"ice\": true}}}", &s));
    CHECK(s.volume.sim_refine == 3 && s.volume.sim_detail == 0.5 && s.volume.sim_ice == 1);

    /* Moving only the position keeps the default view direction. */
    CHECK_OK(parse("{\"camera\": {\"position_m\": [5, 300, 7]}}", &s));
    double moved[3];
    for (int i = 0; i < 3; i++) moved[i] = d.camera.look_at[i] - d.camera.position[i] + s.camera.position[i];
    CHECK(vdiff(s.camera.look_at, moved) < 1e-9);
    CHECK(s.camera.fov_deg == 60 && s.camera.up[1] == 1);

    /* view gives look_at = position + 1000 m * direction. */
    CHECK_OK(parse("{\"camera\": {\"view\": {\"elevation_deg\": 30, \"azimuth_deg\": 90}}}", &s));
    double dir[3];
    atmos_direction_from_angles(30, 90, dir);
    double look[3] = {1000 * dir[0], 1000 + 1000 * dir[1], 1000 * dir[2]};
    CHECK(vdiff(s.camera.look_at, look) < 1e-9);

    /* A fisheye without fov or view: 180°, zenith, up = north. */
    CHECK_OK(parse("{\"camera\": {\"type\": \"fisheye\"}}", &s));
    double zen[3] = {0, 2000, 0}, north[3] = {0, 0, -1};
    CHECK(s.camera.type == ATMOS_CAMERA_FISHEYE && s.camera.fov_deg == 180);
    CHECK(vdiff(s.camera.look_at, zen) < 1e-9);
    CHECK(vdiff(s.camera.up, north) == 0);
    /* ...but given values win, whatever the key order. */
    CHECK_OK(parse("{\"camera\": {\"fov_deg\": 220, \"view\": {\"elevation_deg\": 45, \"azimuth_deg\": 180},"
                   " \"type\": \"fisheye\"}}", &s));
    CHECK(s.camera.fov_deg == 220 && s.camera.up[1] == 1 && s.camera.look_at[2] > 0);
    /* A pinhole looking straight up gets north as up too. */
    CHECK_OK(parse("{\"camera\": {\"view\": {\"elevation_deg\": 90, \"azimuth_deg\": 0}}}", &s));
    CHECK(vdiff(s.camera.up, north) == 0);
    /* Equirect keeps the rest (ignored by that camera, but valid). */
    CHECK_OK(parse("{\"camera\": {\"type\": \"equirect\"}}", &s));
    CHECK(s.camera.type == ATMOS_CAMERA_EQUIRECT && vdiff(s.camera.look_at, d.camera.look_at) < 1e-9);
    /* look_at [0, 0, 0] is a real point (it would read as "default" in the
     * struct): the stored point differs but the direction is the same. */
    CHECK_OK(parse("{\"camera\": {\"position_m\": [30, 40, 0], \"look_at_m\": [0, 0, 0]}}", &s));
    CHECK(s.camera.look_at[0] != 0 || s.camera.look_at[1] != 0 || s.camera.look_at[2] != 0);
    {
        double want[3] = {-0.6, -0.8, 0}, got[3];
        double n = 0;
        for (int i = 0; i < 3; i++) got[i] = s.camera.look_at[i] - s.camera.position[i], n += got[i] * got[i];
        for (int i = 0; i < 3; i++) got[i] /= sqrt(n);
        CHECK(vdiff(got, want) < 1e-12);
    }
    CHECK(parse("{\"camera\": {\"position_m\": [0, 0, 0], \"look_at_m\": [0, 0, 0]}}", &s) == ATMOS_E_INVALID_ARG);
    CHECK(contains(atmos_context_error(ctx), "/camera/look_at_m: must differ from position_m"));
    /* Only one sun angle: the other keeps its default. */
    CHECK_OK(parse("{\"sun\": {\"azimuth_deg\": 100}}", &s));
    CHECK(s.sun.elevation_deg == 22 && s.sun.azimuth_deg == 100 && !s.sun.from_time);

    /* Renderers, volumes, background, sun irradiance. */
    CHECK_OK(parse("{}", &s));
    CHECK(s.renderer == ATMOS_RENDERER_SKY && s.atmosphere.kind == ATMOS_ATMOSPHERE_RILEY && !s.volume.source[0]);
    CHECK(s.slice.slices == 0 && s.path.spp == 64 && s.path.seed == 1 && s.sun.irradiance_count == 0);
    CHECK_OK(parse("{\"volume\": {\"generate\": \"storm\", \"seed\": 7, \"scale\": 0.5, \"position_m\": [1, 2, 3]}}", &s));
    CHECK(s.renderer == ATMOS_RENDERER_SLICE); /* a volume alone selects the slice renderer */
    CHECK(!strcmp(s.volume.source, "generate:storm") && s.volume.seed == 7 && s.volume.scale == 0.5);
    CHECK(s.volume.placed && s.volume.position_m[0] == 1 && s.volume.position_m[1] == 2 && s.volume.position_m[2] == 3);
    CHECK_OK(parse("{\"renderer\": \"path\", \"volume\": {\"file\": \"c.vdb\", \"grids\": [\"density\", \"temp\"], "
                   "\"particle\": \"cloud\", \"density_scale\": 1e8}, \"path\": {\"spp\": 1000, \"time_budget_s\": 30, "
                   "\"seed\": 42, \"max_depth\": 5, \"truncate_deg\": 3.5}, \"background\": {\"type\": \"uniform\", \"radiance\": 0.25}, "
                   "\"sun\": {\"elevation_deg\": 30, \"irradiance\": [1, 2, 3]}}", &s));
    CHECK(s.renderer == ATMOS_RENDERER_PATH && !strcmp(s.volume.source, "c.vdb") && !strcmp(s.volume.grids, "density,temp"));
    CHECK(!strcmp(s.volume.particle, "cloud") && s.volume.density_scale == 1e8 && !s.volume.placed);
    CHECK(s.path.spp == 1000 && s.path.time_budget_s == 30 && s.path.seed == 42 && s.path.max_depth == 5);
    CHECK(s.path.truncate_deg == 3.5);
    CHECK(s.atmosphere.kind == ATMOS_ATMOSPHERE_VACUUM && s.atmosphere.background_radiance == 0.25);
    CHECK(s.sun.irradiance_count == 3 && s.sun.irradiance[2] == 3 && s.sun.elevation_deg == 30);
    CHECK_OK(parse("{\"sun\": {\"irradiance\": 1.5, \"time\": \"2026-06-21T12:00:00Z\", \"latitude_deg\": 40, "
                   "\"longitude_deg\": 0}, \"background\": \"black\", \"slice\": {\"update\": \"eq24\", \"xi\": 0, "
                   "\"low_albedo\": true, \"slices\": 64, \"light_size\": 128, \"grid_max_dim\": 64, "
                   "\"eye_scale\": 0.5}}", &s));
    CHECK(s.sun.from_time && s.sun.irradiance_count == 1 && s.sun.irradiance[0] == 1.5 && s.atmosphere.kind == ATMOS_ATMOSPHERE_VACUUM && s.atmosphere.background_radiance == 0);
    CHECK(s.slice.eq24 == 1 && s.slice.xi == 0 && s.slice.low_albedo == 1 && s.slice.slices == 64 && s.slice.light_size == 128 &&
          s.slice.grid_max_dim == 64 && s.slice.eye_scale == 0.5);
}

typedef struct bad_case {
    const char *json;
    atmos_status status;
    const char *expect1, *expect2; /* substrings of the message (NULL: none) */
} bad_case;

/* Bad scenes: structure and types. */
static const bad_case bad_structure[] = {
    {"{\"bogus\": 1}", ATMOS_E_INVALID_ARG, "scene.json: /bogus: unknown key (allowed: name, image, camera, sun, atmosphere, wavelengths, output, renderer, particles, background, volume, slice, path, animation, nishita, harris, beams, lights, fog, objects)", NULL},
    {"{\"sun\": {\"elevation_deg\": 5, \"Azimuth_deg\": 5}}", ATMOS_E_INVALID_ARG, "/sun/Azimuth_deg: unknown key", "azimuth_deg"},
    {"{\"camera\": {\"view\": {\"elevation_deg\": 5, \"azimuth_deg\": 5, \"roll\": 1}}}", ATMOS_E_INVALID_ARG, "/camera/view/roll: unknown key", NULL},
    {"{\"a/b~c\": 1}", ATMOS_E_INVALID_ARG, "/a~1b~0c: unknown key", NULL},
    {"{\"output\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/output/zz: unknown key (allowed: ", "exr_pixel"}, /* every name listed, none past its array */
    {"{\"animation\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/animation/zz: unknown key (allowed: ", "exposure"}, /* every name listed, none past its array */
    {"{\"image\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/image/zz: unknown key (allowed: ", "height"}, /* every name listed, none past its array */
    {"{\"wavelengths\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/wavelengths/zz: unknown key (allowed: ", "samples"}, /* every name listed, none past its array */
    {"{\"slice\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/slice/zz: unknown key (allowed: ", "slices"}, /* every name listed, none past its array */
    {"{\"nishita\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/nishita/zz: unknown key (allowed: ", "orders"}, /* every name listed, none past its array */
    {"{\"harris\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/harris/zz: unknown key (allowed: ", "spacing_m"}, /* every name listed, none past its array */
    {"{\"beams\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/beams/zz: unknown key (allowed: ", "epsilon"}, /* every name listed, none past its array */
    {"{\"fog\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/fog/zz: unknown key (allowed: ", "extinction_per_m"}, /* every name listed, none past its array */
    {"{\"atmosphere\": {\"zz\": 1}}", ATMOS_E_INVALID_ARG, "/atmosphere/zz: unknown key (allowed: ", "model"}, /* every name listed, none past its array */
    {"[1, 2]", ATMOS_E_INVALID_ARG, "scene.json: /: expected an object, got an array", NULL},
    {"{\"image\": 5}", ATMOS_E_INVALID_ARG, "/image: expected an object, got a number", NULL},
    {"{\"image\": {\"width\": 1.5}}", ATMOS_E_INVALID_ARG, "/image/width: expected an integer, got 1.5", NULL},
    {"{\"image\": {\"height\": null}}", ATMOS_E_INVALID_ARG, "/image/height: expected an integer, got null", NULL},
    {"{\"name\": 42}", ATMOS_E_INVALID_ARG, "/name: expected a string, got a number", NULL},
    {"{\"atmosphere\": {\"sun_disk\": \"yes\"}}", ATMOS_E_INVALID_ARG, "/atmosphere/sun_disk: expected true or false, got a string", NULL},
    {"{\"camera\": {\"position_m\": [0, 2]}}", ATMOS_E_INVALID_ARG, "/camera/position_m: expected an array of 3 numbers, got 2 elements", NULL},
    {"{\"camera\": {\"up\": [0, 1, 0, 0]}}", ATMOS_E_INVALID_ARG, "/camera/up: expected an array of 3 numbers", NULL},
    {"{\"camera\": {\"look_at_m\": [0, 1, \"2\"]}}", ATMOS_E_INVALID_ARG, "/camera/look_at_m/2: expected a number, got a string", NULL},
    {"{\"camera\": {\"type\": \"ortho\"}}", ATMOS_E_INVALID_ARG, "/camera/type: must be one of pinhole, fisheye, equirect, got \"ortho\"", NULL},
    {"{\"wavelengths\": {\"mode\": \"hyper\"}}", ATMOS_E_INVALID_ARG, "/wavelengths/mode: must be one of rgb, spectral", NULL},
    {"{\"output\": {\"tone_curve\": \"aces\"}}", ATMOS_E_INVALID_ARG, "/output/tone_curve: must be one of filmic, reinhard, clamp", NULL},
    {"{\"output\": {\"exr_pixel\": \"double\"}}", ATMOS_E_INVALID_ARG, "/output/exr_pixel: must be one of float, half", NULL},
    {"{\"output\": {\"exposure\": \"bright\"}}", ATMOS_E_INVALID_ARG, "/output/exposure: must be \"auto\" or a number", NULL},
    {"{\"output\": {\"exposure\": true}}", ATMOS_E_INVALID_ARG, "/output/exposure: expected \"auto\" or a number (EV100), got a boolean", NULL},
    {"{\"renderer\": \"raytrace\"}", ATMOS_E_INVALID_ARG, "/renderer: must be one of sky, slice, path, nishita, harris, beams, got \"raytrace\"", NULL},
};

/* Bad scenes: lights, fog, objects: absurd values. */
static const bad_case bad_lights[] = {
    {"{\"lights\": [{\"type\": \"torch\"}]}", ATMOS_E_INVALID_ARG, "/lights/0/type: must be one of point, spot", NULL},
    {"{\"lights\": [{}, {\"intensity_w_sr\": -5}]}", ATMOS_E_INVALID_ARG, "/lights/1/intensity_w_sr: must be in (0, 1000000000]", NULL},
    {"{\"lights\": [{\"type\": \"spot\", \"cone_deg\": 120}]}", ATMOS_E_INVALID_ARG, "/lights/0/cone_deg: must be in [0, 89]", NULL},
    {"{\"lights\": [{\"type\": \"spot\", \"cone_deg\": 80, \"edge_deg\": 20}]}", ATMOS_E_INVALID_ARG, "/lights/0/edge_deg: cone_deg + edge_deg must be at most 90", NULL},
    {"{\"lights\": [{\"type\": \"spot\", \"direction\": [0, 0, 0]}]}", ATMOS_E_INVALID_ARG, "/lights/0/direction: must be a nonzero finite vector", NULL},
    {"{\"lights\": [{\"colour_temperature_k\": 100}]}", ATMOS_E_INVALID_ARG, "/lights/0/colour_temperature_k: must be in [1000, 40000] (0: colour)", NULL},
    {"{\"lights\": [{\"position_m\": [0, 1e300, 0]}]}", ATMOS_E_INVALID_ARG, "/lights/0/position_m/1: must be in", NULL},
    {"{\"lights\": [{\"range_m\": -1}]}", ATMOS_E_INVALID_ARG, "/lights/0/range_m: must be in [0, 1000000]", NULL},
    {"{\"wavelengths\": {\"mode\": \"spectral\"}, \"lights\": [{\"colour\": [1, 0.5, 0.2]}]}", ATMOS_E_INVALID_ARG, "/lights/0/colour: rgb colours need rgb wavelengths", NULL},
    {"{\"lights\": {\"type\": \"spot\"}}", ATMOS_E_INVALID_ARG, "/lights: expected an array of objects, got an object", NULL},
    {"{\"lights\": [{\"cone\": 5}]}", ATMOS_E_INVALID_ARG, "/lights/0/cone: unknown key", NULL},
    {"{\"lights\": [{\"image\": \"w.png\"}]}", ATMOS_E_INVALID_ARG, "/lights/0/image: an image is projected through a spot's cone", NULL},
    {"{\"wavelengths\": {\"mode\": \"spectral\"}, \"lights\": [{\"type\": \"spot\", \"colour_temperature_k\": 3000, \"image\": \"w.png\"}]}", ATMOS_E_INVALID_ARG, "/lights/0/image: an image on a light needs rgb wavelengths", NULL},
    {"{\"fog\": {\"extinction_per_m\": 0}}", ATMOS_E_INVALID_ARG, "/fog/extinction_per_m: must be in (0, 10]", NULL},
    {"{\"fog\": {\"extinction_per_m\": 0.1, \"scattering_per_m\": 0.2}}", ATMOS_E_INVALID_ARG, "/fog/scattering_per_m: must be in [0, 0.1] (at most the extinction)", NULL},
    {"{\"fog\": {\"extinction_per_m\": 0.1, \"g\": 1}}", ATMOS_E_INVALID_ARG, "/fog/g: must be in (-1, 1)", NULL},
    {"{\"fog\": {\"g\": 0.5}}", ATMOS_E_INVALID_ARG, "/fog: needs one of \"extinction_per_m\" and \"visibility_m\"", NULL},
    {"{\"fog\": {\"extinction_per_m\": 0.1, \"visibility_m\": 100}}", ATMOS_E_INVALID_ARG, "/fog: give only one of \"extinction_per_m\" and \"visibility_m\"", NULL},
    {"{\"fog\": {\"visibility_m\": 0.1}}", ATMOS_E_INVALID_ARG, "/fog/visibility_m: must be in [0.3912, 10000000] (metres)", NULL},
    {"{\"fog\": {\"visibility_m\": 100, \"particle\": \"cloud\", \"g\": 0.5}}", ATMOS_E_INVALID_ARG, "/fog: a fog of a particle type takes its albedo and phase function from the type", NULL},
    {"{\"fog\": {\"visibility_m\": 100, \"particle\": \"smog\"}}", ATMOS_E_INVALID_ARG, "/fog/particle: 'smog' is neither in the scene's \"particles\" nor a preset", NULL},
    {"{\"fog\": {\"visibility_m\": 100, \"particle\": \"\"}}", ATMOS_E_INVALID_ARG, "/fog/particle: must name a particle type", NULL},
    {"{\"objects\": [{\"position_m\": [0, 0, 0]}]}", ATMOS_E_INVALID_ARG, "/objects/0: needs \"mesh\" or \"terrain\"", NULL},
    {"{\"objects\": [{\"mesh\": \"builtin:teapot\"}]}", ATMOS_E_INVALID_ARG, "/objects/0: mesh \"builtin:teapot\" is no built-in", NULL},
    {"{\"objects\": [{\"mesh\": \"builtin:box\", \"scale\": [1, 0, 1]}]}", ATMOS_E_INVALID_ARG, "/objects/0/scale/1: must not be zero", NULL},
    {"{\"objects\": [{\"mesh\": \"builtin:box\", \"scale\": 0}]}", ATMOS_E_INVALID_ARG, "/objects/0/scale: must not be zero", NULL},
    {"{\"objects\": [{\"mesh\": \"builtin:box\", \"albedo\": 1.5}]}", ATMOS_E_INVALID_ARG, "/objects/0/albedo/0: must be in [0, 1]", NULL},
    {"{\"objects\": [{\"mesh\": \"builtin:box\", \"terrain\": \"generate:ridges\"}]}", ATMOS_E_INVALID_ARG, "/objects/0: needs either \"mesh\"", NULL},
    {"{\"objects\": [{\"terrain\": \"generate:dunes\", \"height_m\": 10}]}", ATMOS_E_INVALID_ARG, "terrain \"generate:dunes\" is no generator", NULL},
    {"{\"objects\": [{\"terrain\": \"generate:ridges\"}]}", ATMOS_E_INVALID_ARG, "/objects/0: a generated terrain needs height_m > 0", NULL},
    {"{\"objects\": [{\"terrain\": \"dem.tif\", \"size_m\": 0}]}", ATMOS_E_INVALID_ARG, "/objects/0/size_m: must be in (0, 10000000]", NULL},
    {"{\"objects\": [{\"terrain\": \"dem.tif\", \"samples\": 1}]}", ATMOS_E_INVALID_ARG, "/objects/0/samples: must be in [2, 4097]", NULL},
    {"{\"objects\": [{\"terrain\": \"dem.tif\", \"max_triangles\": 9000000}]}", ATMOS_E_INVALID_ARG, "/objects/0/max_triangles: must be in [0, 4000000]", NULL},
    {"{\"renderer\": \"beams\"}", ATMOS_E_INVALID_ARG, "/lights: the beams renderer draws the light of \"lights\" (and of the sun with beams/sun): the scene has neither", NULL},
    {"{\"lights\": [{}], \"fog\": {\"extinction_per_m\": 0.01, \"height_m\": 100}}", ATMOS_E_INVALID_ARG, "/fog/height_m: a height-dependent fog is lit by the sun alone", NULL},
    {"{\"fog\": {\"extinction_per_m\": 0.01, \"height_m\": -1}}", ATMOS_E_INVALID_ARG, "/fog/height_m: must be in [0, 100000]", NULL},
    {"{\"renderer\": \"beams\", \"lights\": [{}], \"camera\": {\"type\": \"fisheye\"}}", ATMOS_E_INVALID_ARG, "/camera/type: the beams renderer supports pinhole cameras only", NULL},
    {"{\"renderer\": \"beams\", \"lights\": [{}], \"beams\": {\"epsilon\": 0}}", ATMOS_E_INVALID_ARG, "/beams/epsilon: must be in (0, 1]", NULL},
};

/* Bad scenes: renderers, background, volume. */
static const bad_case bad_renderers[] = {
    {"{\"renderer\": \"slice\"}", ATMOS_E_INVALID_ARG, "/renderer: \"slice\" renders a volume: the scene needs \"volume\"", NULL},
    {"{\"renderer\": \"sky\", \"volume\": {\"generate\": \"storm\"}}", ATMOS_E_INVALID_ARG, "/volume: the sky renderer draws no volume", NULL},
    {"{\"volume\": {\"generate\": \"storm\"}, \"camera\": {\"type\": \"fisheye\"}}", ATMOS_E_INVALID_ARG, "/camera/type: the slice renderer supports pinhole cameras only", NULL},
    {"{\"renderer\": \"path\", \"volume\": {\"generate\": \"storm\"}, \"camera\": {\"type\": \"equirect\"}}", ATMOS_E_INVALID_ARG, "/volume/position_m: is needed with an equirect camera", NULL},
    {"{\"volume\": {\"generate\": \"blob\"}}", ATMOS_E_INVALID_ARG, "/volume/generate: unknown generator (known: cumulus,", NULL},
    {"{\"volume\": {\"file\": \"a.vdb\", \"generate\": \"storm\"}}", ATMOS_E_INVALID_ARG, "/volume/generate: \"file\" and \"generate\" exclude each other", NULL},
    {"{\"volume\": {\"file\": \"\"}}", ATMOS_E_INVALID_ARG, "/volume/file: must not be empty", NULL},
    {"{\"volume\": {\"file\": \"generate:storm\"}}", ATMOS_E_INVALID_ARG, "/volume/file: use \"generate\": \"storm\"", NULL},
    {"{\"volume\": {\"density_scale\": 2}}", ATMOS_E_INVALID_ARG, "/volume: needs \"file\", \"generate\" or \"simulate\"", NULL},
    {"{\"volume\": {\"generate\": \"storm\", \"density_scale\": 0}}", ATMOS_E_INVALID_ARG, "/volume/density_scale: must be in (0, 1e+30], got 0", NULL},
    {"{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\", \"refine\": 5}}}", ATMOS_E_INVALID_ARG, "/volume/simulate/refine: must be in [1, 4], got 5", NULL},
    {"{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\", \"detail\": 2}}}", ATMOS_E_INVALID_ARG, "/volume/simulate/detail: must be in [0, 1], got 2", NULL},
    {"{\"volume\": {\"simulate\": {\"preset\": \"cumulonimbus\", \"ice\": 1}}}", ATMOS_E_INVALID_ARG, "/volume/simulate/ice: expected true or false", NULL},
    {"{\"volume\": {\"generate\": \"storm\", \"grids\": \"cloud\"}}", ATMOS_E_INVALID_ARG, "/volume/grids: expected an array of grid names, got a string", NULL},
    {"{\"volume\": {\"generate\": \"storm\", \"grids\": []}}", ATMOS_E_INVALID_ARG, "/volume/grids: must not be empty", NULL},
    {"{\"volume\": {\"generate\": \"storm\", \"grids\": [\"a,b\"]}}", ATMOS_E_INVALID_ARG, "/volume/grids/0: a grid name has no ','", NULL},
    {"{\"volume\": {\"generate\": \"storm\", \"seed\": 1.5}}", ATMOS_E_INVALID_ARG, "/volume/seed: expected an integer", NULL},
    {"{\"volume\": {\"generate\": \"storm\", \"position_m\": [0, 1]}}", ATMOS_E_INVALID_ARG, "/volume/position_m: expected an array of 3 numbers", NULL},
    {"{\"slice\": {\"slices\": -1}}", ATMOS_E_INVALID_ARG, "/slice/slices: must be in [0, 8192], got -1", NULL},
    {"{\"slice\": {\"light_size\": 4}}", ATMOS_E_INVALID_ARG, "/slice/light_size: must be in [8, 8192], got 4", NULL},
    {"{\"slice\": {\"xi\": -1}}", ATMOS_E_INVALID_ARG, "/slice/xi: must be in [0, 100], got -1", NULL},
    {"{\"slice\": {\"update\": \"eq23\"}}", ATMOS_E_INVALID_ARG, "/slice/update: must be one of eq25, eq24", NULL},
    {"{\"slice\": {\"low_albedo\": 1}}", ATMOS_E_INVALID_ARG, "/slice/low_albedo: expected true or false", NULL},
    {"{\"slice\": {\"eye_scale\": 0}}", ATMOS_E_INVALID_ARG, "/slice/eye_scale: must be in (0, 2], got 0", NULL},
    {"{\"slice\": {\"eye_scale\": 1.5}}", ATMOS_E_INVALID_ARG, "/slice/eye_scale: must be in (0, 1] or 2, got 1.5", NULL},
    {"{\"slice\": {\"eye_scale\": 2.5}}", ATMOS_E_INVALID_ARG, "/slice/eye_scale: must be in (0, 2], got 2.5", NULL},
    {"{\"path\": {\"spp\": 0}}", ATMOS_E_INVALID_ARG, "/path/spp: must be in [1, 1000000], got 0", NULL},
    {"{\"path\": {\"time_budget_s\": -1}}", ATMOS_E_INVALID_ARG, "/path/time_budget_s: must be in [0, 10000000], got -1", NULL},
    {"{\"path\": {\"seed\": -3}}", ATMOS_E_INVALID_ARG, "/path/seed: must be in [0, ", NULL},
    {"{\"path\": {\"bounces\": 3}}", ATMOS_E_INVALID_ARG, "/path/bounces: unknown key (allowed: spp, time_budget_s, seed, max_depth, truncate_deg, sky_nee, forced, aureole, roulette)", NULL},
    {"{\"path\": {\"truncate_deg\": 21}}", ATMOS_E_INVALID_ARG, "/path/truncate_deg: must be in [0, 20], got 21", NULL},
    {"{\"background\": \"uniform\"}", ATMOS_E_INVALID_ARG, "/background: must be one of sky, black, got \"uniform\"", NULL},
    {"{\"background\": {\"type\": \"uniform\"}}", ATMOS_E_INVALID_ARG, "/background: missing key \"radiance\"", NULL},
    {"{\"background\": {\"type\": \"black\", \"radiance\": 1}}", ATMOS_E_INVALID_ARG, "/background: \"radiance\" goes with \"type\": \"uniform\" only", NULL},
    {"{\"background\": {\"type\": \"uniform\", \"radiance\": -1}}", ATMOS_E_INVALID_ARG, "/background/radiance: must be in [0, 1000000], got -1", NULL},
    {"{\"background\": 3}", ATMOS_E_INVALID_ARG, "/background: expected \"sky\", \"black\" or an object, got a number", NULL},
    {"{\"sun\": {\"irradiance\": \"bright\"}}", ATMOS_E_INVALID_ARG, "/sun/irradiance: expected a number or an array of 3 numbers", NULL},
    {"{\"sun\": {\"irradiance\": -2}}", ATMOS_E_INVALID_ARG, "/sun/irradiance: must be in [0, 1000000], got -2", NULL},
    {"{\"sun\": {\"irradiance\": [1, 2, 3]}, \"wavelengths\": {\"mode\": \"spectral\"}}", ATMOS_E_INVALID_ARG, "/sun/irradiance: three values are the rgb channels", NULL},
    {"{\"image\": {\"width\": 10, \"width\": 20}}", ATMOS_E_INVALID_ARG, "/image/width: duplicate key", NULL},
};

/* Bad scenes: ranges, at each side of each boundary that matters. */
static const bad_case bad_ranges[] = {
    {"{\"image\": {\"width\": 0}}", ATMOS_E_INVALID_ARG, "/image/width: must be in [1, 16384], got 0", NULL},
    {"{\"image\": {\"height\": 16385}}", ATMOS_E_INVALID_ARG, "/image/height: must be in [1, 16384], got 16385", NULL},
    {"{\"image\": {\"width\": 1e10}}", ATMOS_E_INVALID_ARG, "/image/width: must be in [1, 16384]", NULL},
    {"{\"image\": {\"samples_per_pixel\": 257}}", ATMOS_E_INVALID_ARG, "/image/samples_per_pixel: must be in [1, 256], got 257", NULL},
    {"{\"camera\": {\"fov_deg\": 270}}", ATMOS_E_INVALID_ARG, "scene.json: /camera/fov_deg: must be in (0, 180) for a pinhole camera, got 270", NULL},
    {"{\"camera\": {\"fov_deg\": 180}}", ATMOS_E_INVALID_ARG, "/camera/fov_deg: must be in (0, 180) for a pinhole camera, got 180", NULL},
    {"{\"camera\": {\"fov_deg\": 0}}", ATMOS_E_INVALID_ARG, "/camera/fov_deg", "(0, 180)"},
    {"{\"camera\": {\"fov_deg\": 360.5, \"type\": \"fisheye\"}}", ATMOS_E_INVALID_ARG, "/camera/fov_deg: must be in (0, 360] for a fisheye camera, got 360.5", NULL},
    {"{\"camera\": {\"type\": \"fisheye\", \"fov_deg\": -1}}", ATMOS_E_INVALID_ARG, "/camera/fov_deg", "(0, 360]"},
    {"{\"camera\": {\"position_m\": [0, -0.5, 0]}}", ATMOS_E_INVALID_ARG, "/camera/position_m/1: must be in [0, 100000000], got -0.5", NULL},
    {"{\"camera\": {\"position_m\": [0, 100000001, 0]}}", ATMOS_E_INVALID_ARG, "/camera/position_m/1", "[0, 100000000]"},
    {"{\"camera\": {\"look_at_m\": [0, 1000, 0]}}", ATMOS_E_INVALID_ARG, "/camera/look_at_m: must differ from position_m", NULL},
    {"{\"camera\": {\"look_at_m\": [1, 2, 3], \"view\": {\"elevation_deg\": 1, \"azimuth_deg\": 2}}}", ATMOS_E_INVALID_ARG, "/camera/view: cannot be combined with look_at_m", NULL},
    {"{\"camera\": {\"view\": {\"elevation_deg\": 1, \"azimuth_deg\": 2}, \"look_at_m\": [1, 2, 3]}}", ATMOS_E_INVALID_ARG, "/camera/look_at_m: cannot be combined with view", NULL},
    {"{\"camera\": {\"view\": {\"elevation_deg\": 1}}}", ATMOS_E_INVALID_ARG, "/camera/view: missing key \"azimuth_deg\"", NULL},
    {"{\"camera\": {\"view\": {\"elevation_deg\": 90.001, \"azimuth_deg\": 0}}}", ATMOS_E_INVALID_ARG, "/camera/view/elevation_deg: must be in [-90, 90], got 90.001", NULL},
    {"{\"camera\": {\"up\": [0, 0, 0]}}", ATMOS_E_INVALID_ARG, "/camera/up: must be nonzero", NULL},
    {"{\"camera\": {\"up\": [0, 1, 0], \"view\": {\"elevation_deg\": 90, \"azimuth_deg\": 0}}}", ATMOS_E_INVALID_ARG, "/camera/up: must not be parallel to the view direction", NULL},
    {"{\"camera\": {\"type\": \"fisheye\", \"up\": [0, -3, 0]}}", ATMOS_E_INVALID_ARG, "/camera/up: must not be parallel", NULL},
    {"{\"sun\": {\"elevation_deg\": -90.5}}", ATMOS_E_INVALID_ARG, "/sun/elevation_deg: must be in [-90, 90], got -90.5", NULL},
    {"{\"sun\": {\"azimuth_deg\": 360}}", ATMOS_E_INVALID_ARG, "/sun/azimuth_deg: must be in [0, 360), got 360", NULL},
    {"{\"sun\": {\"azimuth_deg\": -0.25}}", ATMOS_E_INVALID_ARG, "/sun/azimuth_deg", "[0, 360)"},
    {"{\"sun\": {\"elevation_deg\": 10, \"time\": \"2026-06-21T12:00:00Z\", \"latitude_deg\": 1, \"longitude_deg\": 2}}", ATMOS_E_INVALID_ARG, "/sun/time: cannot be combined with elevation_deg/azimuth_deg", NULL},
    {"{\"sun\": {\"latitude_deg\": 1, \"longitude_deg\": 2, \"time\": \"2026-06-21T12:00:00Z\", \"azimuth_deg\": 10}}", ATMOS_E_INVALID_ARG, "/sun/azimuth_deg: cannot be combined with time", NULL},
    {"{\"sun\": {\"time\": \"2026-06-21T12:00:00Z\", \"longitude_deg\": 2}}", ATMOS_E_INVALID_ARG, "/sun: missing key \"latitude_deg\"", NULL},
    {"{\"sun\": {\"time\": 20260621}}", ATMOS_E_INVALID_ARG, "/sun/time: expected a string, got a number", NULL},
    {"{\"sun\": {\"time\": \"2026-02-30T00:00:00Z\", \"latitude_deg\": 0, \"longitude_deg\": 0}}", ATMOS_E_INVALID_ARG, "scene.json: /sun/time: ", NULL},
    {"{\"sun\": {\"time\": \"2026-06-21T12:00:00Z\", \"latitude_deg\": 90.5, \"longitude_deg\": 0}}", ATMOS_E_INVALID_ARG, "/sun/latitude_deg: must be in [-90, 90], got 90.5", NULL},
    {"{\"sun\": {\"time\": \"2026-06-21T12:00:00Z\", \"latitude_deg\": 0, \"longitude_deg\": -180.5}}", ATMOS_E_INVALID_ARG, "/sun/longitude_deg: must be in [-180, 180], got -180.5", NULL},
    {"{\"sun\": {\"refraction\": 1}}", ATMOS_E_INVALID_ARG, "/sun/refraction: expected true or false", NULL},
    {"{\"atmosphere\": {\"beta_sl_550_per_m\": 0}}", ATMOS_E_INVALID_ARG, "/atmosphere/beta_sl_550_per_m: must be in (0, 0.01], got 0", NULL},
    {"{\"atmosphere\": {\"beta_sl_550_per_m\": 0.0100001}}", ATMOS_E_INVALID_ARG, "/atmosphere/beta_sl_550_per_m", "(0, 0.01], got 0.0100001"},
    {"{\"atmosphere\": {\"scale_height_m\": 99.9}}", ATMOS_E_INVALID_ARG, "/atmosphere/scale_height_m: must be in [100, 100000], got 99.9", NULL},
    {"{\"atmosphere\": {\"ground_albedo\": 1.01}}", ATMOS_E_INVALID_ARG, "/atmosphere/ground_albedo: must be in [0, 1], got 1.01", NULL},
    {"{\"atmosphere\": {\"ground_albedo\": -0.01}}", ATMOS_E_INVALID_ARG, "/atmosphere/ground_albedo", "[0, 1]"},
    {"{\"atmosphere\": {\"sun_diameter_deg\": 0}}", ATMOS_E_INVALID_ARG, "/atmosphere/sun_diameter_deg: must be in (0, 20], got 0", NULL},
    {"{\"atmosphere\": {\"sun_scale\": 1000001}}", ATMOS_E_INVALID_ARG, "/atmosphere/sun_scale: must be in [0, 1000000]", NULL},
    {"{\"wavelengths\": {\"samples\": 0}}", ATMOS_E_INVALID_ARG, "/wavelengths/samples: must be in [1, 128], got 0", NULL},
    {"{\"wavelengths\": {\"samples\": 129}}", ATMOS_E_INVALID_ARG, "/wavelengths/samples", "[1, 128]"},
    {"{\"output\": {\"exposure\": 40.5}}", ATMOS_E_INVALID_ARG, "/output/exposure: must be in [-20, 40], got 40.5", NULL},
    {"{\"output\": {\"exposure_compensation_ev\": -20.5}}", ATMOS_E_INVALID_ARG, "/output/exposure_compensation_ev: must be in [-20, 20]", NULL},
    {"{\"output\": {\"exposure\": 12, \"exposure_compensation_ev\": 1}}", ATMOS_E_INVALID_ARG, "/output/exposure_compensation_ev: only applies with automatic exposure", NULL},
    {"{\"output\": {\"png_bits\": 12}}", ATMOS_E_INVALID_ARG, "/output/png_bits: must be 8 or 16, got 12", NULL},
    {"{\"output\": {\"png_bits\": 1e300}}", ATMOS_E_INVALID_ARG, "/output/png_bits", NULL},
    {"{\"name\": \"nnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnn\"}", ATMOS_E_INVALID_ARG, "/name: must be at most 127 bytes, got 128", NULL},
};

/* Bad scenes: numbers that are not finite doubles. */
static const bad_case bad_numbers[] = {
    {"{\"camera\": {\"fov_deg\": 1e999}}", ATMOS_E_INVALID_ARG, "/camera/fov_deg: must be a finite number", NULL},
    {"{\"image\": {\"width\": -1e999}}", ATMOS_E_INVALID_ARG, "/image/width: must be a finite number", NULL},
    {"{\"camera\": {\"position_m\": [0, 1e400, 0]}}", ATMOS_E_INVALID_ARG, "/camera/position_m/1: must be a finite number", NULL},
    {"{\"camera\": {\"fov_deg\": NaN}}", ATMOS_E_FORMAT, "scene.json:1:", "malformed JSON"},
};

/* Bad scenes: malformed text. */
static const bad_case bad_text[] = {
    {"", ATMOS_E_FORMAT, "scene.json: empty input", NULL},
    {" \n\t ", ATMOS_E_FORMAT, "empty input", NULL},
    {"{\"image\": {\"width\": 10,}}", ATMOS_E_FORMAT, "scene.json:1:", "malformed JSON"},
    {"{\n  \"image\": {\n    \"width\": 10\n  },\n  \"camera\": ]\n}", ATMOS_E_FORMAT, "scene.json:5:", "malformed JSON"},
    {"{\"image\": {\"width\": 10", ATMOS_E_FORMAT, "unexpected end of input", NULL},
    {"{\"name\": \"unterminated", ATMOS_E_FORMAT, "unexpected end of input inside a string", NULL},
    {"{} {}", ATMOS_E_FORMAT, "scene.json:1:4: malformed JSON: unexpected text after the end", NULL},
    {"{\"name\": \"bad \xff utf8\"}", ATMOS_E_FORMAT, "scene.json:1:15: malformed JSON: invalid UTF-8", NULL},
    {"{\"name\": \"overlong \xc0\xaf\"}", ATMOS_E_FORMAT, "invalid UTF-8", NULL},
    {"{\"name\": \"surrogate \xed\xa0\x80\"}", ATMOS_E_FORMAT, "invalid UTF-8", NULL},
    {"{\"name\": \"tab\there\"}", ATMOS_E_FORMAT, "control character in a string", NULL},
    {"{\"name\": \"nul \\u0000 escape\"}", ATMOS_E_FORMAT, "\\u0000 is not allowed", NULL},
    {"{\"_deep\": [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]}", ATMOS_E_LIMIT, "scene.json:1:", "nesting deeper than 64 levels"},
    {"\"just a string\"", ATMOS_E_INVALID_ARG, "/: expected an object, got a string", NULL},
};

/* Bad scenes: animation. */
static const bad_case bad_animation[] = {
    {"{\"animation\": {\"time_end\": \"2026-06-21T12:00:00Z\"}}", ATMOS_E_INVALID_ARG, "/animation: missing key \"frames\"", NULL},
    {"{\"animation\": {\"frames\": -1, \"elevation_end_deg\": 3}}", ATMOS_E_INVALID_ARG, "/animation/frames: must be in [0, 100000], got -1", NULL},
    {"{\"animation\": {\"frames\": 4, \"fps\": 24}}", ATMOS_E_INVALID_ARG, "/animation/fps: unknown key", "time_end"},
    {"{\"animation\": {\"frames\": 4}}", ATMOS_E_INVALID_ARG, "/animation: 4 frames need an end", NULL},
    {"{\"animation\": {\"frames\": 4, \"time_end\": \"2026-06-21T12:00:00Z\"}}", ATMOS_E_INVALID_ARG,
     "/animation/time_end: needs a sun given by time", NULL},
    {"{\"animation\": {\"frames\": 4, \"time_end\": \"2026-02-30T12:00:00Z\"}, \"sun\": {\"time\": \"2026-06-21T12:00:00Z\", \"latitude_deg\": 40, \"longitude_deg\": -105}}",
     ATMOS_E_INVALID_ARG, "/animation/time_end:", NULL},
    {"{\"sun\": {\"time\": \"2026-06-21T12:00:00Z\", \"latitude_deg\": 40, \"longitude_deg\": -105}, \"animation\": {\"frames\": 4, \"elevation_end_deg\": 3}}",
     ATMOS_E_INVALID_ARG, "/animation/elevation_end_deg: needs a sun given by angles", NULL},
    {"{\"animation\": {\"frames\": 4, \"azimuth_end_deg\": 360}}", ATMOS_E_INVALID_ARG, "/animation/azimuth_end_deg: must be in [0, 360)", NULL},
    {"{\"animation\": {\"frames\": 4, \"elevation_end_deg\": 3, \"exposure\": \"auto\"}}", ATMOS_E_INVALID_ARG,
     "/animation/exposure: must be one of locked, per_frame, got \"auto\"", NULL},
    {"{\"animation\": {\"frames\": 4, \"elevation_end_deg\": -91}}", ATMOS_E_INVALID_ARG, "/animation/elevation_end_deg: must be in [-90, 90]", NULL},
    {"{\"animation\": {\"frames\": 4, \"elevation_end_deg\": 3, \"exposure_limit_ev\": -21}}", ATMOS_E_INVALID_ARG,
     "/animation/exposure_limit_ev: must be in [-20, 40]", NULL},
    {"{\"volume\": {\"generate\": \"cumulus\", \"particle\": \"hail\"}}", ATMOS_E_INVALID_ARG,
     "/volume/particle: 'hail' is neither", NULL},
    {"{\"volume\": {\"simulate\": {\"preset\": \"cumulus_field\"}, \"particle\": \"ice\"}}", ATMOS_E_INVALID_ARG,
     "/volume: \"particle\" does not apply to a simulated volume", NULL},
    {"{\"volume\": {\"file\": \"c.vdb\", \"particle\": \"hail\"}}", ATMOS_E_INVALID_ARG,
     "/volume/particle: 'hail' is neither", NULL},
    {"{\"image\": {\"width\": 10}} \x01", ATMOS_E_FORMAT, "control character", NULL},
};

/* The groups of bad scenes, each checked case by case. */
static const struct {
    const char *name;
    const bad_case *cases;
    int n;
} bad_groups[] = {
    {"structure and types", bad_structure, (int)(sizeof bad_structure / sizeof bad_structure[0])},
    {"lights, fog, objects: absurd values", bad_lights, (int)(sizeof bad_lights / sizeof bad_lights[0])},
    {"renderers, background, volume", bad_renderers, (int)(sizeof bad_renderers / sizeof bad_renderers[0])},
    {"ranges, at each side of each boundary that matters", bad_ranges, (int)(sizeof bad_ranges / sizeof bad_ranges[0])},
    {"numbers that are not finite doubles", bad_numbers, (int)(sizeof bad_numbers / sizeof bad_numbers[0])},
    {"malformed text", bad_text, (int)(sizeof bad_text / sizeof bad_text[0])},
    {"animation", bad_animation, (int)(sizeof bad_animation / sizeof bad_animation[0])},
};

/* Lights, fog and objects read back value by value, with the defaults of what is absent. */
static void test_lights(void)
{
    const char *json = "{\"renderer\": \"beams\", \"beams\": {\"epsilon\": 0.02, \"shadow_size\": 256},"
                       " \"lights\": [{\"type\": \"spot\", \"position_m\": [1, 20, 3], \"direction\": [0, -2, 0],"
                       " \"cone_deg\": 15, \"edge_deg\": 3, \"intensity_w_sr\": 5000, \"colour_temperature_k\": 3200,"
                       " \"range_m\": 40}, {\"colour\": [1, 0.5, 0.25]}],"
                       " \"fog\": {\"extinction_per_m\": 0.05, \"g\": 0.3},"
                       " \"objects\": [{\"mesh\": \"builtin:sphere\", \"position_m\": [0, 5, 0], \"scale\": 2,"
                       " \"albedo\": [0.8, 0.7, 0.6], \"rotation_deg\": [0, 45, 0]}]}";
    atmos_scene s;
    atmos_scene_defaults(&s);
    CHECK(s.light_count == 0 && s.object_count == 0 && !s.fog.enabled && s.beams.epsilon == 0.01 &&
          s.beams.max_subplanes == 64 && s.beams.shadow_size == 512 && s.beams.plane_spacing_m == 0);
    CHECK_OK(parse(json, &s));
    CHECK(s.renderer == ATMOS_RENDERER_BEAMS && s.beams.epsilon == 0.02 && s.beams.shadow_size == 256);
    CHECK(s.light_count == 2 && s.object_count == 1);
    const atmos_scene_light *a = &s.lights[0], *b = &s.lights[1];
    CHECK(a->type == ATMOS_LIGHT_SPOT && a->position_m[1] == 20 && a->direction[1] == -1 && a->cone_deg == 15 &&
          a->edge_deg == 3 && a->intensity_w_sr == 5000 && a->colour_temperature_k == 3200 && a->range_m == 40);
    CHECK(b->type == ATMOS_LIGHT_POINT && b->intensity_w_sr == 100 && b->range_m == 0 && b->colour[1] == 0.5 &&
          b->colour_temperature_k == 0);
    CHECK(s.fog.enabled && s.fog.extinction_per_m == 0.05 && s.fog.scattering_per_m == 0.05 && s.fog.g == 0.3);
    /* visibility (Koschmieder: 3.912 / V at 550 nm) and a fog of a particle type */
    atmos_scene v;
    atmos_scene_defaults(&v);
    CHECK_OK(parse("{\"fog\": {\"visibility_m\": 391.2, \"particle\": \"cloud\"}}", &v));
    CHECK(v.fog.enabled && fabs(v.fog.extinction_per_m - 0.01) < 1e-12 && !strcmp(v.fog.particle, "cloud") &&
          v.fog.visibility_m == 391.2);
    CHECK_OK(atmos_scene_validate(ctx, &v, "scene"));
    const atmos_scene_object *o = &s.objects[0];
    CHECK(!strcmp(o->mesh, "builtin:sphere") && o->position_m[1] == 5 && o->scale[0] == 2 && o->scale[2] == 2 &&
          o->albedo[2] == 0.6 && o->rotation_deg[1] == 45);
    CHECK_OK(atmos_scene_validate(ctx, &s, "scene"));
    s.lights[1].intensity_w_sr = 1e12; /* set in code: the validator's message is the parser's */
    CHECK(atmos_scene_validate(ctx, &s, "scene") == ATMOS_E_INVALID_ARG &&
          contains(atmos_context_error(ctx), "scene: /lights/1/intensity_w_sr: must be in (0, 1000000000]"));
    /* more lights than the bound */
    char big[4096] = "{\"lights\": [";
    for (int i = 0; i <= ATMOS_SCENE_MAX_LIGHTS; i++) strcat(big, i ? ", {}" : "{}");
    strcat(big, "]}");
    CHECK(parse(big, &s) == ATMOS_E_LIMIT && contains(atmos_context_error(ctx), "/lights/32: at most 32 are allowed"));
}

/* Every case of one group is refused with its status and message, the output untouched. */
static int check_bad_group(const char *group, const bad_case *cases, int n)
{
    for (int i = 0; i < n; i++) {
        const bad_case *c = &cases[i];
        atmos_scene s, before;
        memset(&s, 0x5A, sizeof s);
        before = s;
        atmos_context_clear_error(ctx);
        atmos_status st = parse(c->json, &s);
        const char *msg = atmos_context_error(ctx);
        CHECK_MSG(st == c->status, "%s case %d (%s): status %s, expected %s; message: %s", group, i, c->json,
                  atmos_status_string(st), atmos_status_string(c->status), msg);
        CHECK_MSG(contains(msg, c->expect1) && contains(msg, c->expect2),
                  "%s case %d (%s): message \"%s\" lacks \"%s\" / \"%s\"", group, i, c->json, msg, c->expect1,
                  c->expect2 ? c->expect2 : "");
        CHECK_MSG(strncmp(msg, "scene.json", 10) == 0, "%s case %d: message \"%s\" does not start with the source", group, i, msg);
        CHECK_MSG(memcmp(&s, &before, sizeof s) == 0, "%s case %d: output modified on failure", group, i);
    }
    return n;
}

static void test_bad_scenes(void)
{
    int n = 0;
    for (size_t g = 0; g < sizeof bad_groups / sizeof bad_groups[0]; g++) n += check_bad_group(bad_groups[g].name, bad_groups[g].cases, bad_groups[g].n);
    printf("%d bad scenes checked\n", n);

    /* The brief's examples, word for word. */
    atmos_scene s;
    CHECK(parse("{\"camera\": {\"fovv_deg\": 50}}", &s) == ATMOS_E_INVALID_ARG);
    CHECK(strcmp(atmos_context_error(ctx),
                 "scene.json: /camera/fovv_deg: unknown key (allowed: type, position_m, look_at_m, view, up, fov_deg)") == 0);
    CHECK(parse("{\"image\": {\"width\": \"1024\"}}", &s) == ATMOS_E_INVALID_ARG);
    CHECK(strcmp(atmos_context_error(ctx), "scene.json: /image/width: expected an integer, got a string") == 0);

    /* The first error wins: document order. */
    CHECK(parse("{\"image\": {\"height\": 0, \"width\": 0}, \"bogus\": 1}", &s) == ATMOS_E_INVALID_ARG);
    CHECK(contains(atmos_context_error(ctx), "/image/height:"));
    CHECK(parse("{\"bogus\": 1, \"image\": {\"height\": 0}}", &s) == ATMOS_E_INVALID_ARG);
    CHECK(contains(atmos_context_error(ctx), "/bogus:"));

    /* Text without a terminator, and NUL bytes inside the given length. */
    const char unterminated[2] = {'{', '}'};
    CHECK_OK(atmos_scene_parse(ctx, unterminated, 2, "buf", &s));
    CHECK(atmos_scene_parse(ctx, "{}\0", 3, "buf", &s) == ATMOS_E_FORMAT);
    CHECK(contains(atmos_context_error(ctx), "buf:1:3: malformed JSON: NUL byte"));
    CHECK(atmos_scene_parse(ctx, NULL, 0, "buf", &s) == ATMOS_E_FORMAT);
    CHECK(atmos_scene_parse(ctx, NULL, 5, "buf", &s) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_scene_parse(ctx, "{}", 2, "buf", NULL) == ATMOS_E_INVALID_ARG);
    /* A NULL context is allowed: only the status comes back. */
    CHECK(atmos_scene_parse(NULL, "{\"x\": 1}", 8, NULL, &s) == ATMOS_E_INVALID_ARG);
}

static void test_limits(void)
{
    atmos_scene s;
    /* Just over 16 MiB: refused before scanning a byte (spaces would otherwise be "empty"). */
    size_t big = ((size_t)16 << 20) + 1;
    char *buf = malloc(big);
    CHECK(buf != NULL);
    if (!buf) return;
    memset(buf, ' ', big);
    CHECK(atmos_scene_parse(ctx, buf, big, "big.json", &s) == ATMOS_E_LIMIT);
    CHECK(contains(atmos_context_error(ctx), "big.json: input is 16777217 bytes"));
    /* Exactly 16 MiB is accepted: an object padded with whitespace. */
    buf[0] = '{';
    buf[big - 2] = '}';
    CHECK_OK(atmos_scene_parse(ctx, buf, big - 1, "big.json", &s));
    /* 10,000 nested arrays: refused without recursing. */
    size_t depth = 10000;
    memset(buf, '[', depth);
    memset(buf + depth, ']', depth);
    CHECK(atmos_scene_parse(ctx, buf, 2 * depth, "deep.json", &s) == ATMOS_E_LIMIT);
    CHECK(contains(atmos_context_error(ctx), "deep.json:1:65: nesting deeper than 64 levels"));
    /* 64 levels are fine (in an annotation) but 65 are not. */
    for (int levels = 63; levels <= 64; levels++) {
        char deep[256];
        int o = snprintf(deep, sizeof deep, "{\"_a\": ");
        for (int i = 0; i < levels; i++) deep[o++] = '[';
        for (int i = 0; i < levels; i++) deep[o++] = ']';
        deep[o++] = '}';
        deep[o] = '\0';
        CHECK(parse(deep, &s) == (levels == 63 ? ATMOS_OK : ATMOS_E_LIMIT));
    }
    free(buf);
}

static void test_validate(void)
{
    atmos_scene d, s;
    atmos_scene_defaults(&d);
    s = d; s.width = 0;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG);
    CHECK(strcmp(atmos_context_error(ctx), "cli: /image/width: must be in [1, 16384], got 0") == 0);
    s = d; s.camera.fov_deg = 270;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG);
    CHECK(strcmp(atmos_context_error(ctx), "cli: /camera/fov_deg: must be in (0, 180) for a pinhole camera, got 270") == 0);
    s = d; s.camera.type = ATMOS_CAMERA_FISHEYE; s.camera.fov_deg = 270;
    CHECK_OK(atmos_scene_validate(ctx, &s, "cli"));
    s = d; s.camera.type = (atmos_camera_type)7;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/camera/type"));
    s = d; s.camera.position[0] = NAN;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG);
    CHECK(contains(atmos_context_error(ctx), "cli: /camera/position_m/0: must be a finite number, got nan"));
    s = d; memcpy(s.camera.look_at, s.camera.position, sizeof s.camera.look_at);
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/camera/look_at_m: must differ"));
    /* camera.h: zero look_at, up and fov mean "default" (the CLI zeroes the
     * camera when it switches the type), for every type. */
    for (int t = 0; t < 3; t++) {
        s = d;
        memset(s.camera.look_at, 0, sizeof s.camera.look_at);
        memset(s.camera.up, 0, sizeof s.camera.up);
        s.camera.fov_deg = 0;
        s.camera.type = (atmos_camera_type)t;
        CHECK_OK(atmos_scene_validate(ctx, &s, "cli"));
    }
    /* ...but a zero up with an explicit vertical pinhole view is what
     * atmos_camera_init would refuse, so it is refused here too. */
    s = d; memset(s.camera.up, 0, sizeof s.camera.up); s.camera.look_at[0] = 0; s.camera.look_at[1] = 500; s.camera.look_at[2] = 0;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/camera/up: must not be parallel"));
    s.camera.type = ATMOS_CAMERA_FISHEYE;
    CHECK_OK(atmos_scene_validate(ctx, &s, "cli"));
    s = d; s.camera.up[0] = 1e308; s.camera.up[1] = 1e308; s.camera.up[2] = 1e308;
    CHECK_OK(atmos_scene_validate(ctx, &s, "cli")); /* huge but finite and not parallel: no overflow */
    s = d; memset(s.name, 'x', sizeof s.name);
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/name: must be at most 127 bytes"));
    s = d; s.sun.elevation_deg = INFINITY;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/sun/elevation_deg: must be a finite number"));
    s = d; s.sun.from_time = 1; s.sun.time = (atmos_utc_time){2024, 2, 29, 23, 59, 59.5};
    CHECK_OK(atmos_scene_validate(ctx, &s, "cli"));
    s.sun.time.year = 2023;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "cli: /sun/time: not a valid UTC date-time"));
    s = d; s.sun.from_time = 1; s.sun.time = (atmos_utc_time){2024, 1, 1, 0, 0, 0}; s.sun.longitude_deg = 181;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/sun/longitude_deg: must be in [-180, 180]"));
    s = d; s.atmosphere.scale_height_m = 0;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/atmosphere/scale_height_m: must be in [100, 100000], got 0"));
    s = d; s.spectral_samples = 0;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/wavelengths/samples"));
    s = d; s.wavelengths = (atmos_wavelength_mode)5;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/wavelengths/mode"));
    s = d; s.tonemap.manual_exposure = 1; s.tonemap.exposure_ev = 39;
    CHECK_OK(atmos_scene_validate(ctx, &s, "cli"));
    s.tonemap.manual_exposure = 0;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/output/exposure_compensation_ev: must be in [-20, 20], got 39"));
    s = d; s.tonemap.curve = (atmos_tone_curve)3;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/output/tone_curve"));
    s = d; s.png_bits = 12;
    CHECK(atmos_scene_validate(ctx, &s, "cli") == ATMOS_E_INVALID_ARG && contains(atmos_context_error(ctx), "/output/png_bits: must be 8 or 16, got 12"));
    CHECK(atmos_scene_validate(ctx, NULL, "cli") == ATMOS_E_INVALID_ARG);
}

static void test_load(void)
{
    char path[512];
    atmos_scene s;
    test_tmp_path(path, sizeof path, "test_scene_full.json");
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f) return;
    fputs(full_scene, f);
    fclose(f);
    CHECK_OK(atmos_scene_load(ctx, path, &s));
    CHECK(s.width == 1024 && s.camera.fov_deg == 75.5 && strcmp(s.name, "clear noon sky") == 0);

    /* Messages name the file. */
    f = fopen(path, "wb");
    fputs("{\n  \"camera\": {\"fov_deg\": 270}\n}\n", f);
    fclose(f);
    CHECK(atmos_scene_load(ctx, path, &s) == ATMOS_E_INVALID_ARG);
    char expect[600];
    snprintf(expect, sizeof expect, "%s: /camera/fov_deg: must be in (0, 180)", path);
    CHECK(contains(atmos_context_error(ctx), expect));

    test_tmp_path(path, sizeof path, "does-not-exist/scene.json");
    CHECK(atmos_scene_load(ctx, path, &s) == ATMOS_E_IO);
    CHECK(contains(atmos_context_error(ctx), path) && contains(atmos_context_error(ctx), "No such file or directory"));
    test_tmp_path(path, sizeof path, "");
    CHECK(atmos_scene_load(ctx, path, &s) == ATMOS_E_IO); /* a directory */
    CHECK(contains(atmos_context_error(ctx), "Is a directory"));
    CHECK(atmos_scene_load(ctx, NULL, &s) == ATMOS_E_INVALID_ARG);

    /* a path of ATMOS_SCENE_PATH_MAX bytes or more ("./" repeated): kept for messages as "..."
     * and its end */
    char dir[512], lng[1400];
    test_tmp_path(dir, sizeof dir, "");
    int o = snprintf(lng, sizeof lng, "%s/", dir);
    while (o < ATMOS_SCENE_PATH_MAX + 40) o += snprintf(lng + o, sizeof lng - (size_t)o, "./");
    snprintf(lng + o, sizeof lng - (size_t)o, "test_scene_long.json");
    f = fopen(lng, "wb");
    CHECK(f != NULL);
    if (!f) return;
    fputs("{}\n", f);
    fclose(f);
    CHECK_OK(atmos_scene_load(ctx, lng, &s));
    CHECK(strlen(s.file) == ATMOS_SCENE_PATH_MAX - 1 && !strncmp(s.file, "...", 3));
    CHECK(strlen(s.file) > 22 && !strcmp(s.file + strlen(s.file) - 22, "./test_scene_long.json"));
    remove(lng);
}

static void test_sun_direction(void)
{
    atmos_scene s;
    double dir[3], e = -1, a = -1, ref[3];
    atmos_scene_defaults(&s);
    CHECK_OK(atmos_scene_sun_direction(ctx, &s, dir, &e, &a));
    atmos_direction_from_angles(22, 235, ref);
    CHECK(vdiff(dir, ref) < 1e-12);
    CHECK(e == 22 && a == 235);
    /* South-west and above the horizon: x < 0 (west), z > 0 (south), y > 0. */
    CHECK(dir[0] < 0 && dir[1] > 0 && dir[2] > 0);
    CHECK_NEAR(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2], 1, 1e-12);
    CHECK_OK(parse("{\"sun\": {\"elevation_deg\": 90, \"azimuth_deg\": 0}}", &s));
    CHECK_OK(atmos_scene_sun_direction(ctx, &s, dir, NULL, NULL));
    CHECK_NEAR(dir[1], 1, 1e-12);
    CHECK_OK(parse("{\"sun\": {\"elevation_deg\": 0, \"azimuth_deg\": 90}}", &s));
    CHECK_OK(atmos_scene_sun_direction(ctx, &s, dir, NULL, NULL));
    CHECK_NEAR(dir[0], 1, 1e-12); /* due east */
    s.sun.azimuth_deg = NAN;
    CHECK(atmos_scene_sun_direction(ctx, &s, dir, NULL, NULL) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_scene_sun_direction(ctx, NULL, dir, NULL, NULL) == ATMOS_E_INVALID_ARG);
}

/* "animation": frames interpolate the sun between the scene's and the end. */
static void test_animation(void)
{
    atmos_scene s, f;
    /* Time: 5 frames from 23:00 to 01:00 the next day (across midnight and a month end). */
    CHECK_OK(parse("{\"sun\": {\"time\": \"2026-06-30T23:00:00Z\", \"latitude_deg\": 40, \"longitude_deg\": -105},"
                   " \"animation\": {\"frames\": 5, \"time_end\": \"2026-07-01T01:00:00Z\"}}", &s));
    CHECK(s.animation.frames == 5 && s.animation.time_end_set && !s.animation.elevation_end_set);
    CHECK(s.animation.exposure_per_frame == 0); /* "exposure": "locked" unless told */
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 0, &f));
    CHECK(f.sun.time.day == 30 && f.sun.time.hour == 23 && f.sun.time.minute == 0 && f.animation.frames == 0);
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 1, &f));
    CHECK(f.sun.time.month == 6 && f.sun.time.day == 30 && f.sun.time.hour == 23 && f.sun.time.minute == 30);
    CHECK_NEAR(f.sun.time.second, 0, 1e-4);
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 2, &f));
    CHECK(f.sun.time.year == 2026 && f.sun.time.month == 7 && f.sun.time.day == 1 && f.sun.time.hour == 0 &&
          f.sun.time.minute == 0);
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 4, &f));
    CHECK(f.sun.time.month == 7 && f.sun.time.day == 1 && f.sun.time.hour == 1 && f.sun.time.minute == 0 &&
          f.sun.time.second == 0);
    CHECK_OK(atmos_scene_validate(ctx, &f, "frame"));
    CHECK(atmos_scene_animation_frame(ctx, &s, 5, &f) == ATMOS_E_INVALID_ARG);
    CHECK(atmos_scene_animation_frame(ctx, &s, -1, &f) == ATMOS_E_INVALID_ARG);
    CHECK_OK(parse("{\"sun\": {\"elevation_deg\": 5, \"azimuth_deg\": 90},"
                   " \"animation\": {\"frames\": 2, \"elevation_end_deg\": 1, \"exposure\": \"per_frame\"}}", &s));
    CHECK(s.animation.exposure_per_frame == 1);
    CHECK_OK(parse("{\"sun\": {\"elevation_deg\": 5, \"azimuth_deg\": 90},"
                   " \"animation\": {\"frames\": 2, \"elevation_end_deg\": 1, \"exposure\": \"locked\"}}", &s));
    CHECK(s.animation.exposure_per_frame == 0);
    /* The animation's exposure limit: EV100 -2 unless told, kept by each frame. */
    CHECK(s.animation.exposure_limit_ev == ATMOS_SCENE_EXPOSURE_LIMIT_EV && ATMOS_SCENE_EXPOSURE_LIMIT_EV == -2.0);
    CHECK_OK(parse("{\"sun\": {\"elevation_deg\": 5, \"azimuth_deg\": 90},"
                   " \"animation\": {\"frames\": 2, \"elevation_end_deg\": 1, \"exposure_limit_ev\": 3.5}}", &s));
    CHECK(s.animation.exposure_limit_ev == 3.5);
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 1, &f));
    CHECK(f.animation.exposure_limit_ev == 3.5 && f.animation.frames == 0);
    /* Across a year end, backwards in time. */
    CHECK_OK(parse("{\"sun\": {\"time\": \"2027-01-01T00:30:00Z\", \"latitude_deg\": 40, \"longitude_deg\": -105},"
                   " \"animation\": {\"frames\": 2, \"time_end\": \"2026-12-31T23:30:00Z\"}}", &s));
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 1, &f));
    CHECK(f.sun.time.year == 2026 && f.sun.time.month == 12 && f.sun.time.day == 31 && f.sun.time.hour == 23 &&
          f.sun.time.minute == 30);
    /* Angles: elevation linearly, azimuth the shorter way (350 -> 30 passes north). */
    CHECK_OK(parse("{\"sun\": {\"elevation_deg\": 10, \"azimuth_deg\": 350},"
                   " \"animation\": {\"frames\": 5, \"elevation_end_deg\": -2, \"azimuth_end_deg\": 30}}", &s));
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 1, &f));
    CHECK_NEAR(f.sun.elevation_deg, 7, 1e-12);
    CHECK_NEAR(f.sun.azimuth_deg, 0, 1e-9);
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 2, &f));
    CHECK_NEAR(f.sun.azimuth_deg, 10, 1e-9);
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 4, &f));
    CHECK_NEAR(f.sun.elevation_deg, -2, 1e-12);
    CHECK_NEAR(f.sun.azimuth_deg, 30, 1e-9);
    /* Only the elevation moves when only it is given. */
    CHECK_OK(parse("{\"sun\": {\"elevation_deg\": 10, \"azimuth_deg\": 100}, \"animation\": {\"frames\": 3, \"elevation_end_deg\": 0}}", &s));
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 1, &f));
    CHECK(f.sun.elevation_deg == 5 && f.sun.azimuth_deg == 100);
    /* No animation: one frame, the scene itself. */
    atmos_scene_defaults(&s);
    CHECK_OK(atmos_scene_animation_frame(ctx, &s, 0, &f));
    CHECK(memcmp(&s, &f, sizeof s) == 0);
    CHECK(atmos_scene_animation_frame(ctx, &s, 1, &f) == ATMOS_E_INVALID_ARG);
    /* A one-frame animation needs no end. */
    CHECK_OK(parse("{\"animation\": {\"frames\": 1}}", &s));
    /* Validation of scenes changed in code. */
    atmos_scene_defaults(&s);
    s.animation.frames = 3;
    CHECK(atmos_scene_validate(ctx, &s, "code") == ATMOS_E_INVALID_ARG);
    CHECK(contains(atmos_context_error(ctx), "code: /animation: 3 frames need an end"));
    s.animation.time_end_set = 1;
    CHECK(atmos_scene_validate(ctx, &s, "code") == ATMOS_E_INVALID_ARG);
    CHECK(contains(atmos_context_error(ctx), "/animation/time_end: needs a sun given by time"));
    s.animation.time_end_set = 0;
    s.animation.frames = ATMOS_SCENE_MAX_FRAMES + 1;
    CHECK(atmos_scene_validate(ctx, &s, "code") == ATMOS_E_INVALID_ARG);
}

/* Every malformed file kept in tests/crashers/scene must be refused (the replay
 * test only shows they do not crash). */
static void test_crashers(void)
{
    const char *root = getenv("ATMOS_SOURCE_DIR");
    if (!root || !*root) {
        printf("ATMOS_SOURCE_DIR not set: crasher files skipped\n");
        return;
    }
    char dir[512], path[1024];
    snprintf(dir, sizeof dir, "%s/tests/crashers/scene", root);
    DIR *d = opendir(dir);
    CHECK(d != NULL);
    if (!d) return;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        atmos_scene s;
        atmos_status st = atmos_scene_load(ctx, path, &s);
        CHECK_MSG(st == ATMOS_E_FORMAT || st == ATMOS_E_LIMIT || st == ATMOS_E_INVALID_ARG,
                  "%s: %s", path, atmos_status_string(st));
        CHECK_MSG(contains(atmos_context_error(ctx), path), "%s: message \"%s\"", path, atmos_context_error(ctx));
        n++;
    }
    closedir(d);
    CHECK(n >= 4);
    printf("%d crasher files refused\n", n);
}

/* Files named "data:..." are read from $ATMOS_DATA; relative files from the scene's folder. */
static void test_data_paths(void)
{
    char dir[512], file[600], expect[700];
    test_tmp_path(dir, sizeof dir, "");
    snprintf(file, sizeof file, "%s/test_scene_data.vdb", dir);
    FILE *f = fopen(file, "wb");
    CHECK(f != NULL);
    if (!f) return;
    fputs("not read", f);
    fclose(f);
    setenv("ATMOS_DATA", dir, 1);
    const char *text = "{\"volume\": {\"file\": \"data:test_scene_data.vdb\"}}";
    atmos_scene s;
    CHECK_OK(atmos_scene_parse_file(ctx, text, strlen(text), "some/folder/scene.json", NULL, 0, &s));
    CHECK_MSG(!strcmp(s.volume.source, file), "data: path %s, expected %s", s.volume.source, file);
    const char *rel = "{\"volume\": {\"file\": \"clouds/c.vdb\"}}";
    CHECK_OK(atmos_scene_parse_file(ctx, rel, strlen(rel), "some/folder/scene.json", NULL, 0, &s));
    CHECK(!strcmp(s.volume.source, "some/folder/clouds/c.vdb"));
    const char *missing = "{\"atmosphere\": {\"ground_map\": \"data:nothing/here.jpg\"}}";
    CHECK(atmos_scene_parse_file(ctx, missing, strlen(missing), "scene.json", NULL, 0, &s) == ATMOS_E_IO);
    snprintf(expect, sizeof expect, "%s/nothing/here.jpg", dir);
    CHECK(contains(atmos_context_error(ctx), "/atmosphere/ground_map") && contains(atmos_context_error(ctx), expect) &&
          contains(atmos_context_error(ctx), "ATMOS_DATA"));
    unsetenv("ATMOS_DATA");
    remove(file);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_defaults();
    test_full_scene();
    test_absent_keys();
    test_bad_scenes();
    test_lights();
    test_limits();
    test_validate();
    test_load();
    test_data_paths();
    test_sun_direction();
    test_animation();
    test_crashers();
    atmos_context_destroy(ctx);
    return test_summary("test_scene");
}
