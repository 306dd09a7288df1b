/* Shadow maps of the beam renderer (Dobashi et al. 2002 §4.2.2: the visibility H from
 * shadow mapping): the meshes rasterised into depth maps seen from each light, one frustum
 * around a spotlight's cone (up to 60 degrees off its axis) or the six faces of a cube
 * around a point light (and a wider spot). Triangles are clipped at a near plane, drawn
 * with perspective-correct depth at texel centres; a look-up filters the four nearest
 * comparisons bilinearly, so that shadow edges move smoothly between texels. */
#include "render/beams_internal.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NEAR_M 1e-3
#define SPOT_FRUSTUM_MAX_DEG 60.0

void atmos__beams_shadow_free(atmos__beams_light *l)
{
    for (int f = 0; f < l->nfaces; f++) free(l->face[f].depth), l->face[f].depth = NULL;
    l->nfaces = 0;
}

static void set_face(atmos__beams_face *F, const double fwd[3], double tan_half)
{
    const double ref[3] = {fabs(fwd[1]) < 0.9 ? 0 : 1, fabs(fwd[1]) < 0.9 ? 1 : 0, 0};
    memcpy(F->fwd, fwd, sizeof F->fwd);
    atmos__cross3(fwd, ref, F->right);
    atmos__normalize3(F->right);
    atmos__cross3(F->right, fwd, F->up);
    F->tan_half = tan_half;
}

/* A triangle already in the face's frame (x, y, z with z >= near) drawn into the depth map. */
static void draw(atmos__beams_face *F, const double v[3][3])
{
    const int n = F->n;
    double sx[3], sy[3], iz[3];
    for (int k = 0; k < 3; k++) {
        iz[k] = 1.0 / v[k][2];
        sx[k] = (0.5 + 0.5 * v[k][0] * iz[k] / F->tan_half) * n;
        sy[k] = (0.5 + 0.5 * v[k][1] * iz[k] / F->tan_half) * n;
    }
    const double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
    if (area == 0 || !isfinite(area)) return;
    const int x0 = (int)fmax(0, floor(fmin(sx[0], fmin(sx[1], sx[2])))), x1 = (int)fmin(n - 1, ceil(fmax(sx[0], fmax(sx[1], sx[2]))));
    const int y0 = (int)fmax(0, floor(fmin(sy[0], fmin(sy[1], sy[2])))), y1 = (int)fmin(n - 1, ceil(fmax(sy[0], fmax(sy[1], sy[2]))));
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            const double px = x + 0.5, py = y + 0.5;
            double b[3];
            for (int k = 0; k < 3; k++) {
                const int i = (k + 1) % 3, j = (k + 2) % 3;
                b[k] = ((sx[j] - sx[i]) * (py - sy[i]) - (sy[j] - sy[i]) * (px - sx[i])) / area;
            }
            if (b[0] < 0 || b[1] < 0 || b[2] < 0) continue;
            const float z = (float)(1.0 / (b[0] * iz[0] + b[1] * iz[1] + b[2] * iz[2]));
            float *d = F->depth + (size_t)y * n + x;
            if (z < *d) *d = z;
        }
}

/* Clips the triangle (face frame) at z = near (Sutherland-Hodgman) and draws what is left. */
static void clip_draw(atmos__beams_face *F, const double in[3][3])
{
    double poly[4][3];
    int m = 0;
    for (int k = 0; k < 3; k++) {
        const double *a = in[k], *b = in[(k + 1) % 3];
        const int ia = a[2] >= NEAR_M, ib = b[2] >= NEAR_M;
        if (ia) memcpy(poly[m++], a, sizeof poly[0]);
        if (ia != ib) {
            const double s = (NEAR_M - a[2]) / (b[2] - a[2]);
            for (int c = 0; c < 3; c++) poly[m][c] = a[c] + s * (b[c] - a[c]);
            poly[m++][2] = NEAR_M;
        }
    }
    for (int k = 1; k + 1 < m; k++) {
        const double tri[3][3] = {{poly[0][0], poly[0][1], poly[0][2]},
                                  {poly[k][0], poly[k][1], poly[k][2]},
                                  {poly[k + 1][0], poly[k + 1][1], poly[k + 1][2]}};
        draw(F, tri);
    }
}

static void raster_face(atmos__beams_face *F, const double pos[3], atmos_mesh *const *mesh, int nmesh)
{
    for (size_t i = 0; i < (size_t)F->n * F->n; i++) F->depth[i] = INFINITY;
    for (int m = 0; m < nmesh; m++)
        for (int t = 0; t < mesh[m]->triangle_count; t++) {
            double v[3][3];
            for (int k = 0; k < 3; k++) {
                const float *p = mesh[m]->positions + 3 * mesh[m]->indices[3 * t + k];
                const double d[3] = {p[0] - pos[0], p[1] - pos[1], p[2] - pos[2]};
                v[k][0] = atmos__dot3(d, F->right), v[k][1] = atmos__dot3(d, F->up), v[k][2] = atmos__dot3(d, F->fwd);
            }
            if (v[0][2] < NEAR_M && v[1][2] < NEAR_M && v[2][2] < NEAR_M) continue;
            clip_draw(F, v);
        }
}

atmos_status atmos__beams_shadow_build(atmos_context *ctx, atmos__beams_light *l, atmos_mesh *const *mesh, int nmesh,
                                       int size)
{
    l->nfaces = 0;
    if (nmesh == 0) return ATMOS_OK;
    const int spot = l->type == ATMOS_LIGHT_SPOT && l->cos_outer >= cos(SPOT_FRUSTUM_MAX_DEG * ATMOS_DEG2RAD);
    const int nf = spot ? 1 : 6;
    for (int f = 0; f < nf; f++) {
        atmos__beams_face *F = &l->face[f];
        if (spot) set_face(F, l->axis, fmax(1e-3, tan(acos(l->cos_outer)) * 1.02));
        else {
            double d[3] = {0, 0, 0};
            d[f / 2] = f % 2 ? -1 : 1;
            set_face(F, d, 1.0);
        }
        F->n = size;
        F->depth = malloc(sizeof(float) * (size_t)size * size);
        if (!F->depth) {
            l->nfaces = f;
            atmos__beams_shadow_free(l);
            return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for a %dx%d shadow map", size, size);
        }
    }
    l->nfaces = nf;
#pragma omp parallel for schedule(dynamic, 1) num_threads(atmos__threads(ctx))
    for (int f = 0; f < nf; f++) raster_face(&l->face[f], l->pos, mesh, nmesh);
    return ATMOS_OK;
}

double atmos__beams_visibility(const atmos__beams_light *l, const double p[3])
{
    if (!l->nfaces) return 1;
    const double d[3] = {p[0] - l->pos[0], p[1] - l->pos[1], p[2] - l->pos[2]};
    int f = 0;
    if (l->nfaces == 6) { /* the cube face of the largest component */
        const double ax = fabs(d[0]), ay = fabs(d[1]), az = fabs(d[2]);
        const int a = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
        f = 2 * a + (d[a] < 0);
    }
    const atmos__beams_face *F = &l->face[f];
    const double z = atmos__dot3(d, F->fwd);
    if (z <= NEAR_M) return 1;
    const int n = F->n;
    const double fx = (0.5 + 0.5 * atmos__dot3(d, F->right) / (z * F->tan_half)) * n - 0.5;
    const double fy = (0.5 + 0.5 * atmos__dot3(d, F->up) / (z * F->tan_half)) * n - 0.5;
    if (!(fx > -1 && fx < n && fy > -1 && fy < n)) return 1; /* outside the spot's frustum: its falloff is zero there */
    const int x0 = (int)floor(fx), y0 = (int)floor(fy);
    const double ax = fx - x0, ay = fy - y0;
    double h = 0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            const int x = x0 + i < 0 ? 0 : x0 + i > n - 1 ? n - 1 : x0 + i;
            const int y = y0 + j < 0 ? 0 : y0 + j > n - 1 ? n - 1 : y0 + j;
            const double wgt = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
            h += (z < F->depth[(size_t)y * n + x]) * wgt;
        }
    return h;
}

double atmos__beams_falloff(const atmos__beams_light *l, const double p[3])
{
    if (l->type != ATMOS_LIGHT_SPOT) return 1;
    const double d[3] = {p[0] - l->pos[0], p[1] - l->pos[1], p[2] - l->pos[2]};
    const double r = sqrt(atmos__dot3(d, d));
    if (r == 0) return 1;
    const double c = atmos__dot3(d, l->axis) / r;
    if (c >= l->cos_inner) return 1;
    if (c <= l->cos_outer) return 0;
    const double s = (c - l->cos_outer) / (l->cos_inner - l->cos_outer);
    return s * s * (3 - 2 * s);
}
