/* The volume's edges in an image (edge_aa.c): the pixels whose one eye ray through the centre
 * misses or overstates their share of the volume, where a renderer takes four rays instead of
 * one. Shared by the slice renderer ("edge_aa", slice_edges.c) and the Nishita renderer
 * (nishita_render.c). Not part of the API. */
#ifndef ATMOS_RENDER_EDGE_AA_H
#define ATMOS_RENDER_EDGE_AA_H

#include "atmos/atmosphere.h"
#include "render/slice_grid.h"
#include "render/view.h"
#include "volume/volume_access.h"

#include <stddef.h>

typedef struct {
    const sgrid *g;              /* the render grid (the volume box-filtered, slice_grid.c) */
    const atmos__vol_xform *x;   /* its placement */
    const atmos_atmosphere *atm; /* the ground, which ends the rays */
    const atmos_camera *cam;
    double eye[3];               /* the eye in the grid's frame */
    float sig[ATMOS_VOLUME_MAX_FIELDS]; /* the plain cross-sections (the coverage seen), one wavelength */
    double lim;                  /* the transmittance step between neighbours that marks an edge */
    /* the pixels of image row y the volume can reach ([*x0, *x1]); NULL: the whole row */
    void (*row)(const void *ctx, int y, int *x0, int *x1);
    const void *row_ctx;
} atmos__edge_desc;

/* The edge flags of the pixels in r (1: an edge; indexed y * width + x over the whole image,
 * in *buf, grown to width * height * 5 bytes): a pixel is an edge when the volume's
 * transmittance along its centre ray, exp(-tau), differs by more than d->lim from that of one
 * of its eight neighbours. The transmittances are taken over r and a pixel around it, so the
 * flags depend only on the view, not on the region rendered or the thread count. NULL if out
 * of memory. */
const unsigned char *atmos__edge_flags(const atmos__edge_desc *d, const atmos__rect *r, unsigned char **buf,
                                       size_t *cap, int threads);

#endif
