/* The shipped scenes and what they rely on:
 *  - every .json file in scenes/ parses and validates (a scene that a rule change refuses fails here,
 *    not in a user's hands; one whose data: file is missing from the data folder is skipped);
 *  - a generated volume's "particle" names its cloud droplets' type (Fig. 4's glory droplets):
 *    the optics of its "cloud" field are that type's, not the "cloud" preset's; a -D that
 *    replaces a file source by a generator keeps the scene's "particle";
 *  - a volume file framed with no camera lies over the round planet's ground: its box's
 *    bottom is at its own height above the sphere (centre (0, -R, 0)), not tens of km above. */
#include "atmos/atmos.h"
#include "test.h"

#include <dirent.h>
#include <string.h>

static atmos_context *ctx;

static void every_scene_parses(void)
{
    const char *src = getenv("ATMOS_SOURCE_DIR");
    char dir[1024], path[2048];
    snprintf(dir, sizeof dir, "%s/scenes", src ? src : ".");
    DIR *d = opendir(dir);
    CHECK_MSG(d != NULL, "cannot open %s", dir);
    if (!d) return;
    int n = 0, skipped = 0;
    for (struct dirent *e; (e = readdir(d));) {
        const size_t l = strlen(e->d_name);
        if (l < 6 || strcmp(e->d_name + l - 5, ".json")) continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        atmos_scene s;
        atmos_status st = atmos_scene_load(ctx, path, &s);
        if (st == ATMOS_E_IO && strstr(atmos_context_error(ctx), "ATMOS_DATA")) { /* real data not here */
            skipped++;
            continue;
        }
        if (st == ATMOS_OK) st = atmos_scene_validate(ctx, &s, path);
        CHECK_MSG(st == ATMOS_OK, "%s: %s", e->d_name, atmos_context_error(ctx));
        n++;
    }
    closedir(d);
    CHECK_MSG(n >= 20, "only %d scenes read", n);
    printf("every scene: %d parsed and valid, %d skipped (their data is not in the data folder)\n", n, skipped);
}

/* The largest extinction cross-section of a phase table over its wavelengths. */
static double sigma_ext(const atmos_phase_table *t)
{
    double m = 0;
    for (int k = 0; k < atmos_phase_table_wavelength_count(t); k++) {
        double e = 0, s = 0;
        atmos_phase_table_cross_sections(t, k, &e, &s);
        m = e > m ? e : m;
    }
    return m;
}

static atmos_volume *small_volume(double voxel_m, const int dims[3], const double origin[3])
{
    atmos_volume_desc vd = {{dims[0], dims[1], dims[2]}, voxel_m, {origin[0], origin[1], origin[2]}, {0}, 0, 0};
    atmos_volume *v = NULL;
    int f = -1;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "cloud", &f));
    CHECK_OK(atmos_volume_set(ctx, v, f, dims[0] / 2, dims[1] / 2, dims[2] / 2, 1e8f));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    return v;
}

static void generated_particle(void)
{
    const char *src = getenv("ATMOS_SOURCE_DIR");
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/fig04_glory_cumulus.json", src ? src : ".");
    atmos_scene s;
    CHECK_OK(atmos_scene_load(ctx, path, &s));
    CHECK(!strcmp(s.volume.particle, "glory_droplets") && !strncmp(s.volume.source, "generate:", 9));
    const int dims[3] = {2, 2, 2};
    const double o[3] = {0, 1000, 0};
    atmos_volume *v = small_volume(100, dims, o);
    atmos_volume_optics with = {0}, without = {0};
    CHECK_OK(atmos_volume_optics_build(ctx, &s, v, 0, &with));
    s.volume.particle[0] = '\0';
    CHECK_OK(atmos_volume_optics_build(ctx, &s, v, 0, &without));
    /* the glory droplets' own table */
    atmos_particle_desc pd;
    atmos_wavelengths wl;
    atmos_phase_table *t = NULL;
    atmos_phase_table_desc td = {0};
    CHECK_OK(atmos_scene_particle(ctx, &s, "glory_droplets", &pd));
    CHECK_OK(atmos_scene_wavelengths(ctx, &s, &wl));
    CHECK_OK(atmos_phase_table_build(ctx, &pd, &wl, &td, &t));
    CHECK(with.count == 1 && without.count == 1 && t);
    if (with.count == 1 && without.count == 1 && t) {
        CHECK_REL(sigma_ext(with.phase[0]), sigma_ext(t), 1e-9);
        CHECK_MSG(fabs(sigma_ext(without.phase[0]) / sigma_ext(t) - 1) > 0.05, "cloud %g, glory droplets %g",
                  sigma_ext(without.phase[0]), sigma_ext(t));
    }
    atmos_phase_table_destroy(t);
    atmos_volume_optics_free(&with);
    atmos_volume_optics_free(&without);
    atmos_volume_destroy(v);
    /* -D volume.generate over a file source: the file's "particle" (its field's type) goes with
     * it, not to the generated cloud's droplets; one set after the source is kept */
    const char *ov[] = {"volume.generate=cumulus", "volume.particle=snow"};
    const char *json = "{\"volume\": {\"file\": \"d.vdb\", \"particle\": \"ice\", \"grids\": [\"density\"]}}";
    CHECK_OK(atmos_scene_parse_with(ctx, json, strlen(json), "t.json", ov, 1, &s));
    CHECK_MSG(!strcmp(s.volume.source, "generate:cumulus") && !s.volume.particle[0], "particle '%s'",
              s.volume.particle);
    CHECK_OK(atmos_scene_parse_with(ctx, json, strlen(json), "t.json", ov, 2, &s));
    CHECK(!strcmp(s.volume.particle, "snow"));
    /* and back: -D volume.file over a generated cloud with its own droplets */
    const char *ovf[] = {"volume.file=d.vdb"};
    const char *gen = "{\"volume\": {\"generate\": \"cumulus\", \"particle\": \"ice\"}}";
    CHECK_OK(atmos_scene_parse_with(ctx, gen, strlen(gen), "t.json", ovf, 1, &s));
    CHECK_MSG(!s.volume.particle[0], "particle '%s'", s.volume.particle);
}

static void framed_over_the_ground(void)
{
    const char *tmp = getenv("ATMOS_TEST_TMP");
    char path[1024];
    snprintf(path, sizeof path, "%s/framed.json", tmp ? tmp : ".");
    const int dims[3] = {16, 4, 16};
    const double o[3] = {-3000, 5000, 2000}; /* 16 km wide, from 5 km up, off the origin */
    atmos_volume *v = small_volume(1000, dims, o);
    CHECK_OK(atmos_volume_write_raw(ctx, v, path));
    atmos_volume_destroy(v);
    atmos_scene s;
    atmos_scene_defaults(&s);
    snprintf(s.volume.source, sizeof s.volume.source, "%s", path);
    s.renderer = ATMOS_RENDERER_SLICE;
    atmos_volume *f = NULL;
    CHECK_OK(atmos_scene_frame_volume_file(ctx, &s, NAN, &f));
    CHECK(f != NULL && s.volume.placed && s.camera_given);
    const double R = 6360e3, *p = s.volume.position_m;
    /* the bottom's centre: its height over the sphere is its y (the box's own 5 km) */
    const double over = hypot(hypot(p[0], p[2]), p[1] + R) - R;
    CHECK_NEAR(p[1], 5000, 1e-6);
    CHECK_NEAR(over, p[1], 1.0);
    atmos_volume_destroy(f);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    every_scene_parses();
    generated_particle();
    framed_over_the_ground();
    atmos_context_destroy(ctx);
    return test_summary("test_scene_shipped");
}
