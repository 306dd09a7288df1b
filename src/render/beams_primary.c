/* The beam renderer's primary visibility by rasterisation (beams_primary.h): every triangle
 * in front of the near plane (clipped there, Sutherland-Hodgman) projected to the image in
 * double, binned into bands of rows, and each band drawn by one thread: per pixel centre the
 * nearest triangle that surely covers it (at least EDGE_PX inside every edge), and the least
 * depth of any rival that might be as near (one within EDGE_PX of covering it, a covering one
 * within DEPTH_TOL of the nearest, one seen edge-on). A pixel with such a rival is traced. The
 * depth is the view depth, its reciprocal affine across a triangle. A pixel's entry depends on
 * the triangles in their order alone (meshes, then triangles), not on the bands. */
#include "render/beams_primary.h"
#include "render/beams_raster.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NEAR_M 1e-3
#define EDGE_PX 1e-3
#define DEPTH_TOL 1e-6
#define BAND 8
/* Meshes of more triangles than this share of the image's pixels are traced instead: drawing
 * them cost more than the rays they spare (a city of 295 000 triangles over 720x480: 0.61 G
 * instructions against 0.53 G; ridges of 131 000: 0.25 G against 0.46 G; docs/beams.md). */
#define MAX_TRIANGLES_PER_PIXEL 0.6

/* A triangle (or a clipped part of one) on the image: pixel coordinates, 1 / view depth, the
 * rows and columns of the pixel centres its box (widened by EDGE_PX) holds. */
typedef struct stri {
    double x[3], y[3], iz[3];
    int mesh, tri;
    int px0, px1, py0, py1;
} stri;

typedef struct screen {
    const atmos_camera *cam;
    atmos__rect r;
    stri *t;
    size_t n, cap;
    int failed;
} screen;

static void push(screen *S, const double v[3][3], int mesh, int tri)
{
    const atmos_camera *c = S->cam;
    stri s;
    for (int k = 0; k < 3; k++) {
        s.iz[k] = 1.0 / v[k][2];
        s.x[k] = 0.5 * (c->width + v[k][0] * s.iz[k] / c->tan_half_fov * c->height);
        s.y[k] = 0.5 * c->height * (1 - v[k][1] * s.iz[k] / c->tan_half_fov);
    }
    const double x0 = fmin(s.x[0], fmin(s.x[1], s.x[2])) - EDGE_PX, x1 = fmax(s.x[0], fmax(s.x[1], s.x[2])) + EDGE_PX;
    const double y0 = fmin(s.y[0], fmin(s.y[1], s.y[2])) - EDGE_PX, y1 = fmax(s.y[0], fmax(s.y[1], s.y[2])) + EDGE_PX;
    /* the pixel centres (p + 0.5) within the box, clamped to the region before the conversion */
    const double bx0 = fmax(S->r.x0, ceil(x0 - 0.5)), bx1 = fmin(S->r.x1 - 1, floor(x1 - 0.5));
    const double by0 = fmax(S->r.y0, ceil(y0 - 0.5)), by1 = fmin(S->r.y1 - 1, floor(y1 - 0.5));
    if (!(bx0 <= bx1 && by0 <= by1)) return;
    s.px0 = (int)bx0, s.px1 = (int)bx1, s.py0 = (int)by0, s.py1 = (int)by1, s.mesh = mesh, s.tri = tri;
    if (S->n == S->cap) {
        const size_t cap = S->cap ? 2 * S->cap : 4096;
        stri *t = realloc(S->t, sizeof *t * cap);
        if (!t) {
            S->failed = 1;
            return;
        }
        S->t = t, S->cap = cap;
    }
    S->t[S->n++] = s;
}

/* The triangle in the camera's frame (x right, y up, z forward) clipped at z = NEAR_M. */
static void clip_push(screen *S, const double in[3][3], int mesh, int tri)
{
    double poly[4][3];
    const int m = atmos__beams_clip_near(in, NEAR_M, poly);
    for (int k = 1; k + 1 < m; k++) {
        const double t[3][3] = {{poly[0][0], poly[0][1], poly[0][2]},
                                {poly[k][0], poly[k][1], poly[k][2]},
                                {poly[k + 1][0], poly[k + 1][1], poly[k + 1][2]}};
        push(S, t, mesh, tri);
    }
}

static void project(screen *S, const atmos__objects *ob)
{
    const atmos_camera *c = S->cam;
    for (int m = 0; m < ob->n && !S->failed; m++) {
        const atmos_mesh *M = ob->mesh[m];
        for (int t = 0; t < M->triangle_count && !S->failed; t++) {
            double v[3][3];
            for (int k = 0; k < 3; k++) {
                const float *p = M->positions + 3 * M->indices[3 * t + k];
                const double d[3] = {p[0] - c->position[0], p[1] - c->position[1], p[2] - c->position[2]};
                v[k][0] = atmos__dot3(d, c->right), v[k][1] = atmos__dot3(d, c->up), v[k][2] = atmos__dot3(d, c->forward);
            }
            if (v[0][2] < NEAR_M && v[1][2] < NEAR_M && v[2][2] < NEAR_M) continue;
            if (v[0][2] >= NEAR_M && v[1][2] >= NEAR_M && v[2][2] >= NEAR_M) push(S, v, m, t);
            else clip_push(S, v, m, t);
        }
    }
}

/* One band's pixels: rows [y0, y1) of the region, z and u rows of its width each. */
typedef struct band {
    int y0, y1;
    double *z, *u;
    int *mesh, *tri; /* the buffer's rows y0 .. */
} band;

static void rival(band *B, size_t i, double z) { if (z < B->u[i]) B->u[i] = z; }

static void cover(band *B, size_t i, double z, const stri *s)
{
    if (z < B->z[i]) {
        if (B->z[i] <= z * (1 + DEPTH_TOL)) rival(B, i, B->z[i]);
        B->z[i] = z, B->mesh[i] = s->mesh, B->tri[i] = s->tri;
    } else if (z <= B->z[i] * (1 + DEPTH_TOL))
        rival(B, i, z);
}

/* The columns [*pa, *pb] of the triangle's box whose centres on the row at cy may lie within
 * EDGE_PX of it: each edge's function is linear along the row (a pixel of slack each end: the
 * pixels themselves are then classified exactly). 0 when none. */
static int row_span(const stri *s, double sg, const double len[3], double cy, int *pa, int *pb)
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

static void draw(band *B, const stri *s, const atmos__rect *r)
{
    const int W = r->x1 - r->x0, ya = s->py0 > B->y0 ? s->py0 : B->y0, yb = s->py1 < B->y1 - 1 ? s->py1 : B->y1 - 1;
    const double *x = s->x, *y = s->y;
    const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    double len[3];
    for (int k = 0; k < 3; k++) {
        const double ex = x[(k + 2) % 3] - x[(k + 1) % 3], ey = y[(k + 2) % 3] - y[(k + 1) % 3];
        len[k] = sqrt(ex * ex + ey * ey);
    }
    if (!(fabs(area) > 1e-9 * (len[0] + len[1] + len[2])) || !(len[0] > 0 && len[1] > 0 && len[2] > 0)) {
        /* edge-on: a rival over its box, as near as its nearest vertex */
        const double z = 1.0 / fmax(s->iz[0], fmax(s->iz[1], s->iz[2]));
        for (int py = ya; py <= yb; py++)
            for (int px = s->px0; px <= s->px1; px++) rival(B, (size_t)(py - B->y0) * W + (px - r->x0), z);
        return;
    }
    const double sg = area > 0 ? 1 : -1, inv = 1.0 / fabs(area), ilen[3] = {1 / len[0], 1 / len[1], 1 / len[2]};
    for (int py = ya; py <= yb; py++) {
        const double cy = py + 0.5;
        int pa, pb;
        if (!row_span(s, sg, len, cy, &pa, &pb)) continue;
        for (int px = pa; px <= pb; px++) {
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
            const size_t i = (size_t)(py - B->y0) * W + (px - r->x0);
            if (dmin >= EDGE_PX) cover(B, i, z, s);
            else rival(B, i, z);
        }
    }
}

/* The triangles of each band (indices into S->t, in order): *list, band b's at off[b] .. off[b + 1]. */
static int bin(const screen *S, int nb, size_t **off, int **list)
{
    *off = calloc((size_t)nb + 1, sizeof **off);
    if (!*off) return 1;
    for (size_t k = 0; k < S->n; k++)
        for (int b = (S->t[k].py0 - S->r.y0) / BAND; b <= (S->t[k].py1 - S->r.y0) / BAND; b++) (*off)[b + 1]++;
    for (int b = 0; b < nb; b++) (*off)[b + 1] += (*off)[b];
    *list = malloc(sizeof **list * ((*off)[nb] ? (*off)[nb] : 1));
    size_t *at = malloc(sizeof *at * (size_t)nb);
    if (!*list || !at) {
        free(at);
        return 1;
    }
    memcpy(at, *off, sizeof *at * (size_t)nb);
    for (size_t k = 0; k < S->n; k++)
        for (int b = (S->t[k].py0 - S->r.y0) / BAND; b <= (S->t[k].py1 - S->r.y0) / BAND; b++) (*list)[at[b]++] = (int)k;
    free(at);
    return 0;
}

/* The bands drawn, each by one thread; returns 1 when out of memory. */
static int draw_bands(atmos_context *ctx, const screen *S, const size_t *off, const int *list, int nb,
                      atmos__beams_primary *P)
{
    const int W = S->r.x1 - S->r.x0;
    int failed = 0;
    long traced = 0;
#pragma omp parallel num_threads(atmos__threads(ctx)) reduction(+ : traced)
    {
        double *z = malloc(sizeof(double) * 2 * BAND * (size_t)W);
        if (!z) {
#pragma omp atomic write
            failed = 1;
        }
#pragma omp for schedule(dynamic, 1)
        for (int b = 0; b < nb; b++) {
            if (!z) continue;
            band B = {S->r.y0 + b * BAND, S->r.y0 + b * BAND + BAND, z, z + BAND * (size_t)W, NULL, NULL};
            if (B.y1 > S->r.y1) B.y1 = S->r.y1;
            const size_t at = (size_t)b * BAND * W, n = (size_t)(B.y1 - B.y0) * W;
            B.mesh = P->mesh + at, B.tri = P->tri + at;
            for (size_t i = 0; i < n; i++) B.z[i] = B.u[i] = INFINITY, B.mesh[i] = ATMOS__BEAMS_PRIMARY_NONE, B.tri[i] = 0;
            for (size_t k = off[b]; k < off[b + 1]; k++) draw(&B, &S->t[list[k]], &S->r);
            for (size_t i = 0; i < n; i++)
                if (B.u[i] < INFINITY && B.u[i] <= B.z[i] * (1 + DEPTH_TOL)) B.mesh[i] = ATMOS__BEAMS_PRIMARY_TRACE, traced++;
        }
        free(z);
    }
    P->traced = traced;
    return failed;
}

atmos_status atmos__beams_primary_build(atmos_context *ctx, const atmos__objects *ob, const atmos_camera *cam,
                                        const atmos__rect *r, atmos__beams_primary *P)
{
    const int W = r->x1 - r->x0, H = r->y1 - r->y0;
    const size_t n = (size_t)(W > 0 ? W : 0) * (size_t)(H > 0 ? H : 0);
    memset(P, 0, sizeof *P);
    P->r = *r;
    P->mesh = malloc(sizeof(int) * (n ? n : 1)), P->tri = malloc(sizeof(int) * (n ? n : 1));
    if (!P->mesh || !P->tri) {
        atmos__beams_primary_free(P);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for the primary visibility");
    }
    if (n == 0) return ATMOS_OK;
    long triangles = 0;
    for (int m = 0; m < ob->n; m++) triangles += ob->mesh[m]->triangle_count;
    if (cam->type != ATMOS_CAMERA_PINHOLE || triangles > MAX_TRIANGLES_PER_PIXEL * cam->width * (double)cam->height) {
        for (size_t i = 0; i < n; i++) P->mesh[i] = ATMOS__BEAMS_PRIMARY_TRACE, P->tri[i] = 0;
        P->traced = (long)n;
        return ATMOS_OK;
    }
    screen S = {cam, *r, NULL, 0, 0, 0};
    project(&S, ob);
    const int nb = (H + BAND - 1) / BAND;
    size_t *off = NULL;
    int *list = NULL;
    const int failed = S.failed || bin(&S, nb, &off, &list) || draw_bands(ctx, &S, off, list, nb, P);
    free(S.t), free(off), free(list);
    if (failed) {
        atmos__beams_primary_free(P);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for the primary visibility");
    }
    return ATMOS_OK;
}

void atmos__beams_primary_free(atmos__beams_primary *P)
{
    free(P->mesh), free(P->tri);
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
