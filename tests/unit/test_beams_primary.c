/* The beam renderer's primary visibility by rasterisation (render/beams_primary.h) against the
 * traced search through the meshes' hierarchies (atmos__objects_hit), the reference: on every
 * pixel of small scenes the same answer (a hit or not, the same mesh and triangle, the same
 * depth to 1e-12 and the same normal), whether the raster settled the pixel or marked it to be
 * traced; the marked pixels few (the raster does the work); a region the same as the whole
 * frame's buffer over it; one thread and two the same buffer; a fisheye camera all traced.
 * Scenes: a floor that runs behind the eye (clipped at the near plane), a box, a sphere, an
 * aircraft and a mat lying exactly in the floor's plane (the two depths tie: marked); a
 * generated ridge seen low across, at two sizes (the smaller with more triangles than pixels);
 * a generated block city seen low across its streets. */
#include "atmos/atmos.h"
#include "render/beams_primary.h"
#include "test.h"
#include "test_mesh.h"

static atmos_context *ctx;

static atmos_mesh *placed(const char *source, double x, double y, double z, double sx, double sy, double sz, double ry)
{
    atmos_mesh *m = NULL;
    if (atmos_mesh_load(ctx, source, 0, &m) != ATMOS_OK) exit(1);
    return test_mesh_place(ctx, m, x, y, z, sx, sy, sz, ry);
}

static atmos_camera camera(atmos_camera_type type, const double eye[3], const double at[3], double fov, int w, int h)
{
    atmos_camera_desc d;
    memset(&d, 0, sizeof d);
    d.type = type, d.fov_deg = fov;
    memcpy(d.position, eye, sizeof d.position);
    memcpy(d.look_at, at, sizeof d.look_at);
    atmos_camera cam;
    if (atmos_camera_init(ctx, &d, w, h, &cam) != ATMOS_OK) exit(1);
    return cam;
}

/* Every pixel of r: the buffer's answer against the traced one. Returns the pixels that hit. */
static long compare(const atmos__objects *ob, const atmos_camera *cam, const atmos__beams_primary *P, const char *what)
{
    long hits = 0, bad = 0;
    for (int y = P->r.y0; y < P->r.y1; y++)
        for (int x = P->r.x0; x < P->r.x1; x++) {
            double d[3];
            atmos_camera_ray(cam, x + 0.5, y + 0.5, d);
            atmos_mesh_hit a = {0, -1, {0, 0, 0}}, b = {0, -1, {0, 0, 0}};
            int ma = -1, mb = -1;
            const int ha = atmos__beams_primary_hit(P, ob, x, y, cam->position, d, &a, &ma);
            const int hb = atmos__objects_hit(ob, cam->position, d, 0, INFINITY, &b, &mb);
            hits += hb;
            const int same = ha == hb && (!hb || (ma == mb && a.triangle == b.triangle && fabs(a.t - b.t) <= 1e-12 * b.t &&
                                                  a.normal[0] == b.normal[0] && a.normal[1] == b.normal[1] &&
                                                  a.normal[2] == b.normal[2]));
            if (!same && bad++ < 5)
                fprintf(stderr, "%s: pixel %d,%d: raster %d (mesh %d tri %d t %.9g), traced %d (mesh %d tri %d t %.9g)\n", what,
                        x, y, ha, ma, a.triangle, a.t, hb, mb, b.triangle, b.t);
        }
    CHECK_MSG(bad == 0, "%s: %ld pixels differ from the traced hit", what, bad);
    return hits;
}

static void test_studio(void)
{
    atmos_mesh *m[5] = {placed("builtin:plane", 0, 0, 0, 20, 1, 20, 0), placed("builtin:box", -2, 1, -6, 1, 1, 1, 30),
                        placed("builtin:sphere", 1.5, 1.2, -5, 1.2, 1.2, 1.2, 0),
                        placed("builtin:aircraft", 0, 3, -8, 2, 2, 2, 60), placed("builtin:plane", 1, 0, -3, 1.5, 1, 1, 0)};
    double alb[5][ATMOS_MAX_WAVELENGTHS] = {{0}};
    const atmos__objects ob = {5, m, alb};
    const double eye[3] = {0.3, 1.7, 2}, at[3] = {0, 1, -6};
    const atmos_camera cam = camera(ATMOS_CAMERA_PINHOLE, eye, at, 60, 144, 96);
    atmos__beams_primary P;
    const atmos__rect all = {0, 0, cam.width, cam.height};
    CHECK_OK(atmos__beams_primary_build(ctx, &ob, &cam, &all, &P));
    const long hits = compare(&ob, &cam, &P, "studio");
    CHECK(hits > cam.width * cam.height / 2);
    printf("studio: %ld of %d pixels traced, %ld hit\n", P.traced, cam.width * cam.height, hits);
    CHECK(P.traced > 0);                           /* the mat's tie with the floor at least */
    CHECK(P.traced < cam.width * cam.height / 10); /* the raster settles the rest */
    /* a region: the same entries as the whole frame's */
    atmos__beams_primary Q;
    const atmos__rect part = {37, 20, 101, 71};
    CHECK_OK(atmos__beams_primary_build(ctx, &ob, &cam, &part, &Q));
    long differ = 0;
    for (int y = part.y0; y < part.y1; y++)
        for (int x = part.x0; x < part.x1; x++) {
            const size_t i = (size_t)(y - part.y0) * (part.x1 - part.x0) + (x - part.x0), j = (size_t)y * cam.width + x;
            differ += Q.mesh[i] != P.mesh[j] || (P.mesh[j] >= 0 && Q.tri[i] != P.tri[j]);
        }
    CHECK_MSG(differ == 0, "a region's buffer differs from the frame's on %ld pixels", differ);
    compare(&ob, &cam, &Q, "studio region");
    atmos__beams_primary_free(&Q);
    /* one thread: the same buffer */
    atmos_context *one = test_context(1, NULL);
    CHECK_OK(atmos__beams_primary_build(one, &ob, &cam, &all, &Q));
    differ = 0;
    for (size_t i = 0; i < (size_t)cam.width * cam.height; i++) differ += Q.mesh[i] != P.mesh[i] || Q.tri[i] != P.tri[i];
    CHECK_MSG(differ == 0, "one thread's buffer differs from two threads' on %ld pixels", differ);
    atmos__beams_primary_free(&Q);
    atmos_context_destroy(one);
    /* a fisheye: every pixel traced */
    const atmos_camera fish = camera(ATMOS_CAMERA_FISHEYE, eye, at, 180, 48, 48);
    const atmos__rect fr = {0, 0, 48, 48};
    CHECK_OK(atmos__beams_primary_build(ctx, &ob, &fish, &fr, &Q));
    CHECK(Q.traced == 48 * 48);
    atmos__beams_primary_free(&Q);
    atmos__beams_primary_free(&P);
    /* the single-triangle test refuses a triangle out of range */
    const double o[3] = {0, 5, 0}, down[3] = {0, -1, 0};
    CHECK(!atmos_mesh_intersect_triangle(m[0], -1, o, down, 0, INFINITY, NULL));
    CHECK(!atmos_mesh_intersect_triangle(m[0], m[0]->triangle_count, o, down, 0, INFINITY, NULL));
    CHECK(!atmos_mesh_intersect_triangle(NULL, 0, o, down, 0, INFINITY, NULL));
    for (int i = 0; i < 5; i++) atmos_mesh_destroy(m[i]);
}

/* A generated terrain mesh (NULL on failure, which is checked). */
static atmos_mesh *terrain(const char *source, double size_m, double height_m, int samples, uint64_t seed)
{
    atmos_terrain_desc t;
    memset(&t, 0, sizeof t);
    t.source = source, t.size_m = size_m, t.height_m = height_m, t.samples = samples, t.seed = seed;
    atmos_mesh *m = NULL;
    CHECK_OK(atmos_mesh_terrain(ctx, &t, &m));
    return m;
}

static void test_ridges(void)
{
    atmos_mesh *m = terrain("generate:ridges", 8000, 1500, 65, 7);
    if (!m) return;
    double alb[1][ATMOS_MAX_WAVELENGTHS] = {{0}};
    const atmos__objects ob = {1, &m, alb};
    const double eye[3] = {0, 300, 4500}, at[3] = {0, 500, 0};
    const atmos_camera cam = camera(ATMOS_CAMERA_PINHOLE, eye, at, 50, 180, 120);
    atmos__beams_primary P;
    const atmos__rect all = {0, 0, cam.width, cam.height};
    CHECK_OK(atmos__beams_primary_build(ctx, &ob, &cam, &all, &P));
    const long hits = compare(&ob, &cam, &P, "ridges");
    printf("ridges: %ld of %d pixels traced, %ld hit\n", P.traced, cam.width * cam.height, hits);
    CHECK(hits > cam.width * cam.height / 4 && hits < cam.width * cam.height);
    CHECK(P.traced < cam.width * cam.height / 10);
    atmos__beams_primary_free(&P);
    /* a smaller image of the same 8192 triangles, 1.6 a pixel: still drawn, not traced */
    const atmos_camera tiny = camera(ATMOS_CAMERA_PINHOLE, eye, at, 50, 100, 50);
    const atmos__rect small = {0, 0, 100, 50};
    CHECK_OK(atmos__beams_primary_build(ctx, &ob, &tiny, &small, &P));
    printf("ridges at 100x50: %ld of %d pixels traced\n", P.traced, 100 * 50);
    CHECK(P.traced < 100 * 50 / 10);
    compare(&ob, &tiny, &P, "ridges, small");
    atmos__beams_primary_free(&P);
    atmos_mesh_destroy(m);
}

/* A block city seen low across its streets (walls many deep along a ray, most of its triangles
 * hidden or smaller than a pixel), 1.3 triangles a pixel: drawn, the same hits as traced. */
static void test_city(void)
{
    atmos_mesh *m = terrain("generate:city", 2000, 150, 97, 5);
    if (!m) return;
    double alb[1][ATMOS_MAX_WAVELENGTHS] = {{0}};
    const atmos__objects ob = {1, &m, alb};
    const double eye[3] = {0, 60, 1400}, at[3] = {0, 350, 0};
    const atmos_camera cam = camera(ATMOS_CAMERA_PINHOLE, eye, at, 60, 144, 96);
    CHECK(m->triangle_count > cam.width * cam.height);
    atmos__beams_primary P;
    const atmos__rect all = {0, 0, cam.width, cam.height};
    CHECK_OK(atmos__beams_primary_build(ctx, &ob, &cam, &all, &P));
    const long hits = compare(&ob, &cam, &P, "city");
    printf("city: %d triangles, %ld of %d pixels traced, %ld hit\n", m->triangle_count, P.traced,
           cam.width * cam.height, hits);
    CHECK(hits > cam.width * cam.height / 10);
    CHECK(P.traced < cam.width * cam.height / 10);
    /* one thread: the same buffer */
    atmos__beams_primary Q;
    atmos_context *one = test_context(1, NULL);
    CHECK_OK(atmos__beams_primary_build(one, &ob, &cam, &all, &Q));
    long differ = 0;
    for (size_t i = 0; i < (size_t)cam.width * cam.height; i++) differ += Q.mesh[i] != P.mesh[i] || Q.tri[i] != P.tri[i];
    CHECK_MSG(differ == 0, "one thread's buffer differs from two threads' on %ld pixels", differ);
    atmos__beams_primary_free(&Q);
    atmos_context_destroy(one);
    atmos__beams_primary_free(&P);
    atmos_mesh_destroy(m);
}

int main(void)
{
    ctx = test_context(2, NULL);
    test_studio();
    test_ridges();
    test_city();
    atmos_context_destroy(ctx);
    return test_summary("test_beams_primary");
}
