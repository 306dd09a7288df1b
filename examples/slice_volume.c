/* A cloud volume rendered by half-angle slicing (Riley et al. 2004): a file (.vdb with OpenVDB,
 * .nvdb, WRF/CM1 .nc, raw .json) or a generated cumulus, placed in front of the camera and
 * framed the way `atmos render --volume FILE` frames it, lit by the sun at the given
 * elevation. Writes a tone-mapped PNG and prints the volume's size and the render time.
 *
 *   slice_volume [VOLUME_FILE] [--sun ELEVATION_DEG] [--size W H] [-o OUT.png]
 *
 * Without a file: the generator's cumulus (seed 1). */
#include <atmos/atmos.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(atmos_context *ctx, atmos_status st)
{
    fprintf(stderr, "slice_volume: %s\n", ctx ? atmos_context_error(ctx) : atmos_status_string(st));
    return 1;
}

/* The scene: the defaults with the volume's source, the sun's elevation and the image size;
 * the camera framed on the loaded volume. */
static atmos_status make_scene(atmos_context *ctx, const char *file, double sun_deg, int w, int h, atmos_scene *scene,
                               atmos_volume **vol, double offset[3])
{
    atmos_scene_defaults(scene);
    snprintf(scene->volume.source, sizeof scene->volume.source, "%s", file ? file : "generate:cumulus");
    scene->renderer = ATMOS_RENDERER_SLICE;
    scene->sun.elevation_deg = sun_deg;
    if (w > 0) scene->width = w, scene->height = h;
    atmos_status st = atmos_scene_load_volume(ctx, scene, vol, offset);
    if (st == ATMOS_OK) atmos_scene_frame_volume(scene, *vol, offset, 10.0);
    return st;
}

/* Linear spectral image -> sRGB -> tone map -> PNG. */
static atmos_status write_png(atmos_context *ctx, const atmos_scene *scene, const atmos_image *img, const char *path)
{
    atmos_wavelengths wl;
    atmos_image *lin = NULL, *disp = NULL;
    atmos_wavelengths_rgb(&wl);
    atmos_status st = atmos_image_to_srgb(ctx, img, &wl, &lin);
    if (st == ATMOS_OK) st = atmos_tonemap(ctx, lin, &scene->tonemap, &disp);
    if (st == ATMOS_OK) st = atmos_write_png(ctx, disp, path, 8);
    atmos_image_destroy(lin);
    atmos_image_destroy(disp);
    return st;
}

/* A number in [lo, hi] from text ("abc", "30deg" and "" are refused). */
static int number_in(const char *text, double lo, double hi, double *v)
{
    char *end = NULL;
    *v = strtod(text, &end);
    return end != text && !*end && *v >= lo && *v <= hi;
}

int main(int argc, char **argv)
{
    const char *file = NULL, *out = "slice_volume.png";
    double sun = 30.0;
    int w = 0, h = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--sun") && i + 1 < argc) {
            if (!number_in(argv[++i], -90, 90, &sun))
                return fprintf(stderr, "slice_volume: --sun %s: expected an elevation in degrees, in [-90, 90]\n", argv[i]), 2;
        }
        else if (!strcmp(argv[i], "--size") && i + 2 < argc) w = atoi(argv[i + 1]), h = atoi(argv[i + 2]), i += 2;
        else if (!strcmp(argv[i], "-o") && i + 1 < argc) out = argv[++i];
        else if (argv[i][0] != '-') file = argv[i];
        else return fprintf(stderr, "usage: slice_volume [VOLUME_FILE] [--sun DEG] [--size W H] [-o OUT.png]\n"), 2;
    }
    if ((w || h) && (w < 1 || h < 1 || w > 8192 || h > 8192)) return fprintf(stderr, "slice_volume: bad --size\n"), 2;
    atmos_context *ctx = NULL;
    atmos_status st = atmos_context_create(NULL, &ctx);
    if (st != ATMOS_OK) return fail(NULL, st);
    atmos_scene scene;
    atmos_volume *vol = NULL;
    atmos_image *img = NULL;
    atmos_render_info info;
    atmos_slice_settings set;
    atmos_slice_defaults(&set);
    st = make_scene(ctx, file, sun, w, h, &scene, &vol, set.offset_m);
    if (st == ATMOS_OK) st = atmos_render_slice(ctx, &scene, vol, &set, &img, &info);
    if (st == ATMOS_OK) st = write_png(ctx, &scene, img, out);
    if (st == ATMOS_OK) {
        const atmos_volume_desc *d = atmos_volume_get_desc(vol);
        printf("%s: %d x %d x %d voxels of %g m, %d field(s); rendered %dx%d in %.3f s -> %s\n",
               file ? file : "generated cumulus", d->dims[0], d->dims[1], d->dims[2], d->voxel_size_m,
               atmos_volume_field_count(vol), scene.width, scene.height, info.seconds, out);
    }
    int rc = st == ATMOS_OK ? 0 : fail(ctx, st);
    atmos_image_destroy(img);
    atmos_volume_destroy(vol);
    atmos_context_destroy(ctx);
    return rc;
}
