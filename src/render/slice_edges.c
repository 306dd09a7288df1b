/* The slice renderer's edge pixels ("edge_aa"; docs/slice.md, "Antialiasing at the edges").
 *
 * The path tracer's samples spread over each pixel, the slice renderer's one eye ray goes
 * through its centre: where the volume's coverage changes within a pixel (its silhouette,
 * a thin fringe) the centre sample misses or overstates the pixel's share of the volume.
 * With eye_scale 2 every pixel takes four rays; edge_aa takes them only where they matter:
 * the pixels whose transmittance through the volume along the centre ray differs from one
 * of their eight neighbours' by more than edge_aa. The eye buffer is then twice the image per
 * axis, but the other pixels trace one ray through their centre, at eye pixel (2x, 2y), and
 * the three others are left out of the passes (their slice range empty). The flags: edge_aa.c,
 * shared with the Nishita renderer. */
#include "render/edge_aa.h"
#include "render/slice_internal.h"

int atmos__slice_edge_mode(const atmos__slice_plan *sp, const atmos__view *v)
{
    return sp->edge_aa > 0 && v->eye_scale == 1.0;
}

/* The eye spans' pixels of image row y (both eye rows of an image row; unclipped, so the flags
 * do not depend on the region rendered): the volume is zero along the others. */
static void span_row(const void *ctx, int y, int *x0, int *x1)
{
    const sjob *j = ctx;
    const sspan a = j->erow[2 * y], b = j->erow[2 * y + 1];
    *x0 = (a.x0 < b.x0 ? a.x0 : b.x0) / 2, *x1 = (a.x1 > b.x1 ? a.x1 : b.x1) / 2;
}

int atmos__slice_edges(atmos__slice_plan *sp, const atmos_atmosphere *atm, const atmos__view *v, sjob *j, int threads)
{
    atmos__edge_desc e = {&sp->g, &sp->x, atm, &v->cam, {j->eye[0], j->eye[1], j->eye[2]}, {0}, sp->edge_aa,
                          span_row, j};
    /* the plain cross-sections (not delta-M's): the coverage seen */
    for (int f = 0; f < sp->nf; f++) e.sig[f] = sp->tab.sig[f][sp->n / 2];
    const atmos__rect all = {0, 0, v->cam.width, v->cam.height};
    j->edge = atmos__edge_flags(&e, &all, &sp->edge, &sp->edge_cap, threads);
    return j->edge != NULL;
}
