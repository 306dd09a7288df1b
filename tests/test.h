/* Minimal test harness: CHECK-style macros that count and report failures.
 * Each test program ends with `return test_summary("name");`, which prints
 * "name: N passed, N failed" and returns nonzero on any failure. */
#ifndef ATMOS_TEST_H
#define ATMOS_TEST_H

#include "atmos/atmos.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* 1 in the sanitizer copies of the tests (asan.*): they are there for memory errors, the numbers
 * are checked by the plain copy (unit.*), so a slow test may run fewer of its cases there. */
#if defined(__has_feature) /* clang says it so; GCC defines __SANITIZE_ADDRESS__ */
#if __has_feature(address_sanitizer)
#define TEST_ASAN_ 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(TEST_ASAN_)
#define TEST_SANITIZED 1
#else
#define TEST_SANITIZED 0
#endif

static int test_passed_, test_failed_;

#define CHECK(cond)                                                                   \
    do {                                                                              \
        if (cond) test_passed_++;                                                     \
        else { test_failed_++; fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); } \
    } while (0)

#define CHECK_MSG(cond, ...)                                                          \
    do {                                                                              \
        if (cond) test_passed_++;                                                     \
        else { test_failed_++; fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
               fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); }                   \
    } while (0)

/* |a-b| <= tol */
#define CHECK_NEAR(a, b, tol)                                                         \
    do {                                                                              \
        double a_ = (a), b_ = (b), t_ = (tol);                                        \
        if (fabs(a_ - b_) <= t_) test_passed_++;                                      \
        else { test_failed_++; fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.10g, %s = %.10g, tol %.3g\n", \
                                       __FILE__, __LINE__, #a, a_, #b, b_, t_); }     \
    } while (0)

/* relative error |a-b|/|b| <= rel (absolute when b == 0) */
#define CHECK_REL(a, b, rel)                                                          \
    do {                                                                              \
        double a_ = (a), b_ = (b), r_ = (rel);                                        \
        double e_ = b_ != 0 ? fabs(a_ - b_) / fabs(b_) : fabs(a_);                    \
        if (e_ <= r_) test_passed_++;                                                 \
        else { test_failed_++; fprintf(stderr, "%s:%d: CHECK_REL failed: %s = %.10g, %s = %.10g, rel err %.3g > %.3g\n", \
                                       __FILE__, __LINE__, #a, a_, #b, b_, e_, r_); } \
    } while (0)

#define CHECK_OK(expr)                                                                \
    do {                                                                              \
        atmos_status s_ = (expr);                                                     \
        if (s_ == ATMOS_OK) test_passed_++;                                           \
        else { test_failed_++; fprintf(stderr, "%s:%d: %s returned %s\n", __FILE__, __LINE__, #expr, \
                                       atmos_status_string(s_)); }                    \
    } while (0)

/* A number in [0, 1) from a splitmix64 stream (Steele, Lea and Flood 2014): *state is the
 * stream's position, advanced by one draw. */
static inline double test_uniform_from(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

static inline int test_summary(const char *name)
{
    printf("%s: %d passed, %d failed\n", name, test_passed_, test_failed_);
    return test_failed_ ? 1 : 0;
}

/* A context for a test: `threads` threads, no log, its tables cached in `cache_dir` (the test's
 * scratch cache; NULL: the user's); exits on failure. */
static inline atmos_context *test_context(int threads, const char *cache_dir)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = threads;
    d.cache_dir = cache_dir;
    d.log = NULL;
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) exit(1);
    return ctx;
}

/* A generated preset volume (seed; voxel edge in metres, 0: the preset's own), checked. */
static inline atmos_volume *test_generate(atmos_context *ctx, const char *preset, uint64_t seed, double voxel)
{
    atmos_volume_generate_desc g = {.seed = seed, .voxel_size_m = voxel};
    atmos_volume *v = NULL;
    atmos_status st = atmos_volume_generate(ctx, preset, &g, &v);
    CHECK_MSG(st == ATMOS_OK, "%s: %s", preset, atmos_context_error(ctx));
    return v;
}

/* The index of v's field called name, -1 if it has none. */
static inline int test_field_index(const atmos_volume *v, const char *name)
{
    for (int f = 0; f < atmos_volume_field_count(v); f++)
        if (!strcmp(atmos_volume_field_name(v, f), name)) return f;
    return -1;
}

/* The scenes the renderers' volume tests share: rgb, a vacuum (no air: the volume alone), the sun
 * at sun_el, sun_az (degrees, not from a date) with a 0.05 degree disk. */
static inline void test_vacuum_scene(atmos_scene *s, double sun_el, double sun_az)
{
    atmos_scene_defaults(s);
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
    s->atmosphere.kind = ATMOS_ATMOSPHERE_VACUUM;
    s->atmosphere.sun_diameter_deg = 0.05;
    s->sun.from_time = 0;
    s->sun.elevation_deg = sun_el, s->sun.azimuth_deg = sun_az;
}

/* A finalized volume of one field (name, particle type) of dims voxels of size vs (m), its corner
 * at origin (m), the density buf (x fastest, m^-3); NULL (and a failed check) on an error. */
static inline atmos_volume *test_dense_volume(atmos_context *ctx, const int dims[3], double vs,
                                              const double origin[3], const char *name, const char *type,
                                              const float *buf)
{
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    for (int a = 0; a < 3; a++) vd.dims[a] = dims[a], vd.origin_m[a] = origin[a];
    vd.voxel_size_m = vs;
    atmos_volume *v = NULL;
    int f = -1, off[3] = {0, 0, 0}, size[3] = {dims[0], dims[1], dims[2]};
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    if (!v) return NULL;
    CHECK_OK(atmos_volume_add_field(ctx, v, name, type, &f));
    CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, buf, 1.0f));
    CHECK_OK(atmos_volume_finalize(ctx, v));
    return v;
}

/* test_dense_volume's volume of one "cloud" field of type "hg", its base (dims[0] x dims[2]
 * voxels of size vs) centred over the origin, 1000 m up. */
static inline atmos_volume *test_cloud_volume(atmos_context *ctx, const int dims[3], double vs, const float *buf)
{
    const double org[3] = {-0.5 * dims[0] * vs, 1000, -0.5 * dims[2] * vs};
    return test_dense_volume(ctx, dims, vs, org, "cloud", "hg", buf);
}

/* One frame of scene s (volume v, optics; the volume where its own coordinates put it, as
 * atmos_render_path does) through a plan made for it, checked; NULL on failure. Rows [y0, y1)
 * alone when y1 > y0 (the rest of the image left as created), else the whole frame. */
static inline atmos_image *test_plan_frame_rows(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v,
                                                const atmos_volume_optics *optics, int y0, int y1)
{
    atmos_plan_desc d;
    memset(&d, 0, sizeof d);
    d.optics = optics;
    d.offset_given = 1;
    atmos_plan *p = NULL;
    atmos_frame f;
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_create(ctx, s, v, &d, &p));
    if (p && atmos_frame_from_scene(ctx, s, &f) == ATMOS_OK && atmos_plan_image_create(p, &f, &img) == ATMOS_OK) {
        const atmos_region r = {0, y0, s->width, y1};
        CHECK_MSG(atmos_plan_render(p, &f, y1 > y0 ? &r : NULL, img, NULL) == ATMOS_OK, "render: %s",
                  atmos_context_error(ctx));
    }
    atmos_plan_destroy(p);
    return img;
}

/* The Nishita renderer as Nishita et al. 1996 wrote it (orders 2-3 by reference patterns, sky
 * elements): its default since 2026-12-07 is the discrete-ordinates field (do, delta-M). */
static inline void test_nishita_paper(atmos_scene *s)
{
    s->nishita.do_field = 0, s->nishita.mc_delta_m = 0;
}

/* test_plan_frame_rows' whole frame. */
static inline atmos_image *test_plan_frame(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v,
                                           const atmos_volume_optics *optics)
{
    return test_plan_frame_rows(ctx, s, v, optics, 0, 0);
}

/* The fraction of pixel (x, y) of a w x w pinhole image (vertical field fov_deg) inside the disk
 * of a sphere on the optical axis whose angular radius has the sine s: 32 x 32 rays over the
 * pixel's area (the pixel's rays are symmetric about the axis). */
static inline double test_disk_coverage(int x, int y, int w, double fov_deg, double s)
{
    const double th = tan(0.5 * fov_deg * 3.14159265358979323846 / 180.0);
    int in = 0;
    for (int b = 0; b < 32; b++)
        for (int a = 0; a < 32; a++) {
            const double u = (2.0 * (x + (a + 0.5) / 32) / w - 1.0) * th, v = (2.0 * (y + (b + 0.5) / 32) / w - 1.0) * th;
            in += (u * u + v * v) / (1.0 + u * u + v * v) < s * s; /* sin^2 of the angle to the axis */
        }
    return in / 1024.0;
}

/* Scratch path for a test's output files: $ATMOS_TEST_TMP/name (or /tmp). */
static inline void test_tmp_path(char *buf, size_t cap, const char *name)
{
    const char *dir = getenv("ATMOS_TEST_TMP");
    snprintf(buf, cap, "%s/%s", dir && *dir ? dir : "/tmp", name);
}

/* The whole file at path in a malloc'ed buffer (*n bytes), or NULL. */
static inline unsigned char *test_slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    *n = 0;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long sz = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc(sz > 0 ? (size_t)sz : 1);
    *n = buf && sz > 0 ? fread(buf, 1, (size_t)sz, f) : 0;
    fclose(f);
    return buf;
}

#endif
