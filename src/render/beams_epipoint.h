/* A point light's cube shadow map along epipolar lines (docs/beams.md, *Shadow maps* and the
 * nineteenth round under *Speed*): the rectification of Baran, Chen, Durand and Lehtinen 2010
 * ("A hierarchical volumetric shadow algorithm for single scattering") and Chen, Baran, Kavan
 * and Jensen 2011 ("Real-time volumetric shadows using 1D min-max mipmaps") for a point light,
 * on the CPU. Every eye ray o + t d lies in a half-plane through the axis from the light to the
 * eye; the half-planes at even angles psi_j round that axis are resampled from the cube map
 * once a frame. Within a half-plane, directions from the light are cut into three pieces of
 * 60 degrees, each sampled at even steps of its gnomonic coordinate q (tan of the angle from the
 * piece's centre), each sample the nearest object as -1/x (x its distance along the piece's
 * centre direction): a straight ray's -1/x is then linear in q, as a depth is along the sun's
 * lines, so a 1-D min/max tree per piece gives the ray's lit stretches in closed form
 * (beams_epipolar.h's walk). A ray blends the two half-planes round its own. Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_EPIPOINT_H
#define ATMOS_RENDER_BEAMS_EPIPOINT_H

#include <stddef.h>

typedef struct atmos__beams_light atmos__beams_light;

typedef struct atmos__beams_pl {
    int lines;            /* half-planes (0: none; the rays take the sub-planes) */
    int cnt;              /* samples a piece, at q = qmin + i dq */
    size_t cells;         /* a piece's tree cells */
    double e;             /* the eye's distance from the light */
    double a[3], e1[3], e2[3]; /* a: from the light toward the eye; half-plane j along cos psi e1 + sin psi e2 */
    double dpsi, qmin, dq;
    double eye[3];        /* the eye they were made from */
    float *m, *lh;        /* per half-plane and piece: cnt samples; its tree (2 cells' floats each) */
    size_t cap;           /* the block's floats */
} atmos__beams_pl;

/* The lines of the light l's cube map from the eye (kept when the eye has not moved): 0, or -1
 * out of memory; none (pl->lines 0) without a cube map or beyond max_samples. */
int atmos__beams_pl_build(atmos__beams_pl *pl, const atmos__beams_light *l, const double eye[3], size_t max_samples,
                          int threads);
void atmos__beams_pl_free(atmos__beams_pl *pl);

/* The lit stretches of the ray eye + t d (d a unit vector) over [t0, t1] along the two half-planes
 * round its own, passed to lit(u, ta, tb, weight) in increasing t for each, weighted by the
 * ray's nearness to each (the weights sum to 1: the visibility blended linearly across the
 * half-planes, as a filtered look-up blends across texels). Returns 0, or -1 when the lines
 * cannot tell (the ray along the axis): nothing is passed then. */
int atmos__beams_pl_walk(const atmos__beams_pl *pl, const double d[3], double t0, double t1,
                         void (*lit)(void *u, double ta, double tb, double weight), void *u);

#endif
