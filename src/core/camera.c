/* Cameras: pinhole, equidistant fisheye, equirectangular. */
#include "core/pinhole.h"
#include "core/internal.h"
#include "core/vec.h"

#include <math.h>
#include <string.h>

void atmos_direction_from_angles(double elevation_deg, double azimuth_deg, double dir[3])
{
    double e = elevation_deg * ATMOS_DEG2RAD, a = azimuth_deg * ATMOS_DEG2RAD;
    double ce = cos(e);
    /* x east, y up, z south: north is -z, azimuth clockwise from north towards east. */
    dir[0] = ce * sin(a);
    dir[1] = sin(e);
    dir[2] = -ce * cos(a);
}

void atmos_direction_to_angles(const double dir[3], double *elevation_deg, double *azimuth_deg)
{
    double h = sqrt(dir[0] * dir[0] + dir[2] * dir[2]);
    double e = atan2(dir[1], h) * ATMOS_RAD2DEG;
    double a = h > 0 ? atan2(dir[0], -dir[2]) * ATMOS_RAD2DEG : 0.0;
    if (a < 0) a += 360.0;
    if (a >= 360.0) a -= 360.0;
    if (elevation_deg) *elevation_deg = e;
    if (azimuth_deg) *azimuth_deg = a;
}

void atmos_camera_defaults(atmos_camera_type type, const double position[3], atmos_camera_desc *out)
{
    memset(out, 0, sizeof *out);
    out->type = type;
    for (int i = 0; i < 3; i++) out->position[i] = out->look_at[i] = position[i];
    if (type == ATMOS_CAMERA_FISHEYE) {
        out->look_at[1] += 1.0; /* zenith */
        out->up[2] = -1.0;      /* north at the top */
        out->fov_deg = 180.0;
    } else {
        out->look_at[2] -= 1.0; /* north, level */
        out->up[1] = 1.0;
        out->fov_deg = type == ATMOS_CAMERA_PINHOLE ? 60.0 : 180.0;
    }
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    double r[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    o[0] = r[0], o[1] = r[1], o[2] = r[2];
}
static double norm3(double v[3])
{
    double l = sqrt(atmos__dot3(v, v));
    if (l > 0) v[0] /= l, v[1] /= l, v[2] /= l;
    return l;
}
static int finite3(const double v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

atmos_status atmos_camera_init(atmos_context *ctx, const atmos_camera_desc *desc, int width, int height,
                               atmos_camera *out)
{
    if (!desc || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera: missing description");
    if (width < 1 || height < 1 || width > ATMOS_IMAGE_MAX_DIM || height > ATMOS_IMAGE_MAX_DIM)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera: image size must be 1..%d pixels, got %dx%d",
                            ATMOS_IMAGE_MAX_DIM, width, height);
    if (desc->type != ATMOS_CAMERA_PINHOLE && desc->type != ATMOS_CAMERA_FISHEYE &&
        desc->type != ATMOS_CAMERA_EQUIRECT)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera/type: unknown camera type %d", (int)desc->type);
    if (!finite3(desc->position))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera/position_m: must be 3 finite numbers");
    if (!finite3(desc->look_at))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera/look_at_m: must be 3 finite numbers");
    if (!finite3(desc->up)) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera/up: must be 3 finite numbers");
    if (desc->position[1] < 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "camera/position_m: altitude (y) must be >= 0 (above the ground), got %g",
                            desc->position[1]);
    atmos_camera c;
    memset(&c, 0, sizeof c);
    c.type = desc->type;
    c.width = width;
    c.height = height;
    for (int i = 0; i < 3; i++) c.position[i] = desc->position[i];

    int fisheye = desc->type == ATMOS_CAMERA_FISHEYE;
    double fwd[3], up[3];
    int has_look = desc->look_at[0] != 0 || desc->look_at[1] != 0 || desc->look_at[2] != 0;
    if (has_look) {
        for (int i = 0; i < 3; i++) fwd[i] = desc->look_at[i] - desc->position[i];
    } else {
        fwd[0] = 0, fwd[1] = fisheye ? 1 : 0, fwd[2] = fisheye ? 0 : -1;
    }
    int has_up = desc->up[0] != 0 || desc->up[1] != 0 || desc->up[2] != 0;
    if (has_up) {
        for (int i = 0; i < 3; i++) up[i] = desc->up[i];
    } else if (fisheye && fabs(fwd[1]) > 0.99 * sqrt(atmos__dot3(fwd, fwd))) {
        up[0] = 0, up[1] = 0, up[2] = -1; /* looking up or down: north at the top */
    } else {
        up[0] = 0, up[1] = 1, up[2] = 0;
    }
    if (desc->type != ATMOS_CAMERA_EQUIRECT) {
        if (norm3(fwd) < 1e-9)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera/look_at_m: must differ from position_m");
        double right[3];
        cross3(fwd, up, right);
        if (norm3(right) < 1e-9)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "camera/up: must not be zero or parallel to the view direction");
        cross3(right, fwd, up);
        for (int i = 0; i < 3; i++) c.forward[i] = fwd[i], c.right[i] = right[i], c.up[i] = up[i];
    }
    double fov = desc->fov_deg;
    if (desc->type == ATMOS_CAMERA_PINHOLE) {
        if (fov == 0) fov = 60;
        if (!(fov > 0 && fov < 180))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera/fov_deg: must be in (0, 180) for a pinhole camera, got %g", fov);
        c.tan_half_fov = tan(0.5 * fov * ATMOS_DEG2RAD);
    } else if (fisheye) {
        if (fov == 0) fov = 180;
        if (!(fov > 0 && fov <= 360))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "camera/fov_deg: must be in (0, 360] for a fisheye camera, got %g", fov);
    } else {
        fov = 180;
    }
    c.fov_deg = fov;
    *out = c;
    return ATMOS_OK;
}

double atmos__camera_pinhole_u(const atmos_camera *cam, double x)
{
    return (2.0 * x - cam->width) / cam->height * cam->tan_half_fov;
}

double atmos__camera_pinhole_v(const atmos_camera *cam, double y)
{
    const double H = cam->height;
    return (H - 2.0 * y) / H * cam->tan_half_fov;
}

void atmos__camera_pinhole_dir(const atmos_camera *cam, double u, double v, double dir[3])
{
    for (int i = 0; i < 3; i++) dir[i] = cam->forward[i] + u * cam->right[i] + v * cam->up[i];
    norm3(dir);
}

/* As norm3 after the sum above, term by term in the same order (no contraction in ISO C: the
 * same bits); a zero length divides by 1, which leaves the zeros as norm3 does. */
ATMOS_CLONES void atmos__camera_pinhole_dirs(const atmos_camera *cam,
                                                                                   const double *u, int n, double v,
                                                                                   double *dx, double *dy, double *dz)
{
    const double *F = cam->forward, *R = cam->right, *U = cam->up;
    for (int i = 0; i < n; i++) {
        const double x = F[0] + u[i] * R[0] + v * U[0], y = F[1] + u[i] * R[1] + v * U[1];
        const double z = F[2] + u[i] * R[2] + v * U[2];
        const double l = sqrt(x * x + y * y + z * z), s = l > 0 ? l : 1.0;
        dx[i] = x / s, dy[i] = y / s, dz[i] = z / s;
    }
}

int atmos_camera_ray(const atmos_camera *cam, double x, double y, double dir[3])
{
    const double W = cam->width, H = cam->height;
    if (cam->type == ATMOS_CAMERA_EQUIRECT) {
        double az = (x / W - 0.5) * 360.0;
        double el = 90.0 - (y / H) * 180.0;
        atmos_direction_from_angles(el, az, dir);
        return 1;
    }
    double u, v; /* image-plane coordinates: right, up */
    if (cam->type == ATMOS_CAMERA_PINHOLE) {
        atmos__camera_pinhole_dir(cam, atmos__camera_pinhole_u(cam, x), atmos__camera_pinhole_v(cam, y), dir);
        return 1;
    }
    /* Equidistant fisheye: angle from the axis proportional to the distance from
     * the centre; the field of view spans the circle inscribed in the image. */
    double s = W < H ? W : H;
    u = (2.0 * x - W) / s;
    v = (H - 2.0 * y) / s;
    double r = sqrt(u * u + v * v);
    if (r > 1.0) {
        dir[0] = dir[1] = dir[2] = 0;
        return 0;
    }
    double theta = r * 0.5 * cam->fov_deg * ATMOS_DEG2RAD;
    double st = sin(theta), ct = cos(theta);
    double cu = r > 0 ? u / r : 0, cv = r > 0 ? v / r : 0;
    for (int i = 0; i < 3; i++) dir[i] = ct * cam->forward[i] + st * (cu * cam->right[i] + cv * cam->up[i]);
    norm3(dir);
    return 1;
}
