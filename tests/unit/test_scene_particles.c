/* User-defined particle types in scene files ("particles"): parsing, validation
 * messages, lookup by name, and tables built from them. */
#include "atmos/atmos.h"
#include "test.h"

static atmos_context *ctx;

static atmos_status parse(const char *json, atmos_scene *s)
{
    atmos_context_clear_error(ctx);
    return atmos_scene_parse(ctx, json, strlen(json), "scene.json", s);
}

static void test_valid(void)
{
    atmos_scene s;
    const char *json =
        "{\"particles\": {"
        " \"fog\": {\"kind\": \"water\", \"size\": {\"distribution\": \"lognormal\", \"radius_m\": 4e-6, \"sigma\": 0.35,"
        "          \"r_max_m\": 5e-5}, \"sigma_ext_m2\": 1e-10},"
        " \"drizzle\": {\"kind\": \"water\", \"size\": {\"distribution\": \"gamma\", \"radius_m\": 5e-5, \"alpha\": 2, \"gamma\": 1}},"
        " \"haze\": {\"kind\": \"analytic\", \"lobes\": [{\"type\": \"hg\", \"g\": 0.7, \"weight\": 0.9},"
        "          {\"type\": \"cornette_shanks\", \"g\": -0.3, \"weight\": 0.1}], \"albedo\": 0.95},"
        " \"plates\": {\"preset\": \"ice\", \"habit\": \"plate\", \"aspect_ratio\": 0.2, \"rays\": 100000},"
        " \"_note\": \"ignored\"}}";
    CHECK_OK(parse(json, &s));
    CHECK(s.particle_count == 4);
    atmos_particle_desc p;
    CHECK_OK(atmos_scene_particle(ctx, &s, "fog", &p));
    CHECK(p.kind == ATMOS_PARTICLE_WATER && p.size.kind == ATMOS_SIZE_LOGNORMAL);
    CHECK(p.size.r_m == 4e-6 && p.size.sigma == 0.35 && p.size.r_max == 5e-5 && p.sigma_ext_m2 == 1e-10);
    CHECK(!strcmp(p.name, "fog"));
    CHECK_OK(atmos_scene_particle(ctx, &s, "drizzle", &p));
    CHECK(p.size.kind == ATMOS_SIZE_GAMMA && p.size.alpha == 2 && p.size.gamma == 1);
    CHECK_OK(atmos_scene_particle(ctx, &s, "haze", &p));
    CHECK(p.kind == ATMOS_PARTICLE_ANALYTIC && p.analytic.count == 2 && p.analytic.kind[1] == ATMOS_PHASE_CORNETTE_SHANKS);
    CHECK(p.analytic.g[0] == 0.7 && p.analytic.weight[1] == 0.1 && p.albedo == 0.95);
    /* a preset as the starting point keeps the preset's other settings */
    atmos_particle_desc ice;
    CHECK_OK(atmos_particle_preset(ctx, "ice", &ice));
    CHECK_OK(atmos_scene_particle(ctx, &s, "plates", &p));
    CHECK(p.kind == ATMOS_PARTICLE_ICE && p.habit == ATMOS_CRYSTAL_PLATE && p.aspect_ratio == 0.2 && p.rays == 100000);
    CHECK(p.sigma_ext_m2 == ice.sigma_ext_m2);
    /* names that are not in the scene fall back to the presets */
    CHECK_OK(atmos_scene_particle(ctx, &s, "rain", &p));
    CHECK(p.kind == ATMOS_PARTICLE_WATER);
    CHECK(atmos_scene_particle(ctx, &s, "nope", &p) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "fog") && strstr(atmos_context_error(ctx), "cloud"));

    /* A user-defined analytic mixture builds a normalised table whose g is the
     * weighted mean of the lobes' mean cosines (HG: g; Cornette-Shanks: 3g(4+g^2)/(5(2+g^2))). */
    CHECK_OK(atmos_scene_particle(ctx, &s, "haze", &p));
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_phase_table *t = NULL;
    atmos_phase_table_desc td = {1};
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (t) {
        double gcs = 3 * -0.3 * (4 + 0.09) / (5 * (2 + 0.09));
        CHECK_NEAR(atmos_phase_table_g(t, 1), 0.9 * 0.7 + 0.1 * gcs, 1e-4);
        CHECK_NEAR(atmos_phase_table_albedo(t, 1), 0.95, 1e-12);
    }
    atmos_phase_table_destroy(t);
    /* "albedo": 0 is a purely absorbing medium, not "computed". */
    p.albedo = 0;
    p.albedo_set = 1;
    t = NULL;
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (t) CHECK(atmos_phase_table_albedo(t, 0) == 0.0 && atmos_phase_table_albedo(t, 2) == 0.0);
    atmos_phase_table_destroy(t);
    p.albedo_set = 0;
    t = NULL;
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (t) CHECK(atmos_phase_table_albedo(t, 0) == 1.0);
    atmos_phase_table_destroy(t);
}

static void test_errors(void)
{
    static const struct {
        const char *json;
        const char *expect;
    } cases[] = {
        {"{\"particles\": []}", "/particles: expected an object"},
        {"{\"particles\": {\"a b\": {\"kind\": \"air\"}}}", "/particles/a b: a particle name"},
        {"{\"particles\": {\"x\": {}}}", "/particles/x: needs \"kind\" or \"preset\""},
        {"{\"particles\": {\"x\": {\"kind\": \"plasma\"}}}", "/particles/x/kind: must be one of air, water, ice, snow, analytic"},
        {"{\"particles\": {\"x\": {\"kind\": \"water\"}}}", "/particles/x: water particles need size.radius_m"},
        {"{\"particles\": {\"x\": {\"kind\": \"water\", \"size\": {\"distribution\": \"lognormal\", \"radius_m\": 1e-5}}}}",
         "a lognormal size needs size.sigma"},
        {"{\"particles\": {\"x\": {\"kind\": \"water\", \"size\": {\"radius_m\": 0.5}}}}", "/particles/x/size/radius_m: must be in (0, 0.005]"},
        {"{\"particles\": {\"x\": {\"kind\": \"water\", \"size\": {\"radius\": 1e-5}}}}", "/particles/x/size/radius: unknown key"},
        {"{\"particles\": {\"x\": {\"kind\": \"analytic\"}}}", "analytic particles need \"lobes\""},
        {"{\"particles\": {\"x\": {\"kind\": \"analytic\", \"lobes\": [{\"type\": \"hg\", \"g\": 1}]}}}", "/particles/x/lobes/0/g: must be in (-1, 1)"},
        {"{\"particles\": {\"x\": {\"kind\": \"analytic\", \"lobes\": [{\"g\": 0.5}]}}}", "/particles/x/lobes/0: missing key \"type\""},
        {"{\"particles\": {\"x\": {\"kind\": \"analytic\", \"lobes\": [{\"type\": \"hg\", \"weight\": 0}]}}}", "at least one lobe with weight > 0"},
        {"{\"particles\": {\"x\": {\"preset\": \"hail\"}}}", "/particles/x/preset: unknown preset"},
        {"{\"particles\": {\"x\": {\"kind\": \"ice\", \"albedo\": 2}}}", "/particles/x/albedo: must be in [0, 1]"},
        /* the ranges the crystal tables take, told when the scene is read, not when its table is built */
        {"{\"particles\": {\"x\": {\"kind\": \"snow\", \"distortion\": 1.2}}}", "/particles/x/distortion: must be in [0, 1]"},
        {"{\"particles\": {\"x\": {\"kind\": \"ice\", \"aspect_ratio\": 0.005}}}", "/particles/x/aspect_ratio: must be in [0.01, 100]"},
        {"{\"particles\": {\"x\": {\"kind\": \"air\"}, \"x\": {\"kind\": \"air\"}}}", "/particles/x: duplicate key"},
        {"{\"particles\": {\"a\": {\"kind\": \"air\"}, \"b\": {\"kind\": \"air\"}, \"c\": {\"kind\": \"air\"}, \"d\": {\"kind\": \"air\"},"
         " \"e\": {\"kind\": \"air\"}, \"f\": {\"kind\": \"air\"}, \"g\": {\"kind\": \"air\"}, \"h\": {\"kind\": \"air\"}, \"i\": {\"kind\": \"air\"}}}",
         "/particles/i: at most 8 particle types"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        atmos_scene s;
        atmos_status st = parse(cases[i].json, &s);
        CHECK_MSG(st == ATMOS_E_INVALID_ARG, "case %zu: status %s", i, atmos_status_string(st));
        CHECK_MSG(strstr(atmos_context_error(ctx), cases[i].expect) != NULL, "case %zu: message \"%s\" lacks \"%s\"", i,
                  atmos_context_error(ctx), cases[i].expect);
    }
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_valid();
    test_errors();
    atmos_context_destroy(ctx);
    return test_summary("test_scene_particles");
}
