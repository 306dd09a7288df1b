/* The beam renderer's shadow-map look-ups along a light's ray (beams_shadow.c), always inlined
 * (ATMOS_CLONE_HELPER) into their callers' clones: beams_shadow.c's runs and beams_tint.c's
 * samples of a spot with an image, which read the light at each sample without a call. Not part
 * of the API. */
#ifndef ATMOS_RENDER_BEAMS_LOOKUP_H
#define ATMOS_RENDER_BEAMS_LOOKUP_H

#include "render/beams_internal.h"
#include "render/beams_tiles.h"
#include "core/vec.h"
#include "core/clones.h"

#include <math.h>
#include <stddef.h>

#define ATMOS__BEAMS_NEAR_M 1e-3 /* the near plane of the lights' maps (m) */

/* What a look-up reads of a face, in locals: a run's loop (read_point) takes them once, where
 * the fields read after a branch in the loop would be loaded again at every sample (the compiler
 * does not hoist a load that the loop may not reach). */
typedef struct face_at {
    int n;
    double hn, tan_half; /* 0.5 n, the same bits as 0.5 * F->n */
    const float *depth, *min, *max;
    const int *tile_x, *tile_y;
} face_at;

ATMOS_CLONE_HELPER face_at face_of(const atmos__beams_face *F)
{
    return (face_at){F->n, 0.5 * F->n, F->tan_half, F->depth, F->tiles.min, F->tiles.max, F->tile_x, F->tile_y};
}

/* texels() at coordinates inside the map (fx, fy in (-1, n)). */
ATMOS_CLONE_HELPER double texels_in(const face_at *F, double fx, double fy, double z)
{
    if (z <= ATMOS__BEAMS_NEAR_M) return 1;
    const int n = F->n;
    const int xi = (int)(fx + 1), yi = (int)(fy + 1), x0 = xi - 1, y0 = yi - 1; /* floor: fx, fy > -1 */
    const int tile = F->tile_y[yi] + F->tile_x[xi]; /* atmos__beams_tiles_at(&tiles, x0, y0, shift) */
    if (z < F->min[tile]) return 1;
    if (z >= F->max[tile]) return 0;
    return atmos__beams_depth_blend(F->depth, n, fx, fy, x0, y0, z);
}

/* H at depth z and texel coordinates (fx, fy) of face F: the four nearest comparisons, blended. */
ATMOS_CLONE_HELPER double texels(const atmos__beams_face *F, double fx, double fy, double z)
{
    const int n = F->n;
    if (!(fx > -1 && fx < n && fy > -1 && fy < n)) return 1; /* outside the spot's frustum: its falloff is zero there */
    const face_at a = face_of(F);
    return texels_in(&a, fx, fy, z);
}

/* H at the point (x, y, z) of face F's frame. */
ATMOS_CLONE_HELPER double lookup(const atmos__beams_face *F, double x, double y, double z)
{
    if (z <= ATMOS__BEAMS_NEAR_M) return 1;
    const int n = F->n;
    const double k = 0.5 * n / (z * F->tan_half);
    return texels(F, 0.5 * n + x * k - 0.5, 0.5 * n + y * k - 0.5, z);
}

/* The cube face of w's largest component. */
ATMOS_CLONE_HELPER int cube_face(const double w[3])
{
    const double ax = fabs(w[0]), ay = fabs(w[1]), az = fabs(w[2]);
    const int a = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
    return 2 * a + (w[a] < 0);
}

/* atmos__beams_ray_falloff, inlined into ray_light. */
ATMOS_CLONE_HELPER double ray_falloff(const atmos__beams_ray *r, double t)
{
    const atmos__beams_light *l = r->l;
    if (l->L.type != ATMOS_LIGHT_SPOT) return 1;
    const double z = r->a0 + t * r->a1, w2 = r->ww0 + t * (2 * r->wd + t);
    if (z <= 0 || z * z <= l->L.cos_outer * l->L.cos_outer * w2) return 0;
    if (z * z >= l->L.cos_inner * l->L.cos_inner * w2) return 1;
    const double s = (z / sqrt(w2) - l->L.cos_outer) / (l->L.cos_inner - l->L.cos_outer);
    return s * s * (3 - 2 * s);
}

/* atmos__beams_ray_light, inlined into read_run's clones and beams_tint.c's samples. */
ATMOS_CLONE_HELPER double ray_light(const atmos__beams_ray *r, double t)
{
    const atmos__beams_light *l = r->l;
    const double fall = ray_falloff(r, t);
    if (!l->nfaces || fall == 0) return fall;
    int f = 0;
    if (l->nfaces == 6) {
        const double w[3] = {r->w0[0] + t * r->d[0], r->w0[1] + t * r->d[1], r->w0[2] + t * r->d[2]};
        f = cube_face(w);
    }
    return fall * lookup(&l->face[f], r->f0[f][0] + t * r->f1[f][0], r->f0[f][1] + t * r->f1[f][1],
                         r->f0[f][2] + t * r->f1[f][2]);
}

/* Face f's (F, face_of(&r->l->face[f])) texel coordinates and depth of the ray at t (0 if behind
 * the near plane). */
ATMOS_CLONE_HELPER int project(const atmos__beams_ray *r, int f, const face_at *F, double t, double *fx,
                               double *fy, double *z)
{
    *z = r->f0[f][2] + t * r->f1[f][2];
    if (*z <= ATMOS__BEAMS_NEAR_M) return 0;
    const double k = F->hn / (*z * F->tan_half);
    *fx = F->hn + (r->f0[f][0] + t * r->f1[f][0]) * k - 0.5;
    *fy = F->hn + (r->f0[f][1] + t * r->f1[f][1]) * k - 0.5;
    return *fx > -1 && *fx < F->n && *fy > -1 && *fy < F->n;
}

ATMOS_CLONE_HELPER int inside_inner(const atmos__beams_ray *r, double t)
{
    const double z = r->a0 + t * r->a1, w2 = r->ww0 + t * (2 * r->wd + t);
    return z > 0 && z * z >= r->l->L.cos_inner * r->l->L.cos_inner * w2;
}

/* atmos__beams_ray_uniform (beams_internal.h), inlined into its callers' clones. */
ATMOS_CLONE_HELPER int ray_uniform(const atmos__beams_ray *r, double ta, double tb, double *h, int *full)
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
    const atmos__beams_face *F = &l->face[f];
    const face_at a = face_of(F);
    if (!project(r, f, &a, ta, &xa, &ya, &za) || !project(r, f, &a, tb, &xb, &yb, &zb)) return 0;
    const int x0 = (int)(atmos__mind(xa, xb) + 1) - 1, x1 = (int)(atmos__maxd(xa, xb) + 1) - 1;
    const int y0 = (int)(atmos__mind(ya, yb) + 1) - 1, y1 = (int)(atmos__maxd(ya, yb) + 1) - 1;
    float lo, hi;
    atmos__beams_tiles_range_in(&F->tiles, x0, x1, y0, y1, &lo, &hi);
    if (atmos__maxd(za, zb) < lo) return 1;
    if (atmos__mind(za, zb) >= hi) return *h = 0, 1;
    return 0;
}

#endif
