/* A pinhole camera's ray in two steps (camera.c): the image-plane coordinates of a pixel's
 * column and row (a division each), then the direction from them. atmos_camera_ray is the two
 * together; a renderer that keeps the coordinates per column and per row gets its rays, the
 * same bits, without the divisions. */
#ifndef ATMOS_CORE_PINHOLE_H
#define ATMOS_CORE_PINHOLE_H

#include "atmos/camera.h"

/* The image-plane coordinate right of the axis of the image's x (pixels; centres at + 0.5). */
double atmos__camera_pinhole_u(const atmos_camera *cam, double x);
/* The image-plane coordinate above the axis of the image's y. */
double atmos__camera_pinhole_v(const atmos_camera *cam, double y);
/* The unit direction through the image-plane point (u, v). */
void atmos__camera_pinhole_dir(const atmos_camera *cam, double u, double v, double dir[3]);
/* The unit directions through (u[i], v) for i < n, in three arrays (x, y, z): the same bits as
 * atmos__camera_pinhole_dir's, a row at a time (the roots and divisions vectorised). */
void atmos__camera_pinhole_dirs(const atmos_camera *cam, const double *u, int n, double v, double *dx, double *dy,
                                double *dz);

#endif
