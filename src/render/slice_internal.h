/* Internals of the slice renderer (src/render/slice.c, slice_pass.c): the render grid,
 * the optics tables, the per-frame job and the two passes. Not part of the API. */
#ifndef ATMOS_RENDER_SLICE_INTERNAL_H
#define ATMOS_RENDER_SLICE_INTERNAL_H

#include "core/internal.h"

#define SLICE_OCC_B 4          /* occupancy block edge, render-grid voxels */
#define SLICE_F_ORDERS 256     /* F_n and S(n) tabulated at integer n = 0..SLICE_F_ORDERS */

/* The volume box-filtered onto a dense grid (integer factor f native voxels per
 * render voxel), fields interleaved per voxel, with one empty voxel of padding on
 * every side so that the trilinear interpolant falls to zero at the edges, and a
 * coarse occupancy grid (Riley §3.2's majorant idea: blocks that are exactly empty
 * are skipped without interpolating). */
typedef struct {
    int nf;
    int c[3];             /* render voxels per axis, padding included */
    float *v;             /* c0*c1*c2*nf */
    int ob[3];
    unsigned char *occ;   /* ob0*ob1*ob2 */
    float sc, off[3];     /* u = g * sc + off: grid-frame metres -> render-voxel coordinate */
    double box_lo[3], box_hi[3]; /* grid-frame metres where the interpolant may be nonzero */
} sgrid;

typedef struct {
    int n;                     /* wavelengths */
    int nf;                    /* fields */
    float sig[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* sigma_ext, m^2 */
    float sca[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* albedo * sigma_ext */
    int no;                    /* Ams orders tabulated: 1..no */
    int ng[ATMOS_VOLUME_MAX_FIELDS];
    const double *grid[ATMOS_VOLUME_MAX_FIELDS];  /* theta, degrees */
    float *ams[ATMOS_VOLUME_MAX_FIELDS];          /* [(a * no + (order - 1)) * n + k]: the wavelengths of
                                                     an angle and order side by side, so that the
                                                     bilinear taps of all wavelengths of a sample
                                                     fall in two cache lines */
    float *F[ATMOS_VOLUME_MAX_FIELDS];            /* [k * (SLICE_F_ORDERS+1) + n]: F_n (Eq. 23) */
    float *S[ATMOS_VOLUME_MAX_FIELDS];            /* same layout: S(n) = sum_{i<=n} ln F_i */
} stables;

/* Pixels x0..x1 of one image row, or texels of one light-buffer row, that a slice
 * touches (x0 > x1: none). */
typedef struct {
    int x0, x1;
} sspan;

typedef struct {
    int n, nf;
    int W, H, L;                 /* eye buffer (the image, or smaller: eye_scale), light buffer side */
    double sx, sy;               /* image pixels per eye-buffer pixel (1 = the image is the eye buffer) */
    int nslices;
    int btf;                     /* back-to-front */
    int low_albedo, eq24;
    float xi;
    double h[3], lt[3], e1[3], e2[3]; /* half vector, light propagation, light basis */
    double s0, ds;               /* slice planes s_k = s0 + (k + 0.5) ds along h */
    double eye[3], he;           /* eye in grid frame, h . eye */
    double u0, v0, du, dv;       /* light buffer: texel (a, b) centre at u0 + (a+0.5) du, ... */
    double hl;                   /* h . lt */
    const sgrid *g;
    const stables *t;
    /* Per pixel. Slice planes are parallel, so the point where a pixel's ray meets
     * slice k is linear in k: render-voxel coordinate U0 + k dU, light-buffer
     * coordinate (texel units, centres at integers) F0 + k dF. */
    float *pU0[3], *pdU[3], *pF0[2], *pdF[2];
    float *pdelta;               /* eye-ray length of a slab */
    float *pinv;                 /* 1 / (h . d) */
    int *pk0, *pk1;              /* slices the ray crosses inside the box */
    int *pa;                     /* [pix * nf + f] Ams angle row offset (a * no * n) */
    float *pw;                   /* [pix * nf + f] weight of the next angle */
    float *L_eye, *T_eye;        /* [c * pst + pix] (pst: plane stride >= npix) */
    size_t pst;
    float *pixblock;             /* owns all the per-pixel planes */
    /* Per light texel; render-voxel coordinate of texel (a, b) on slice k:
     * lA + a lEa + b lEb + k lEk. */
    int *lk0, *lk1;
    double lA[3], lEa[3], lEb[3], lEk[3];
    float ldelta;                /* light-ray length of a slab */
    /* The light ring (see render): batch + 1 slots of L*L texels, each I per wavelength
     * then n ([texel * (n + 1) + c]); nsc[s] = I[s] + n. */
    int batch;
    float *ring, **I, **nsc;
    /* Per slice: the pixels of each row and the texels of each light row whose
     * samples may fall in occupied blocks ([k * H + y], [k * L + b]). */
    sspan *espan, *lspan, *wspan; /* wspan: union of the light spans of slices k - batch..k */
    /* Their union over the slices, per image row and per light row: the only pixels
     * and texels the render reads or writes (the rest keep the sky / are never read). */
    sspan *erow, *lrow;
} sjob;

/* Eye pass of slice k over pixels x0..x1 of image row y (Eq. 26); light pass of slice k
 * over texels x0..x1 of light row b (Eq. 21, 25 / 24) where texels a0..a1 may meet
 * occupied blocks (the others of x0..x1 are copied from the arriving buffer). Each
 * returns the samples that fell in occupied blocks. Ib/nb (Ic/nc) are the light
 * arriving at slice k, In/nn the light leaving it. The fast versions process a span
 * in chunks of structure-of-arrays samples with vectorisable loops and a polynomial
 * exp; the reference versions are the plain scalar loops with libm's expf/logf
 * (atmos_slice_settings.reference). Both write only their own pixels/texels. */
long long atmos__slice_eye_span(const sjob *j, int k, int y, int x0, int x1, const float *Ib, const float *nb);
long long atmos__slice_light_span(const sjob *j, int k, int b, int x0, int x1, int a0, int a1, const float *Ic,
                                  const float *nc, float *In, float *nn);
long long atmos__slice_eye_span_ref(const sjob *j, int k, int y, int x0, int x1, const float *Ib, const float *nb);
long long atmos__slice_light_span_ref(const sjob *j, int k, int b, int x0, int x1, int a0, int a1, const float *Ic,
                                      const float *nc, float *In, float *nn);

#endif
