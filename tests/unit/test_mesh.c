/* Meshes: the built-in sphere's ray hits against the analytic sphere, the hierarchy against
 * a brute-force test of every triangle, outward winding, transforms, OBJ files written here
 * (a small one read back with the right counts and bounds; broken, empty, NaN, out-of-range
 * and oversized ones refused with a clear error). */
#include "atmos/atmos.h"
#include "test.h"

static atmos_context *ctx;

/* The analytic sphere |x - c| = r: the nearest t > 0 of o + t d (d unit), or -1. */
static double sphere_t(const double o[3], const double d[3], const double c[3], double r)
{
    const double oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
    const double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    const double q = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r, disc = b * b - q;
    if (disc < 0) return -1;
    const double t = -b - sqrt(disc);
    return t > 0 ? t : -1;
}

/* A deterministic sequence in [0, 1). */
static double rnd(unsigned *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (*s >> 8) / 16777216.0;
}

/* Rays from far away aimed at points of the sphere's disc within frac of its radius. */
static void ray_at(unsigned *seed, const double c[3], double r, double frac, double o[3], double d[3])
{
    double dir[3];
    for (;;) {
        for (int k = 0; k < 3; k++) dir[k] = 2 * rnd(seed) - 1;
        const double l = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        if (l > 0.1 && l < 1) {
            for (int k = 0; k < 3; k++) dir[k] /= l;
            break;
        }
    }
    /* an offset perpendicular to dir of length < frac r */
    double a[3] = {dir[1], -dir[0], 0};
    if (fabs(dir[2]) > 0.9) a[0] = 0, a[1] = dir[2], a[2] = -dir[1];
    const double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), off = frac * r * sqrt(rnd(seed));
    for (int k = 0; k < 3; k++) o[k] = c[k] + 5 * r * dir[k] + off * a[k] / la, d[k] = -dir[k];
}

static void test_sphere(void)
{
    atmos_mesh *m = NULL;
    CHECK_OK(atmos_mesh_load(ctx, "builtin:sphere", 0, &m));
    if (!m) return;
    /* triangles inside the unit sphere by at most ~2.4e-3 (a cell's half diagonal 0.069 rad);
     * at incidence below 45 degrees a hit moves by at most that over cos 45 */
    const double c0[3] = {0, 0, 0};
    unsigned seed = 7;
    int bad = 0, badn = 0;
    for (int i = 0; i < 2000; i++) {
        double o[3], d[3];
        ray_at(&seed, c0, 1, 0.7, o, d);
        atmos_mesh_hit h;
        const double ta = sphere_t(o, d, c0, 1);
        if (!atmos_mesh_intersect(m, o, d, 0, 1e9, &h) || fabs(h.t - ta) > 3.5e-3) bad++;
        else {
            double p[3];
            for (int k = 0; k < 3; k++) p[k] = o[k] + ta * d[k];
            if (p[0] * h.normal[0] + p[1] * h.normal[1] + p[2] * h.normal[2] < 0.999) badn++;
        }
    }
    CHECK_MSG(bad == 0, "%d of 2000 rays missed the analytic sphere's hit by more than 3.5e-3", bad);
    CHECK_MSG(badn == 0, "%d of 2000 normals off the analytic one by more than 2.6 degrees", badn);
    /* rays passing 1 % outside never hit */
    int hits = 0;
    for (int i = 0; i < 500; i++) {
        double o[3], d[3];
        ray_at(&seed, c0, 1, 0, o, d);
        double a[3] = {d[1], -d[0], 0};
        if (fabs(d[2]) > 0.9) a[0] = 0, a[1] = d[2], a[2] = -d[1];
        const double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        for (int k = 0; k < 3; k++) o[k] += 1.01 * a[k] / la;
        hits += atmos_mesh_intersect(m, o, d, 0, 1e9, NULL);
    }
    CHECK(hits == 0);
    /* moved and scaled: the same against the sphere of radius 2 at (10, 5, -3) */
    atmos_mesh_transform t;
    atmos_mesh_transform_identity(&t);
    t.position_m[0] = 10, t.position_m[1] = 5, t.position_m[2] = -3;
    t.scale[0] = t.scale[1] = t.scale[2] = 2;
    t.rotation_deg[1] = 30;
    CHECK_OK(atmos_mesh_apply_transform(ctx, m, &t));
    const double c1[3] = {10, 5, -3};
    bad = 0;
    for (int i = 0; i < 500; i++) {
        double o[3], d[3];
        ray_at(&seed, c1, 2, 0.7, o, d);
        atmos_mesh_hit h;
        if (!atmos_mesh_intersect(m, o, d, 0, 1e9, &h) || fabs(h.t - sphere_t(o, d, c1, 2)) > 7e-3) bad++;
    }
    CHECK_MSG(bad == 0, "%d of 500 rays off the moved sphere", bad);
    CHECK_NEAR(m->lo[1], 3, 1e-5);
    CHECK_NEAR(m->hi[1], 7, 1e-5);
    t.scale[1] = 0;
    CHECK(atmos_mesh_apply_transform(ctx, m, &t) == ATMOS_E_INVALID_ARG);
    atmos_mesh_destroy(m);
}

/* Moller-Trumbore over every triangle, written again here: the hierarchy's reference. */
static double brute_t(const atmos_mesh *m, const double o[3], const double d[3])
{
    double best = INFINITY;
    for (int i = 0; i < m->triangle_count; i++) {
        const float *p[3];
        for (int c = 0; c < 3; c++) p[c] = m->positions + 3 * m->indices[3 * i + c];
        double e1[3], e2[3], s[3], pv[3], qv[3];
        for (int k = 0; k < 3; k++) e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k], s[k] = o[k] - p[0][k];
        pv[0] = d[1] * e2[2] - d[2] * e2[1], pv[1] = d[2] * e2[0] - d[0] * e2[2], pv[2] = d[0] * e2[1] - d[1] * e2[0];
        const double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
        if (det == 0) continue;
        const double u = (s[0] * pv[0] + s[1] * pv[1] + s[2] * pv[2]) / det;
        qv[0] = s[1] * e1[2] - s[2] * e1[1], qv[1] = s[2] * e1[0] - s[0] * e1[2], qv[2] = s[0] * e1[1] - s[1] * e1[0];
        const double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) / det;
        const double t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
        if (u >= 0 && v >= 0 && u + v <= 1 && t > 0 && t < best) best = t;
    }
    return best;
}

static void test_builtins(void)
{
    for (const char *const *n = atmos_mesh_builtin_names(); *n; n++) {
        char src[64];
        snprintf(src, sizeof src, "builtin:%s", *n);
        atmos_mesh *m = NULL;
        CHECK_OK(atmos_mesh_load(ctx, src, 0, &m));
        if (!m) continue;
        CHECK(m->triangle_count > 0 && m->lo[0] >= -1 && m->hi[0] <= 1 && m->lo[2] >= -1 && m->hi[2] <= 1);
        /* closed meshes wind outward: each face normal points away from the solid's inside */
        if (!strcmp(*n, "sphere") || !strcmp(*n, "box")) {
            int inward = 0;
            for (int i = 0; i < m->triangle_count; i++) {
                double c[3] = {0, 0, 0}, e1[3], e2[3];
                const float *p[3];
                for (int k = 0; k < 3; k++) p[k] = m->positions + 3 * m->indices[3 * i + k];
                for (int k = 0; k < 3; k++) c[k] = (p[0][k] + p[1][k] + p[2][k]) / 3, e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k];
                const double nx = e1[1] * e2[2] - e1[2] * e2[1], ny = e1[2] * e2[0] - e1[0] * e2[2],
                             nz = e1[0] * e2[1] - e1[1] * e2[0];
                inward += nx * c[0] + ny * c[1] + nz * c[2] <= 0;
            }
            CHECK_MSG(inward == 0, "builtin:%s: %d triangles wound inward", *n, inward);
        }
        /* the hierarchy against every triangle */
        unsigned seed = 11;
        int bad = 0;
        for (int i = 0; i < 300; i++) {
            double o[3], d[3];
            const double c[3] = {0, 0, 0};
            ray_at(&seed, c, 1.2, 1.0, o, d);
            atmos_mesh_hit h;
            const double tb = brute_t(m, o, d);
            const int hit = atmos_mesh_intersect(m, o, d, 0, 1e9, &h);
            if (hit != isfinite(tb) || (hit && fabs(h.t - tb) > 1e-9 * (1 + tb))) bad++;
        }
        CHECK_MSG(bad == 0, "builtin:%s: %d of 300 rays differ from the brute-force test", *n, bad);
        atmos_mesh_destroy(m);
    }
    atmos_mesh *m = NULL;
    CHECK(atmos_mesh_load(ctx, "builtin:teapot", 0, &m) == ATMOS_E_INVALID_ARG && !m);
    CHECK(strstr(atmos_context_error(ctx), "teapot") != NULL);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (f) fputs(text, f), fclose(f);
}

/* Loading text written as an OBJ file must fail with want and a message containing needle. */
static void expect_fail(const char *name, const char *text, int max_tris, atmos_status want, const char *needle)
{
    char path[1024];
    test_tmp_path(path, sizeof path, name);
    if (text) write_file(path, text);
    else remove(path);
    atmos_mesh *m = NULL;
    const atmos_status st = atmos_mesh_load(ctx, path, max_tris, &m);
    CHECK_MSG(st == want && !m, "%s: got %s (%s)", name, atmos_status_string(st), atmos_context_error(ctx));
    CHECK_MSG(strstr(atmos_context_error(ctx), needle) != NULL, "%s: message \"%s\" lacks \"%s\"", name,
              atmos_context_error(ctx), needle);
    atmos_mesh_destroy(m);
}

static void test_obj(void)
{
    char path[1024];
    test_tmp_path(path, sizeof path, "small.obj");
    write_file(path, "# a quad and a triangle\n"
                     "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nv 1 0.5 -3\n"
                     "vn 0 0 1\n"
                     "f 1//1 2//1 3//1 4//1\n"
                     "f 1 3 5\n");
    atmos_mesh *m = NULL;
    CHECK_OK(atmos_mesh_load(ctx, path, 0, &m));
    if (m) {
        CHECK(m->vertex_count == 5 && m->triangle_count == 3 && !m->vertex_normals);
        CHECK(m->lo[0] == 0 && m->lo[1] == 0 && m->lo[2] == -3 && m->hi[0] == 2 && m->hi[1] == 1 && m->hi[2] == 0);
        const double o[3] = {1.5, 0.4, 5}, d[3] = {0, 0, -1};
        atmos_mesh_hit h;
        CHECK(atmos_mesh_intersect(m, o, d, 0, 100, &h) && fabs(h.t - 5) < 1e-9 && h.normal[2] > 0.999);
        atmos_mesh_destroy(m);
    }
    /* comments after a line's content (OBJ: '#' to the end of the line), the same triangles;
     * a comment's own '#' after a face's vertices was read as a vertex index */
    write_file(path, "v 0 0 0 # the origin\nv 2 0 0\nv 2 1 0\t#right\nv 0 1 0\nv 1 0.5 -3\n"
                     "vn 0 0 1 # up\n"
                     "f 1//1 2//1 3//1 4//1 # the quad\n"
                     "f 1 3 5#tri\n"
                     "# f 1 2 3 4 5\n");
    m = NULL;
    CHECK_OK(atmos_mesh_load(ctx, path, 0, &m));
    if (m) {
        CHECK(m->vertex_count == 5 && m->triangle_count == 3);
        CHECK(m->lo[0] == 0 && m->lo[1] == 0 && m->lo[2] == -3 && m->hi[0] == 2 && m->hi[1] == 1 && m->hi[2] == 0);
        atmos_mesh_destroy(m);
    }
    expect_fail("comment_bound.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 # 1 2 3\nf 1 2 3 # 4\n", 1,
                ATMOS_E_LIMIT, "more than 1 triangles");
    expect_fail("comment_after.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0 # third\nf 1 2 x # bad\n", 0, ATMOS_E_FORMAT,
                "line 4: a face's vertex 'x'");
    expect_fail("missing.obj", NULL, 0, ATMOS_E_IO, "missing.obj");
    expect_fail("broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", 0, ATMOS_E_FORMAT, "broken.obj");
    expect_fail("garbage.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x y\n", 0, ATMOS_E_FORMAT, "garbage.obj");
    expect_fail("nofaces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", 0, ATMOS_E_FORMAT, "no triangles");
    expect_fail("empty.obj", "", 0, ATMOS_E_FORMAT, "no triangles");
    /* a truncated file (its last face cut to two vertices): the line, not a mesh of fewer faces */
    expect_fail("cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 4 1", 0, ATMOS_E_FORMAT, "line 6");
    expect_fail("png.obj", "\211PNG\r\n\032\n", 0, ATMOS_E_FORMAT, "not an OBJ file");
    expect_fail("bom.obj", "\357\273\277v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 0, ATMOS_E_FORMAT, "byte-order mark");
    expect_fail("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", 0, ATMOS_E_FORMAT, "line 2");
    expect_fail("huge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 1 2 4\n", 2, ATMOS_E_LIMIT,
                "more than 2 triangles");
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    test_sphere();
    test_builtins();
    test_obj();
    atmos_context_destroy(ctx);
    return test_summary("test_mesh");
}
