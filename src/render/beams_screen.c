/* Screen-space adaptive subsampling of the airlight (beams_screen.h). */
#include "render/beams_screen.h"
#include "core/clones.h"
#include "core/vec.h"

#include <math.h>

/* One band being filled: the screen, the thread's scratch, the band's pixels and their state. */
typedef struct band {
    const atmos__beams_screen *s;
    double *scratch;
    int y0, w;       /* the band's first row, its width (the screen's) */
    double *out;
    unsigned char *state;
    uint64_t *seen; /* per pixel: what its evaluation saw (atmos__beams_air_fn), two masks */
    long evaluated, shared;
} band;

static size_t at(const band *b, int x, int y) { return (size_t)(y - b->y0) * b->w + (size_t)(x - b->s->r.x0); }
static size_t pix(const atmos__beams_screen *s, int x, int y)
{
    return (size_t)(y - s->r.y0) * (size_t)(s->r.x1 - s->r.x0) + (size_t)(x - s->r.x0);
}

int atmos__beams_screen_nodes(int a, int b, int k, int *X)
{
    int n = 0;
    for (int x = a; x < b; x += k) X[n++] = x;
    if (n && X[n - 1] != b - 1) X[n++] = b - 1;
    return n;
}

/* Pixel (x, y) evaluated, unless it was; known (NULL: none): what the corners of the cell it
 * lies in agree on (corners()). */
static void eval(band *b, int x, int y, const uint64_t *known)
{
    const size_t i = at(b, x, y);
    if (b->state[i] == 2) return;
    const atmos__beams_screen *s = b->s;
    s->air(s->user, b->scratch, x, y, s->T[pix(s, x, y)], known, b->seen + 2 * i, b->out + i * s->nw);
    b->state[i] = 2, b->evaluated++, b->shared += known != NULL;
}

/* What the four corners of the cell [x0, x1] x [y0, y1] (evaluated) all saw, into known; NULL
 * when the cell is too large to share it (s->share) or they agree on nothing. */
static const uint64_t *corners(const band *b, int x0, int y0, int x1, int y1, uint64_t known[2])
{
    if (x1 - x0 > b->s->share || y1 - y0 > b->s->share) return NULL;
    const uint64_t *c[4] = {b->seen + 2 * at(b, x0, y0), b->seen + 2 * at(b, x1, y0), b->seen + 2 * at(b, x0, y1),
                            b->seen + 2 * at(b, x1, y1)};
    for (int m = 0; m < 2; m++) known[m] = c[0][m] & c[1][m] & c[2][m] & c[3][m];
    return known[0] | known[1] ? known : NULL;
}

/* dim[k]: the least of base[i nw + k] over the pixels i of [x0, x1] x [y0, y1] (each row's
 * values one block; the minima exact, so the same values in the AVX2 clone). */
ATMOS_CLONES_NOINLINE static void least_base(const atmos__beams_screen *s, int x0, int y0, int x1, int y1, double *dim)
{
    const int nw = s->nw, n = (x1 - x0 + 1) * nw;
    for (int k = 0; k < nw; k++) dim[k] = INFINITY;
    for (int y = y0; y <= y1; y++) {
        const float *row = s->base + pix(s, x0, y) * nw;
        for (int j = 0; j < n; j += nw)
            for (int k = 0; k < nw; k++) dim[k] = atmos__mind(row[j + k], dim[k]);
    }
}

/* Whether every pixel of [x0, x1] x [y0, y1] sees the same object at depths within the ratio
 * 1 + s->depth of each other (or all the sky). */
ATMOS_CLONE_HELPER int same_surface(const atmos__beams_screen *s, int x0, int y0, int x1, int y1)
{
    const int m = s->object[pix(s, x0, y0)];
    double lo = INFINITY, hi = 0;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            const size_t i = pix(s, x, y);
            if (s->object[i] != m) return 0;
            lo = atmos__mind(s->T[i], lo), hi = atmos__maxd(s->T[i], hi); /* fmin, fmax: no NaN here */
        }
    return isinf(lo) || hi <= lo * (1 + s->depth);
}

/* Whether row y of span sp holds [x0 - m, x1 + m] (or to the region's edge). */
static int holds(const atmos__beams_screen *s, const int *sp, int y, int x0, int x1, int m)
{
    const int lo = sp[2 * y], hi = sp[2 * y + 1];
    return (lo <= x0 - m || lo <= s->r.x0) && (hi > x1 + m || hi >= s->r.x1);
}

/* Whether a light's span touches the cell [x0, x1] x [y0, y1] without holding its corners'
 * rows a cell's width beyond it on either side (beams_screen.h): then its beam may lie between
 * the corners (a span is wider than its beam by a pixel or two each side), or its edge cross the
 * cell. A span wider than s->wide cells' widths in every row of the cell is left out: its beam's
 * screen image is convex, so it cannot hide between the corners, and its edge across the cell
 * leaves a corner or a tested point on each side, for the tests of agree() to find (a row where
 * the span ends or is empty counts as narrow: its tip or its end may be in the cell). */
static int crossed(const atmos__beams_screen *s, int x0, int y0, int x1, int y1)
{
    const int m = x1 - x0 > y1 - y0 ? x1 - x0 : y1 - y0;
    for (int i = 0; i < s->nspan; i++) {
        if (!(s->span_mask >> i & 1)) continue;
        const int *sp = s->span + 2 * (size_t)i * s->span_h;
        if (holds(s, sp, y0, x0, x1, m) && holds(s, sp, y1, x0, x1, m)) continue; /* well inside */
        int touches = 0, narrow = !(s->wide > 0);
        for (int y = y0; y <= y1; y++) {
            touches |= sp[2 * y] <= x1 && sp[2 * y + 1] > x0 && sp[2 * y + 1] > sp[2 * y];
            narrow |= sp[2 * y + 1] - sp[2 * y] < s->wide * m;
        }
        if (touches && narrow) return 1;
    }
    return 0;
}

/* Whether any light's span touches the cell [x0, x1] x [y0, y1] (its airlight may be other than 0). */
static int touched(const atmos__beams_screen *s, int x0, int y0, int x1, int y1)
{
    for (int i = 0; i < s->nspan; i++) {
        if (!(s->span_mask >> i & 1)) continue;
        const int *sp = s->span + 2 * (size_t)i * s->span_h;
        for (int y = y0; y <= y1; y++)
            if (sp[2 * y] <= x1 && sp[2 * y + 1] > x0 && sp[2 * y + 1] > sp[2 * y]) return 1;
    }
    return 0;
}

/* The bilinear weights of (x, y) in the cell [x0, x1] x [y0, y1]. */
static void weights(int x0, int y0, int x1, int y1, int x, int y, double w[4])
{
    const double u = x1 > x0 ? (double)(x - x0) / (x1 - x0) : 0, v = y1 > y0 ? (double)(y - y0) / (y1 - y0) : 0;
    w[0] = (1 - u) * (1 - v), w[1] = u * (1 - v), w[2] = (1 - u) * v, w[3] = u * v;
}

/* agree()'s test with dim[k] the least light without the airlight of the cell's pixels: the
 * corners c's spread and each point cm[j] (weights w[j]) against their interpolation, within
 * s->spread and curve of the least light a pixel of the cell may have. A dim[k] lower than the
 * cell's least passes only where that passes (the sums and products below are monotone in it),
 * a higher one fails only where that fails. */
ATMOS_CLONE_HELPER int within(const atmos__beams_screen *s, const double *const c[4], const double *const *cm,
                              const double (*w)[4], int np, double curve, const double *dim)
{
    for (int k = 0; k < s->nw; k++) {
        const double lo = atmos__mind(atmos__mind(c[0][k], c[1][k]), atmos__mind(c[2][k], c[3][k]));
        const double hi = atmos__maxd(atmos__maxd(c[0][k], c[1][k]), atmos__maxd(c[2][k], c[3][k]));
        const double scale = lo + dim[k]; /* the least light a pixel of the cell may have */
        if (!(hi - lo <= s->spread * scale)) return 0;
        for (int j = 0; j < np; j++) {
            const double mid = w[j][0] * c[0][k] + w[j][1] * c[1][k] + w[j][2] * c[2][k] + w[j][3] * c[3][k];
            if (!(fabs(cm[j][k] - mid) <= curve * scale)) return 0;
        }
    }
    return 1;
}

/* Whether the cell's corners c agree (beams_screen.h), and each of its points (px[j], py[j]),
 * j < np, evaluated, lies within curve of the light it may have of their interpolation. The
 * least light without the airlight over the cell's pixels (least_base) is read only where two
 * bounds of it do not settle the test: 0 below (that light is never negative: albedos within
 * [0, 1], the lights' and the sky's light not negative), the least of the four corners' above
 * (they are pixels of the cell); the same answer as the least itself gives. An AVX2 clone where
 * the processor has it (same_surface and within inlined into it: the same IEEE operations, the
 * same answers). */
ATMOS_CLONES static int agree(const band *b, const double *c[4], int x0, int y0, int x1, int y1, const int *px,
                              const int *py, int np, double curve)
{
    const atmos__beams_screen *s = b->s;
    const int nw = s->nw;
    double dim[ATMOS__BEAMS_SCREEN_MAX_NW], w[5][4];
    const double *cm[5];
    if (!same_surface(s, x0, y0, x1, y1)) return 0;
    for (int j = 0; j < np; j++) {
        weights(x0, y0, x1, y1, px[j], py[j], w[j]);
        cm[j] = b->out + at(b, px[j], py[j]) * nw;
    }
    for (int k = 0; k < nw; k++) dim[k] = 0;
    if (within(s, c, cm, (const double (*)[4])w, np, curve, dim)) return 1;
    const float *q[4] = {s->base + pix(s, x0, y0) * nw, s->base + pix(s, x1, y0) * nw, s->base + pix(s, x0, y1) * nw,
                         s->base + pix(s, x1, y1) * nw};
    for (int k = 0; k < nw; k++) /* the corners' least, as least_base takes it */
        dim[k] = atmos__mind(q[3][k], atmos__mind(q[2][k], atmos__mind(q[1][k], atmos__mind(q[0][k], INFINITY))));
    if (!within(s, c, cm, (const double (*)[4])w, np, curve, dim)) return 0;
    least_base(s, x0, y0, x1, y1, dim);
    return within(s, c, cm, (const double (*)[4])w, np, curve, dim);
}

/* fill()'s pixels with nw wavelengths (inlined into fill: a constant nw unrolls the loop over
 * them). The band's fields are read once: the state's byte stores may alias them. */
ATMOS_CLONE_HELPER void fill_nw(const band *b, int x0, int y0, int x1, int y1, const int nw)
{
    double *const out = b->out;
    unsigned char *const state = b->state;
    const size_t bw = (size_t)b->w;
    const int by0 = b->y0, rx0 = b->s->r.x0;
    const double *c[4] = {out + at(b, x0, y0) * nw, out + at(b, x1, y0) * nw, out + at(b, x0, y1) * nw,
                          out + at(b, x1, y1) * nw};
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            const size_t i = (size_t)(y - by0) * bw + (size_t)(x - rx0); /* at(b, x, y) */
            if (state[i]) continue;
            double w[4];
            weights(x0, y0, x1, y1, x, y, w);
#pragma omp simd /* the corners are evaluated (state set): pixel i is none of them */
            for (int k = 0; k < nw; k++)
                out[i * nw + k] = w[0] * c[0][k] + w[1] * c[1][k] + w[2] * c[2][k] + w[3] * c[3][k];
            state[i] = 1;
        }
}

/* The cell [x0, x1] x [y0, y1], its corners c evaluated, filled by bilinear interpolation
 * (the pixels not evaluated; the wavelengths in one loop, vectorised in the AVX2 clone, and
 * unrolled for three, the rgb mode's, and 16, the spectral mode's: the same bits). */
ATMOS_CLONES_NOINLINE static void fill(band *b, int x0, int y0, int x1, int y1)
{
    if (b->s->nw == 3)
        fill_nw(b, x0, y0, x1, y1, 3);
    else if (b->s->nw == 16)
        fill_nw(b, x0, y0, x1, y1, 16);
    else
        fill_nw(b, x0, y0, x1, y1, b->s->nw);
}

/* The cell [x0, x1] x [y0, y1], its corners evaluated: interpolated, or cut into four. A cell
 * wider or taller than 4 evaluates the nine points of its quarters' corners and, when each of
 * the five new ones agrees with the corners' interpolation (and no light's span crosses it), is
 * filled quarter by quarter from those: the quarters' centres are not evaluated (a lattice of 8
 * thus costs half the nodes of one of 4 where the airlight is smooth over 8 pixels). */
static void cell(band *b, int x0, int y0, int x1, int y1)
{
    const atmos__beams_screen *s = b->s;
    const int nw = s->nw, xm = (x0 + x1) / 2, ym = (y0 + y1) / 2, big = x1 - x0 > 2 || y1 - y0 > 2;
    const int large = x1 - x0 > 4 || y1 - y0 > 4;
    if (x1 - x0 <= 1 && y1 - y0 <= 1) return; /* every pixel a corner */
    const double *c[4] = {b->out + at(b, x0, y0) * nw, b->out + at(b, x1, y0) * nw, b->out + at(b, x0, y1) * nw,
                          b->out + at(b, x1, y1) * nw};
    const int px[3] = {x0, xm, x1}, py[3] = {y0, ym, y1};
    uint64_t agreed[2];
    const uint64_t *known = corners(b, x0, y0, x1, y1, agreed);
    if (s->bound && s->span && !touched(s, x0, y0, x1, y1)) { /* its corners 0, and every pixel */
        fill(b, x0, y0, x1, y1);
        return;
    }
    const int cut = crossed(s, x0, y0, x1, y1);
    if (large) {
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 3; i++) eval(b, px[i], py[j], known);
        const int mx[5] = {xm, xm, xm, x0, x1}, my[5] = {ym, y0, y1, ym, ym}; /* the centre, the edges' midpoints */
        if (!cut && agree(b, c, x0, y0, x1, y1, mx, my, 5, 0.5 * s->curve)) {
            for (int j = 0; j < 2; j++)
                for (int i = 0; i < 2; i++) fill(b, px[i], py[j], px[i + 1], py[j + 1]);
            return;
        }
    } else {
        if (big) eval(b, xm, ym, known);
        if (!cut && agree(b, c, x0, y0, x1, y1, &xm, &ym, big, s->curve)) {
            fill(b, x0, y0, x1, y1);
            return;
        }
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 3; i++) eval(b, px[i], py[j], known);
    }
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++)
            if (px[i + 1] > px[i] || py[j + 1] > py[j]) cell(b, px[i], py[j], px[i + 1], py[j + 1]);
}

long atmos__beams_screen_band(const atmos__beams_screen *s, double *scratch, const int *X, int nx, int y0, int y1,
                              double *out, unsigned char *state, uint64_t *seen, long *shared)
{
    band b = {s, scratch, y0, s->r.x1 - s->r.x0, out, state, seen, 0, 0};
    for (int i = 0; i + 1 < nx; i++) cell(&b, X[i], y0, X[i + 1], y1);
    if (nx == 1 && y1 > y0) cell(&b, X[0], y0, X[0], y1); /* a single column */
    *shared += b.shared;
    return b.evaluated;
}
