/* The clouds of a scene's spherical atmosphere as an ordinary volume (atmos_scene_cloud_volume):
 * a box of the world frame (the local tangent frame at the origin: x east, y up, z south)
 * whose voxels hold the cloud layer's extinction at their centres
 * (atmos_atmosphere_cloud_extinction) as number densities of the "cloud" particle:
 * density = extinction / sigma_ext of the preset (Riley et al. 2004 Table 2), so that the slice
 * renderer and the path tracer draw the same optical depths as the cloud spheres. The box
 * reaches down to the layer's base at its corners, where the curved layer has dropped
 * (x^2 + z^2) / (2 R) below the tangent plane. */
#include "scene/scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double atmos_scene_cloud_volume_across(double half_width_m, double voxel_size_m)
{
    return half_width_m > 0 && voxel_size_m > 0 ? ceil(2.0 * half_width_m / voxel_size_m) : 0;
}

atmos_status atmos_scene_cloud_volume(atmos_context *ctx, const atmos_scene *scene, const double centre_xz[2],
                                      double half_width_m, double voxel_size_m, atmos_volume **out)
{
    if (!scene || !out || !centre_xz) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "cloud volume: NULL argument");
    *out = NULL;
    if (!scene->earth.cloud_image[0])
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "cloud volume: the scene's atmosphere has no \"clouds\"");
    if (!(half_width_m > 0 && voxel_size_m > 0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "cloud volume: need a half width > 0 and a voxel size > 0");
    const double across = atmos_scene_cloud_volume_across(half_width_m, voxel_size_m);
    if (!(across <= ATMOS_CLOUD_VOLUME_MAX_ACROSS))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "cloud volume: a half width of %g m in voxels of %g m gives %.*g voxels across (allowed 1..%d)",
                            half_width_m, voxel_size_m, across < 1e9 ? 10 : 3, across, ATMOS_CLOUD_VOLUME_MAX_ACROSS);
    atmos_particle_desc cloud;
    atmos_status st = atmos_particle_preset(ctx, "cloud", &cloud);
    if (st) return st;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *atm = NULL;
    if ((st = atmos_scene_atmosphere_create(ctx, scene, &wl, &atm))) return st;
    const atmos_atmosphere_desc *ad = atmos_atmosphere_get_desc(atm);
    const double R = ad->planet_radius_m, base = ad->clouds.base_m, top = ad->clouds.top_m;
    const double cx = centre_xz[0], cz = centre_xz[1];
    const double far2 = (fabs(cx) + half_width_m) * (fabs(cx) + half_width_m) +
                        (fabs(cz) + half_width_m) * (fabs(cz) + half_width_m);
    const double y0 = floor((base - far2 / (2.0 * R)) / voxel_size_m) * voxel_size_m;
    const double tall = ceil((top - y0) / voxel_size_m); /* the curved layer's depth below the box's top */
    if (!(tall <= ATMOS_CLOUD_VOLUME_MAX_ACROSS)) {
        atmos_atmosphere_destroy(atm);
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "cloud volume: a box of half width %g m centred at (%g, %g) m reaches so far round the Earth "
                            "that the cloud layer falls %.3g m across it: %.3g voxels of %g m tall (allowed 1..%d); "
                            "centre it nearer the origin or make it smaller",
                            half_width_m, cx, cz, top - y0, tall, voxel_size_m, ATMOS_CLOUD_VOLUME_MAX_ACROSS);
    }
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = vd.dims[2] = (int)across;
    vd.dims[1] = (int)tall;
    vd.voxel_size_m = voxel_size_m;
    vd.origin_m[0] = cx - half_width_m, vd.origin_m[1] = y0, vd.origin_m[2] = cz - half_width_m;
    atmos_volume *v = NULL;
    float *plane = NULL;
    int field = 0;
    st = atmos_volume_create(ctx, &vd, &v);
    if (!st) st = atmos_volume_add_field(ctx, v, "cloud", "cloud", &field);
    const size_t nxy = (size_t)vd.dims[0] * (size_t)vd.dims[1];
    if (!st && !(plane = malloc(nxy * sizeof *plane))) st = atmos__error(ctx, ATMOS_E_NOMEM, "cloud volume: out of memory");
    for (int k = 0; !st && k < vd.dims[2]; k++) {
        for (int j = 0; j < vd.dims[1]; j++)
            for (int i = 0; i < vd.dims[0]; i++) {
                const double p[3] = {vd.origin_m[0] + (i + 0.5) * voxel_size_m, y0 + (j + 0.5) * voxel_size_m,
                                     vd.origin_m[2] + (k + 0.5) * voxel_size_m};
                plane[(size_t)j * vd.dims[0] + i] = (float)(atmos_atmosphere_cloud_extinction(atm, p) / cloud.sigma_ext_m2);
            }
        const int off[3] = {0, 0, k}, size[3] = {vd.dims[0], vd.dims[1], 1};
        st = atmos_volume_set_dense(ctx, v, field, off, size, plane, 1.0f);
    }
    if (!st) st = atmos_volume_finalize(ctx, v);
    free(plane);
    atmos_atmosphere_destroy(atm);
    if (st) {
        atmos_volume_destroy(v);
        return st;
    }
    *out = v;
    return ATMOS_OK;
}
