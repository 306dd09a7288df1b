/* The bounding volume hierarchy of a mesh and the ray queries over it. Built top-down by
 * splitting at the middle of the triangles' centroid bounds along their widest axis (by
 * count when that leaves a side empty, or past a depth where the middle split keeps being
 * lopsided), at most LEAF triangles a leaf. Traversal keeps a stack and visits the nearer
 * child first; triangles are tested by the Moller-Trumbore algorithm (1997) in double. */
#include "mesh/mesh_internal.h"
#include "mesh/mesh_walk.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEAF 4
#define MAX_DEPTH 64
#define MIDDLE_DEPTH 40 /* beyond it, splits are by count: the depth stays below 64 */

typedef struct node {
    float lo[3], hi[3];
    int first; /* leaf: the first of count triangles in order[]; inner: the left child (right = left + 1) */
    int count; /* 0 for an inner node */
} node;

struct atmos__mesh_bvh {
    node *nodes;
    int nnodes, cap;
    int *order;
};

typedef struct build {
    const atmos_mesh *m;
    float *centroid; /* 3 a triangle */
    float *box;      /* 6 a triangle: lo, hi */
    atmos__mesh_bvh *b;
} build;

static void bounds_of(const build *B, int first, int count, float lo[3], float hi[3], float clo[3], float chi[3])
{
    for (int k = 0; k < 3; k++) lo[k] = clo[k] = INFINITY, hi[k] = chi[k] = -INFINITY;
    for (int i = first; i < first + count; i++) {
        const int t = B->b->order[i];
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], B->box[6 * t + k]), hi[k] = fmaxf(hi[k], B->box[6 * t + 3 + k]);
            clo[k] = fminf(clo[k], B->centroid[3 * t + k]), chi[k] = fmaxf(chi[k], B->centroid[3 * t + k]);
        }
    }
}

/* Splits order[first, first + count) in two; returns the size of the left part (0 < n < count). */
static int split(const build *B, int first, int count, const float clo[3], const float chi[3], int depth)
{
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
    int *o = B->b->order + first;
    int left = 0;
    if (depth < MIDDLE_DEPTH && chi[axis] > clo[axis]) {
        const float mid = 0.5f * (clo[axis] + chi[axis]);
        int j = count - 1;
        while (left <= j) {
            if (B->centroid[3 * o[left] + axis] < mid) left++;
            else {
                const int t = o[left];
                o[left] = o[j], o[j--] = t;
            }
        }
    }
    return left > 0 && left < count ? left : count / 2;
}

static void make_node(build *B, int at, int first, int count, int depth)
{
    float clo[3], chi[3];
    node *n = &B->b->nodes[at];
    bounds_of(B, first, count, n->lo, n->hi, clo, chi);
    if (count <= LEAF || depth >= MAX_DEPTH - 1) {
        n->first = first, n->count = count;
        return;
    }
    const int left = split(B, first, count, clo, chi, depth);
    const int child = B->b->nnodes;
    B->b->nnodes += 2;
    n->first = child, n->count = 0;
    make_node(B, child, first, left, depth + 1);
    make_node(B, child + 1, first + left, count - left, depth + 1);
}

void atmos__mesh_bvh_destroy(atmos__mesh_bvh *b)
{
    if (!b) return;
    free(b->nodes);
    free(b->order);
    free(b);
}

atmos_status atmos__mesh_bvh_build(atmos_context *ctx, atmos_mesh *m)
{
    atmos__mesh_bvh_destroy(m->bvh);
    m->bvh = NULL;
    const int n = m->triangle_count;
    atmos__mesh_bvh *b = calloc(1, sizeof *b);
    build B = {m, malloc(sizeof(float) * 3 * (size_t)n), malloc(sizeof(float) * 6 * (size_t)n), b};
    if (b) b->cap = 2 * n, b->nodes = malloc(sizeof(node) * (size_t)b->cap), b->order = malloc(sizeof(int) * (size_t)n);
    if (!b || !B.centroid || !B.box || !b->nodes || !b->order) {
        free(B.centroid), free(B.box), atmos__mesh_bvh_destroy(b);
        return atmos__error(ctx, ATMOS_E_NOMEM, "mesh: out of memory for the hierarchy of %d triangles", n);
    }
    for (int t = 0; t < n; t++) {
        b->order[t] = t;
        for (int k = 0; k < 3; k++) {
            float lo = INFINITY, hi = -INFINITY;
            for (int c = 0; c < 3; c++) {
                const float x = m->positions[3 * m->indices[3 * t + c] + k];
                lo = fminf(lo, x), hi = fmaxf(hi, x);
            }
            B.box[6 * t + k] = lo, B.box[6 * t + 3 + k] = hi, B.centroid[3 * t + k] = 0.5f * (lo + hi);
        }
    }
    b->nnodes = 1;
    make_node(&B, 0, 0, n, 0);
    free(B.centroid), free(B.box);
    node *fit = realloc(b->nodes, sizeof(node) * (size_t)b->nnodes); /* room for 2n nodes was the worst case */
    if (fit) b->nodes = fit, b->cap = b->nnodes;
    m->bvh = b;
    return ATMOS_OK;
}

/* Entry distance of the ray into a node's box (INFINITY if it misses within [tmin, tmax]). */
static double box_entry(const node *n, const double o[3], const double inv[3], double tmin, double tmax)
{
    for (int k = 0; k < 3; k++) {
        double t0 = (n->lo[k] - o[k]) * inv[k], t1 = (n->hi[k] - o[k]) * inv[k];
        if (t0 > t1) {
            const double t = t0;
            t0 = t1, t1 = t;
        }
        if (t0 > tmin) tmin = t0;
        if (t1 < tmax) tmax = t1;
        if (!(tmin <= tmax)) return INFINITY;
    }
    return tmin;
}

/* Moller-Trumbore: the ray's t and the barycentrics (u, v) of triangle tri, or 0. */
static int hit_triangle(const atmos_mesh *m, int tri, const double o[3], const double d[3], double *t, double *u,
                        double *v)
{
    const uint32_t *id = m->indices + 3 * tri;
    const float *a = m->positions + 3 * id[0], *b = m->positions + 3 * id[1], *c = m->positions + 3 * id[2];
    const double e1[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
    const double e2[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
    double p[3], q[3];
    atmos__cross3(d, e2, p);
    const double det = atmos__dot3(e1, p);
    if (det == 0) return 0;
    const double inv = 1.0 / det, s[3] = {o[0] - a[0], o[1] - a[1], o[2] - a[2]};
    *u = atmos__dot3(s, p) * inv;
    if (*u < 0 || *u > 1) return 0;
    atmos__cross3(s, e1, q);
    *v = atmos__dot3(d, q) * inv;
    if (*v < 0 || *u + *v > 1) return 0;
    *t = atmos__dot3(e2, q) * inv;
    return 1;
}

static void hit_normal(const atmos_mesh *m, int tri, double u, double v, const double d[3], double n[3])
{
    if (m->vertex_normals) {
        const uint32_t *id = m->indices + 3 * tri;
        for (int k = 0; k < 3; k++)
            n[k] = (1 - u - v) * m->normals[3 * id[0] + k] + u * m->normals[3 * id[1] + k] + v * m->normals[3 * id[2] + k];
        atmos__normalize3(n);
    } else {
        for (int k = 0; k < 3; k++) n[k] = m->normals[3 * tri + k];
    }
    if (atmos__dot3(n, d) > 0) n[0] = -n[0], n[1] = -n[1], n[2] = -n[2];
}

int atmos_mesh_intersect(const atmos_mesh *m, const double o[3], const double d[3], double tmin, double tmax,
                         atmos_mesh_hit *hit)
{
    if (!m || !m->bvh) return 0;
    const atmos__mesh_bvh *b = m->bvh;
    const double inv[3] = {1.0 / d[0], 1.0 / d[1], 1.0 / d[2]};
    int stack[MAX_DEPTH + 2], sp = 0, best = -1;
    double bu = 0, bv = 0;
    if (box_entry(&b->nodes[0], o, inv, tmin, tmax) == INFINITY) return 0;
    stack[sp++] = 0;
    while (sp) {
        const node *n = &b->nodes[stack[--sp]];
        if (n->count) {
            for (int i = n->first; i < n->first + n->count; i++) {
                double t, u, v;
                if (hit_triangle(m, b->order[i], o, d, &t, &u, &v) && t > tmin && t < tmax)
                    tmax = t, best = b->order[i], bu = u, bv = v;
            }
            continue;
        }
        const double t0 = box_entry(&b->nodes[n->first], o, inv, tmin, tmax);
        const double t1 = box_entry(&b->nodes[n->first + 1], o, inv, tmin, tmax);
        const int near = t0 <= t1 ? n->first : n->first + 1, far = near == n->first ? n->first + 1 : n->first;
        if (atmos__maxd(t0, t1) < INFINITY) stack[sp++] = far;
        if (atmos__mind(t0, t1) < INFINITY) stack[sp++] = near;
    }
    if (best < 0) return 0;
    if (hit) {
        hit->t = tmax, hit->triangle = best;
        hit_normal(m, best, bu, bv, d, hit->normal);
    }
    return 1;
}

int atmos_mesh_intersect_triangle(const atmos_mesh *m, int tri, const double o[3], const double d[3], double tmin,
                                  double tmax, atmos_mesh_hit *hit)
{
    double t, u, v;
    if (!m || tri < 0 || tri >= m->triangle_count || !hit_triangle(m, tri, o, d, &t, &u, &v) || !(t > tmin && t < tmax))
        return 0;
    if (hit) {
        hit->t = t, hit->triangle = tri;
        hit_normal(m, tri, u, v, d, hit->normal);
    }
    return 1;
}

static double centre_distance2(const node *n, const double eye[3])
{
    double s = 0;
    for (int k = 0; k < 3; k++) {
        const double c = 0.5 * ((double)n->lo[k] + n->hi[k]) - eye[k];
        s += c * c;
    }
    return s;
}

void atmos__mesh_walk(const atmos_mesh *m, const double eye[3], atmos__mesh_enter_fn enter, atmos__mesh_leaf_fn leaf,
                      void *user)
{
    if (!m || !m->bvh) return;
    const atmos__mesh_bvh *b = m->bvh;
    int stack[MAX_DEPTH + 2], sp = 0;
    stack[sp++] = 0;
    while (sp) {
        const node *n = &b->nodes[stack[--sp]];
        if (!enter(user, n->lo, n->hi)) continue;
        if (n->count) {
            leaf(user, b->order + n->first, n->count);
            continue;
        }
        const int a = n->first, c = n->first + 1;
        const int near = centre_distance2(&b->nodes[a], eye) <= centre_distance2(&b->nodes[c], eye) ? a : c;
        stack[sp++] = near == a ? c : a;
        stack[sp++] = near;
    }
}
