/* An orbit around a cloud from one plan: the scene is turned into a plan once (the volume
 * generated and placed, its optics tables built, the renderer's grids and buffers made), then
 * 36 frames are rendered from it with the camera 10 degrees further round each time. Only the
 * per-frame work is repeated. Writes orbit_NN.png (and orbit_NN.exr with --exr) and prints the
 * time of each frame.
 *
 *   orbit [SCENE.json] [--size N] [--frames N] [--out DIR] [--exr]
 *
 * Without a scene: a generated cumulus 4 km away, the sun 30 degrees high. */
#include <atmos/atmos.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *default_scene =
    "{\"name\": \"orbit\", \"image\": {\"width\": 320, \"height\": 200},"
    " \"camera\": {\"type\": \"pinhole\", \"position_m\": [0, 1200, 0], \"look_at_m\": [0, 1800, -4000], \"fov_deg\": 45},"
    " \"volume\": {\"generate\": \"cumulus\", \"seed\": 1, \"position_m\": [0, 1000, -4000]},"
    " \"sun\": {\"elevation_deg\": 30, \"azimuth_deg\": 200}}";

static int fail(atmos_context *ctx, atmos_status st)
{
    fprintf(stderr, "orbit: %s\n", ctx ? atmos_context_error(ctx) : atmos_status_string(st));
    return 1;
}

/* Writes frame i of the orbit: linear sRGB to EXR (optional), tone-mapped to PNG. */
static atmos_status write_frame(atmos_context *ctx, const atmos_plan *plan, const atmos_frame *f, const atmos_image *img,
                                const char *dir, int i, int exr)
{
    char path[4096];
    atmos_image *lin = NULL, *disp = NULL;
    atmos_status st = atmos_image_to_srgb(ctx, img, atmos_plan_wavelengths(plan), &lin);
    if (st == ATMOS_OK && exr) {
        snprintf(path, sizeof path, "%s/orbit_%02d.exr", dir, i);
        st = atmos_write_exr(ctx, lin, path, NULL);
    }
    if (st == ATMOS_OK) st = atmos_tonemap(ctx, lin, &f->tonemap, &disp);
    if (st == ATMOS_OK) {
        snprintf(path, sizeof path, "%s/orbit_%02d.png", dir, i);
        st = atmos_write_png(ctx, disp, path, 8);
    }
    atmos_image_destroy(lin);
    atmos_image_destroy(disp);
    return st;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *dir = ".";
    int size = 0, frames = 36, exr = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) dir = argv[++i];
        else if (!strcmp(argv[i], "--exr")) exr = 1;
        else if (argv[i][0] != '-') scene_path = argv[i];
        else return fprintf(stderr, "usage: orbit [SCENE.json] [--size N] [--frames N] [--out DIR] [--exr]\n"), 2;
    }
    if (frames < 1 || frames > 3600 || size < 0 || size > 4096) return fprintf(stderr, "orbit: bad --frames or --size\n"), 2;
    atmos_context *ctx = NULL;
    atmos_status st = atmos_context_create(NULL, &ctx);
    if (st != ATMOS_OK) return fail(NULL, st);
    atmos_scene scene;
    st = scene_path ? atmos_scene_load(ctx, scene_path, &scene)
                    : atmos_scene_parse(ctx, default_scene, strlen(default_scene), "orbit", &scene);
    if (st == ATMOS_OK && size) scene.width = size, scene.height = size * 5 / 8 > 0 ? size * 5 / 8 : 1;
    atmos_plan *plan = NULL;
    atmos_frame f;
    atmos_image *img = NULL;
    if (st == ATMOS_OK) st = atmos_plan_create(ctx, &scene, NULL, NULL, &plan); /* once */
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &scene, &f);
    if (st == ATMOS_OK) st = atmos_plan_image_create(plan, &f, &img);
    for (int i = 0; i < frames && st == ATMOS_OK; i++) {
        atmos_render_info info;
        if (i) atmos_frame_orbit(&f, plan, 360.0 / frames);
        st = atmos_plan_render(plan, &f, NULL, img, &info); /* only the frame's work */
        if (st == ATMOS_OK) st = write_frame(ctx, plan, &f, img, dir, i, exr);
        if (st == ATMOS_OK) printf("frame %2d: %.1f ms\n", i, 1e3 * info.seconds);
    }
    int rc = st == ATMOS_OK ? 0 : fail(ctx, st);
    atmos_image_destroy(img);
    atmos_plan_destroy(plan);
    atmos_context_destroy(ctx);
    return rc;
}
