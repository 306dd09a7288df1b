/* Volume file readers: OpenVDB (.vdb), NanoVDB (.nvdb), NetCDF (WRF, CM1).
 *
 * Fixtures: the .vdb/.nvdb files come from tests/tools/make_vdb_fixtures.cpp (run by
 * ctest before this test; directory in $ATMOS_VDB_FIXTURES) with values that are a
 * formula of their index; the .nc files are written here with libnetcdf. The real
 * files (Disney cloud, dragon, a WRF run) are read from $ATMOS_SHARED_DATA/real or
 * $ATMOS_SOURCE_DIR/../shared/data/real; when absent those checks print "skipped"
 * and count as neither passed nor failed. Readers are called directly, not through
 * atmos_volume_load(), so this test checks the readers alone.
 */
#define _POSIX_C_SOURCE 200809L /* mkdtemp-free: fileno, ftruncate not needed; strdup */
#include "atmos/atmos.h"
#include "test.h"
#include "volume/reader_common.h"
#include "volume/volume_internal.h"
#ifdef ATMOS_HAVE_OPENVDB
#include "volume/openvdb_shim.h"
#endif
#ifdef ATMOS_HAVE_NETCDF
#include <netcdf.h>
#endif

#include <dirent.h>
#include <stdint.h>

static atmos_context *ctx;
static int skipped;

static void skip(const char *what)
{
    printf("skipped: %s\n", what);
    skipped++;
}

static int file_exists(const char *p)
{
    FILE *f = fopen(p, "rb");
    if (f) fclose(f);
    return f != NULL;
}

static void fixture(char *buf, size_t cap, const char *name)
{
    const char *d = getenv("ATMOS_VDB_FIXTURES");
    snprintf(buf, cap, "%s/%s", d && *d ? d : ".", name);
}

static void real_file(char *buf, size_t cap, const char *name)
{
    const char *d = getenv("ATMOS_SHARED_DATA");
    const char *src = getenv("ATMOS_SOURCE_DIR");
    if (d && *d) snprintf(buf, cap, "%s/real/%s", d, name);
    else snprintf(buf, cap, "%s/../shared/data/real/%s", src && *src ? src : ".", name);
}

static int field_index(const atmos_volume *v, const char *name)
{
    for (int f = 0; f < atmos_volume_field_count(v); f++)
        if (strcmp(atmos_volume_field_name(v, f), name) == 0) return f;
    return -1;
}

/* World position of the centre of VDB index (i, j, k) under world = A idx + t. */
static void vdb_world(const double A[9], const double t[3], int i, int j, int k, double w[3])
{
    for (int r = 0; r < 3; r++) w[r] = t[r] + A[3 * r] * i + A[3 * r + 1] * j + A[3 * r + 2] * k;
}

static double fixture_value(int i, int j, int k) { return 1 + (i + 2) + 10 * j + 100 * k; }

/* The fixture's known contents, placed by (A, t): every voxel value, the tile's
 * coverage, the count of active voxels, the placement. */
static void check_fixture_volume(const atmos_volume *v, const double A[9], const double t[3], const char *what)
{
    int f = field_index(v, "cloud");
    CHECK_MSG(f >= 0, "%s: no 'cloud' field", what);
    if (f < 0) return;
    CHECK(strcmp(atmos_volume_field_particle(v, f), "cloud") == 0);
    const atmos_volume_desc *d = atmos_volume_get_desc(v);
    CHECK_MSG(d->dims[0] == 26 && d->dims[1] == 8 && d->dims[2] == 8, "%s: dims %d %d %d", what, d->dims[0],
              d->dims[1], d->dims[2]);
    double vs = sqrt(A[0] * A[0] + A[3] * A[3] + A[6] * A[6]);
    CHECK_NEAR(d->voxel_size_m, vs, 1e-9);
    int bad = 0;
    for (int k = 0; k <= 1; k++)
        for (int j = 0; j <= 2; j++)
            for (int i = -2; i <= 1; i++) {
                double w[3];
                vdb_world(A, t, i, j, k, w);
                double s = atmos_volume_sample(v, f, w);
                if (fabs(s - fixture_value(i, j, k)) > 1e-4) {
                    if (!bad++) fprintf(stderr, "%s: voxel (%d %d %d) = %g, want %g\n", what, i, j, k, s,
                                        fixture_value(i, j, k));
                }
            }
    CHECK_MSG(bad == 0, "%s: %d voxels wrong", what, bad);
    /* The tile covers (16..23, 0..7, 0..7): its corners and centre hold 2.5. */
    bad = 0;
    const int corners[][3] = {{16, 0, 0}, {23, 7, 7}, {16, 7, 0}, {23, 0, 7}, {20, 4, 4}};
    for (int c = 0; c < 5; c++) {
        double w[3];
        vdb_world(A, t, corners[c][0], corners[c][1], corners[c][2], w);
        if (fabs(atmos_volume_sample(v, f, w) - 2.5) > 1e-6) bad++;
    }
    CHECK_MSG(bad == 0, "%s: tile coverage wrong at %d points", what, bad);
    /* Between the voxels and the tile: empty. */
    double w[3];
    vdb_world(A, t, 8, 1, 1, w);
    CHECK_NEAR(atmos_volume_sample(v, f, w), 0.0, 0);
    atmos_volume_field_stats st;
    CHECK_OK(atmos_volume_field_stats_get(ctx, v, f, &st));
    CHECK_MSG(st.active_voxels == 24 + 512, "%s: %llu active", what, (unsigned long long)st.active_voxels);
    CHECK_NEAR(st.min, 1, 1e-6);
    CHECK_NEAR(st.max, fixture_value(1, 2, 1), 1e-4);
}

static const double small_A[9] = {0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5};
static const double small_t[3] = {10, 20, 30};
/* 90 degrees about y, voxel 2: index x -> world -z, index z -> world +x. */
static const double rot_A[9] = {0, 0, 2, 0, 2, 0, -2, 0, 0};
static const double rot_t[3] = {1, 2, 3};

typedef atmos_status (*loader)(atmos_context *, const char *, const atmos_volume_load_desc *, atmos_volume **);

static void check_status(loader load, const char *path, const atmos_volume_load_desc *desc, atmos_status want,
                         const char *needle)
{
    atmos_volume *v = NULL;
    atmos_status st = load(ctx, path, desc, &v);
    const char *msg = atmos_context_error(ctx);
    CHECK_MSG(st == want, "%s: status %s, want %s (%s)", path, atmos_status_string(st), atmos_status_string(want),
              msg);
    CHECK_MSG(v == NULL, "%s: volume returned on failure", path);
    if (st != ATMOS_OK) {
        CHECK_MSG(strstr(msg, path) != NULL, "%s: message does not name the file: %s", path, msg);
        if (needle) CHECK_MSG(strstr(msg, needle) != NULL, "%s: message lacks '%s': %s", path, needle, msg);
    }
    atmos_volume_destroy(v);
}

/* ------------------------------------------------------------ OpenVDB */

#ifdef ATMOS_HAVE_OPENVDB
static void test_openvdb_fixtures(void)
{
    char p[1024];
    const char *names[] = {"small.vdb", "small_zip.vdb", "small_blosc.vdb"};
    for (int n = 0; n < 3; n++) {
        fixture(p, sizeof p, names[n]);
        atmos_volume *v = NULL;
        CHECK_OK(atmos__volume_load_openvdb(ctx, p, NULL, &v));
        if (!v) continue;
        /* Default: only "density", named "cloud". */
        CHECK(atmos_volume_field_count(v) == 1);
        check_fixture_volume(v, small_A, small_t, names[n]);
        const atmos_volume_desc *d = atmos_volume_get_desc(v);
        CHECK_NEAR(d->origin_m[0], 10 + 0.5 * (-2.5), 1e-9);
        CHECK_NEAR(d->origin_m[1], 20 + 0.5 * (-0.5), 1e-9);
        CHECK_NEAR(d->origin_m[2], 30 + 0.5 * (-0.5), 1e-9);
        for (int i = 0; i < 9; i++) CHECK(d->rotation[i] == (i % 4 == 0 ? 1.0 : 0.0)); /* identity, resolved by the core */
        atmos_volume_destroy(v);
    }
    /* Several grids by name; a non-preset name keeps its name; desc->field names density. */
    fixture(p, sizeof p, "small.vdb");
    atmos_volume_load_desc ld = {.grids = "density,temperature", .field = "rain", .density_scale = 2};
    atmos_volume *v = NULL;
    CHECK_OK(atmos__volume_load_openvdb(ctx, p, &ld, &v));
    if (v) {
        CHECK(atmos_volume_field_count(v) == 2);
        int r = field_index(v, "rain"), t = field_index(v, "temperature");
        CHECK(r >= 0 && t >= 0);
        if (r >= 0 && t >= 0) {
            CHECK(strcmp(atmos_volume_field_particle(v, r), "rain") == 0);
            CHECK(strcmp(atmos_volume_field_particle(v, t), "rain") == 0);
            double w[3];
            vdb_world(small_A, small_t, 0, 0, 0, w);
            CHECK_NEAR(atmos_volume_sample(v, t, w), 300 * 2, 1e-3);
            CHECK_NEAR(atmos_volume_sample(v, r, w), 2 * fixture_value(0, 0, 0), 1e-4);
        }
        atmos_volume_destroy(v);
    }
    /* Rotation. */
    fixture(p, sizeof p, "rotated.vdb");
    v = NULL;
    CHECK_OK(atmos__volume_load_openvdb(ctx, p, NULL, &v));
    if (v) {
        check_fixture_volume(v, rot_A, rot_t, "rotated.vdb");
        const atmos_volume_desc *d = atmos_volume_get_desc(v);
        CHECK_NEAR(d->rotation[2], 1, 1e-9);  /* world x from index z */
        CHECK_NEAR(d->rotation[6], -1, 1e-9); /* world z from -index x */
        atmos_volume_destroy(v);
    }
    /* Errors. */
    atmos_volume_load_desc missing = {.grids = "smoke"};
    check_status(atmos__volume_load_openvdb, p, &missing, ATMOS_E_FORMAT, "grids present: density");
    fixture(p, sizeof p, "small.vdb");
    atmos_volume_load_desc vel = {.grids = "vel"};
    check_status(atmos__volume_load_openvdb, p, &vel, ATMOS_E_FORMAT, "vec3s");
    fixture(p, sizeof p, "vel_only.vdb");
    check_status(atmos__volume_load_openvdb, p, NULL, ATMOS_E_FORMAT, "no float grid");
    fixture(p, sizeof p, "nonuniform.vdb");
    check_status(atmos__volume_load_openvdb, p, NULL, ATMOS_E_UNSUPPORTED, "non-uniform voxel size");
    fixture(p, sizeof p, "frustum.vdb");
    check_status(atmos__volume_load_openvdb, p, NULL, ATMOS_E_UNSUPPORTED, "non-linear");
    fixture(p, sizeof p, "negative.vdb");
    check_status(atmos__volume_load_openvdb, p, NULL, ATMOS_E_FORMAT, "grid 'density'");
    fixture(p, sizeof p, "small.vdb");
    atmos_volume_load_desc tiny = {.max_memory = 1000};
    check_status(atmos__volume_load_openvdb, p, &tiny, ATMOS_E_LIMIT, "memory limit");
    check_status(atmos__volume_load_openvdb, "/nonexistent/x.vdb", NULL, ATMOS_E_IO, "cannot open");
    /* Two float grids of the same name: both load (OpenVDB names the second "cloud[1]"). */
    fixture(p, sizeof p, "dup_names.vdb");
    v = NULL;
    CHECK_OK(atmos__volume_load_openvdb(ctx, p, NULL, &v));
    if (v) {
        CHECK_MSG(atmos_volume_field_count(v) == 2, "%d fields", atmos_volume_field_count(v));
        CHECK(field_index(v, "cloud[0]") >= 0 && field_index(v, "cloud[1]") >= 0);
        atmos_volume_destroy(v);
    }
}

/* Writes the first n bytes of buf to path, with byte `flip` (if < n) set to `value`. */
static void write_mutant(const char *path, const unsigned char *buf, size_t n, size_t flip, unsigned char value)
{
    FILE *f = fopen(path, "wb");
    if (!f) return;
    fwrite(buf, 1, n, f);
    if (flip < n) {
        fseek(f, (long)flip, SEEK_SET);
        fputc(value, f);
    }
    fclose(f);
}

/* Damaged copies of the fixtures: every cut (a truncated file) must be refused, naming the
 * file; a flipped byte must give a volume or an error naming the file, never a crash of
 * this process (the library reads behind the fence). */
static void test_openvdb_damaged(void)
{
    const char *names[] = {"small.vdb", "small_blosc.vdb", "small_zip.vdb"};
    int cuts = 0, flips = 0, flips_ok = 0;
    for (int n = 0; n < 3; n++) {
        char p[1024], q[1024];
        fixture(p, sizeof p, names[n]);
        size_t size;
        unsigned char *buf = test_slurp(p, &size);
        CHECK_MSG(buf != NULL, "cannot read %s", p);
        if (!buf) continue;
        test_tmp_path(q, sizeof q, "damaged.vdb");
        const size_t stride = size / 97 + 1;
        for (size_t cut = 0; cut < size; cut += stride, cuts++) {
            write_mutant(q, buf, cut, SIZE_MAX, 0);
            atmos_volume *v = NULL;
            atmos_status st = atmos__volume_load_openvdb(ctx, q, NULL, &v);
            CHECK_MSG(st != ATMOS_OK, "%s cut to %zu bytes of %zu loaded", names[n], cut, size);
            if (st != ATMOS_OK) CHECK_MSG(strstr(atmos_context_error(ctx), q), "%s", atmos_context_error(ctx));
            atmos_volume_destroy(v);
        }
        if (n == 0) {
            /* the header's own message for a cut inside the grid, and for the crashers */
            write_mutant(q, buf, size / 2, SIZE_MAX, 0);
            check_status(atmos__volume_load_openvdb, q, NULL, ATMOS_E_FORMAT, "truncated");
            const char *src = getenv("ATMOS_SOURCE_DIR");
            snprintf(q, sizeof q, "%s/tests/crashers/volume/truncated_uncompressed.vdb", src && *src ? src : ".");
            check_status(atmos__volume_load_openvdb, q, NULL, ATMOS_E_FORMAT, "truncated: grid 'density' ends at");
            snprintf(q, sizeof q, "%s/tests/crashers/volume/dragon_creator_length.vdb", src && *src ? src : ".");
            check_status(atmos__volume_load_openvdb, q, NULL, ATMOS_E_FORMAT, "grids claimed");
            test_tmp_path(q, sizeof q, "damaged.vdb");
            /* a tree that disagrees with the count OpenVDB wrote next to it (here the count is
             * changed, as a damaged mask would change the tree) */
            unsigned char *c = malloc(size);
            size_t at = SIZE_MAX;
            for (size_t i = 0; c && i + 16 + 17 + 8 <= size && at == SIZE_MAX; i++)
                if (memcmp(buf + i, "file_voxel_count", 16) == 0) at = i + 16 + 4 + 5 + 4; /* type "int64", size 8 */
            CHECK_MSG(at != SIZE_MAX, "no file_voxel_count in %s", names[n]);
            if (c && at != SIZE_MAX) {
                memcpy(c, buf, size);
                c[at] ^= 1;
                write_mutant(q, c, size, SIZE_MAX, 0);
                check_status(atmos__volume_load_openvdb, q, NULL, ATMOS_E_FORMAT, "the file's own count says");
            }
            free(c);
        }
#ifdef __SANITIZE_ADDRESS__
        const size_t flip_stride = size / 10 + 1; /* a fork of a sanitized process is slow */
#else
        const size_t flip_stride = size / 40 + 1;
#endif
        for (size_t at = 7; n > 0 && at < size; at += flip_stride, flips++) {
            write_mutant(q, buf, size, at, (unsigned char)(buf[at] ^ 0xb5));
            atmos_volume *v = NULL;
            atmos_status st = atmos__volume_load_openvdb(ctx, q, NULL, &v);
            if (st == ATMOS_OK) flips_ok++;
            else CHECK_MSG(strstr(atmos_context_error(ctx), q), "%s", atmos_context_error(ctx));
            atmos_volume_destroy(v);
        }
        free(buf);
    }
    printf("damaged OpenVDB fixtures: %d cuts refused, %d flipped bytes (%d loaded)\n", cuts, flips, flips_ok);
}

/* The real files: counts from the file via the shim, placement and values via the reader. */
static void test_openvdb_real(void)
{
    char p[1024];
    real_file(p, sizeof p, "wdas_cloud_sixteenth.vdb");
    if (!file_exists(p)) {
        skip("wdas_cloud_sixteenth.vdb not found");
    } else {
        char msg[256];
        atmos__vdb *f = NULL;
        CHECK(atmos__vdb_open(p, &f, msg, sizeof msg) == ATMOS__VDB_OK);
        atmos__vdb_grid_stats gs;
        CHECK(f && atmos__vdb_load_grid(f, 0, &gs, msg, sizeof msg) == ATMOS__VDB_OK);
        CHECK_MSG(gs.active_voxels == 415642, "active %llu", (unsigned long long)gs.active_voxels);
        CHECK(gs.bbox_min[0] == -66 && gs.bbox_min[1] == -21 && gs.bbox_min[2] == -90);
        CHECK(gs.bbox_max[0] == 59 && gs.bbox_max[1] == 64 && gs.bbox_max[2] == 63);
        CHECK(gs.min >= 0 && gs.max <= 1.0 && gs.max > 0.5);
        atmos__vdb_close(f);

        atmos_volume *v = NULL;
        CHECK_OK(atmos__volume_load_openvdb(ctx, p, NULL, &v));
        if (v) {
            const atmos_volume_desc *d = atmos_volume_get_desc(v);
            CHECK(d->dims[0] == 126 && d->dims[1] == 86 && d->dims[2] == 154);
            CHECK_NEAR(d->voxel_size_m, 10.0 / 3.0, 1e-4);
            atmos_volume_field_stats st;
            CHECK_OK(atmos_volume_field_stats_get(ctx, v, 0, &st));
            /* Active voxels holding exactly 0 are not "density > 0". */
            CHECK(st.active_voxels <= 415642 && st.active_voxels > 300000);
            CHECK_MSG(st.file_active_voxels == 415642, "file active %llu", (unsigned long long)st.file_active_voxels);
            CHECK(st.max <= 1.0 && st.max > 0.5 && st.min > 0);
            /* Bounds: the index box in metres (cell-centred, so half a voxel beyond). */
            CHECK(st.bounds_m[0][0] >= (-66.5) * d->voxel_size_m - 1e-6);
            CHECK(st.bounds_m[1][1] <= (64.5) * d->voxel_size_m + 1e-6);
            printf("wdas cloud: %llu voxels > 0 (file: %llu active, %llu in leaves, %llu tiles), values %g..%g, "
                   "bounds [%.2f %.2f %.2f]..[%.2f %.2f %.2f] m\n",
                   (unsigned long long)st.active_voxels, (unsigned long long)gs.active_voxels,
                   (unsigned long long)gs.leaf_voxels, (unsigned long long)gs.active_tiles, st.min, st.max,
                   st.bounds_m[0][0], st.bounds_m[0][1], st.bounds_m[0][2], st.bounds_m[1][0], st.bounds_m[1][1],
                   st.bounds_m[1][2]);
            atmos_volume_destroy(v);
        }
    }
    real_file(p, sizeof p, "dragon.vdb");
    if (!file_exists(p)) {
        skip("dragon.vdb not found");
    } else {
        atmos_volume *v = NULL;
        CHECK_OK(atmos__volume_load_openvdb(ctx, p, NULL, &v));
        if (v) {
            atmos_volume_field_stats st;
            CHECK_OK(atmos_volume_field_stats_get(ctx, v, 0, &st));
            CHECK_MSG(st.active_voxels == 19660, "dragon active %llu", (unsigned long long)st.active_voxels);
            CHECK(st.min > 0 && st.max <= 1.0);
            const atmos_volume_desc *d = atmos_volume_get_desc(v);
            CHECK(d->dims[0] == 70 && d->dims[1] == 49 && d->dims[2] == 31);
            CHECK_NEAR(d->voxel_size_m, 0.1, 1e-6);
            printf("dragon: %llu voxels, values %g..%g, bounds [%.2f %.2f %.2f]..[%.2f %.2f %.2f] m\n",
                   (unsigned long long)st.active_voxels, st.min, st.max, st.bounds_m[0][0], st.bounds_m[0][1],
                   st.bounds_m[0][2], st.bounds_m[1][0], st.bounds_m[1][1], st.bounds_m[1][2]);
            atmos_volume_destroy(v);
        }
    }
}
#endif

/* ------------------------------------------------------------ NanoVDB */

#ifdef ATMOS_HAVE_NANOVDB
static void spit(const char *path, const unsigned char *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return;
    fwrite(b, 1, n, f);
    fclose(f);
}

static void test_nanovdb(void)
{
    char p[1024];
    fixture(p, sizeof p, "small.nvdb");
    if (!file_exists(p)) {
        CHECK_MSG(0, "NanoVDB fixtures missing (%s): did the fixtures.vdb test run?", p);
        return;
    }
    atmos_volume *v = NULL;
    CHECK_OK(atmos__volume_load_nanovdb(ctx, p, NULL, &v));
    if (v) {
        check_fixture_volume(v, small_A, small_t, "small.nvdb");
        atmos_volume_destroy(v);
    }
    fixture(p, sizeof p, "two.nvdb");
    v = NULL;
    CHECK_OK(atmos__volume_load_nanovdb(ctx, p, NULL, &v)); /* default picks density */
    if (v) {
        CHECK(atmos_volume_field_count(v) == 1);
        check_fixture_volume(v, small_A, small_t, "two.nvdb");
        atmos_volume_destroy(v);
    }
    atmos_volume_load_desc both = {.grids = "temperature,density"};
    v = NULL;
    CHECK_OK(atmos__volume_load_nanovdb(ctx, p, &both, &v));
    if (v) {
        CHECK(atmos_volume_field_count(v) == 2);
        int t = field_index(v, "temperature");
        double w[3];
        vdb_world(small_A, small_t, 0, 0, 0, w);
        CHECK(t >= 0 && fabs(atmos_volume_sample(v, t, w) - 300) < 1e-3);
        atmos_volume_destroy(v);
    }
    atmos_volume_load_desc missing = {.grids = "smoke"};
    check_status(atmos__volume_load_nanovdb, p, &missing, ATMOS_E_FORMAT, "grids present: temperature, density");

    fixture(p, sizeof p, "rotated.nvdb");
    v = NULL;
    CHECK_OK(atmos__volume_load_nanovdb(ctx, p, NULL, &v));
    if (v) {
        check_fixture_volume(v, rot_A, rot_t, "rotated.nvdb");
        atmos_volume_destroy(v);
    }
    fixture(p, sizeof p, "nonuniform.nvdb");
    check_status(atmos__volume_load_nanovdb, p, NULL, ATMOS_E_UNSUPPORTED, "non-uniform");
    fixture(p, sizeof p, "negative.nvdb");
    check_status(atmos__volume_load_nanovdb, p, NULL, ATMOS_E_FORMAT, "negative");
    fixture(p, sizeof p, "small.nvdb");
    atmos_volume_load_desc tiny = {.max_memory = 2000};
    check_status(atmos__volume_load_nanovdb, p, &tiny, ATMOS_E_LIMIT, NULL);
    /* A quantized grid: refused, saying quantized grids are the reason. */
    fixture(p, sizeof p, "fp16.nvdb");
    check_status(atmos__volume_load_nanovdb, p, NULL, ATMOS_E_UNSUPPORTED, "quantized Fp16");
    fixture(p, sizeof p, "small.nvdb");

    /* Modified copies: compressed codec, truncation, every single-byte corruption
     * of the header and a sweep of corruptions through the grid (no crash, and a
     * failure is always a clean status). */
    size_t n = 0;
    unsigned char *b = test_slurp(p, &n);
    CHECK(b && n > 1000);
    if (!b || n <= 1000) {
        free(b);
        return;
    }
    char q[1024];
    test_tmp_path(q, sizeof q, "zip.nvdb");
    unsigned char *c = malloc(n);
    memcpy(c, b, n);
    c[14] = 1; /* codec ZIP */
    spit(q, c, n);
    check_status(atmos__volume_load_nanovdb, q, NULL, ATMOS_E_UNSUPPORTED, "zip");
    test_tmp_path(q, sizeof q, "trunc.nvdb");
    spit(q, b, n / 2);
    check_status(atmos__volume_load_nanovdb, q, NULL, ATMOS_E_FORMAT, "truncated");
    spit(q, b, 10);
    check_status(atmos__volume_load_nanovdb, q, NULL, ATMOS_E_FORMAT, NULL);
    /* every cut of the file is refused */
    for (size_t cut = 0; cut < n; cut += n / 89 + 1) {
        spit(q, b, cut);
        atmos_volume *tv = NULL;
        CHECK_MSG(atmos__volume_load_nanovdb(ctx, q, NULL, &tv) != ATMOS_OK, "small.nvdb cut to %zu bytes loaded", cut);
        atmos_volume_destroy(tv);
    }
    int unclean = 0, loaded = 0;
    /* A small limit keeps mutants that spread voxels far apart cheap to refuse. */
    atmos_volume_load_desc small_mem = {.max_memory = 16u << 20};
    for (size_t off = 0; off < n; off += (off < 2000 ? 1 : 997)) {
        memcpy(c, b, n);
        c[off] ^= (unsigned char)(0x5a + off);
        atmos_volume *cv = NULL;
        atmos_status st = atmos__volume_load_nanovdb_mem(ctx, "mutant.nvdb", c, n, &small_mem, &cv);
        if (st == ATMOS_OK) loaded++;
        else if ((st != ATMOS_E_FORMAT && st != ATMOS_E_UNSUPPORTED && st != ATMOS_E_LIMIT) ||
                 !strstr(atmos_context_error(ctx), "mutant.nvdb")) {
            if (unclean++ < 3) fprintf(stderr, "byte %zu: %s: %s\n", off, atmos_status_string(st), atmos_context_error(ctx));
        }
        atmos_volume_destroy(cv);
    }
    CHECK_MSG(unclean == 0, "%d corrupted copies failed without a clean status/message", unclean);
    CHECK(loaded > 0); /* flipping a value byte still gives a valid grid */
    free(c);
    free(b);
}
#endif

/* ------------------------------------------------------------ crashers */

static int has_suffix(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && strcmp(s + a - b, suf) == 0;
}

static void test_crashers(void)
{
    char dir[1024];
    const char *src = getenv("ATMOS_SOURCE_DIR");
    snprintf(dir, sizeof dir, "%s/tests/crashers/volume", src && *src ? src : ".");
    DIR *d = opendir(dir);
    CHECK_MSG(d != NULL, "cannot open %s", dir);
    if (!d) return;
    int count = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.') continue;
        char p[2048];
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        loader load = NULL;
#ifdef ATMOS_HAVE_NANOVDB
        if (has_suffix(e->d_name, ".nvdb")) load = atmos__volume_load_nanovdb;
#endif
#ifdef ATMOS_HAVE_OPENVDB
        if (has_suffix(e->d_name, ".vdb")) load = atmos__volume_load_openvdb;
#endif
#ifdef ATMOS_HAVE_NETCDF
        if (has_suffix(e->d_name, ".nc")) load = atmos__volume_load_netcdf;
#endif
        if (!load) continue;
        /* limit_*: absurd sizes, refused before allocating; the rest are malformed. */
        check_status(load, p, NULL, strncmp(e->d_name, "limit_", 6) == 0 ? ATMOS_E_LIMIT : ATMOS_E_FORMAT, NULL);
        count++;
    }
    closedir(d);
    CHECK_MSG(count >= 3, "only %d volume crashers ran", count);
    printf("volume crashers: %d files\n", count);
}

#include "test_volume_readers_netcdf.inc"

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
#ifdef ATMOS_HAVE_OPENVDB
    test_openvdb_fixtures();
    test_openvdb_damaged();
    test_openvdb_real();
#else
    skip("OpenVDB reader not built");
#endif
#ifdef ATMOS_HAVE_NANOVDB
    test_nanovdb();
#else
    skip("NanoVDB reader not built");
#endif
#ifdef ATMOS_HAVE_NETCDF
    test_netcdf();
#else
    skip("NetCDF reader not built");
#endif
    test_crashers();
    atmos_context_destroy(ctx);
    if (skipped) printf("test_volume_readers: %d check groups skipped (not counted as passed)\n", skipped);
    return test_summary("test_volume_readers");
}
