/* Screen-space adaptive subsampling of the beam renderer's airlight (docs/beams.md,
 * *Subsampling the airlight*): the light the fog scatters toward the eye is evaluated on a
 * lattice of every k-th pixel, and each cell of the lattice is filled by bilinear
 * interpolation when its corners agree (the same object seen at similar depths by every pixel
 * of the cell, the corners' airlight within a share of the pixels' light of each other, and,
 * for a cell wider than 2, its centre evaluated and close to the interpolation); otherwise it
 * is cut into four and each part tried again, down to single pixels evaluated exactly; a cell
 * wider than 4 is tested on the nine corners of its quarters and, when they agree, filled
 * quarter by quarter from them (its quarters' centres not evaluated). A cell that a light's
 * span (the screen image of its lit cone) touches without holding its corners' rows a cell's
 * width beyond it on either side is always cut: a beam narrower than the cell, between its
 * corners, or an edge of a beam across it, is found without a node on it; unless the span is
 * many cells wide in every row of the cell (wide): the screen image of a beam is convex, so a
 * wide one cannot pass between the corners, and its edge leaves a tested point on each side
 * for the other tests to find (a row where the span ends counts as narrow). Where the airlight is
 * 0 outside the spans (no sun), a cell that no span touches is filled with its corners' zeros
 * without its tests (a dark cell across a silhouette is not cut). Each evaluation hands back
 * what it saw (two masks, the caller's meaning), and a pixel evaluated in a cut cell of at most
 * `share` pixels is handed what all four of the cell's corners saw alike. The surfaces' direct
 * light stays per pixel (the caller's). Not part of the API. */
#ifndef ATMOS_RENDER_BEAMS_SCREEN_H
#define ATMOS_RENDER_BEAMS_SCREEN_H

#include "render/view.h"
#include "atmos/spectrum.h"

#include <stdint.h>

/* The most values a pixel. */
#define ATMOS__BEAMS_SCREEN_MAX_NW ATMOS_MAX_WAVELENGTHS

/* The airlight of pixel (x, y), whose ray ends at depth T (INFINITY: none), into A[0 .. nw);
 * scratch is the calling thread's own buffer. known (NULL: none): what the corners of the cell
 * being cut agree on (the caller's meaning: bit j of known[0] / known[1], the stretch j of a
 * shared light's ray lit / dark in every corner), which the pixel may take rather than sample;
 * seen: the pixel's own, for the cells it is a corner of. */
typedef void (*atmos__beams_air_fn)(void *user, double *scratch, int x, int y, double T, const uint64_t *known,
                                    uint64_t seen[2], double *A);

typedef struct atmos__beams_screen {
    atmos__rect r;            /* the pixels */
    int k, nw;                /* the lattice's step (a power of two), the values a pixel */
    double spread;            /* the corners' airlight may differ by this share of their light */
    double curve;             /* a cell's centre may differ from the interpolation by this share */
    double depth;             /* the depths of a cell may differ by this ratio less 1 */
    const double *T;          /* per pixel of r, row by row: the distance to the surface seen */
    const int *object;        /* per pixel of r: the object seen, -1 for none */
    const float *base;        /* per pixel of r: its light without the airlight, nw values */
    /* The lit cones' hint: per light i < nspan and image row y, the columns
     * [span[2 (i span_h + y)], span[2 (i span_h + y) + 1]) outside which that light's airlight
     * is 0 (the screen image of a hull of its lit part, convex per row); NULL: none. */
    const int *span;
    int nspan, span_h;
    uint32_t span_mask;       /* the lights whose spans are hints here (light i: bit i) */
    int bound;                /* 1: the airlight is 0 outside those spans (no sun): a cell that no
                               * span touches is 0, filled without its tests */
    int wide;                 /* a span at least this many cells' widths wide in each of a cell's
                               * rows is not its hint there (0: every span) */
    int share;                /* a cell at most this many pixels wide and tall hands its corners'
                               * agreement (known) to the pixels evaluated in it (0: none) */
    atmos__beams_air_fn air;
    void *user;
} atmos__beams_screen;

/* The lattice's coordinates over [a, b): a, a + k, a + 2k, ... and b - 1, into X (room for
 * (b - a - 1) / k + 2); returns their count. */
int atmos__beams_screen_nodes(int a, int b, int k, int *X);

/* The airlight of a band of the image: the pixels [r.x0, r.x1) x [y0, y1] (y1 included) into
 * out (nw values a pixel, row by row over the band), of which the lattice's nodes on rows y0
 * and y1 (columns X[0 .. nx)) are given (state 2 there, 0 elsewhere, and their seen masks in
 * seen, two a pixel like out's values); each cell between them filled from left to right,
 * state 1 where interpolated, 2 where evaluated. Returns the pixels evaluated, of which those
 * handed their cell's corners' agreement (known) are added to *shared. */
long atmos__beams_screen_band(const atmos__beams_screen *s, double *scratch, const int *X, int nx, int y0, int y1,
                              double *out, unsigned char *state, uint64_t *seen, long *shared);

#endif
