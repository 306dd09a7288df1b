/* Terrain from height maps (atmos_mesh_terrain): a GeoTIFF and a 16-bit PNG written here
 * through GDAL read back with the right heights at known pixels (raw, scaled, normalised,
 * with a stride), the generated ridges are deterministic by seed and span [0, height_m], and
 * broken, missing, non-raster, absurdly sized, NaN and flat inputs are clear errors. */
#include "atmos/atmos.h"
#include "mesh/mesh_internal.h"
#include "test.h"

#ifdef ATMOS_HAVE_GDAL
#include <cpl_conv.h>
#include <gdal.h>
#endif

static atmos_context *ctx;

/* The height of grid vertex (i, j) of a terrain mesh nx wide. */
static double vy(const atmos_mesh *m, int nx, int i, int j) { return m->positions[3 * ((size_t)j * nx + i) + 1]; }

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (f) fputs(text, f), fclose(f);
}

static atmos_status load(const char *source, double size, double height_m, double scale, int stride, int max_tris,
                         atmos_mesh **m)
{
    atmos_terrain_desc d;
    memset(&d, 0, sizeof d);
    d.source = source, d.size_m = size, d.height_m = height_m, d.height_scale = scale, d.stride = stride;
    d.max_triangles = max_tris;
    *m = NULL;
    return atmos_mesh_terrain(ctx, &d, m);
}

static void expect_fail(const char *source, atmos_status want, const char *needle)
{
    atmos_mesh *m = NULL;
    const atmos_status st = load(source, 100, 0, 0, 0, 0, &m);
    CHECK_MSG(st == want && !m, "%s: got %s (%s)", source, atmos_status_string(st), atmos_context_error(ctx));
    CHECK_MSG(strstr(atmos_context_error(ctx), needle) != NULL, "%s: message \"%s\" lacks \"%s\"", source,
              atmos_context_error(ctx), needle);
    atmos_mesh_destroy(m);
}

static void test_generated(void)
{
    atmos_terrain_desc d;
    memset(&d, 0, sizeof d);
    d.source = "generate:ridges", d.size_m = 1000, d.height_m = 250, d.samples = 65, d.seed = 7;
    atmos_mesh *a = NULL, *b = NULL, *c = NULL;
    CHECK_OK(atmos_mesh_terrain(ctx, &d, &a));
    CHECK_OK(atmos_mesh_terrain(ctx, &d, &b));
    d.seed = 8;
    CHECK_OK(atmos_mesh_terrain(ctx, &d, &c));
    if (a && b && c) {
        CHECK(a->vertex_count == 65 * 65 && a->triangle_count == 2 * 64 * 64);
        CHECK(!memcmp(a->positions, b->positions, sizeof(float) * 3 * (size_t)a->vertex_count));
        CHECK(memcmp(a->positions, c->positions, sizeof(float) * 3 * (size_t)a->vertex_count) != 0);
        CHECK_NEAR(a->lo[1], 0, 1e-3);
        CHECK_NEAR(a->hi[1], 250, 1e-3);
        CHECK_NEAR(a->lo[0], -500, 1e-3);
        CHECK_NEAR(a->hi[2], 500, 1e-3);
        /* a ray straight down meets the grid at the height of the vertex below it */
        const double o[3] = {a->positions[3 * 100], 1000, a->positions[3 * 100 + 2]}, dn[3] = {0, -1, 0};
        atmos_mesh_hit h;
        CHECK(atmos_mesh_intersect(a, o, dn, 0, 1e4, &h) && fabs(1000 - h.t - a->positions[3 * 100 + 1]) < 1e-3 &&
              h.normal[1] > 0);
    }
    atmos_mesh_destroy(a), atmos_mesh_destroy(b), atmos_mesh_destroy(c);
    /* the city: streets at 0 (the first 3 samples of every 12), buildings within [0.15, 1] of height_m */
    d.source = "generate:city", d.samples = 49, d.seed = 3;
    CHECK_OK(atmos_mesh_terrain(ctx, &d, &a));
    if (a) {
        int street_ok = 1, building_ok = 1;
        for (int j = 0; j < 49; j++)
            for (int i = 0; i < 49; i++) {
                const double y = vy(a, 49, i, j);
                if (i % 12 < 3 || j % 12 < 3) street_ok &= y == 0;
                else if (i < 48 && j < 48) building_ok &= y >= 0.15 * 250 - 1e-3 && y <= 250 + 1e-3;
            }
        CHECK(street_ok && building_ok);
        atmos_mesh_destroy(a);
        a = NULL;
    }
    d.source = "generate:ridges", d.samples = 65;
    d.source = "generate:dunes";
    CHECK(atmos_mesh_terrain(ctx, &d, &a) == ATMOS_E_INVALID_ARG && !a);
    d.source = "generate:ridges", d.samples = 4097;
    CHECK(atmos_mesh_terrain(ctx, &d, &a) == ATMOS_E_LIMIT && !a); /* 33.5 M triangles */
    d.samples = 65, d.height_m = 0;
    CHECK(atmos_mesh_terrain(ctx, &d, &a) == ATMOS_E_INVALID_ARG && !a);
    d.height_m = 10, d.size_m = 0;
    CHECK(atmos_mesh_terrain(ctx, &d, &a) == ATMOS_E_INVALID_ARG && !a);
}

#ifdef ATMOS_HAVE_GDAL
/* value of pixel (i, j) in the test rasters */
static double pix(int i, int j) { return 1000 + 37 * i + 211 * j; }

/* A w x h raster of pix() (one pixel NaN if nan_at >= 0) written through GDAL's driver; PNG
 * only by copy, from an in-memory raster. */
static int write_raster(const char *driver, const char *path, int w, int h, GDALDataType type, int nan_at)
{
    GDALAllRegister();
    GDALDriverH mem = GDALGetDriverByName("MEM"), drv = GDALGetDriverByName(driver);
    if (!mem || !drv) return 0;
    GDALDatasetH ds = GDALCreate(mem, "", w, h, 1, type, NULL);
    if (!ds) return 0;
    double *v = malloc(sizeof(double) * (size_t)w * h);
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) v[(size_t)j * w + i] = pix(i, j);
    if (nan_at >= 0) v[nan_at] = NAN;
    int ok = v && GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Write, 0, 0, w, h, v, w, h, GDT_Float64, 0, 0) == CE_None;
    GDALDatasetH out = ok ? GDALCreateCopy(drv, path, ds, FALSE, NULL, NULL, NULL) : NULL;
    ok = ok && out;
    if (out) GDALClose(out);
    GDALClose(ds);
    free(v);
    return ok;
}

static void test_files(void)
{
    char tif[1024], png[1024], path[1024];
    test_tmp_path(tif, sizeof tif, "dem.tif");
    test_tmp_path(png, sizeof png, "dem16.png");
    CHECK(write_raster("GTiff", tif, 7, 5, GDT_Float32, -1));
    CHECK(write_raster("PNG", png, 9, 9, GDT_UInt16, -1));
    atmos_mesh *m = NULL;
    /* GeoTIFF, raw metres: vertex (i, j) holds pixel (i, j), 10 m apart, centred */
    CHECK_OK(load(tif, 60, 0, 0, 0, 0, &m));
    if (m) {
        CHECK(m->vertex_count == 35 && m->triangle_count == 48);
        const int at[4][2] = {{0, 0}, {6, 0}, {3, 2}, {6, 4}};
        for (int k = 0; k < 4; k++) CHECK_NEAR(vy(m, 7, at[k][0], at[k][1]), pix(at[k][0], at[k][1]), 1e-3);
        CHECK_NEAR(m->positions[3 * (2 * 7 + 3)], 0, 1e-4);       /* column 3 of 7 at x = 0 */
        CHECK_NEAR(m->positions[3 * (2 * 7 + 3) + 2], 0, 1e-4);   /* row 2 of 5 at z = 0 */
        CHECK_NEAR(m->positions[3 * 6], 30, 1e-4);
        atmos_mesh_destroy(m);
    }
    /* 16-bit PNG, scaled by 0.5 */
    CHECK_OK(load(png, 80, 0, 0.5, 0, 0, &m));
    if (m) {
        CHECK(m->vertex_count == 81);
        CHECK_NEAR(vy(m, 9, 8, 8), 0.5 * pix(8, 8), 1e-3);
        CHECK_NEAR(vy(m, 9, 5, 1), 0.5 * pix(5, 1), 1e-3);
        atmos_mesh_destroy(m);
    }
    /* normalised to 300 m */
    CHECK_OK(load(png, 80, 300, 0, 0, 0, &m));
    if (m) {
        const double lo = pix(0, 0), hi = pix(8, 8);
        CHECK_NEAR(vy(m, 9, 4, 7), (pix(4, 7) - lo) / (hi - lo) * 300, 1e-3);
        CHECK_NEAR(m->hi[1], 300, 1e-3);
        atmos_mesh_destroy(m);
    }
    /* every other pixel: 8 x 8 cells = 128 triangles > 100, so the automatic stride is 2 */
    CHECK_OK(load(png, 80, 0, 0, 0, 100, &m));
    if (m) {
        CHECK(m->vertex_count == 25 && m->triangle_count == 32);
        CHECK_NEAR(vy(m, 5, 3, 1), pix(6, 2), 1e-3);
        CHECK_NEAR(m->positions[3 * 1] - m->positions[0], 20, 1e-4);
        atmos_mesh_destroy(m);
    }
    CHECK(load(png, 80, 0, 0, 1, 100, &m) == ATMOS_E_LIMIT && !m); /* stride 1 asked: 128 triangles */
    /* bad files */
    test_tmp_path(path, sizeof path, "missing.tif");
    remove(path);
    expect_fail(path, ATMOS_E_IO, "missing.tif");
    test_tmp_path(path, sizeof path, "broken.tif");
    write_file(path, "II*\\0 this is no tiff at all");
    expect_fail(path, ATMOS_E_FORMAT, "broken.tif");
    test_tmp_path(path, sizeof path, "points.geojson");
    write_file(path, "{\"type\": \"FeatureCollection\", \"features\": [{\"type\": \"Feature\", \"properties\": {},"
                     " \"geometry\": {\"type\": \"Point\", \"coordinates\": [1, 2]}}]}");
    expect_fail(path, ATMOS_E_FORMAT, "points.geojson");
    test_tmp_path(path, sizeof path, "thin.tif");
    CHECK(write_raster("GTiff", path, 1, 40, GDT_Int16, -1));
    expect_fail(path, ATMOS_E_LIMIT, "1 x 40 pixels");
    test_tmp_path(path, sizeof path, "wide.tif");
    CHECK(write_raster("GTiff", path, 70000, 2, GDT_Byte, -1));
    expect_fail(path, ATMOS_E_LIMIT, "70000 x 2 pixels");
    test_tmp_path(path, sizeof path, "nan.tif");
    CHECK(write_raster("GTiff", path, 4, 4, GDT_Float32, 5));
    expect_fail(path, ATMOS_E_FORMAT, "pixel (1, 1) is not finite");
}

/* The module's stamp (core/module.h): a module built for another libatmos is refused with a
 * message saying so, never called; the right one gives its entry. */
static void test_module_stamp(void)
{
    atmos__module_stamp want = {"", ATMOS__MODULE_ABI, {sizeof(atmos__heights), 0, 0}};
    snprintf(want.version, sizeof want.version, "%s", atmos_version());
    char why[512] = "";
    CHECK(atmos__module_symbol(ATMOS__GDAL_MODULE, ATMOS__GDAL_MODULE_ENTRY, &want, why, sizeof why) != NULL);
    atmos__module_stamp stale = want;
    stale.abi = ATMOS__MODULE_ABI + 1;
    CHECK(atmos__module_symbol(ATMOS__GDAL_MODULE, ATMOS__GDAL_MODULE_ENTRY, &stale, why, sizeof why) == NULL);
    CHECK(strstr(why, "built for another libatmos") != NULL);
    stale = want, stale.sizes[0] += 8; /* atmos__heights grown on one side */
    CHECK(atmos__module_symbol(ATMOS__GDAL_MODULE, ATMOS__GDAL_MODULE_ENTRY, &stale, why, sizeof why) == NULL);
    snprintf(stale.version, sizeof stale.version, "0.0.1"), stale.sizes[0] = want.sizes[0];
    CHECK(atmos__module_symbol(ATMOS__GDAL_MODULE, ATMOS__GDAL_MODULE_ENTRY, &stale, why, sizeof why) == NULL);
    CHECK(strstr(why, "0.0.1") != NULL);
}
#endif

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_generated();
#ifdef ATMOS_HAVE_GDAL
    test_files();
    test_module_stamp();
#else
    atmos_mesh *m = NULL;
    CHECK(load("x.tif", 10, 0, 0, 0, 0, &m) == ATMOS_E_UNSUPPORTED);
#endif
    atmos_context_destroy(ctx);
    return test_summary("test_terrain");
}
