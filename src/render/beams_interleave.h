/* Interleaved sampling for the beam renderer (Keller and Heidrich 2001, "Interleaved
 * Sampling", Eurographics Workshop on Rendering): the pixels of each N x N block sample the
 * light between the planes at N^2 different offsets, and a discontinuity filter averages the
 * airlight over the N x N pixels round each pixel that see the same object at a similar
 * depth, so every pixel gets N^2 offsets' worth of samples for the cost of one (and the
 * image is blurred by as much: docs/beams.md measures both). Not part of the API. */
#ifndef ATMOS_BEAMS_INTERLEAVE_H
#define ATMOS_BEAMS_INTERLEAVE_H

#include "render/view.h"

/* The airlight of a frame's pixels and what they see, over the rectangle `e` (the frame's
 * rectangle widened by the filter's reach, clipped to the image). */
typedef struct atmos__beams_il {
    int n;              /* N: the block's side */
    int nw;             /* values per pixel */
    atmos__rect e;      /* the pixels held */
    float *air;         /* the lights' airlight, nw per pixel, row-major over e */
    float *depth;       /* the distance to the surface seen, INFINITY for none */
    int *object;        /* the object seen, -1 for none */
} atmos__beams_il;

/* Room for the rectangle r of a width x height image widened by N - 1; 0 or ATMOS_E_NOMEM. */
int atmos__beams_il_init(atmos__beams_il *il, int n, int nw, const atmos__rect *r, int width, int height);
void atmos__beams_il_free(atmos__beams_il *il);

/* The offset in (0, 1) at which pixel (x, y) samples within each part between two planes. */
double atmos__beams_il_offset(int n, int x, int y);

/* Pixel (x, y)'s index in the held rectangle, or -1 outside it. */
long atmos__beams_il_index(const atmos__beams_il *il, int x, int y);

/* The filtered airlight of pixel (x, y) of the frame's rectangle, added to px[0 .. nw). */
void atmos__beams_il_add(const atmos__beams_il *il, int x, int y, float *px);

#endif
