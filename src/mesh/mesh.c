/* Meshes (include/atmos/mesh.h): allocation (loading: mesh_load.c), the checks every
 * mesh passes before use (finite vertices, indices in range, at least one triangle), normals,
 * transforms. */
#include "mesh/mesh_internal.h"
#include "core/vec.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void atmos_mesh_transform_identity(atmos_mesh_transform *t)
{
    memset(t, 0, sizeof *t);
    t->scale[0] = t->scale[1] = t->scale[2] = 1.0;
}

atmos_status atmos__mesh_alloc(atmos_context *ctx, long nv, long nt, int vertex_normals, atmos_mesh **out)
{
    *out = NULL;
    if (nt > ATMOS_MESH_MAX_TRIANGLES || nv > 3L * ATMOS_MESH_MAX_TRIANGLES)
        return atmos__error(ctx, ATMOS_E_LIMIT, "mesh: %ld triangles, %ld vertices: more than the bound of %d triangles",
                            nt, nv, ATMOS_MESH_MAX_TRIANGLES);
    atmos_mesh *m = calloc(1, sizeof *m);
    if (!m) return atmos__error(ctx, ATMOS_E_NOMEM, "mesh: out of memory");
    m->vertex_count = (int)nv, m->triangle_count = (int)nt, m->vertex_normals = vertex_normals;
    m->positions = calloc((size_t)(nv ? nv : 1) * 3, sizeof(float));
    m->indices = calloc((size_t)(nt ? nt : 1) * 3, sizeof(uint32_t));
    m->normals = calloc((size_t)((vertex_normals ? nv : nt) ? (vertex_normals ? nv : nt) : 1) * 3, sizeof(float));
    if (!m->positions || !m->indices || !m->normals) {
        atmos_mesh_destroy(m);
        return atmos__error(ctx, ATMOS_E_NOMEM, "mesh: out of memory for %ld triangles", nt);
    }
    *out = m;
    return ATMOS_OK;
}

void atmos_mesh_destroy(atmos_mesh *m)
{
    if (!m) return;
    atmos__mesh_bvh_destroy(m->bvh);
    free(m->positions);
    free(m->indices);
    free(m->normals);
    free(m);
}

/* The triangles' own unit normals (zero for a degenerate triangle). */
static void face_normals(atmos_mesh *m)
{
    for (int t = 0; t < m->triangle_count; t++) {
        const float *a = m->positions + 3 * m->indices[3 * t], *b = m->positions + 3 * m->indices[3 * t + 1],
                    *c = m->positions + 3 * m->indices[3 * t + 2];
        double e1[3], e2[3], n[3];
        for (int k = 0; k < 3; k++) e1[k] = (double)b[k] - a[k], e2[k] = (double)c[k] - a[k];
        atmos__cross3(e1, e2, n);
        atmos__normalize3(n);
        for (int k = 0; k < 3; k++) m->normals[3 * t + k] = (float)n[k];
    }
}

atmos_status atmos_mesh_finish(atmos_context *ctx, atmos_mesh *m)
{
    if (!m) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mesh: missing mesh");
    if (m->triangle_count < 1) return atmos__error(ctx, ATMOS_E_FORMAT, "mesh: no triangles");
    for (int k = 0; k < 3; k++) m->lo[k] = INFINITY, m->hi[k] = -INFINITY;
    for (long i = 0; i < (long)m->vertex_count; i++)
        for (int k = 0; k < 3; k++) {
            const float x = m->positions[3 * i + k];
            if (!isfinite(x) || fabsf(x) > 1e8f)
                return atmos__error(ctx, ATMOS_E_FORMAT, "mesh: vertex %ld is not finite or beyond 1e8 m", i + 1);
            m->lo[k] = fminf(m->lo[k], x), m->hi[k] = fmaxf(m->hi[k], x);
        }
    for (long i = 0; i < 3L * m->triangle_count; i++)
        if (m->indices[i] >= (uint32_t)m->vertex_count)
            return atmos__error(ctx, ATMOS_E_FORMAT, "mesh: triangle %ld refers to vertex %u, the mesh has %d", i / 3 + 1,
                                m->indices[i] + 1, m->vertex_count);
    if (!m->vertex_normals) face_normals(m);
    return atmos__mesh_bvh_build(ctx, m);
}

/* Row-major 3x3: rotation about x, then y, then z (right-handed). */
static void rotation(const double deg[3], double R[9])
{
    const double a = deg[0] * ATMOS_DEG2RAD, b = deg[1] * ATMOS_DEG2RAD, c = deg[2] * ATMOS_DEG2RAD;
    const double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cc = cos(c), sc = sin(c);
    /* Rz * Ry * Rx */
    const double r[9] = {cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa,
                         sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa,
                         -sb,     cb * sa,                cb * ca};
    memcpy(R, r, sizeof r);
}

atmos_status atmos_mesh_apply_transform(atmos_context *ctx, atmos_mesh *m, const atmos_mesh_transform *t)
{
    if (!m || !t) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mesh transform: missing argument");
    for (int k = 0; k < 3; k++)
        if (!isfinite(t->position_m[k]) || !isfinite(t->scale[k]) || !isfinite(t->rotation_deg[k]) || t->scale[k] == 0)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "mesh transform: values must be finite, scales nonzero");
    double R[9];
    rotation(t->rotation_deg, R);
    for (long i = 0; i < (long)m->vertex_count; i++) {
        float *p = m->positions + 3 * i;
        const double s[3] = {p[0] * t->scale[0], p[1] * t->scale[1], p[2] * t->scale[2]};
        for (int r = 0; r < 3; r++) p[r] = (float)(R[3 * r] * s[0] + R[3 * r + 1] * s[1] + R[3 * r + 2] * s[2] + t->position_m[r]);
    }
    /* vertex normals by the inverse transpose: divided by the scales, then rotated (the
     * triangles' own normals are made again by atmos_mesh_finish) */
    for (long i = 0; m->vertex_normals && i < (long)m->vertex_count; i++) {
        float *n = m->normals + 3 * i;
        const double s[3] = {n[0] / t->scale[0], n[1] / t->scale[1], n[2] / t->scale[2]};
        double o[3];
        for (int r = 0; r < 3; r++) o[r] = R[3 * r] * s[0] + R[3 * r + 1] * s[1] + R[3 * r + 2] * s[2];
        atmos__normalize3(o);
        for (int r = 0; r < 3; r++) n[r] = (float)o[r];
    }
    return atmos_mesh_finish(ctx, m);
}
