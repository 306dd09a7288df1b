/* Height maps from raster files through GDAL (Debian's libgdal-dev): 16-bit PNG, GeoTIFF and
 * whatever else GDAL reads; band 1, every stride-th row and column (atmos_mesh_terrain). Built
 * as the module libatmos_gdal.so, opened by mesh_gdal.c on the first height map file
 * (core/module.h), so that a program reading none does not load GDAL and its hundred
 * libraries; it calls nothing of the library: its messages go back in msg. */
#include "mesh/mesh_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cpl_error.h>
#include <gdal.h>

/* The message into msg, st returned (atmos__error's part that the module can do). */
static atmos_status fail(char *msg, size_t cap, atmos_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, cap, fmt, ap);
    va_end(ap);
    return st;
}

/* The least stride that keeps 2 (nx - 1)(nz - 1) triangles of a w x h grid within max. */
static int terrain_stride(long w, long h, long max_triangles)
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
static atmos_status read_rows(char *msg, size_t cap, const char *path, GDALRasterBandH band, int w, int stride,
                              atmos__heights *out, double *lo)
{
    int has_nodata = 0;
    const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
    double *row = malloc(sizeof(double) * (size_t)w);
    if (!row) return fail(msg, cap, ATMOS_E_NOMEM, "terrain %s: out of memory", path);
    *lo = INFINITY;
    for (int j = 0; j < out->nz; j++) {
        if (GDALRasterIO(band, GF_Read, 0, j * stride, w, 1, row, w, 1, GDT_Float64, 0, 0) != CE_None) {
            free(row);
            return fail(msg, cap, ATMOS_E_IO, "terrain %s: reading row %d: %s", path, j * stride,
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
                return fail(msg, cap, ATMOS_E_FORMAT, "terrain %s: pixel (%d, %d) is not finite", path, i * stride,
                            j * stride);
            }
            out->h[(size_t)j * out->nx + i] = v;
            *lo = fmin(*lo, v);
        }
    }
    /* the file's last row too, where the stride passes it: a file cut short there would
       otherwise be read without a word */
    const int last = GDALGetRasterBandYSize(band) - 1;
    if ((out->nz - 1) * stride < last &&
        GDALRasterIO(band, GF_Read, 0, last, w, 1, row, w, 1, GDT_Float64, 0, 0) != CE_None) {
        free(row);
        return fail(msg, cap, ATMOS_E_IO, "terrain %s: reading row %d (the last): %s", path, last,
                    gdal_message("read error"));
    }
    free(row);
    return ATMOS_OK;
}

/* What the module was built for (core/module.h): the library checks it before the entry. */
extern const atmos__module_stamp atmos_module_stamp;
__attribute__((visibility("default"))) const atmos__module_stamp atmos_module_stamp = ATMOS__GDAL_MODULE_STAMP;

/* The module's entry (mesh_internal.h's atmos__gdal_module_entry). */
atmos_status atmos_gdal_module_v1(const char *path, int stride, long max_triangles, atmos__heights *out, char *msg,
                                  size_t cap);
__attribute__((visibility("default"))) atmos_status
atmos_gdal_module_v1(const char *path, int stride, long max_triangles, atmos__heights *out, char *msg, size_t cap)
{
    memset(out, 0, sizeof *out); /* the file opens: mesh_gdal.c saw to it */
    GDALAllRegister();
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
    GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
    atmos_status st = ATMOS_OK;
    if (!ds) st = fail(msg, cap, ATMOS_E_FORMAT, "terrain %s: not a raster GDAL can read (%s)", path,
                       gdal_message("unknown format"));
    else if (GDALGetRasterCount(ds) < 1)
        st = fail(msg, cap, ATMOS_E_FORMAT, "terrain %s: the file holds no raster band", path);
    const int w = ds ? GDALGetRasterXSize(ds) : 0, h = ds ? GDALGetRasterYSize(ds) : 0;
    if (st == ATMOS_OK && (w < 2 || h < 2 || w > ATMOS_TERRAIN_MAX_SIDE || h > ATMOS_TERRAIN_MAX_SIDE))
        st = fail(msg, cap, ATMOS_E_LIMIT, "terrain %s: %d x %d pixels: a height map needs 2 to %d a side", path, w,
                  h, ATMOS_TERRAIN_MAX_SIDE);
    if (st == ATMOS_OK) {
        const int chosen = stride <= 0; /* the stride from max_triangles, not the scene's */
        if (chosen) stride = terrain_stride(w, h, max_triangles);
        out->nx = (w - 1) / stride + 1, out->nz = (h - 1) / stride + 1;
        if ((out->nx < 2 || out->nz < 2) && chosen)
            st = fail(msg, cap, ATMOS_E_INVALID_ARG,
                      "terrain %s: max_triangles %ld is too few for a height map of %d x %d: at least 2 (one "
                      "cell of two triangles)", path, max_triangles, w, h);
        else if (out->nx < 2 || out->nz < 2)
            st = fail(msg, cap, ATMOS_E_INVALID_ARG, "terrain %s: a stride of %d leaves fewer than 2 x 2 samples of %d x %d",
                      path, stride, w, h);
        else if (2L * (out->nx - 1) * (out->nz - 1) > max_triangles)
            st = fail(msg, cap, ATMOS_E_LIMIT, "terrain %s: a stride of %d gives %ld triangles, more than %ld", path,
                      stride, 2L * (out->nx - 1) * (out->nz - 1), max_triangles);
        else if (!(out->h = malloc(sizeof(double) * (size_t)out->nx * out->nz)))
            st = fail(msg, cap, ATMOS_E_NOMEM, "terrain %s: out of memory", path);
    }
    double lo = INFINITY;
    if (st == ATMOS_OK) st = read_rows(msg, cap, path, GDALGetRasterBand(ds, 1), w, stride, out, &lo);
    if (st == ATMOS_OK && !isfinite(lo)) st = fail(msg, cap, ATMOS_E_FORMAT, "terrain %s: every pixel is no-data", path);
    for (size_t i = 0; st == ATMOS_OK && i < (size_t)out->nx * out->nz; i++)
        if (isnan(out->h[i])) out->h[i] = lo;
    if (ds) GDALClose(ds);
    CPLPopErrorHandler();
    if (st != ATMOS_OK) free(out->h), out->h = NULL;
    return st;
}
