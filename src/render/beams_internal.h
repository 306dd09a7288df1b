/* Dobashi, Yamamoto and Nishita 2002 §4's light beams ("renderer": "beams", docs/beams.md):
 * point lights and spotlights in a uniform fog, the shadows of meshes in the air by shadow
 * maps, sampling planes facing the view with a pre-integrated scattering table and
 * sub-planes. The plan's part (beams_plan.c), the table (beams_table.c), the shadow maps
 * (beams_shadow.c) and the frame (beams_render.c). Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_INTERNAL_H
#define ATMOS_RENDER_BEAMS_INTERNAL_H

#include "core/vec.h"
#include "light/lamp.h"
#include "render/objects.h"
#include "render/beams_kept.h"
#include "render/beams_sky.h"
#include "render/beams_sun.h"
#include "render/beams_tiles.h"
#include "render/plan_internal.h"

#include <math.h>
#include <string.h>

/* The pre-integrated scattering of a point light toward the eye (Dobashi Eq. 8-9, with the
 * substitution of Sun et al. 2005). For a ray passing at distance v from the light, with u
 * the signed distance along the ray from Q (the ray's point nearest the light) and
 * theta = atan(u / v), the light scattered toward the eye between u_a and u_b per unit
 * intensity is
 *     exp(-sigma_t t_Q) / v * (W(theta_b, x) - W(theta_a, x)),  x = sigma_t v,
 *     W(theta, x) = sigma_s * int_{-pi/2}^{theta} p(-sin th) exp(-x tan(pi/4 + th/2)) dth,
 * t_Q the distance from the eye to Q and p the phase function: two look-ups for any
 * interval, whatever its length (Dobashi's q(u, v) is a difference of W at a fixed
 * interval). Tabulated over nt values of s = u / (|u| + v) in [-1, 1] (theta
 * without an arctangent per look-up: tan theta = s / (1 - |s|)) and nx values of
 * x = x_max w^2, w in [0, 1] (finer near the light); linear in s, cubic in w. */
/* The fog's reach from a light, in optical depths: beyond, exp(-50) of the light is left. */
#define ATMOS__BEAMS_MAX_OPTICAL_RANGE 50.0

typedef struct atmos__beams_table {
    int nt, nx;
    double x_max;
    double *w;               /* nx rows of nt values, stored by node: row j's node i at i nx + j */
} atmos__beams_table;

atmos_status atmos__beams_table_build(atmos_context *ctx, double sigma_t, double sigma_s, const atmos__fog_optics *phase,
                                      double x_max, atmos__beams_table *out);
void atmos__beams_table_free(atmos__beams_table *t);

/* The four rows and their weights for one x (a ray and a light): W at any theta is then
 * atmos__beams_table_at. */
typedef struct atmos__beams_column {
    const double *rows; /* the first row's node 0: node i of the four at rows + i nx, side by side */
    double wt[4];
} atmos__beams_column;
void atmos__beams_table_column(const atmos__beams_table *t, double x, atmos__beams_column *c);
/* W at s for the column c (linear in s between the nodes, the column's cubic weights); inline. */
static inline double atmos__beams_table_at(const atmos__beams_table *t, const atmos__beams_column *c, double s)
{
    const double f = atmos__clampd((s + 1) * (0.5 * (t->nt - 1)), 0, t->nt - 1);
    int i = (int)f;
    if (i > t->nt - 2) i = t->nt - 2;
    /* the four rows' terms as one vector (each lane the scalar's operations), summed in order */
    typedef double v4d __attribute__((vector_size(32)));
    v4d p, q, w;
    memcpy(&p, c->rows + (size_t)i * t->nx, sizeof p), memcpy(&q, c->rows + (size_t)(i + 1) * t->nx, sizeof q);
    memcpy(&w, c->wt, sizeof w);
    const v4d u = w * (p + (f - i) * (q - p));
    double v = 0;
    for (int k = 0; k < 4; k++) v += u[k];
    return v;
}
/* The table's coordinate of the point u along a ray passing at v from the light. */
static inline double atmos__beams_table_s(double u, double v) { return u / ((u < 0 ? -u : u) + v); }

/* A depth map seen from a light through one frustum: the distance along fwd of the nearest
 * surface through each of n x n texels spanning [-tan_half, tan_half]^2 of the image plane. */
typedef struct atmos__beams_face {
    double right[3], up[3], fwd[3];
    double tan_half;
    int n;
    float *depth;
    atmos__beams_tiles tiles;   /* its min/max pyramid (beams_tiles.h) */
    int *tile_x, *tile_y;       /* per floor + 1 of a look-up's coordinate (0 .. n + 1): its tile's
                                 * column, and its tile's row times the tiles a side (one block) */
} atmos__beams_face;

typedef struct atmos__beams_light {
    atmos__lamp L;               /* the light itself (light/lamp.h) */
    int nfaces;                  /* 0: no shadow casters; 1: a spot's frustum; 6: a cube map */
    atmos__beams_face face[6];
} atmos__beams_light;

/* The plan's progress over every light's shadow maps (stage "beams shadow maps"): faces done
 * of the total, and the caller's wish to stop (atmos__progress_step). */
typedef struct atmos__beams_progress {
    int done, total, cancelled;
} atmos__beams_progress;

/* How many depth maps the light gets: 0 without meshes, 1 for a spot's frustum, 6 for a cube. */
int atmos__beams_shadow_faces(const atmos__lamp *L, int nmesh);
/* The light's shadow maps of the meshes, size texels a side (beams_shadow.c), each face done
 * counted in *pr; ATMOS_E_CANCELLED when the progress callback asked to stop. */
atmos_status atmos__beams_shadow_build(atmos_context *ctx, atmos__beams_light *l, atmos_mesh *const *mesh, int nmesh,
                                       int size, atmos__beams_progress *pr);
void atmos__beams_shadow_free(atmos__beams_light *l);
/* H: the share of the light reaching p past the meshes, in [0, 1] (2x2 filtered). */
double atmos__beams_visibility(const atmos__beams_light *l, const double p[3]);
/* Whether the light's shadow map settles the surface point p (cos_n: the cosine between its
 * normal and the direction toward the light): 1 lit, 0 in shadow, -1 when it cannot tell (an
 * exact shadow ray is needed). The 3 x 3 texels round p's are compared with p's depth less a
 * bias that grows with the texels' size and the slope of the surface seen from the light: lit
 * when none of them holds a nearer surface, dark when all do (docs/beams.md *Surfaces' shadows*). */
int atmos__beams_surface_visible(const atmos__beams_light *l, const double p[3], double cos_n);

/* One ray's view of one light, for the sub-planes: the point o + t d relative to the light,
 * its depth along the spot's axis and its coordinates in each shadow face, all linear in t
 * (set once per ray; a sample then costs a few multiply-adds and at most one square root). */
typedef struct atmos__beams_ray {
    const atmos__beams_light *l;
    double ww0, wd;          /* |w(0)|^2 and w(0).d: |w(t)|^2 = ww0 + 2 t wd + t^2 */
    double w0[3], d[3];      /* w(t) = w0 + t d */
    double a0, a1;           /* the depth along the axis: a0 + t a1 */
    double f0[6][3], f1[6][3]; /* per face: (right, up, fwd) coordinates a0 + t a1 */
    double u0, u1, v0, v1;   /* a spot with an image: w(t)'s along its right and down, in texels at unit depth */
} atmos__beams_ray;
void atmos__beams_ray_init(const atmos__beams_light *l, const double o[3], const double d[3], atmos__beams_ray *r);
/* atmos__beams_ray_init in two steps, for many rays from one eye o: the part of a ray's view
 * that depends on o alone (l, w0, ww0, a0, u0, v0, f0), set once a frame and light into e, then
 * per ray d the rest (atmos__beams_ray_from: the same bits as atmos__beams_ray_init). */
void atmos__beams_ray_eye(const atmos__beams_light *l, const double o[3], atmos__beams_ray *e);
void atmos__beams_ray_from(const atmos__beams_ray *e, const double d[3], atmos__beams_ray *r);
/* The spot's falloff times the visibility H at o + t d (as the two functions above). */
double atmos__beams_ray_light(const atmos__beams_ray *r, double t);
/* What is the same all along [ta, tb] of the ray: 1 if H is (*h: 0 or 1; the segment nearer
 * or farther than every depth of the shadow map's tiles it crosses), and then *full = 1 if the
 * falloff is 1 too (the segment inside the spot's inner cone); 0 when H may vary. */
int atmos__beams_ray_uniform(const atmos__beams_ray *r, double ta, double tb, double *h, int *full);
/* The spot's falloff alone at o + t d (1 for a point light). */
double atmos__beams_ray_falloff(const atmos__beams_ray *r, double t);
/* The sum of the falloff at the m points t = ta + (s + o) step, s = 0 .. m - 1 (one tight loop:
 * the same values as m calls of atmos__beams_ray_falloff, added in order). */
double atmos__beams_ray_falloff_sum(const atmos__beams_ray *r, double ta, double step, double o, int m);
/* The sum of atmos__beams_ray_light at the points t = ta + (s + o) step, s = s0 .. s1 - 1: runs
 * of them along which the shadow map's tiles prove H the same (atmos__beams_ray_uniform) cost
 * the falloff alone or nothing; the others are halved, down to a few samples read one by one. */
double atmos__beams_ray_light_sum(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1);
/* The same sum when the tiles have just failed to settle a span holding [s0, s1): a run of
 * more than 8 is halved at once, without testing it again (a test of a part that the span's
 * test would have passed passes too, the pyramid's ranges being nested, so for a point light
 * the sum is the same to the bit; for a spot the falloff's runs may be added in another order). */
double atmos__beams_ray_light_sum_split(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1);

/* A spot with an image (stained glass, beams_tint.c): the sum of atmos__beams_ray_light times
 * the image's tint at the samples t = ta + (s + o) step, s = s0 .. s1 - 1, added to h (rgb).
 * Runs of more than 8 of them whose image the tint proves the same (atmos__lamp_tint_same)
 * are that tint times atmos__beams_ray_light_sum, runs the shadow map's tiles prove dark
 * nothing; the rest halved, down to 8 samples read one by one. */
void atmos__beams_ray_tinted_sum(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1, double h[3]);
/* Dobashi's sub-planes of an interval whose f_l is fl: ceil(fl / unit), at least 1, at most
 * max_sub (the renderer's and the stained glass's intervals alike). */
ATMOS_CLONE_HELPER int atmos__beams_subplanes(double fl, double unit, int max_sub)
{
    const double need = ceil(fl / unit);
    return need < 1 ? 1 : need > max_sub ? max_sub : (int)need;
}
/* A spot with an image (stained glass) over the ray's n intervals f (beams_render.c's layout:
 * f[2k], f[2k + 2] the ends of interval k, f[2k + 1] its f_l): each interval whose f_l > 0 gets
 * ceil(f_l / unit) sub-planes (at most max_sub), their samples at offset o, whose tinted sum
 * (atmos__beams_ray_tinted_sum) over the sub-planes times f_l is added into sum (rgb, set);
 * returns the sub-planes counted, those of the intervals the image leaves black included. */
int atmos__beams_ray_tinted(const atmos__beams_ray *r, const double *f, int n, double unit, int max_sub, double o,
                            double sum[3]);
/* Narrows [*t0, *t1] of the ray to where the spot's image may tint it (its non-black texels'
 * pyramid, atmos__lamp's box, with a margin for rounding): outside, the tint is 0. Returns 0
 * when no part is left. */
int atmos__beams_ray_tint_span(const atmos__beams_ray *r, double *t0, double *t1);

/* The plan's kept buffers (struct atmos__beams_plan's kept). */
enum {
    ATMOS__BEAMS_KEPT_PRIMARY, /* two: the mesh and the triangle arrays */
    ATMOS__BEAMS_KEPT_OBJECT = ATMOS__BEAMS_KEPT_PRIMARY + 2,
    ATMOS__BEAMS_KEPT_DEPTH,
    ATMOS__BEAMS_KEPT_BASE,
    ATMOS__BEAMS_KEPT_NODE,
    ATMOS__BEAMS_KEPT_DIR,
    ATMOS__BEAMS_KEPT_HIDDEN, /* the sky behind's mask (sky_behind) */
    ATMOS__BEAMS_KEPT_NODE_X, /* the lattice's columns and rows, its nodes' masks (subsampled) */
    ATMOS__BEAMS_KEPT_NODE_Y,
    ATMOS__BEAMS_KEPT_SEEN,
    ATMOS__BEAMS_KEPT_COUNT
};

struct atmos__beams_plan {
    atmos__objects obj;                      /* the meshes and their albedos */
    int nlights;
    atmos__beams_light *lights;
    double sigma_t, sigma_s;                 /* 0 without fog */
    atmos__beams_table table;
    atmos__beams_fog fog;                    /* the fog along rays (beams_sun.h) */
    atmos__fog_optics optics;                /* the fog's coefficients and phase function */
    int sun_on;                              /* the sun lights the scene (beams/sun) */
    int exact_shadows;                       /* surfaces' shadows of the lights by exact rays alone */
    atmos__beams_sun sun;                    /* its map, built for the last frame's sun (sun.dir) */
    atmos__beams_epi epi;                    /* the map's epipolar lines from the last frame's eye */
    atmos__beams_sky sky;                    /* the sky's light on the objects, kept between frames */
    /* the last frame, along the ray through the image's centre: Dobashi Fig. 5's counts */
    int centre_planes, centre_subplanes;
    /* the last frame's pixels, and how many of them had their airlight evaluated (the others
     * interpolated: beams/screen_step, beams_screen.h; evaluations counted again where two bands meet,
     * and in each of a frame's two layers, the spots' and the other lights', when it has both) */
    long air_pixels, air_evaluated;
    long air_shared; /* of the evaluated, those handed their cell's corners' agreement (beams_screen.h) */
    long air_unread; /* the stretches of their rays taken within a run of agreed ones, no W looked up */
    long air_told;   /* the stretches a merged sample told lit or dark to the cells around (merged) */
    /* a frame's per-pixel buffers, kept for the next frame (beams_kept.h): the primary
     * visibility's two, then the subsampled frame's (beams_render.c) */
    atmos__beams_kept kept[ATMOS__BEAMS_KEPT_COUNT];
};

/* The sun for a frame (beams_plan.c): its light at the eye, its shadow map (made again when
 * the sun has moved). */
atmos_status atmos__beams_sun_frame(atmos_plan *p, const atmos__view *v);


#endif
