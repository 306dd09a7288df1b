/* The optical depth of a volume along every pixel's ray: a key for error analyses by
 * optical depth (atmos compare --by). */
#include "core/internal.h"

#include <math.h>

atmos_status atmos_render_optical_depth(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                              const double *sigma_ext, const double offset_m[3], atmos_image **out)
{
    if (!scene || !volume || !sigma_ext || !offset_m || !out)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "optical depth image: missing argument");
    *out = NULL;
    atmos_camera cam;
    atmos_status st = atmos_camera_init(ctx, &scene->camera, scene->width, scene->height, &cam);
    if (st != ATMOS_OK) return st;
    atmos_image *img = NULL;
    if ((st = atmos_image_create(ctx, scene->width, scene->height, 1, &img)) != ATMOS_OK) return st;
    const double o[3] = {cam.position[0] - offset_m[0], cam.position[1] - offset_m[1], cam.position[2] - offset_m[2]};
    const int W = scene->width, H = scene->height;
    /* Each pixel is written by one iteration: the image is the same on any thread count. */
#pragma omp parallel for schedule(dynamic, 4) num_threads(atmos__threads(ctx))
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double d[3];
            float tau = 0.0f;
            if (atmos_camera_ray(&cam, x + 0.5, y + 0.5, d))
                tau = (float)atmos_volume_optical_depth(volume, sigma_ext, o, d, 0.0, INFINITY);
            img->pixels[(size_t)y * W + x] = tau;
        }
    *out = img;
    return ATMOS_OK;
}
