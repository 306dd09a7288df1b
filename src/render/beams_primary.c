/* The beam renderer's primary visibility by rasterisation (beams_primary.h). The image is cut
 * into tiles of TILE x TILE pixels, each drawn by one thread: for each mesh its hierarchy is
 * walked nearest boxes first (mesh_walk.h), a box skipped when it lies behind the near plane,
 * beside the tile, or behind the surfaces already drawn at every pixel centre it may cover;
 * a leaf's triangles are clipped at the near plane (Sutherland-Hodgman), projected in double
 * and drawn: per pixel centre the nearest triangle that surely covers it (at least EDGE_PX
 * inside every edge), and the least depth of any rival that might be as near (one within
 * EDGE_PX of covering it, a covering one within DEPTH_TOL of the nearest, one seen edge-on). A
 * pixel with such a rival is traced. The depth is the view depth, its reciprocal affine across
 * a triangle. A skipped box holds nothing that could change a pixel's entry (neither a nearer
 * cover nor a rival within DEPTH_TOL), and the entries do not depend on the order the
 * triangles are drawn in, so the buffer is the one every triangle drawn would give, whatever
 * the tiles and the threads. A city's walls many deep along a ray cost their hierarchy's boxes,
 * not their pixels. */
#include "render/beams_primary.h"
#include "render/beams_raster.h"
#include "mesh/mesh_walk.h"
#include "core/clones.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NEAR_M 1e-3
#define EDGE_PX 1e-3
#define DEPTH_TOL 1e-6
#define TILE 64
/* A box is hidden when every pixel centre it may cover has a surface nearer than its nearest
 * corner by more than DEPTH_TOL and this much more (rounding of the drawn depths). */
#define HIDDEN_MARGIN 1e-9

/* A triangle (or a clipped part of one) on the image: pixel coordinates, 1 / view depth, the
 * rows and columns of the tile's pixel centres its box (widened by EDGE_PX) holds. */
typedef struct stri {
    double x[3], y[3], iz[3];
    int mesh, tri;
    int px0, px1, py0, py1;
} stri;

/* One tile's pixels [x0, x1) x [y0, y1), row by row: the nearest covering depth z, the least
 * depth u of a rival, the mesh and triangle; and the mesh being drawn. */
typedef struct tile {
    const atmos_camera *cam;
    const atmos__objects *ob;
    int x0, x1, y0, y1, mesh;
    double *z, *u;
    int *mm, *tri;
} tile;

/* The least and the greatest of three. Here atmos__mind / atmos__maxd stand for fmin / fmax,
 * which are calls into the maths library: the same values, since no operand is a NaN (the
 * projected vertices are finite; unlike fmin, a NaN here would not always be skipped), and a
 * zero's sign does not change the bounds' ceil, floor and comparisons. */
#define MIN3(v) atmos__mind((v)[0], atmos__mind((v)[1], (v)[2]))
#define MAX3(v) atmos__maxd((v)[0], atmos__maxd((v)[1], (v)[2]))

static size_t at(const tile *T, int px, int py) { return (size_t)(py - T->y0) * (size_t)(T->x1 - T->x0) + (size_t)(px - T->x0); }

/* A point's camera frame (x right, y up, z forward). */
static void view(const atmos_camera *c, const double p[3], double v[3])
{
    const double d[3] = {p[0] - c->position[0], p[1] - c->position[1], p[2] - c->position[2]};
    v[0] = atmos__dot3(d, c->right), v[1] = atmos__dot3(d, c->up), v[2] = atmos__dot3(d, c->forward);
}

static void to_pixel(const atmos_camera *c, const double v[3], double iz, double *x, double *y)
{
    *x = 0.5 * (c->width + v[0] * iz / c->tan_half_fov * c->height);
    *y = 0.5 * c->height * (1 - v[1] * iz / c->tan_half_fov);
}

/* The triangle on the image and the tile's pixel centres within its box; 0 when none. */
ATMOS_CLONE_HELPER int setup(const tile *T, const double v[3][3], int tri, stri *s)
{
    for (int k = 0; k < 3; k++) {
        s->iz[k] = 1.0 / v[k][2];
        to_pixel(T->cam, v[k], s->iz[k], &s->x[k], &s->y[k]);
    }
    const double x0 = MIN3(s->x) - EDGE_PX, x1 = MAX3(s->x) + EDGE_PX;
    const double y0 = MIN3(s->y) - EDGE_PX, y1 = MAX3(s->y) + EDGE_PX;
    /* the pixel centres (p + 0.5) within the box, clamped to the tile before the conversion */
    const double bx0 = atmos__maxd(ceil(x0 - 0.5), T->x0), bx1 = atmos__mind(floor(x1 - 0.5), T->x1 - 1);
    const double by0 = atmos__maxd(ceil(y0 - 0.5), T->y0), by1 = atmos__mind(floor(y1 - 0.5), T->y1 - 1);
    if (!(bx0 <= bx1 && by0 <= by1)) return 0;
    s->px0 = (int)bx0, s->px1 = (int)bx1, s->py0 = (int)by0, s->py1 = (int)by1, s->mesh = T->mesh, s->tri = tri;
    return 1;
}

static void rival(tile *T, size_t i, double z) { if (z < T->u[i]) T->u[i] = z; }

static void cover(tile *T, size_t i, double z, const stri *s)
{
    if (z < T->z[i]) {
        if (T->z[i] <= z * (1 + DEPTH_TOL)) rival(T, i, T->z[i]);
        T->z[i] = z, T->mm[i] = s->mesh, T->tri[i] = s->tri;
    } else if (z <= T->z[i] * (1 + DEPTH_TOL))
        rival(T, i, z);
}

/* The columns [*pa, *pb] of the triangle's box whose centres on the row at cy may lie within
 * EDGE_PX of it: each edge's function is linear along the row (a pixel of slack each end: the
 * pixels themselves are then classified exactly). 0 when none. */
ATMOS_CLONE_HELPER int row_span(const stri *s, double sg, const double len[3], double cy, int *pa, int *pb)
{
    double lo = s->px0, hi = s->px1;
    for (int k = 0; k < 3; k++) {
        const int i = (k + 1) % 3, j = (k + 2) % 3;
        /* e(cx) = sg ((x_j - x_i)(cy - y_i) - (y_j - y_i)(cx - x_i)) = a cx + c >= -EDGE_PX len */
        const double a = -sg * (s->y[j] - s->y[i]), c = sg * ((s->x[j] - s->x[i]) * (cy - s->y[i]) + (s->y[j] - s->y[i]) * s->x[i]);
        const double bound = -EDGE_PX * len[k] - c; /* a cx >= bound */
        if (a > 0) lo = lo > bound / a - 0.5 - 1 ? lo : bound / a - 0.5 - 1;
        else if (a < 0) hi = hi < bound / a - 0.5 + 1 ? hi : bound / a - 0.5 + 1;
        else if (0 < bound) return 0;
    }
    if (!(lo <= hi)) return 0;
    *pa = (int)ceil(lo), *pb = (int)floor(hi);
    return *pa <= *pb;
}

/* Whether draw() may skip the pixels whose drawn surface is nearer than the triangle's nearest
 * vertex (znear) by more than DEPTH_TOL and HIDE_SLACK: its depth at a pixel centre is then
 * beyond that surface's DEPTH_TOL, so it is neither a nearer cover nor a rival that could count
 * (a rival's depth matters only within DEPTH_TOL of the pixel's final surface, which is never
 * farther than the one drawn now). A covered pixel's depth is at least znear but for the
 * rounding of its edge functions against the area: with the vertices within HIDE_COORD pixels
 * of the origin (their products below 2^27, each edge function's error below 1e-7) and an area
 * of at least a pixel, its depth is within 1e-6 of at least znear, well inside HIDE_SLACK. */
#define HIDE_COORD 4096
#define HIDE_SLACK 1e-5
static int hides(const stri *s, double area)
{
    for (int k = 0; k < 3; k++)
        if (!(fabs(s->x[k]) < HIDE_COORD && fabs(s->y[k]) < HIDE_COORD)) return 0;
    return fabs(area) >= 1;
}

/* A rival's depth is at least the nearest vertex's (the depth extrapolated past a thin
 * triangle's edge can be far nearer than any point of it), so a triangle is never nearer than
 * its box: what makes hiding a box exact. */
ATMOS_CLONE_HELPER void draw(tile *T, const stri *s)
{
    const double *x = s->x, *y = s->y;
    const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    const double znear = 1.0 / MAX3(s->iz);
    double len[3];
    for (int k = 0; k < 3; k++) {
        const double ex = x[(k + 2) % 3] - x[(k + 1) % 3], ey = y[(k + 2) % 3] - y[(k + 1) % 3];
        len[k] = sqrt(ex * ex + ey * ey);
    }
    if (!(fabs(area) > 1e-9 * (len[0] + len[1] + len[2])) || !(len[0] > 0 && len[1] > 0 && len[2] > 0)) {
        /* edge-on: a rival over its box, as near as its nearest vertex */
        for (int py = s->py0; py <= s->py1; py++)
            for (int px = s->px0; px <= s->px1; px++) rival(T, at(T, px, py), znear);
        return;
    }
    const double sg = area > 0 ? 1 : -1, inv = 1.0 / fabs(area), ilen[3] = {1 / len[0], 1 / len[1], 1 / len[2]};
    /* a pixel whose surface drawn already is nearer than znear by more than DEPTH_TOL and
     * HIDE_SLACK is skipped: nothing drawn here changes its entry (see hides) */
    const double zhide = hides(s, area) ? znear / ((1 + DEPTH_TOL) * (1 + HIDE_SLACK)) : 0;
    for (int py = s->py0; py <= s->py1; py++) {
        const double cy = py + 0.5;
        int pa, pb;
        if (!row_span(s, sg, len, cy, &pa, &pb)) continue;
        for (int px = pa; px <= pb; px++) {
            if (T->z[at(T, px, py)] < zhide) continue;
            const double cx = px + 0.5;
            double e[3], dmin = INFINITY;
            for (int k = 0; k < 3; k++) {
                const int i = (k + 1) % 3, j = (k + 2) % 3;
                e[k] = sg * ((x[j] - x[i]) * (cy - y[i]) - (y[j] - y[i]) * (cx - x[i]));
                const double dk = e[k] * ilen[k];
                dmin = dk < dmin ? dk : dmin;
            }
            if (dmin < -EDGE_PX) continue;
            const double z = 1.0 / ((e[0] * s->iz[0] + e[1] * s->iz[1] + e[2] * s->iz[2]) * inv);
            if (dmin >= EDGE_PX) cover(T, at(T, px, py), z, s);
            else rival(T, at(T, px, py), atmos__maxd(z, znear));
        }
    }
}

/* A mesh's triangles of a leaf: into the camera's frame, clipped at z = NEAR_M
 * (Sutherland-Hodgman), drawn. */
ATMOS_CLONES static void leaf(void *user, const int *tri, int n)
{
    tile *T = user;
    const atmos_mesh *M = T->ob->mesh[T->mesh];
    for (int j = 0; j < n; j++) {
        double v[3][3];
        for (int k = 0; k < 3; k++) {
            const float *p = M->positions + 3 * M->indices[3 * tri[j] + k];
            const double q[3] = {p[0], p[1], p[2]};
            view(T->cam, q, v[k]);
        }
        if (v[0][2] < NEAR_M && v[1][2] < NEAR_M && v[2][2] < NEAR_M) continue;
        stri s;
        if (v[0][2] >= NEAR_M && v[1][2] >= NEAR_M && v[2][2] >= NEAR_M) {
            if (setup(T, v, tri[j], &s)) draw(T, &s);
            continue;
        }
        double poly[4][3];
        const int m = atmos__beams_clip_near(v, NEAR_M, poly);
        for (int k = 1; k + 1 < m; k++) {
            const double t[3][3] = {{poly[0][0], poly[0][1], poly[0][2]},
                                    {poly[k][0], poly[k][1], poly[k][2]},
                                    {poly[k + 1][0], poly[k + 1][1], poly[k + 1][2]}};
            if (setup(T, t, tri[j], &s)) draw(T, &s);
        }
    }
}

/* Whether to draw what a node's box holds: not when the box lies wholly behind the near plane,
 * beside the tile, or behind the surfaces already drawn at every pixel centre it may cover. */
ATMOS_CLONES static int enter(void *user, const float lo[3], const float hi[3])
{
    const tile *T = user;
    double zmin = INFINITY, xa = INFINITY, xb = -INFINITY, ya = INFINITY, yb = -INFINITY;
    int behind = 0;
    for (int k = 0; k < 8; k++) {
        const double p[3] = {(k & 1 ? hi : lo)[0], (k & 2 ? hi : lo)[1], (k & 4 ? hi : lo)[2]};
        double v[3], x, y;
        view(T->cam, p, v);
        zmin = atmos__mind(v[2], zmin);
        if (v[2] < NEAR_M) {
            behind++;
            continue;
        }
        to_pixel(T->cam, v, 1.0 / v[2], &x, &y);
        xa = atmos__mind(x, xa), xb = atmos__maxd(x, xb), ya = atmos__mind(y, ya), yb = atmos__maxd(y, yb);
    }
    if (behind == 8) return 0;
    int px0 = T->x0, px1 = T->x1 - 1, py0 = T->y0, py1 = T->y1 - 1;
    if (!behind) { /* the box's projection is the hull of its corners'; a pixel of slack */
        const double bx0 = atmos__maxd(ceil(xa - 1.5), T->x0), bx1 = atmos__mind(floor(xb + 0.5), T->x1 - 1);
        const double by0 = atmos__maxd(ceil(ya - 1.5), T->y0), by1 = atmos__mind(floor(yb + 0.5), T->y1 - 1);
        if (!(bx0 <= bx1 && by0 <= by1)) return 0;
        px0 = (int)bx0, px1 = (int)bx1, py0 = (int)by0, py1 = (int)by1;
    }
    const double zlim = zmin / ((1 + DEPTH_TOL) * (1 + HIDDEN_MARGIN));
    for (int py = py0; py <= py1; py++)
        for (int px = px0; px <= px1; px++)
            if (!(T->z[at(T, px, py)] < zlim)) return 1;
    return 0;
}

/* The tiles drawn, each by one thread; returns 1 when out of memory. */
static int draw_tiles(atmos_context *ctx, const atmos__objects *ob, const atmos_camera *cam, atmos__beams_primary *P)
{
    const atmos__rect *r = &P->r;
    const int W = r->x1 - r->x0, nx = (W + TILE - 1) / TILE, ny = (r->y1 - r->y0 + TILE - 1) / TILE;
    int failed = 0;
    long traced = 0;
#pragma omp parallel num_threads(atmos__threads(ctx)) reduction(+ : traced)
    {
        double *z = malloc(sizeof(double) * 2 * TILE * TILE);
        int *mt = malloc(sizeof(int) * 2 * TILE * TILE);
        if (!z || !mt) {
#pragma omp atomic write
            failed = 1;
        }
#pragma omp for schedule(dynamic, 1)
        for (int b = 0; b < nx * ny; b++) {
            if (!z || !mt) continue;
            tile T = {cam, ob, r->x0 + b % nx * TILE, 0, r->y0 + b / nx * TILE, 0, 0, z, z + TILE * TILE, mt, mt + TILE * TILE};
            T.x1 = T.x0 + TILE < r->x1 ? T.x0 + TILE : r->x1, T.y1 = T.y0 + TILE < r->y1 ? T.y0 + TILE : r->y1;
            const size_t n = (size_t)(T.x1 - T.x0) * (size_t)(T.y1 - T.y0);
            for (size_t i = 0; i < n; i++) T.z[i] = T.u[i] = INFINITY, T.mm[i] = ATMOS__BEAMS_PRIMARY_NONE, T.tri[i] = 0;
            for (T.mesh = 0; T.mesh < ob->n; T.mesh++) atmos__mesh_walk(ob->mesh[T.mesh], cam->position, enter, leaf, &T);
            for (int py = T.y0; py < T.y1; py++)
                for (int px = T.x0; px < T.x1; px++) {
                    const size_t i = at(&T, px, py), o = (size_t)(py - r->y0) * W + (size_t)(px - r->x0);
                    const int trace = T.u[i] < INFINITY && T.u[i] <= T.z[i] * (1 + DEPTH_TOL);
                    P->mesh[o] = trace ? ATMOS__BEAMS_PRIMARY_TRACE : T.mm[i], P->tri[o] = trace ? 0 : T.tri[i];
                    traced += trace;
                }
        }
        free(z), free(mt);
    }
    P->traced = traced;
    return failed;
}

atmos_status atmos__beams_primary_build(atmos_context *ctx, const atmos__objects *ob, const atmos_camera *cam,
                                        const atmos__rect *r, atmos__beams_primary *P)
{
    return atmos__beams_primary_build_kept(ctx, ob, cam, r, NULL, P);
}

atmos_status atmos__beams_primary_build_kept(atmos_context *ctx, const atmos__objects *ob, const atmos_camera *cam,
                                             const atmos__rect *r, atmos__beams_kept keep[2], atmos__beams_primary *P)
{
    const int W = r->x1 - r->x0, H = r->y1 - r->y0;
    const size_t n = (size_t)(W > 0 ? W : 0) * (size_t)(H > 0 ? H : 0), bytes = sizeof(int) * (n ? n : 1);
    memset(P, 0, sizeof *P);
    P->r = *r;
    P->owned = !keep;
    P->mesh = keep ? atmos__beams_kept_get(&keep[0], bytes) : malloc(bytes);
    P->tri = keep ? atmos__beams_kept_get(&keep[1], bytes) : malloc(bytes);
    if (!P->mesh || !P->tri) {
        atmos__beams_primary_free(P);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for the primary visibility");
    }
    if (n == 0) return ATMOS_OK;
    if (cam->type != ATMOS_CAMERA_PINHOLE) {
        for (size_t i = 0; i < n; i++) P->mesh[i] = ATMOS__BEAMS_PRIMARY_TRACE, P->tri[i] = 0;
        P->traced = (long)n;
        return ATMOS_OK;
    }
    if (draw_tiles(ctx, ob, cam, P)) {
        atmos__beams_primary_free(P);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for the primary visibility");
    }
    return ATMOS_OK;
}

void atmos__beams_primary_free(atmos__beams_primary *P)
{
    if (P->owned) free(P->mesh), free(P->tri);
    P->mesh = P->tri = NULL;
}

int atmos__beams_primary_hit(const atmos__beams_primary *P, const atmos__objects *ob, int x, int y, const double eye[3],
                             const double d[3], atmos_mesh_hit *hit, int *which)
{
    const size_t i = (size_t)(y - P->r.y0) * (size_t)(P->r.x1 - P->r.x0) + (size_t)(x - P->r.x0);
    const int m = P->mesh[i];
    if (m == ATMOS__BEAMS_PRIMARY_NONE) return 0;
    if (m >= 0 && atmos_mesh_intersect_triangle(ob->mesh[m], P->tri[i], eye, d, 0, INFINITY, hit)) {
        *which = m;
        return 1;
    }
    return atmos__objects_hit(ob, eye, d, 0, INFINITY, hit, which);
}
