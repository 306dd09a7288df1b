/* Shadow maps of the beam renderer (Dobashi et al. 2002 §4.2.2: the visibility H from
 * shadow mapping): the meshes rasterised into depth maps seen from each light, one frustum
 * around a spotlight's cone (up to 60 degrees off its axis) or the six faces of a cube
 * around a point light (and a wider spot). Triangles are clipped at a near plane, drawn
 * with perspective-correct depth at texel centres; a look-up filters the four nearest
 * comparisons bilinearly, so that shadow edges move smoothly between texels. */
#include "render/beams_internal.h"
#include "render/beams_raster.h"
#include "render/beams_lookup.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NEAR_M ATMOS__BEAMS_NEAR_M
#define BEAMS_CLONES ATMOS_CLONES
#define SPOT_FRUSTUM_MAX_DEG 60.0

void atmos__beams_shadow_free(atmos__beams_light *l)
{
    for (int f = 0; f < l->nfaces; f++) {
        free(l->face[f].depth), free(l->face[f].tile_x), atmos__beams_tiles_free(&l->face[f].tiles);
        l->face[f].depth = NULL, l->face[f].tile_x = l->face[f].tile_y = NULL;
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
    const int m = atmos__beams_clip_near(in, NEAR_M, poly);
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

/* The face's tile_x and tile_y: atmos__beams_tiles_at's two terms for each floor x0 = i - 1 of a
 * look-up's coordinate (-1 .. n), so that a look-up's tile is two loads and an add. */
static void tile_index(atmos__beams_face *F)
{
    for (int i = 0; i < F->n + 2; i++) {
        F->tile_x[i] = atmos__beams_tiles_at(&F->tiles, i - 1, -1, ATMOS__BEAMS_LIGHT_TILE_SHIFT);
        F->tile_y[i] = atmos__beams_tiles_at(&F->tiles, -1, i - 1, ATMOS__BEAMS_LIGHT_TILE_SHIFT);
    }
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
        F->n = size;
        F->depth = malloc(sizeof(float) * (size_t)size * size);
        F->tile_x = malloc(sizeof(int) * 2 * ((size_t)size + 2)), F->tile_y = F->tile_x ? F->tile_x + size + 2 : NULL;
        memset(&F->tiles, 0, sizeof F->tiles);
        if (!F->depth || !F->tile_x) {
            l->nfaces = f + 1;
            atmos__beams_shadow_free(l);
            return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for a %dx%d shadow map", size, size);
        }
    }
    l->nfaces = nf;
    int failed = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(atmos__threads(ctx))
    for (int f = 0; f < nf; f++) {
        if (atmos__cancelled(&pr->cancelled)) continue;
        raster_face(&l->face[f], l->L.pos, mesh, nmesh);
        if (atmos__beams_tiles_build(&l->face[f].tiles, l->face[f].depth, l->face[f].n, ATMOS__BEAMS_LIGHT_TILE_SHIFT, 1)) {
#pragma omp atomic write
            failed = 1;
        } else
            tile_index(&l->face[f]);
        atmos__progress_step(ctx, "beams shadow maps", &pr->done, pr->total, &pr->cancelled);
    }
    if (failed) {
        atmos__beams_shadow_free(l);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for a %dx%d shadow map's tiles", size, size);
    }
    if (atmos__cancelled(&pr->cancelled)) return atmos__error(ctx, ATMOS_E_CANCELLED, "render beams: cancelled");
    return ATMOS_OK;
}

double atmos__beams_visibility(const atmos__beams_light *l, const double p[3])
{
    if (!l->nfaces) return 1;
    const double d[3] = {p[0] - l->L.pos[0], p[1] - l->L.pos[1], p[2] - l->L.pos[2]};
    const atmos__beams_face *F = &l->face[l->nfaces == 6 ? cube_face(d) : 0];
    return lookup(F, atmos__dot3(d, F->right), atmos__dot3(d, F->up), atmos__dot3(d, F->fwd));
}

void atmos__beams_ray_eye(const atmos__beams_light *l, const double o[3], atmos__beams_ray *e)
{
    e->l = l;
    for (int a = 0; a < 3; a++) e->w0[a] = o[a] - l->L.pos[a];
    e->ww0 = atmos__dot3(e->w0, e->w0), e->a0 = atmos__dot3(e->w0, l->L.axis);
    if (l->L.tex) { /* in texels at unit depth, the image's rows downward */
        const double kx = 0.5 * l->L.tw / l->L.tan_max, ky = -0.5 * l->L.th / l->L.tan_max;
        e->u0 = kx * atmos__dot3(e->w0, l->L.right), e->v0 = ky * atmos__dot3(e->w0, l->L.up);
    }
    /* a cube's faces 2a and 2a + 1 look along +-axis a: the odd one's right and fwd are the even
     * one's negated, its up the same (set_face: the cross products' signs flip exactly), so its
     * coordinates are the even one's with two signs flipped, the same bits */
    const int cube = l->nfaces == 6;
    for (int f = 0; f < l->nfaces; f += 1 + cube) {
        const atmos__beams_face *F = &l->face[f];
        e->f0[f][0] = atmos__dot3(e->w0, F->right), e->f0[f][1] = atmos__dot3(e->w0, F->up);
        e->f0[f][2] = atmos__dot3(e->w0, F->fwd);
        if (cube) e->f0[f + 1][0] = -e->f0[f][0], e->f0[f + 1][1] = e->f0[f][1], e->f0[f + 1][2] = -e->f0[f][2];
    }
}

/* An AVX2 clone where the processor has it (the same IEEE operations: the same bits), as
 * atmos__beams_ray_uniform below. */
BEAMS_CLONES void atmos__beams_ray_from(const atmos__beams_ray *e, const double d[3], atmos__beams_ray *r)
{
    const atmos__beams_light *l = e->l;
    r->l = l, r->ww0 = e->ww0, r->a0 = e->a0;
    for (int a = 0; a < 3; a++) r->w0[a] = e->w0[a], r->d[a] = d[a];
    r->wd = atmos__dot3(r->w0, d), r->a1 = atmos__dot3(d, l->L.axis);
    if (l->L.tex) {
        const double kx = 0.5 * l->L.tw / l->L.tan_max, ky = -0.5 * l->L.th / l->L.tan_max;
        r->u0 = e->u0, r->u1 = kx * atmos__dot3(d, l->L.right);
        r->v0 = e->v0, r->v1 = ky * atmos__dot3(d, l->L.up);
    }
    const int cube = l->nfaces == 6;
    for (int f = 0; f < l->nfaces; f += 1 + cube) {
        const atmos__beams_face *F = &l->face[f];
        r->f0[f][0] = e->f0[f][0], r->f1[f][0] = atmos__dot3(d, F->right);
        r->f0[f][1] = e->f0[f][1], r->f1[f][1] = atmos__dot3(d, F->up);
        r->f0[f][2] = e->f0[f][2], r->f1[f][2] = atmos__dot3(d, F->fwd);
        if (cube) {
            r->f0[f + 1][0] = e->f0[f + 1][0], r->f1[f + 1][0] = -r->f1[f][0];
            r->f0[f + 1][1] = e->f0[f + 1][1], r->f1[f + 1][1] = r->f1[f][1];
            r->f0[f + 1][2] = e->f0[f + 1][2], r->f1[f + 1][2] = -r->f1[f][2];
        }
    }
}

void atmos__beams_ray_init(const atmos__beams_light *l, const double o[3], const double d[3], atmos__beams_ray *r)
{
    atmos__beams_ray e;
    atmos__beams_ray_eye(l, o, &e);
    atmos__beams_ray_from(&e, d, r);
}

BEAMS_CLONES int atmos__beams_ray_uniform(const atmos__beams_ray *r, double ta, double tb, double *h, int *full)
{
    return ray_uniform(r, ta, tb, h, full);
}

double atmos__beams_ray_falloff(const atmos__beams_ray *r, double t) { return ray_falloff(r, t); }

/* The samples t = ta + (s + o) step, s in [*ka, *kb), inside the spot's inner cone (falloff 1):
 * the cone is convex, so they are one run, between the roots of (z(t))^2 = cos^2 |w(t)|^2 on
 * the side where z > 0; a sample of margin each side, so that the roots' rounding cannot
 * take in one outside (those are evaluated). An empty run when the roots are ill-conditioned. */
static void inner_run(const atmos__beams_ray *r, double ta, double step, double o, int m, int *ka, int *kb)
{
    *ka = *kb = 0;
    const double c2 = r->l->L.cos_inner * r->l->L.cos_inner;
    const double A = r->a1 * r->a1 - c2, B = 2 * (r->a0 * r->a1 - c2 * r->wd), C = r->a0 * r->a0 - c2 * r->ww0;
    const double disc = B * B - 4 * A * C;
    if (!(fabs(A) > 1e-9) || !(disc > 0) || !(step > 0)) return;
    const double q = -0.5 * (B + copysign(sqrt(disc), B)), r1 = fmin(q / A, C / q), r2 = fmax(q / A, C / q);
    /* z > 0 on a half-line; within it, the double cone's one nappe */
    const double tz = -r->a0 / r->a1;
    double lo = -INFINITY, hi = INFINITY;
    if (r->a1 > 0) lo = tz;
    else if (r->a1 < 0) hi = tz;
    else if (!(r->a0 > 0)) return;
    if (A < 0) lo = fmax(lo, r1), hi = fmin(hi, r2); /* between the roots */
    else if (r2 > lo && r2 < hi) lo = r2;           /* beyond the roots, on the half-line */
    else if (r1 > lo && r1 < hi) hi = r1;
    else return;
    const double s0 = ceil((lo - ta) / step - o) + 1, s1 = floor((hi - ta) / step - o) - 1;
    if (!(s0 <= s1)) return;
    *ka = s0 < 0 ? 0 : s0 > m ? m : (int)s0;
    *kb = s1 + 1 > m ? m : s1 + 1 < *ka ? *ka : (int)(s1 + 1);
}

/* The falloff summed over samples [s0, s1) (one tight loop the compiler vectorises; an AVX2
 * clone where the processor has it: four lanes, each the same IEEE operations, so the same bits). */
BEAMS_CLONES static double falloff_run(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1)
{
    const atmos__beams_light *l = r->l;
    /* branch-free, so that the loop vectorises: the cosine off the axis clamped into the edge
     * (below the outer cone 0, inside the inner 1: the smoothstep's own values there) */
    const double co = l->L.cos_outer, inv = 1 / (l->L.cos_inner - l->L.cos_outer);
    double sum = 0, f[64];
    for (int b = s0; b < s1; b += 64) {
        const int n = s1 - b < 64 ? s1 - b : 64;
        for (int s = 0; s < n; s++) { /* vectorised: no reduction here */
            const double t = ta + (b + s + o) * step;
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

double atmos__beams_ray_falloff_sum(const atmos__beams_ray *r, double ta, double step, double o, int m)
{
    if (r->l->L.type != ATMOS_LIGHT_SPOT) return m;
    int ka, kb;
    inner_run(r, ta, step, o, m, &ka, &kb);
    return falloff_run(r, ta, step, o, 0, ka) + (kb - ka) + falloff_run(r, ta, step, o, kb, m);
}

BEAMS_CLONES double atmos__beams_ray_light(const atmos__beams_ray *r, double t) { return ray_light(r, t); }

/* The texel coordinates and depths on face f of the samples t = ta + (s + o) step, s in [s0, s1)
 * (at most RUN_READ of them), as lookup() computes them: one loop that vectorises (the divisions
 * four at a time in the AVX2 clone, each lane the same IEEE operations: the same bits). */
#define RUN_READ 32
BEAMS_CLONES static void run_texels(const atmos__beams_ray *r, int f, double ta, double step, double o, int s0, int s1,
                                    double *fx, double *fy, double *z)
{
    const atmos__beams_face *F = &r->l->face[f];
    const int n = F->n;
    const double x0 = r->f0[f][0], x1 = r->f1[f][0], y0 = r->f0[f][1], y1 = r->f1[f][1];
    const double z0 = r->f0[f][2], z1 = r->f1[f][2], th = F->tan_half;
    for (int s = 0; s < s1 - s0; s++) {
        const double t = ta + (s0 + s + o) * step, zs = z0 + t * z1;
        const double k = 0.5 * n / (zs * th); /* not used where zs <= NEAR_M (texels() returns 1 first) */
        z[s] = zs, fx[s] = 0.5 * n + (x0 + t * x1) * k - 0.5, fy[s] = 0.5 * n + (y0 + t * y1) * k - 0.5;
    }
}

/* A point light's samples [s0, s1) in the cube's face f (its pyramid; at most half a texel past
 * its edge by rounding), summed: no falloff, each sample's is 1. Projected one by one (project:
 * the same operations as run_texels; the runs are short, about 8 samples on average: the
 * vectorised loop's call and setup cost more than it saves), no division where the sample is
 * behind the near plane (texels_in's 1 there). */
ATMOS_CLONE_HELPER double read_point(const atmos__beams_ray *r, int f, double ta, double step, double o, int s0, int s1)
{
    const face_at F = face_of(&r->l->face[f]);
    double h = 0;
    for (int s = s0; s < s1; s++) {
        double fx, fy, z;
        project(r, f, &F, ta + (s + o) * step, &fx, &fy, &z); /* its frustum test not needed: texels_in's */
        h += z <= NEAR_M ? 1 : texels_in(&F, fx, fy, z);
    }
    return h;
}

/* The samples [s0, s1) (at most RUN_READ) of atmos__beams_ray_light_sum read one by one: when
 * they all lie in one face of the map (the first's and the last's, each as
 * atmos__beams_ray_light finds it), a point light's by read_point, a spot's texels projected
 * together (run_texels), else each alone. The same sum, in order. An AVX2 clone where the
 * processor has it (read_point inlined into it: the same IEEE operations, the same bits). */
BEAMS_CLONES static double read_run(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1)
{
    const atmos__beams_light *l = r->l;
    double h = 0;
    int f = 0;
    if (l->nfaces == 6) { /* a face's pyramid is convex: the first and the last sample's face is the run's */
        const double t0 = ta + (s0 + o) * step, t1 = ta + (s1 - 1 + o) * step;
        const double w0[3] = {r->w0[0] + t0 * r->d[0], r->w0[1] + t0 * r->d[1], r->w0[2] + t0 * r->d[2]};
        const double w1[3] = {r->w0[0] + t1 * r->d[0], r->w0[1] + t1 * r->d[1], r->w0[2] + t1 * r->d[2]};
        f = cube_face(w0);
        if (s1 - s0 > 1 && cube_face(w1) != f) f = -1;
    }
    if (!l->nfaces || f < 0) {
        for (int s = s0; s < s1; s++) h += ray_light(r, ta + (s + o) * step);
        return h;
    }
    if (l->L.type != ATMOS_LIGHT_SPOT) return read_point(r, f, ta, step, o, s0, s1);
    double fx[RUN_READ], fy[RUN_READ], z[RUN_READ];
    run_texels(r, f, ta, step, o, s0, s1, fx, fy, z);
    for (int s = s0; s < s1; s++) {
        const double fall = ray_falloff(r, ta + (s + o) * step);
        h += fall == 0 ? 0 : fall * texels(&l->face[f], fx[s - s0], fy[s - s0], z[s - s0]);
    }
    return h;
}

/* The longest run of samples atmos__beams_ray_light_sum reads without asking the tiles: a
 * spot's 8 (the inner cone's run and the tiles spare its falloff's evaluations), a point
 * light's RUN_READ (the tiles' test of a run inside an interval they did not settle costs
 * about 400 instructions and settles about half: reading the run costs less; docs/beams.md,
 * issue 17's twenty-seventh round). */
static int run_max(const atmos__beams_ray *r) { return r->l->L.type == ATMOS_LIGHT_SPOT ? 8 : RUN_READ; }

double atmos__beams_ray_light_sum(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1)
{
    if (s1 - s0 > run_max(r)) { /* what is the same along the run's samples, from the tiles */
        double same;
        int full;
        if (atmos__beams_ray_uniform(r, ta + (s0 + o) * step, ta + (s1 - 1 + o) * step, &same, &full)) {
            if (full || same == 0) return same * (s1 - s0);
            return atmos__beams_ray_falloff_sum(r, ta, step, o + s0, s1 - s0);
        }
        const int mid = s0 + (s1 - s0) / 2;
        return atmos__beams_ray_light_sum(r, ta, step, o, s0, mid) + atmos__beams_ray_light_sum(r, ta, step, o, mid, s1);
    }
    return read_run(r, ta, step, o, s0, s1);
}

double atmos__beams_ray_light_sum_split(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1)
{
    if (s1 - s0 <= run_max(r)) return atmos__beams_ray_light_sum(r, ta, step, o, s0, s1);
    const int mid = s0 + (s1 - s0) / 2;
    return atmos__beams_ray_light_sum(r, ta, step, o, s0, mid) + atmos__beams_ray_light_sum(r, ta, step, o, mid, s1);
}

/* The texels' size relative to the depth and the slope: a plane through p with normal cosine
 * cos_n toward the light is seen, through a direction d texels (of angular size a) off p's, at
 * a depth differing from p's by about d a z / (cos_n r) (r the distance, z the depth): the 3 x 3
 * texels lie within 1.5 sqrt 2 texels, taken twice over, plus the floats' rounding. Beyond a
 * bias of a fifth of the depth (a surface seen edge-on) the map cannot tell. */
#define SURFACE_BIAS_TEXELS 4.3
#define SURFACE_BIAS_MAX 0.2

int atmos__beams_surface_visible(const atmos__beams_light *l, const double p[3], double cos_n)
{
    if (!l->nfaces) return 1;
    const double d[3] = {p[0] - l->L.pos[0], p[1] - l->L.pos[1], p[2] - l->L.pos[2]};
    const atmos__beams_face *F = &l->face[l->nfaces == 6 ? cube_face(d) : 0];
    const double z = atmos__dot3(d, F->fwd), r = sqrt(atmos__dot3(d, d));
    if (!(z > NEAR_M) || !(cos_n > 0)) return -1;
    const int n = F->n;
    const double k = 0.5 * n / (z * F->tan_half);
    const double fx = 0.5 * n + atmos__dot3(d, F->right) * k - 0.5, fy = 0.5 * n + atmos__dot3(d, F->up) * k - 0.5;
    if (!(fx >= 1 && fx < n - 2 && fy >= 1 && fy < n - 2)) return -1; /* its ring beside the map */
    const int cx = (int)(fx + 0.5), cy = (int)(fy + 0.5);
    const double rel = SURFACE_BIAS_TEXELS * (2 * F->tan_half / n) * z / (cos_n * r) + 1e-5;
    if (rel > SURFACE_BIAS_MAX) return -1;
    const double zb = z * (1 - rel);
    int nearer = 0;
    for (int y = cy - 1; y <= cy + 1; y++) {
        const float *row = F->depth + (size_t)y * n;
        for (int x = cx - 1; x <= cx + 1; x++) nearer += row[x] < zb;
    }
    return nearer == 0 ? 1 : nearer == 9 ? 0 : -1;
}
