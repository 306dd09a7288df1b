/* Shape statistics of a cloud field seen from above (docs/clouds.md "Shape statistics"):
 * the projected cloud mask (vertical optical depth at or above a threshold), its connected
 * clouds, each cloud's area and perimeter, the perimeter-area dimension D (P ~ A^(D/2),
 * Lovejoy 1982), the size distribution's power-law slope, the cloud fraction and how flat
 * the clouds' bases are.
 *
 * Two steps: atmos_cloud_columns_from_volume projects a volume onto its horizontal plane
 * (the columns' optical depths, bases and tops), atmos_cloud_stats_measure finds the clouds
 * of such columns (or of columns made by hand, as the tests do), atmos_cloud_stats_fit fits
 * the laws to any list of clouds (several fields' clouds pooled).
 */
#ifndef ATMOS_CLOUDSTATS_H
#define ATMOS_CLOUDSTATS_H

#include "atmos/base.h"
#include "atmos/volume.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A horizontal grid of columns, nx by ny square pixels of edge dx_m (x fastest). */
typedef struct atmos_cloud_columns {
    int nx, ny;
    double dx_m;
    float *tau;    /* vertical optical depth of each column */
    float *base_m; /* height where the optical depth counted from below reaches the base
                      threshold (NAN where it never does) */
    float *top_m;  /* the same counted from above */
} atmos_cloud_columns;

/* Allocates the three arrays (tau 0, bases and tops NAN); 1..65536 pixels a side, at most 2^30
 * in all. */
ATMOS_API atmos_status atmos_cloud_columns_create(atmos_context *ctx, int nx, int ny, double dx_m,
                                                  atmos_cloud_columns *out);
ATMOS_API void atmos_cloud_columns_free(atmos_cloud_columns *c);

/* The columns of an unrotated volume: the vertical is the grid's y axis, the pixels its
 * x (across) and z (along) voxels. Extinction = sum_f eta_f sigma_ext[f] (a sigma of 0 leaves
 * a field out), integrated voxel by voxel (each voxel's value over its whole height); base and
 * top where the optical depth counted from below / above reaches base_tau, linear within the
 * voxel. A rotated volume or non-cubic input gives ATMOS_E_INVALID_ARG. */
ATMOS_API atmos_status atmos_cloud_columns_from_volume(atmos_context *ctx, const atmos_volume *vol,
                                                       const double *sigma_ext, double base_tau,
                                                       atmos_cloud_columns *out);

typedef struct atmos_cloud_stats_desc {
    double tau_threshold;  /* a column is cloudy when tau >= this (0 = 1) */
    int connectivity;      /* 4 (default, 0) or 8 neighbours */
    int periodic;          /* nonzero: the grid wraps round (a simulation's periodic sides), clouds
                              joined across opposite edges; else clouds touching the edge are
                              marked and left out of the fits */
    double fit_min_pixels; /* D, flatness and the size fit use clouds of at least this many
                              pixels (0 = 10) */
    double size_min_m, size_max_m; /* the size fit's range of equivalent diameters (0 = from the
                              smallest fitted cloud's / to the largest cloud's) */
} atmos_cloud_stats_desc;

typedef struct atmos_cloud {
    int pixels;
    double area_m2;          /* pixels dx^2 */
    double perimeter_m;      /* the mask's outline by marching squares through the pixel centres
                                (pixel-edge midpoints joined; a smooth shape's length x 1.055) */
    double crack_perimeter_m;/* the pixel edges between the cloud and clear columns (x 4/pi) */
    double diameter_m;       /* equivalent diameter sqrt(4 A / pi) */
    double base_mean_m, base_sd_m; /* over the cloud's columns with a base */
    double depth_m;          /* highest top - lowest base */
    int edge;                /* touches the grid's edge (never when periodic) */
} atmos_cloud;

typedef struct atmos_cloud_fit {
    int clouds, edge_clouds, fitted;  /* all, touching the edge, used by the fits */
    double cloud_fraction;            /* cloudy pixels / pixels (edge clouds included) */
    double d, d_se;                   /* perimeter-area dimension from the marching-squares
                                         perimeter (least squares of log P on log A, D = 2 slope) */
    double d_crack, d_crack_se;       /* the same from the crack perimeter */
    double fit_area_min_m2, fit_area_max_m2;
    double size_slope, size_slope_se; /* b of n(d) ~ d^-b by maximum likelihood over
                                         [size_min_m, size_max_m] (a truncated power law) */
    double size_slope_hist, size_slope_hist_se; /* b by least squares on the log-binned
                                         histogram (bins a factor sqrt 2 wide) */
    double size_min_m, size_max_m;    /* the range used; NaN when none was given and no cloud
                                         was fitted (nothing to fit: every slope is NaN) */
    int size_n;                       /* clouds inside the size range */
    double flatness_median, flatness_mean; /* base sd / depth over the fitted clouds: median,
                                         and the mean weighted by area */
    int flatness_n;
} atmos_cloud_fit;

typedef struct atmos_cloud_stats {
    int nclouds;
    atmos_cloud *clouds;
    int *label;             /* per pixel: the cloud's index, -1 clear (nx * ny) */
    long cloudy_pixels, pixels;
    atmos_cloud_fit fit;
} atmos_cloud_stats;

/* Labels the clouds of the columns and fits them. Free with atmos_cloud_stats_free. */
ATMOS_API atmos_status atmos_cloud_stats_measure(atmos_context *ctx, const atmos_cloud_columns *cols,
                                                 const atmos_cloud_stats_desc *desc, atmos_cloud_stats *out);
ATMOS_API void atmos_cloud_stats_free(atmos_cloud_stats *s);

/* The fits of a list of clouds (edge clouds skipped), e.g. several fields' pooled; the cloud
 * fraction is cloudy / total pixels. */
ATMOS_API void atmos_cloud_stats_fit(const atmos_cloud *clouds, int n, long cloudy_pixels, long pixels,
                                     double dx_m, const atmos_cloud_stats_desc *desc, atmos_cloud_fit *out);

#ifdef __cplusplus
}
#endif
#endif
