/* Height maps from raster files through GDAL (Debian's libgdal-dev): 16-bit PNG, GeoTIFF and
 * whatever else GDAL reads; band 1, every stride-th row and column (atmos_mesh_terrain). */
#include "mesh/mesh_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef ATMOS_HAVE_GDAL
#include <cpl_error.h>
#include <gdal.h>

int atmos__terrain_stride(long w, long h, long max_triangles)
{
    int s = 1;
    while (2L * ((w - 1) / s) * ((h - 1) / s) > max_triangles) s++;
    return s;
}

/* GDAL's last message, or a default. */
static const char *gdal_message(const char *fallback)
{
    const char *m = CPLGetLastErrorMsg();
    return m && m[0] ? m : fallback;
}

/* The kept rows read into out (nx x nz allocated); the lowest valid value in *lo. */
static atmos_status read_rows(atmos_context *ctx, const char *path, GDALRasterBandH band, int w, int stride,
                              atmos__heights *out, double *lo)
{
    int has_nodata = 0;
    const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
    double *row = malloc(sizeof(double) * (size_t)w);
    if (!row) return atmos__error(ctx, ATMOS_E_NOMEM, "terrain %s: out of memory", path);
    *lo = INFINITY;
    for (int j = 0; j < out->nz; j++) {
        if (GDALRasterIO(band, GF_Read, 0, j * stride, w, 1, row, w, 1, GDT_Float64, 0, 0) != CE_None) {
            free(row);
            return atmos__error(ctx, ATMOS_E_IO, "terrain %s: reading row %d: %s", path, j * stride,
                                gdal_message("read error"));
        }
        for (int i = 0; i < out->nx; i++) {
            const double v = row[(size_t)i * stride];
            if (has_nodata && (v == nodata || (isnan(v) && isnan(nodata)))) {
                out->h[(size_t)j * out->nx + i] = NAN; /* filled below */
                continue;
            }
            if (!isfinite(v)) {
                free(row);
                return atmos__error(ctx, ATMOS_E_FORMAT, "terrain %s: pixel (%d, %d) is not finite", path, i * stride,
                                    j * stride);
            }
            out->h[(size_t)j * out->nx + i] = v;
            *lo = fmin(*lo, v);
        }
    }
    free(row);
    return ATMOS_OK;
}

atmos_status atmos__terrain_read(atmos_context *ctx, const char *path, int stride, long max_triangles,
                                 atmos__heights *out)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "rb"); /* GDAL's own message for a missing file is vaguer */
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "terrain %s: cannot open: %s", path, strerror(errno));
    fclose(f);
    GDALAllRegister();
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
    GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
    atmos_status st = ATMOS_OK;
    if (!ds) st = atmos__error(ctx, ATMOS_E_FORMAT, "terrain %s: not a raster GDAL can read (%s)", path,
                               gdal_message("unknown format"));
    else if (GDALGetRasterCount(ds) < 1)
        st = atmos__error(ctx, ATMOS_E_FORMAT, "terrain %s: the file holds no raster band", path);
    const int w = ds ? GDALGetRasterXSize(ds) : 0, h = ds ? GDALGetRasterYSize(ds) : 0;
    if (st == ATMOS_OK && (w < 2 || h < 2 || w > ATMOS_TERRAIN_MAX_SIDE || h > ATMOS_TERRAIN_MAX_SIDE))
        st = atmos__error(ctx, ATMOS_E_LIMIT, "terrain %s: %d x %d pixels: a height map needs 2 to %d a side", path, w,
                          h, ATMOS_TERRAIN_MAX_SIDE);
    if (st == ATMOS_OK) {
        const int chosen = stride <= 0; /* the stride from max_triangles, not the scene's */
        if (chosen) stride = atmos__terrain_stride(w, h, max_triangles);
        out->nx = (w - 1) / stride + 1, out->nz = (h - 1) / stride + 1;
        if ((out->nx < 2 || out->nz < 2) && chosen)
            st = atmos__error(ctx, ATMOS_E_INVALID_ARG,
                              "terrain %s: max_triangles %ld is too few for a height map of %d x %d: at least 2 (one "
                              "cell of two triangles)", path, max_triangles, w, h);
        else if (out->nx < 2 || out->nz < 2)
            st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "terrain %s: a stride of %d leaves fewer than 2 x 2 samples of %d x %d",
                              path, stride, w, h);
        else if (2L * (out->nx - 1) * (out->nz - 1) > max_triangles)
            st = atmos__error(ctx, ATMOS_E_LIMIT, "terrain %s: a stride of %d gives %ld triangles, more than %ld", path,
                              stride, 2L * (out->nx - 1) * (out->nz - 1), max_triangles);
        else if (!(out->h = malloc(sizeof(double) * (size_t)out->nx * out->nz)))
            st = atmos__error(ctx, ATMOS_E_NOMEM, "terrain %s: out of memory", path);
    }
    double lo = INFINITY;
    if (st == ATMOS_OK) st = read_rows(ctx, path, GDALGetRasterBand(ds, 1), w, stride, out, &lo);
    if (st == ATMOS_OK && !isfinite(lo)) st = atmos__error(ctx, ATMOS_E_FORMAT, "terrain %s: every pixel is no-data", path);
    for (size_t i = 0; st == ATMOS_OK && i < (size_t)out->nx * out->nz; i++)
        if (isnan(out->h[i])) out->h[i] = lo;
    if (ds) GDALClose(ds);
    CPLPopErrorHandler();
    if (st != ATMOS_OK) free(out->h), out->h = NULL;
    return st;
}

#else

atmos_status atmos__terrain_read(atmos_context *ctx, const char *path, int stride, long max_triangles,
                                 atmos__heights *out)
{
    (void)stride, (void)max_triangles;
    memset(out, 0, sizeof *out);
    return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                        "terrain %s: height map files need GDAL: install libgdal-dev and build atmos again", path);
}

#endif
