/* Internals of the slice renderer (src/render/slice.c, slice_pass.c): the render grid,
 * the optics tables, the per-frame job and the two passes. Not part of the API. */
#ifndef ATMOS_RENDER_SLICE_INTERNAL_H
#define ATMOS_RENDER_SLICE_INTERNAL_H

#include "core/internal.h"

#include "render/slice_grid.h"
#include "render/slice_tables.h"

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
