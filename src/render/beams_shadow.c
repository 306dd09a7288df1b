/* Shadow maps of the beam renderer (Dobashi et al. 2002 §4.2.2: the visibility H from
 * shadow mapping): the meshes rasterised into depth maps seen from each light, one frustum
 * around a spotlight's cone (up to 60 degrees off its axis) or the six faces of a cube
 * around a point light (and a wider spot). Triangles are clipped at a near plane, drawn
 * with perspective-correct depth at texel centres; a look-up filters the four nearest
 * comparisons bilinearly, so that shadow edges move smoothly between texels. */
#include "render/beams_internal.h"
#include "render/beams_raster.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NEAR_M 1e-3
#define TILE 8
#define SPOT_FRUSTUM_MAX_DEG 60.0

void atmos__beams_shadow_free(atmos__beams_light *l)
{
    for (int f = 0; f < l->nfaces; f++) {
        free(l->face[f].depth), free(l->face[f].tile_min);
        l->face[f].depth = l->face[f].tile_min = l->face[f].tile_max = NULL;
    }
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
    atmos__beams_raster(F->depth, n, sx, sy, iz, 1);
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

/* The tiles' bounds (atmos__beams_face), each over its texels and a ring of one around, then
 * each coarser level's cells over their 2x2 children. */
static void tile_bounds(atmos__beams_face *F)
{
    const int n = F->n, T = F->tiles;
    for (int ty = 0; ty < T; ty++)
        for (int tx = 0; tx < T; tx++) {
            float lo = INFINITY, hi = 0;
            for (int y = ty * TILE - 1; y <= (ty + 1) * TILE; y++)
                for (int x = tx * TILE - 1; x <= (tx + 1) * TILE; x++) {
                    const float z = F->depth[(size_t)(y < 0 ? 0 : y >= n ? n - 1 : y) * n + (x < 0 ? 0 : x >= n ? n - 1 : x)];
                    lo = fminf(lo, z), hi = fmaxf(hi, z);
                }
            F->tile_min[ty * T + tx] = lo, F->tile_max[ty * T + tx] = hi;
        }
    for (int k = 1; k < F->levels; k++) {
        const int m = F->level_n[k], c = F->level_n[k - 1];
        const float *cmin = F->tile_min + F->level_at[k - 1], *cmax = F->tile_max + F->level_at[k - 1];
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++) {
                float lo = INFINITY, hi = 0;
                for (int y = 2 * j; y < 2 * j + 2 && y < c; y++)
                    for (int x = 2 * i; x < 2 * i + 2 && x < c; x++)
                        lo = fminf(lo, cmin[y * c + x]), hi = fmaxf(hi, cmax[y * c + x]);
                F->tile_min[F->level_at[k] + (size_t)j * m + i] = lo, F->tile_max[F->level_at[k] + (size_t)j * m + i] = hi;
            }
    }
}

/* The levels' sizes and offsets; the cells of all levels. */
static size_t plan_levels(atmos__beams_face *F)
{
    size_t at = 0;
    int m = F->tiles, k = 0;
    for (;;) {
        F->level_n[k] = m, F->level_at[k] = at;
        at += (size_t)m * m, k++;
        if (m == 1) break;
        m = (m + 1) / 2;
    }
    F->levels = k;
    return at;
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
    tile_bounds(F);
}

int atmos__beams_shadow_faces(const atmos__lamp *L, int nmesh)
{
    if (nmesh == 0) return 0;
    return L->type == ATMOS_LIGHT_SPOT && L->cos_outer >= cos(SPOT_FRUSTUM_MAX_DEG * ATMOS_DEG2RAD) ? 1 : 6;
}

atmos_status atmos__beams_shadow_build(atmos_context *ctx, atmos__beams_light *l, atmos_mesh *const *mesh, int nmesh,
                                       int size, atmos__beams_progress *pr)
{
    l->nfaces = 0;
    const int nf = atmos__beams_shadow_faces(&l->L, nmesh), spot = nf == 1;
    if (nf == 0) return ATMOS_OK;
    for (int f = 0; f < nf; f++) {
        atmos__beams_face *F = &l->face[f];
        if (spot) set_face(F, l->L.axis, fmax(1e-3, tan(acos(l->L.cos_outer)) * 1.02));
        else {
            double d[3] = {0, 0, 0};
            d[f / 2] = f % 2 ? -1 : 1;
            set_face(F, d, 1.0);
        }
        F->n = size, F->tiles = (size + TILE - 1) / TILE;
        const size_t cells = plan_levels(F);
        F->depth = malloc(sizeof(float) * (size_t)size * size);
        F->tile_min = malloc(sizeof(float) * 2 * cells);
        F->tile_max = F->tile_min ? F->tile_min + cells : NULL;
        if (!F->depth || !F->tile_min) {
            l->nfaces = f + 1;
            atmos__beams_shadow_free(l);
            return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for a %dx%d shadow map", size, size);
        }
    }
    l->nfaces = nf;
#pragma omp parallel for schedule(dynamic, 1) num_threads(atmos__threads(ctx))
    for (int f = 0; f < nf; f++) {
        if (atmos__cancelled(&pr->cancelled)) continue;
        raster_face(&l->face[f], l->L.pos, mesh, nmesh);
        atmos__progress_step(ctx, "beams shadow maps", &pr->done, pr->total, &pr->cancelled);
    }
    if (atmos__cancelled(&pr->cancelled)) return atmos__error(ctx, ATMOS_E_CANCELLED, "render beams: cancelled");
    return ATMOS_OK;
}

/* H at the point (x, y, z) of face F's frame: the four nearest comparisons, blended. */
static double lookup(const atmos__beams_face *F, double x, double y, double z)
{
    if (z <= NEAR_M) return 1;
    const int n = F->n;
    const double k = 0.5 * n / (z * F->tan_half);
    const double fx = 0.5 * n + x * k - 0.5, fy = 0.5 * n + y * k - 0.5;
    if (!(fx > -1 && fx < n && fy > -1 && fy < n)) return 1; /* outside the spot's frustum: its falloff is zero there */
    const int x0 = (int)(fx + 1) - 1, y0 = (int)(fy + 1) - 1; /* floor: fx, fy > -1 */
    const int tile = (y0 < 0 ? 0 : y0 / TILE) * F->tiles + (x0 < 0 ? 0 : x0 / TILE);
    if (z < F->tile_min[tile]) return 1;
    if (z >= F->tile_max[tile]) return 0;
    const double ax = fx - x0, ay = fy - y0;
    const int xa = x0 < 0 ? 0 : x0, xb = x0 + 1 > n - 1 ? n - 1 : x0 + 1;
    const int ya = y0 < 0 ? 0 : y0, yb = y0 + 1 > n - 1 ? n - 1 : y0 + 1;
    const float *ra = F->depth + (size_t)ya * n, *rb = F->depth + (size_t)yb * n;
    const double top = (1 - ax) * (z < ra[xa]) + ax * (z < ra[xb]), bottom = (1 - ax) * (z < rb[xa]) + ax * (z < rb[xb]);
    return (1 - ay) * top + ay * bottom;
}

/* The cube face of w's largest component. */
static int cube_face(const double w[3])
{
    const double ax = fabs(w[0]), ay = fabs(w[1]), az = fabs(w[2]);
    const int a = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
    return 2 * a + (w[a] < 0);
}

double atmos__beams_visibility(const atmos__beams_light *l, const double p[3])
{
    if (!l->nfaces) return 1;
    const double d[3] = {p[0] - l->L.pos[0], p[1] - l->L.pos[1], p[2] - l->L.pos[2]};
    const atmos__beams_face *F = &l->face[l->nfaces == 6 ? cube_face(d) : 0];
    return lookup(F, atmos__dot3(d, F->right), atmos__dot3(d, F->up), atmos__dot3(d, F->fwd));
}

void atmos__beams_ray_init(const atmos__beams_light *l, const double o[3], const double d[3], atmos__beams_ray *r)
{
    r->l = l;
    for (int a = 0; a < 3; a++) r->w0[a] = o[a] - l->L.pos[a], r->d[a] = d[a];
    r->ww0 = atmos__dot3(r->w0, r->w0), r->wd = atmos__dot3(r->w0, d);
    r->a0 = atmos__dot3(r->w0, l->L.axis), r->a1 = atmos__dot3(d, l->L.axis);
    for (int f = 0; f < l->nfaces; f++) {
        const atmos__beams_face *F = &l->face[f];
        r->f0[f][0] = atmos__dot3(r->w0, F->right), r->f1[f][0] = atmos__dot3(d, F->right);
        r->f0[f][1] = atmos__dot3(r->w0, F->up), r->f1[f][1] = atmos__dot3(d, F->up);
        r->f0[f][2] = atmos__dot3(r->w0, F->fwd), r->f1[f][2] = atmos__dot3(d, F->fwd);
    }
}

/* Face f's texel coordinates and depth of the ray at t (0 if behind the near plane). */
static int project(const atmos__beams_ray *r, int f, double t, double *fx, double *fy, double *z)
{
    const atmos__beams_face *F = &r->l->face[f];
    *z = r->f0[f][2] + t * r->f1[f][2];
    if (*z <= NEAR_M) return 0;
    const double k = 0.5 * F->n / (*z * F->tan_half);
    *fx = 0.5 * F->n + (r->f0[f][0] + t * r->f1[f][0]) * k - 0.5;
    *fy = 0.5 * F->n + (r->f0[f][1] + t * r->f1[f][1]) * k - 0.5;
    return *fx > -1 && *fx < F->n && *fy > -1 && *fy < F->n;
}

static int inside_inner(const atmos__beams_ray *r, double t)
{
    const double z = r->a0 + t * r->a1, w2 = r->ww0 + t * (2 * r->wd + t);
    return z > 0 && z * z >= r->l->L.cos_inner * r->l->L.cos_inner * w2;
}

int atmos__beams_ray_uniform(const atmos__beams_ray *r, double ta, double tb, double *h, int *full)
{
    const atmos__beams_light *l = r->l;
    *full = l->L.type != ATMOS_LIGHT_SPOT || (inside_inner(r, ta) && inside_inner(r, tb)); /* the cone is convex */
    *h = 1;
    if (!l->nfaces) return 1;
    int f = 0;
    if (l->nfaces == 6) { /* both ends in one face's pyramid: so is the segment */
        const double wa[3] = {r->w0[0] + ta * r->d[0], r->w0[1] + ta * r->d[1], r->w0[2] + ta * r->d[2]};
        const double wb[3] = {r->w0[0] + tb * r->d[0], r->w0[1] + tb * r->d[1], r->w0[2] + tb * r->d[2]};
        if ((f = cube_face(wa)) != cube_face(wb)) return 0;
    }
    double xa, ya, za, xb, yb, zb; /* depth is linear along the segment, its image a straight line */
    if (!project(r, f, ta, &xa, &ya, &za) || !project(r, f, tb, &xb, &yb, &zb)) return 0;
    const atmos__beams_face *F = &l->face[f];
    const int x0 = (int)(atmos__mind(xa, xb) + 1) - 1, x1 = (int)(atmos__maxd(xa, xb) + 1) - 1;
    const int y0 = (int)(atmos__mind(ya, yb) + 1) - 1, y1 = (int)(atmos__maxd(ya, yb) + 1) - 1;
    const int tx0 = x0 < 0 ? 0 : x0 / TILE, tx1 = x1 < 0 ? 0 : x1 / TILE, ty0 = y0 < 0 ? 0 : y0 / TILE,
              ty1 = y1 < 0 ? 0 : y1 / TILE;
    int k = 0; /* the finest level where the tiles' box spans at most 2 x 2 cells */
    while (k + 1 < F->levels && ((tx1 >> k) - (tx0 >> k) > 1 || (ty1 >> k) - (ty0 >> k) > 1)) k++;
    const float *cmin = F->tile_min + F->level_at[k], *cmax = F->tile_max + F->level_at[k];
    const int m = F->level_n[k];
    float lo = INFINITY, hi = 0;
    for (int ty = ty0 >> k; ty <= ty1 >> k; ty++)
        for (int tx = tx0 >> k; tx <= tx1 >> k; tx++)
            lo = cmin[ty * m + tx] < lo ? cmin[ty * m + tx] : lo, hi = cmax[ty * m + tx] > hi ? cmax[ty * m + tx] : hi;
    if (atmos__maxd(za, zb) < lo) return 1;
    if (atmos__mind(za, zb) >= hi) return *h = 0, 1;
    return 0;
}

double atmos__beams_ray_falloff(const atmos__beams_ray *r, double t)
{
    const atmos__beams_light *l = r->l;
    if (l->L.type != ATMOS_LIGHT_SPOT) return 1;
    const double z = r->a0 + t * r->a1, w2 = r->ww0 + t * (2 * r->wd + t);
    if (z <= 0 || z * z <= l->L.cos_outer * l->L.cos_outer * w2) return 0;
    if (z * z >= l->L.cos_inner * l->L.cos_inner * w2) return 1;
    const double s = (z / sqrt(w2) - l->L.cos_outer) / (l->L.cos_inner - l->L.cos_outer);
    return s * s * (3 - 2 * s);
}

double atmos__beams_ray_falloff_sum(const atmos__beams_ray *r, double ta, double step, double o, int m)
{
    const atmos__beams_light *l = r->l;
    if (l->L.type != ATMOS_LIGHT_SPOT) return m;
    /* branch-free, so that the loop vectorises: the cosine off the axis clamped into the edge
     * (below the outer cone 0, inside the inner 1: the smoothstep's own values there) */
    const double co = l->L.cos_outer, inv = 1 / (l->L.cos_inner - l->L.cos_outer);
    double sum = 0, f[64];
    for (int s0 = 0; s0 < m; s0 += 64) {
        const int n = m - s0 < 64 ? m - s0 : 64;
        for (int s = 0; s < n; s++) { /* vectorised: no reduction here */
            const double t = ta + (s0 + s + o) * step;
            const double z = r->a0 + t * r->a1, w2 = r->ww0 + t * (2 * r->wd + t);
            double q = (z / sqrt(w2 > 1e-300 ? w2 : 1e-300) - co) * inv;
            q = q < 0 ? 0 : q;
            q = q > 1 ? 1 : q;
            f[s] = q * q * (3 - 2 * q);
        }
        for (int s = 0; s < n; s++) sum += f[s]; /* in order */
    }
    return sum;
}

double atmos__beams_ray_light(const atmos__beams_ray *r, double t)
{
    const atmos__beams_light *l = r->l;
    const double fall = atmos__beams_ray_falloff(r, t);
    if (!l->nfaces || fall == 0) return fall;
    int f = 0;
    if (l->nfaces == 6) {
        const double w[3] = {r->w0[0] + t * r->d[0], r->w0[1] + t * r->d[1], r->w0[2] + t * r->d[2]};
        f = cube_face(w);
    }
    return fall * lookup(&l->face[f], r->f0[f][0] + t * r->f1[f][0], r->f0[f][1] + t * r->f1[f][1],
                         r->f0[f][2] + t * r->f1[f][2]);
}
