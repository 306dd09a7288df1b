/* Where a sphere falls on the image (pcloud.h, atmos__pcloud_screen_box), for the three
 * cameras: a pinhole's perspective, the equidistant fisheye (the angle from the axis
 * proportional to the distance from the image's centre) and the equirectangular map of
 * azimuth and elevation (atmos_camera_ray). A sphere seen from outside is the cap of
 * directions within alpha = asin(r / d) of its centre's; the box bounds the cap's image. */
#include "particles/pcloud.h"
#include "core/internal.h"

#include <math.h>

/* The box [x0, x1) x [y0, y1) of image points (xs, ys)[0..n) widened by a pixel, clipped to
 * rect; 0 when empty. */
static int box_of(const double *xs, const double *ys, int n, const int rect[4], int bb[4])
{
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int i = 0; i < n; i++) x0 = fmin(x0, xs[i]), x1 = fmax(x1, xs[i]), y0 = fmin(y0, ys[i]), y1 = fmax(y1, ys[i]);
    bb[0] = (int)fmax(rect[0], floor(x0) - 1.0), bb[1] = (int)fmin(rect[2], ceil(x1) + 1.0);
    bb[2] = (int)fmax(rect[1], floor(y0) - 1.0), bb[3] = (int)fmin(rect[3], ceil(y1) + 1.0);
    return bb[0] < bb[1] && bb[2] < bb[3];
}

static int pinhole_box(const atmos_camera *cam, const double rel[3], double r, const int rect[4], int bb[4], double *Zout)
{
    double X = 0, Y = 0, Z = 0;
    for (int i = 0; i < 3; i++) X += rel[i] * cam->right[i], Y += rel[i] * cam->up[i], Z += rel[i] * cam->forward[i];
    if (Z <= r) return 0; /* behind the eye, or the eye inside the sphere */
    const double W = cam->width, H = cam->height, f = H / (2.0 * cam->tan_half_fov), den = Z * Z - r * r;
    /* the sphere's outline exactly: the planes x = u z through the eye that touch it, |X - u Z| =
     * r sqrt(1 + u^2), have u = (X Z -+ r sqrt(X^2 + Z^2 - r^2)) / (Z^2 - r^2); the same for y.
     * A pixel more on each side for the rounding of the splat's own test. */
    const double sx = r * sqrt(X * X + den), sy = r * sqrt(Y * Y + den);
    const double u0 = (X * Z - sx) / den, u1 = (X * Z + sx) / den, v0 = (Y * Z - sy) / den, v1 = (Y * Z + sy) / den;
    bb[0] = (int)fmax(rect[0], floor(0.5 * W + f * u0) - 1.0), bb[1] = (int)fmin(rect[2], ceil(0.5 * W + f * u1) + 1.0);
    bb[2] = (int)fmax(rect[1], floor(0.5 * H - f * v1) - 1.0), bb[3] = (int)fmin(rect[3], ceil(0.5 * H - f * v0) + 1.0);
    *Zout = Z;
    return bb[0] < bb[1] && bb[2] < bb[3];
}

/* The fisheye: polar angle theta from the axis and angle phi on the image (from the right,
 * toward up); the cap spans theta in [tc - alpha, tc + alpha] and, when it does not hold the
 * axis, phi within asin(sin alpha / sin tc) of its centre's. Image radius rho = theta / theta_max
 * (1 at the inscribed circle's edge). */
static int fisheye_box(const atmos_camera *cam, const double rel[3], double d, double alpha, const int rect[4], int bb[4])
{
    double X = 0, Y = 0, Z = 0;
    for (int i = 0; i < 3; i++) X += rel[i] * cam->right[i], Y += rel[i] * cam->up[i], Z += rel[i] * cam->forward[i];
    const double tmax = 0.5 * cam->fov_deg * ATMOS_DEG2RAD, tc = acos(fmax(-1.0, fmin(1.0, Z / d)));
    if (tc - alpha >= tmax) return 0; /* wholly outside the field of view */
    const double W = cam->width, H = cam->height, s = 0.5 * (W < H ? W : H);
    const double r0 = fmax(tc - alpha, 0.0) / tmax, r1 = fmin((tc + alpha) / tmax, 1.0);
    double xs[8], ys[8];
    int n = 0;
    if (tc <= alpha || tc + alpha >= ATMOS_PI) { /* the cap holds the axis or its opposite: a disc */
        xs[0] = 0.5 * W - s * r1, xs[1] = 0.5 * W + s * r1, ys[0] = 0.5 * H - s * r1, ys[1] = 0.5 * H + s * r1;
        return box_of(xs, ys, 2, rect, bb);
    }
    const double pc = atan2(Y, X), dp = asin(fmin(1.0, sin(alpha) / sin(tc)));
    const double ph[2] = {pc - dp, pc + dp}, rr[2] = {r0, r1};
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++) xs[n] = 0.5 * W + s * rr[b] * cos(ph[a]), ys[n++] = 0.5 * H - s * rr[b] * sin(ph[a]);
    /* the outer arc's extremes along the image axes, where it crosses them */
    for (int k = -4; k <= 4 && n < 8; k++) {
        const double q = 0.5 * ATMOS_PI * k;
        if (q > ph[0] && q < ph[1]) xs[n] = 0.5 * W + s * r1 * cos(q), ys[n++] = 0.5 * H - s * r1 * sin(q);
    }
    return box_of(xs, ys, n, rect, bb);
}

/* The equirectangular map: x = (azimuth / 360 + 1/2) W (azimuth from north, clockwise), y =
 * (90 - elevation) / 180 H, in the world's axes. The cap spans elevation [ec - alpha, ec +
 * alpha] and azimuth within asin(sin alpha / cos ec) of its centre's; every column when it
 * holds a pole or crosses the map's seam behind the viewer. */
static int equirect_box(const atmos_camera *cam, const double rel[3], double d, double alpha, const int rect[4], int bb[4])
{
    const double W = cam->width, H = cam->height, ec = asin(fmax(-1.0, fmin(1.0, rel[1] / d)));
    const double az = atan2(rel[0], -rel[2]), half = 0.5 * ATMOS_PI;
    double xs[2] = {0.0, W}, ys[2];
    ys[0] = (half - fmin(ec + alpha, half)) / ATMOS_PI * H, ys[1] = (half - fmax(ec - alpha, -half)) / ATMOS_PI * H;
    if (ec + alpha < half && ec - alpha > -half) {
        const double da = asin(fmin(1.0, sin(alpha) / cos(ec)));
        if (az - da > -ATMOS_PI && az + da < ATMOS_PI)
            xs[0] = ((az - da) / (2.0 * ATMOS_PI) + 0.5) * W, xs[1] = ((az + da) / (2.0 * ATMOS_PI) + 0.5) * W;
    }
    return box_of(xs, ys, 2, rect, bb);
}

int atmos__pcloud_screen_box(const atmos_camera *cam, const double c[3], double r, const int rect[4], int bb[4],
                             double *Zout)
{
    double rel[3];
    for (int i = 0; i < 3; i++) rel[i] = c[i] - cam->position[i];
    if (cam->type == ATMOS_CAMERA_PINHOLE) return pinhole_box(cam, rel, r, rect, bb, Zout);
    const double d = sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
    if (d <= r) return 0; /* the eye inside the sphere */
    *Zout = d;
    const double alpha = asin(r / d);
    return cam->type == ATMOS_CAMERA_FISHEYE ? fisheye_box(cam, rel, d, alpha, rect, bb)
                                             : equirect_box(cam, rel, d, alpha, rect, bb);
}
