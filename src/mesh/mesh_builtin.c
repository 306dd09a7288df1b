/* The built-in meshes (atmos_mesh_builtin_names): a sphere, a box, a plane, and a simple
 * aircraft of a cylinder and boxes. All fit in [-1, 1]^3; a scene's transform sizes them. */
#include "mesh/mesh_internal.h"

#include <math.h>
#include <string.h>

/* Sphere tessellation: SPHERE_LON segments around, SPHERE_LAT from pole to pole. The
 * vertices lie on the unit sphere, so the triangles are inside it by at most
 * 1 - cos(pi / SPHERE_LON) ~ 1.2e-3 of the radius (docs/beams.md). */
#define SPHERE_LON 64
#define SPHERE_LAT 32
#define CYL_SEGMENTS 24

typedef struct builder {
    atmos_mesh *m;
    int nv, nt;
} builder;

static int add_v(builder *b, double x, double y, double z)
{
    float *p = b->m->positions + 3 * b->nv;
    p[0] = (float)x, p[1] = (float)y, p[2] = (float)z;
    return b->nv++;
}

static void add_t(builder *b, int i, int j, int k)
{
    uint32_t *t = b->m->indices + 3 * b->nt++;
    t[0] = (uint32_t)i, t[1] = (uint32_t)j, t[2] = (uint32_t)k;
}

/* The box c +- h: each face two triangles, counter-clockwise seen from outside. */
static void add_box(builder *b, const double c[3], const double h[3])
{
    for (int a = 0; a < 3; a++)
        for (int s = -1; s <= 1; s += 2) {
            const int u = (a + 1) % 3, v = (a + 2) % 3;
            const double du[4] = {-1, 1, 1, -1}, dv[4] = {-1, -1, 1, 1};
            int id[4];
            for (int q = 0; q < 4; q++) {
                double p[3];
                p[a] = c[a] + s * h[a], p[u] = c[u] + du[q] * h[u], p[v] = c[v] + dv[q] * h[v];
                id[q] = add_v(b, p[0], p[1], p[2]);
            }
            if (s > 0) add_t(b, id[0], id[1], id[2]), add_t(b, id[0], id[2], id[3]);
            else add_t(b, id[0], id[2], id[1]), add_t(b, id[0], id[3], id[2]);
        }
}

/* A capped cylinder of radius r along z from z0 to z1 around (cx, cy). */
static void add_cylinder(builder *b, double cx, double cy, double r, double z0, double z1)
{
    const int base = b->nv;
    for (int i = 0; i < CYL_SEGMENTS; i++) {
        const double a = 2 * ATMOS_PI * i / CYL_SEGMENTS;
        add_v(b, cx + r * cos(a), cy + r * sin(a), z0);
        add_v(b, cx + r * cos(a), cy + r * sin(a), z1);
    }
    const int c0 = add_v(b, cx, cy, z0), c1 = add_v(b, cx, cy, z1);
    for (int i = 0; i < CYL_SEGMENTS; i++) {
        const int j = (i + 1) % CYL_SEGMENTS;
        const int A = base + 2 * i, B = base + 2 * j, C = base + 2 * j + 1, D = base + 2 * i + 1;
        add_t(b, A, B, C), add_t(b, A, C, D);
        add_t(b, c1, D, C), add_t(b, c0, B, A);
    }
}

static void make_sphere(builder *b)
{
    const int top = add_v(b, 0, 1, 0);
    for (int i = 1; i < SPHERE_LAT; i++) {
        const double th = ATMOS_PI * i / SPHERE_LAT;
        for (int j = 0; j < SPHERE_LON; j++) {
            const double ph = 2 * ATMOS_PI * j / SPHERE_LON;
            add_v(b, sin(th) * cos(ph), cos(th), -sin(th) * sin(ph));
        }
    }
    const int bottom = add_v(b, 0, -1, 0);
    const int L = SPHERE_LON;
#define RING(i, j) (1 + ((i) - 1) * L + ((j) % L))
    for (int j = 0; j < L; j++) {
        add_t(b, top, RING(1, j), RING(1, j + 1));
        add_t(b, bottom, RING(SPHERE_LAT - 1, j + 1), RING(SPHERE_LAT - 1, j));
        for (int i = 1; i + 1 < SPHERE_LAT; i++) {
            add_t(b, RING(i, j), RING(i + 1, j), RING(i + 1, j + 1));
            add_t(b, RING(i, j), RING(i + 1, j + 1), RING(i, j + 1));
        }
    }
#undef RING
    memcpy(b->m->normals, b->m->positions, sizeof(float) * 3 * (size_t)b->nv); /* unit sphere */
}

static void make_aircraft(builder *b)
{
    add_cylinder(b, 0, 0, 0.09, -1.0, 0.9);                              /* fuselage, nose at -z */
    add_box(b, (const double[3]){0, 0, -0.1}, (const double[3]){0.8, 0.015, 0.15});  /* wings */
    add_box(b, (const double[3]){0, 0.02, 0.8}, (const double[3]){0.3, 0.012, 0.08}); /* tailplane */
    add_box(b, (const double[3]){0, 0.18, 0.82}, (const double[3]){0.012, 0.16, 0.08}); /* fin */
}

const char *const *atmos_mesh_builtin_names(void)
{
    static const char *const names[] = {"sphere", "box", "plane", "aircraft", NULL};
    return names;
}

atmos_status atmos__mesh_builtin(atmos_context *ctx, const char *name, atmos_mesh **out)
{
    const int which = !strcmp(name, "sphere") ? 0 : !strcmp(name, "box") ? 1 : !strcmp(name, "plane") ? 2
                      : !strcmp(name, "aircraft") ? 3 : -1;
    if (which < 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mesh: unknown built-in \"%.64s\" (known: sphere, box, plane, aircraft)",
                            name);
    /* room enough for each (the counts are set from what was made) */
    const long nv = which == 0 ? 2 + (long)SPHERE_LON * (SPHERE_LAT - 1) : 256;
    const long nt = which == 0 ? 2L * SPHERE_LON * (SPHERE_LAT - 1) : 256;
    atmos_status st = atmos__mesh_alloc(ctx, nv, nt, which == 0, out);
    if (st != ATMOS_OK) return st;
    builder b = {*out, 0, 0};
    if (which == 0) make_sphere(&b);
    else if (which == 1) add_box(&b, (const double[3]){0, 0, 0}, (const double[3]){1, 1, 1});
    else if (which == 2) {
        const int a = add_v(&b, -1, 0, -1), c = add_v(&b, 1, 0, -1), d = add_v(&b, 1, 0, 1), e = add_v(&b, -1, 0, 1);
        add_t(&b, a, e, d), add_t(&b, a, d, c); /* facing +y */
    } else make_aircraft(&b);
    (*out)->vertex_count = b.nv, (*out)->triangle_count = b.nt;
    st = atmos_mesh_finish(ctx, *out);
    if (st != ATMOS_OK) atmos_mesh_destroy(*out), *out = NULL;
    return st;
}
