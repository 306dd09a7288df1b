/* One way to read a finalized volume. Every reader goes through this header: the
 * public sampling and optical depth (volume_sample.c), the path tracer's medium
 * (render/path_medium.c), the slice renderer's render grid (render/slice_grid.c) and
 * the raw writer. It holds the four pieces that used to exist once per reader:
 *
 *   1. one world <-> index transform (atmos__vol_xform);
 *   2. one trilinear sampler: one gather of the eight corner voxels (one brick look-up
 *      when they share a brick) and one blend, in float (the path tracer) and in double
 *      (atmos_volume_sample, the optical depth) precision, generated from one text;
 *   3. one 3D DDA over the bricks (Amanatides & Woo 1987, "A fast voxel traversal
 *      algorithm for ray tracing") with each brick's per-field (min, max) of the
 *      interpolant, built once at finalize (volume_range.c);
 *   4. "for each occupied brick" and the boxes of the occupied bricks.
 *
 * Conventions. Index space: voxel (i,j,k) covers [i, i+1) x [j, j+1) x [k, k+1) and
 * holds the density at its centre (i+1/2, j+1/2, k+1/2). Inside the box [0,n]^3 the
 * density is the trilinear interpolant of the voxel centres with indices clamped to
 * the grid (the half voxel next to a face carries the face voxel's value); outside the
 * box it is 0. World = org + R (index * voxel size).
 *
 * The hot parts are static inline so that the renderers' inner loops keep the code
 * inlined and compiled with their own flags. Everything here is read-only: any number
 * of threads may use a finalized volume. Not part of the API.
 */
#ifndef ATMOS_VOLUME_ACCESS_H
#define ATMOS_VOLUME_ACCESS_H

#include "volume/volume_grid.h"

#include <math.h>
#include <stdint.h>

/* The sampler, the transform and the DDA sit in the renderers' innermost loops: force them
 * inline (at -O2 GCC otherwise keeps the sampler's set-up out of line: a call per sample,
 * the corners passed through memory). */
#if defined(__GNUC__)
#define ATMOS__VOL_INLINE static inline __attribute__((always_inline))
#else
#define ATMOS__VOL_INLINE static inline
#endif

/* ------------------------------------------------------------------ world <-> index */

/* atmos__vol_xform (volume_grid.h): org, R, vs, inv_vs. */

/* The volume's own transform (set up once at create). */
ATMOS__VOL_INLINE const atmos__vol_xform *atmos__vol_xform_of(const atmos_volume *v) { return &v->xform; }

/* The volume's transform moved by offset (metres; NULL = not moved). */
void atmos__vol_xform_init(const atmos_volume *v, const double offset[3], atmos__vol_xform *x);

/* World vector -> grid frame (rotation only, metres): R^T d. */
ATMOS__VOL_INLINE void atmos__vol_dir_to_frame(const atmos__vol_xform *x, const double d[3], double g[3])
{
    const double *r = x->R;
    const double g0 = r[0] * d[0] + r[3] * d[1] + r[6] * d[2], g1 = r[1] * d[0] + r[4] * d[1] + r[7] * d[2],
                 g2 = r[2] * d[0] + r[5] * d[1] + r[8] * d[2];
    g[0] = g0, g[1] = g1, g[2] = g2;
}

/* World point -> continuous index coordinates: R^T (p - org) / vs. */
ATMOS__VOL_INLINE void atmos__vol_point_to_index(const atmos__vol_xform *x, const double p[3], double q[3])
{
    const double e[3] = {p[0] - x->org[0], p[1] - x->org[1], p[2] - x->org[2]};
    atmos__vol_dir_to_frame(x, e, q);
    for (int a = 0; a < 3; a++) q[a] *= x->inv_vs;
}

/* World direction -> index space (no translation); a ray parameter t keeps its unit. */
ATMOS__VOL_INLINE void atmos__vol_dir_to_index(const atmos__vol_xform *x, const double d[3], double qd[3])
{
    atmos__vol_dir_to_frame(x, d, qd);
    for (int a = 0; a < 3; a++) qd[a] *= x->inv_vs;
}

/* Grid-frame point (metres along the grid's axes from its corner) -> world: org + R g. */
void atmos__vol_frame_to_point(const atmos__vol_xform *x, const double g[3], double p[3]);
/* Index point -> world: org + R (q vs). */
void atmos__vol_index_to_point(const atmos__vol_xform *x, const double q[3], double p[3]);
/* Index-space direction -> world: R (qd vs). */
void atmos__vol_index_to_dir(const atmos__vol_xform *x, const double qd[3], double d[3]);

/* q inside the closed index box [0, n] (where the interpolant may be nonzero)? */
ATMOS__VOL_INLINE int atmos__vol_inside(const atmos_volume *v, const double q[3])
{
    return q[0] >= 0 && q[1] >= 0 && q[2] >= 0 && q[0] <= v->desc.dims[0] && q[1] <= v->desc.dims[1] &&
           q[2] <= v->desc.dims[2];
}

/* One voxel of a field (indices in range): 0 in empty bricks. */
ATMOS__VOL_INLINE float atmos__vol_voxel(const atmos_volume *v, int field, int i, int j, int k)
{
    return vol_voxel(v, &v->field[field], i, j, k);
}

/* ------------------------------------------------------------------ trilinear sampler */

/* The eight voxels the interpolant reads at one point, shared by all fields. Corner n
 * takes the upper index on x if n & 1, on y if n & 2, on z if n & 4. */
typedef struct {
    int i0[3], i1[3];  /* lower and upper voxel per axis, clamped to the grid */
    uint64_t brick;    /* brick position of i0 */
    int same;          /* all eight in that brick: one table look-up per field */
    int ox[2], oy[2], oz[2]; /* offsets inside a brick of the lower/upper x, y, z (used when same) */
} atmos__vol_corners;

/* Corners from the unclamped lower index l = floor(q - 1/2) per axis, q in the box (so
 * l >= -1 and l + 1 >= 0). */
ATMOS__VOL_INLINE void atmos__vol_corners_from(const atmos_volume *v, const int l[3], atmos__vol_corners *c)
{
    for (int a = 0; a < 3; a++) {
        const int n = v->desc.dims[a];
        int i = l[a], i1 = i + 1;
        if (i < 0) i = 0;
        if (i1 > n - 1) i1 = n - 1;
        if (i > n - 1) i = n - 1;
        c->i0[a] = i;
        c->i1[a] = i1;
    }
    c->same = (c->i0[0] >> VOL_BRICK_LOG2) == (c->i1[0] >> VOL_BRICK_LOG2) &&
              (c->i0[1] >> VOL_BRICK_LOG2) == (c->i1[1] >> VOL_BRICK_LOG2) &&
              (c->i0[2] >> VOL_BRICK_LOG2) == (c->i1[2] >> VOL_BRICK_LOG2);
    c->brick = vol_brick_index(v, c->i0[0], c->i0[1], c->i0[2]);
    const int M = VOL_BRICK - 1;
    c->ox[0] = c->i0[0] & M, c->ox[1] = c->i1[0] & M;
    c->oy[0] = (c->i0[1] & M) * VOL_BRICK, c->oy[1] = (c->i1[1] & M) * VOL_BRICK;
    c->oz[0] = (c->i0[2] & M) * VOL_BRICK * VOL_BRICK, c->oz[1] = (c->i1[2] & M) * VOL_BRICK * VOL_BRICK;
}

/* The eight corner values of a field. Returns 0 (out untouched) when they all lie in
 * one empty brick, i.e. the interpolant is exactly 0 there. */
ATMOS__VOL_INLINE int atmos__vol_gather(const atmos_volume *v, int field, const atmos__vol_corners *c, float out[8])
{
    const vol_field *fl = &v->field[field];
    if (c->same) {
        const uint32_t s = fl->table[c->brick];
        if (!s) return 0;
        const float *p = vol_brick_data(v, s);
        const int x0 = c->ox[0], x1 = c->ox[1], y0 = c->oy[0], y1 = c->oy[1], z0 = c->oz[0], z1 = c->oz[1];
        out[0] = p[z0 + y0 + x0], out[1] = p[z0 + y0 + x1], out[2] = p[z0 + y1 + x0], out[3] = p[z0 + y1 + x1];
        out[4] = p[z1 + y0 + x0], out[5] = p[z1 + y0 + x1], out[6] = p[z1 + y1 + x0], out[7] = p[z1 + y1 + x1];
        return 1;
    }
    for (int n = 0; n < 8; n++)
        out[n] = vol_voxel(v, fl, n & 1 ? c->i1[0] : c->i0[0], n & 2 ? c->i1[1] : c->i0[1], n & 4 ? c->i1[2] : c->i0[2]);
    return 1;
}

/* The two precisions are one text: the setup (corner index and weight per axis) and the
 * blend (x, then y, then z; the order the renderers' images depend on, bit for bit) are
 * written once and instantiated for T = float and T = double. The corners are converted
 * to T before any arithmetic, so the double variant computes exactly in double. */
#define ATMOS__VOL_DEFINE_SAMPLER(T, FLOOR, SFX)                                                                  \
    /* Corners and weights at index point q (inside the box; see atmos__vol_inside). */                         \
    ATMOS__VOL_INLINE void atmos__vol_setup_##SFX(const atmos_volume *v, const double q[3], atmos__vol_corners *c,  \
                                              T w[3])                                                           \
    {                                                                                                           \
        int l[3];                                                                                               \
        for (int a = 0; a < 3; a++) {                                                                           \
            const T x = (T)q[a] - (T)0.5, fl = FLOOR(x);                                                        \
            l[a] = (int)fl;                                                                                     \
            w[a] = x - fl;                                                                                      \
        }                                                                                                       \
        atmos__vol_corners_from(v, l, c);                                                                       \
    }                                                                                                           \
    ATMOS__VOL_INLINE T atmos__vol_blend_##SFX(const float c[8], const T w[3])                                      \
    {                                                                                                           \
        const T x00 = (T)c[0] + w[0] * ((T)c[1] - (T)c[0]), x10 = (T)c[2] + w[0] * ((T)c[3] - (T)c[2]);        \
        const T x01 = (T)c[4] + w[0] * ((T)c[5] - (T)c[4]), x11 = (T)c[6] + w[0] * ((T)c[7] - (T)c[6]);        \
        const T y0 = x00 + w[1] * (x10 - x00), y1 = x01 + w[1] * (x11 - x01);                                   \
        return y0 + w[2] * (y1 - y0);                                                                           \
    }                                                                                                           \
    /* The interpolant of one field at the point set up in c, w. */                                            \
    ATMOS__VOL_INLINE T atmos__vol_sample_##SFX(const atmos_volume *v, int field, const atmos__vol_corners *c,      \
                                            const T w[3])                                                       \
    {                                                                                                           \
        float k[8];                                                                                             \
        return atmos__vol_gather(v, field, c, k) ? atmos__vol_blend_##SFX(k, w) : (T)0;                         \
    }

ATMOS__VOL_DEFINE_SAMPLER(float, floorf, f)
ATMOS__VOL_DEFINE_SAMPLER(double, floor, d)

/* ------------------------------------------------------------------ brick DDA */

/* A ray q + t qd (index space) walked brick by brick (Amanatides & Woo 1987): tn[a] is
 * the t at which the ray leaves the current brick across axis a, stepped by dt[a]
 * (incrementally, so every reader sees the same brick boundaries bit for bit). */
typedef struct {
    int c[3], st[3];   /* brick coordinates, step direction per axis */
    double tn[3], dt[3];
    uint64_t idx;      /* brick index of c */
    int64_t sidx[3];   /* change of idx per step along each axis */
} atmos__vol_dda;

/* Starts at the brick containing q + t0 qd (clamped to the grid). */
ATMOS__VOL_INLINE void atmos__vol_dda_init(const atmos_volume *v, const double q[3], const double qd[3], double t0,
                                       atmos__vol_dda *g)
{
    for (int a = 0; a < 3; a++) {
        const double x = q[a] + t0 * qd[a];
        int c = (int)floor(x * (1.0 / VOL_BRICK));
        if (c < 0) c = 0;
        if (c > v->nb[a] - 1) c = v->nb[a] - 1;
        g->c[a] = c;
        if (qd[a] > 0) {
            g->st[a] = 1;
            g->dt[a] = VOL_BRICK / qd[a];
            g->tn[a] = ((double)(c + 1) * VOL_BRICK - q[a]) / qd[a];
        } else if (qd[a] < 0) {
            g->st[a] = -1;
            g->dt[a] = -VOL_BRICK / qd[a];
            g->tn[a] = ((double)c * VOL_BRICK - q[a]) / qd[a];
        } else {
            g->st[a] = 0;
            g->dt[a] = INFINITY;
            g->tn[a] = INFINITY;
        }
    }
    g->sidx[0] = g->st[0];
    g->sidx[1] = (int64_t)g->st[1] * v->nb[0];
    g->sidx[2] = (int64_t)g->st[2] * v->nb[0] * v->nb[1];
    g->idx = ((uint64_t)g->c[2] * v->nb[1] + g->c[1]) * v->nb[0] + g->c[0];
}

/* t at which the ray leaves the current brick. */
ATMOS__VOL_INLINE double atmos__vol_dda_tend(const atmos__vol_dda *g)
{
    const double t = g->tn[0] < g->tn[1] ? g->tn[0] : g->tn[1];
    return t < g->tn[2] ? t : g->tn[2];
}

/* Steps into the next brick (one axis at a time: where the ray crosses an edge the brick
 * in between is visited with zero length); returns 0 when leaving the grid. */
ATMOS__VOL_INLINE int atmos__vol_dda_step(const atmos_volume *v, atmos__vol_dda *g)
{
    const int a = g->tn[0] < g->tn[1] ? (g->tn[0] < g->tn[2] ? 0 : 2) : (g->tn[1] < g->tn[2] ? 1 : 2);
    g->c[a] += g->st[a];
    if (g->c[a] < 0 || g->c[a] >= v->nb[a]) return 0;
    g->tn[a] += g->dt[a];
    g->idx += (uint64_t)g->sidx[a];
    return 1;
}

/* Bounds of the interpolant in brick position idx: per field f, r[2f] <= eta_f <= r[2f+1]
 * everywhere in the brick (min and max of the voxels its interpolation reads); all zero
 * where every field is 0. Majorant of the extinction: sum_f sigma_f r[2f+1] (Riley et
 * al. 2004 Eq. 3); a brick whose majorant is 0 is exactly empty. */
ATMOS__VOL_INLINE const float *atmos__vol_range(const atmos_volume *v, uint64_t idx)
{
    return v->range + (size_t)v->cell[idx] * 2 * (size_t)v->nfields;
}

ATMOS__VOL_INLINE const float *atmos__vol_dda_range(const atmos_volume *v, const atmos__vol_dda *g)
{
    return atmos__vol_range(v, g->idx);
}

/* The DDA's current brick has all-zero bounds (no field reaches it): the quick test that
 * lets a traversal skip empty space without reading the bounds. */
ATMOS__VOL_INLINE int atmos__vol_dda_empty(const atmos_volume *v, const atmos__vol_dda *g) { return v->cell[g->idx] == 0; }

/* ------------------------------------------------------------------ occupied bricks */

/* Brick box [lo, hi] (inclusive, brick coordinates) of the bricks allocated by any
 * field; 0 if there are none. */
int atmos__vol_occupied_box(const atmos_volume *v, int lo[3], int hi[3]);
/* Brick box of the positions whose range is not all zero (where a ray can meet
 * density: the occupied bricks grown by the ring the interpolation reaches); 0 if none. */
int atmos__vol_range_box(const atmos_volume *v, int lo[3], int hi[3]);

/* "For each occupied brick" of one field, in brick-index order (x fastest, z slowest):
 *     atmos__vol_brick_it it = {0};
 *     while (atmos__vol_next_brick(v, f, &it)) use(it.o, it.data);  */
typedef struct {
    uint64_t next;      /* brick index to look at next */
    int o[3];           /* the brick's first voxel */
    const float *data;  /* its VOL_BRICK_VOXELS values, x fastest */
} atmos__vol_brick_it;
int atmos__vol_next_brick(const atmos_volume *v, int field, atmos__vol_brick_it *it);

#endif
