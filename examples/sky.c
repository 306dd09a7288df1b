/* The sky of a scene as an image: the built-in default scene (or SCENE.json) rendered without
 * its volume, written as a linear HDR PFM (sRGB primaries) and a tone-mapped PNG, and the
 * radiance at the image's centre printed per wavelength.
 *
 *   sky [SCENE.json] [--size W H] [--out PREFIX]
 *
 * Writes PREFIX.pfm and PREFIX.png (default prefix: "sky"). */
#include <atmos/atmos.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(atmos_context *ctx, atmos_status st)
{
    fprintf(stderr, "sky: %s\n", ctx ? atmos_context_error(ctx) : atmos_status_string(st));
    return 1;
}

/* Writes the spectral image as PREFIX.pfm (linear sRGB) and PREFIX.png (tone-mapped). */
static atmos_status write_outputs(atmos_context *ctx, const atmos_scene *scene, const atmos_image *img,
                                  const atmos_wavelengths *wl, const char *prefix)
{
    char path[4096];
    atmos_image *lin = NULL, *disp = NULL;
    atmos_status st = atmos_image_to_srgb(ctx, img, wl, &lin);
    if (st == ATMOS_OK) {
        snprintf(path, sizeof path, "%s.pfm", prefix);
        st = atmos_write_pfm(ctx, lin, path);
    }
    if (st == ATMOS_OK) st = atmos_tonemap(ctx, lin, &scene->tonemap, &disp);
    if (st == ATMOS_OK) {
        snprintf(path, sizeof path, "%s.png", prefix);
        st = atmos_write_png(ctx, disp, path, 8);
    }
    atmos_image_destroy(lin);
    atmos_image_destroy(disp);
    return st;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *prefix = "sky";
    int w = 0, h = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 2 < argc) w = atoi(argv[i + 1]), h = atoi(argv[i + 2]), i += 2;
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) prefix = argv[++i];
        else if (argv[i][0] != '-') scene_path = argv[i];
        else return fprintf(stderr, "usage: sky [SCENE.json] [--size W H] [--out PREFIX]\n"), 2;
    }
    atmos_context *ctx = NULL;
    atmos_status st = atmos_context_create(NULL, &ctx);
    if (st != ATMOS_OK) return fail(NULL, st);
    atmos_scene scene;
    if (scene_path) st = atmos_scene_load(ctx, scene_path, &scene);
    else atmos_scene_defaults(&scene);
    if (st == ATMOS_OK && (w || h)) {
        if (w < 1 || h < 1 || w > 8192 || h > 8192) return atmos_context_destroy(ctx), fprintf(stderr, "sky: bad --size\n"), 2;
        scene.width = w, scene.height = h;
    }
    atmos_image *img = NULL;
    atmos_render_info info;
    atmos_wavelengths wl;
    if (st == ATMOS_OK) st = atmos_render_sky(ctx, &scene, &img, &info);
    if (st == ATMOS_OK && scene.wavelengths == ATMOS_WAVELENGTHS_SPECTRAL) st = atmos_wavelengths_spectral(scene.spectral_samples, &wl);
    else atmos_wavelengths_rgb(&wl);
    if (st == ATMOS_OK) st = write_outputs(ctx, &scene, img, &wl, prefix);
    if (st == ATMOS_OK) {
        const float *px = img->pixels + ((size_t)(img->height / 2) * img->width + img->width / 2) * img->channels;
        printf("%dx%d in %.3f s, sun %.1f deg high; radiance at the centre:\n", img->width, img->height, info.seconds,
               info.sun_elevation_deg);
        for (int k = 0; k < wl.count; k++) printf("  %6.1f nm  %.6g W m^-2 sr^-1 nm^-1\n", wl.nm[k], px[k]);
    }
    int rc = st == ATMOS_OK ? 0 : fail(ctx, st);
    atmos_image_destroy(img);
    atmos_context_destroy(ctx);
    return rc;
}
