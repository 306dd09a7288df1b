/* The sun's map along epipolar lines (beams_epipolar.h): the lines' samples and 1-D min/max
 * trees, built once a frame, and a ray's walk down one line's tree. */
#include "render/beams_epipolar.h"
#include "render/beams_sun.h"
#include "core/clones.h"
#include "core/internal.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LEVELS 32
#define LEAF 4 /* segments a cell of the trees' finest level covers */

void atmos__beams_epi_free(atmos__beams_epi *e)
{
    free(e->at), free(e->m);
    memset(e, 0, sizeof *e);
}

/* The cells of a tree over nseg segments: level 0 holds ceil(nseg / LEAF) of them, each level
 * above half as many, rounded up, down to one. */
static size_t tree_cells(int nseg, int *levels)
{
    size_t total = 0;
    int l = 0;
    for (int c = (nseg + LEAF - 1) / LEAF; c > 0; c = c == 1 ? 0 : (c + 1) / 2) total += (size_t)c, l++;
    if (levels) *levels = l;
    return total;
}

/* Where the half-line from (ex, ey) at the angle of (c, sn) runs inside box: [*r0, *r1]
 * (empty when *r1 <= *r0). */
static void clip(const double box[4], double ex, double ey, double c, double sn, double *r0, double *r1)
{
    double a = 0, b = INFINITY;
    const double o[2] = {ex, ey}, v[2] = {c, sn};
    for (int k = 0; k < 2; k++) {
        const double lo = box[2 * k], hi = box[2 * k + 1];
        if (fabs(v[k]) < 1e-12) {
            if (o[k] < lo || o[k] > hi) b = -1;
            continue;
        }
        double t0 = (lo - o[k]) / v[k], t1 = (hi - o[k]) / v[k];
        if (t0 > t1) {
            const double x = t0;
            t0 = t1, t1 = x;
        }
        a = fmax(a, t0), b = fmin(b, t1);
    }
    *r0 = a, *r1 = b;
}

/* Samples i0 .. i0 + cnt - 1 (cnt <= CHUNK) of the line from (ex, ey) along (c, sn), first at k0
 * texels: the depth of the map at each sample's look-up coordinates, the four nearest texels'
 * depths blended when all four hold an object, else the nearest texel's; INFINITY beside the
 * map. Three steps, vectorised in the AVX2 clone: the coordinates, weights and the four texels'
 * indices; the loads, a loop for each of the four texels (hardware gathers with this file's
 * tuning, CMakeLists.txt); their blend or the nearest one (the same IEEE operations in the same order as one sample at a
 * time, and ISO C contracts no products: the same bits). */
#define CHUNK 128
#if defined(__GNUC__) && !defined(__clang__)
/* comparisons that cannot trap (no FP exception is enabled here): lets GCC if-convert the
 * loops' selects; the values are the same */
#  define NO_TRAPS __attribute__((optimize("no-trapping-math")))
#else
#  define NO_TRAPS
#endif
ATMOS_CLONES_NOINLINE NO_TRAPS static void samples(const atmos__beams_sun *s, double ex, double ey, double c, double sn, int k0,
                                          int i0, int cnt, float *restrict out)
{
    const int n = s->n;
    double ax[CHUNK], ay[CHUNK];
    int at[4][CHUNK], in[CHUNK];
    float d[4][CHUNK];
#pragma omp simd
    for (int i = 0; i < cnt; i++) {
        const double r = k0 + i0 + i, fx0 = ex + r * c, fy0 = ey + r * sn;
        const int inside = (fx0 > -1) & (fx0 < n) & (fy0 > -1) & (fy0 < n);
        const double fx = inside ? fx0 : 0, fy = inside ? fy0 : 0;
        const int x0 = (int)(fx + 1) - 1, y0 = (int)(fy + 1) - 1;
        ax[i] = fx - x0, ay[i] = fy - y0, in[i] = inside;
        const int xa = x0 < 0 ? 0 : x0, xb = x0 + 1 > n - 1 ? n - 1 : x0 + 1;
        const int ya = (y0 < 0 ? 0 : y0) * n, yb = (y0 + 1 > n - 1 ? n - 1 : y0 + 1) * n; /* n <= 8192 (shadow_size): n^2 < 2^31 */
        at[0][i] = ya + xa, at[1][i] = ya + xb, at[2][i] = yb + xa, at[3][i] = yb + xb;
    }
    const float *restrict depth = s->depth;
    for (int q = 0; q < 4; q++) {
        const int *restrict a = at[q];
        float *restrict dq = d[q];
#pragma omp simd
        for (int i = 0; i < cnt; i++) dq[i] = depth[a[i]];
    }
#pragma omp simd
    for (int i = 0; i < cnt; i++) {
        const float d00 = d[0][i], d01 = d[1][i], d10 = d[2][i], d11 = d[3][i];
        const double bx = ax[i], by = ay[i];
        const float blend = (float)((1 - by) * ((1 - bx) * d00 + bx * d01) + by * ((1 - bx) * d10 + bx * d11));
        const float top = bx < 0.5 ? d00 : d01, bottom = bx < 0.5 ? d10 : d11, near = by < 0.5 ? top : bottom;
        const int all = (d00 < INFINITY) & (d01 < INFINITY) & (d10 < INFINITY) & (d11 < INFINITY);
        out[i] = !in[i] ? INFINITY : all ? blend : near;
    }
}

/* Line j's samples and its tree; built for AVX2 as well (the same operations, the same bits). */
ATMOS_CLONES static void fill(atmos__beams_epi *e, const atmos__beams_sun *s, int j)
{
    const double th = j * e->dth, c = cos(th), sn = sin(th);
    const int cnt = e->cnt[j], k0 = e->k0[j];
    float *m = e->m + e->at[j], *lh = e->lh + 2 * e->tat[j]; /* a cell's least depth, then its greatest */
    for (int i = 0; i < cnt; i += CHUNK) samples(s, e->ex, e->ey, c, sn, k0, i, cnt - i < CHUNK ? cnt - i : CHUNK, m + i);
    const int nseg = cnt - 1;
    int c0 = (nseg + LEAF - 1) / LEAF;
    const int whole = nseg / LEAF; /* the cells of LEAF segments each: unrolled, in the same order */
    for (int i = 0; i < whole; i++) {
        const float *mi = m + LEAF * i;
        float lo = mi[0], hi = lo;
        for (int k = 1; k <= LEAF; k++) lo = mi[k] < lo ? mi[k] : lo, hi = mi[k] > hi ? mi[k] : hi;
        lh[2 * i] = lo, lh[2 * i + 1] = hi;
    }
    for (int i = whole; i < c0; i++) {
        float lo = m[LEAF * i], hi = lo;
        for (int k = LEAF * i + 1; k <= LEAF * (i + 1) && k <= nseg; k++) lo = m[k] < lo ? m[k] : lo, hi = m[k] > hi ? m[k] : hi;
        lh[2 * i] = lo, lh[2 * i + 1] = hi;
    }
    for (; c0 > 1; c0 = (c0 + 1) / 2) {
        float *nlh = lh + 2 * c0;
        for (int i = 0; 2 * i < c0; i++) {
            const float *a = lh + 4 * i, *b = 2 * i + 1 < c0 ? a + 2 : a;
            nlh[2 * i] = a[0] < b[0] ? a[0] : b[0], nlh[2 * i + 1] = a[1] < b[1] ? b[1] : a[1];
        }
        lh = nlh;
    }
}

/* The block *p of at least want elements of size each (its capacity *cap): 0, or -1 out of memory.
 * Made again only when it must grow, then by an eighth more and to its whole pages: the lines'
 * count changes as the eye moves, and each block made anew faults its pages in again (about 2 ms
 * a 2 MB page here, docs/beams.md *Fifty-fourth round*). */
static int reserve(void **p, size_t *cap, size_t want, size_t size)
{
    if (want <= *cap) return 0;
    free(*p);
    const size_t bytes = atmos__big_size(size * (want + want / 8));
    *cap = 0;
    if (!(*p = atmos__big_alloc(bytes))) return -1; /* on 2 MB pages where large */
    *cap = bytes / size;
    return 0;
}

int atmos__beams_epi_build(atmos__beams_epi *e, const atmos__beams_sun *s, const double eye[3], size_t max_samples,
                           int threads)
{
    if (!s->n) {
        e->lines = 0;
        return 0;
    }
    const double ex = (atmos__dot3(eye, s->right) - s->u0) / s->texel - 0.5;
    const double ey = (atmos__dot3(eye, s->up) - s->v0) / s->texel - 0.5;
    if (e->lines && e->sun == s && e->gen == s->gen && e->ex == ex && e->ey == ey && e->max_samples == max_samples)
        return 0; /* the same lines */
    e->lines = 0, e->ex = ex, e->ey = ey, e->sun = s, e->gen = s->gen, e->max_samples = max_samples;
    double R = 1;
    for (int k = 0; k < 4; k++) R = fmax(R, hypot(s->box[k & 1] - e->ex, s->box[2 + (k >> 1)] - e->ey));
    const double lines = ceil(2 * ATMOS_PI * R);
    if (lines > 1 << 20) return 0;
    const int L = (int)lines < 8 ? 8 : (int)lines;
    if (reserve((void **)&e->at, &e->cap_lines, (2 * sizeof(size_t) + 2 * sizeof(int)) * (size_t)L, 1)) {
        atmos__beams_epi_free(e);
        return -1;
    }
    e->tat = e->at + L, e->k0 = (int *)(e->tat + L), e->cnt = e->k0 + L;
    e->dth = 2 * ATMOS_PI / L;
    size_t samples = 0, cells = 0;
    for (int j = 0; j < L; j++) {
        double r0, r1;
        clip(s->box, e->ex, e->ey, cos(j * e->dth), sin(j * e->dth), &r0, &r1);
        e->k0[j] = r1 > r0 ? (int)floor(r0) : 0;
        e->cnt[j] = r1 > r0 ? (int)ceil(r1) - e->k0[j] + 1 : 0;
        e->at[j] = samples, e->tat[j] = cells;
        samples += (size_t)e->cnt[j], cells += tree_cells(e->cnt[j] - 1, NULL);
    }
    if (samples > max_samples) return 0;
    if (reserve((void **)&e->m, &e->cap_floats, samples + 2 * cells + 1, sizeof(float))) {
        atmos__beams_epi_free(e);
        return -1;
    }
    e->lh = e->m + samples;
    e->lines = L;
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads > 0 ? threads : 1)
    for (int j = 0; j < L; j++) fill(e, s, j);
    return 0;
}

/* A walk down one line: the ray's range [r0, r1] and depth zc + r zs, the stretch being gathered. */
typedef struct walk {
    const float *m, *lh;
    size_t off[MAX_LEVELS];
    double k0, zc, zs, r0, r1, a, b;
    int open;
    void (*lit)(void *u, double ra, double rb);
    void *u;
} walk;

ATMOS_CLONE_HELPER void add(walk *w, double ra, double rb)
{
    if (w->open && ra <= w->b) {
        w->b = rb;
        return;
    }
    if (w->open) w->lit(w->u, w->a, w->b);
    w->a = ra, w->b = rb, w->open = 1;
}

/* [ra, rb] where the map's depth runs linearly from da to db (finite): lit up to or from where
 * the ray's depth crosses it. */
ATMOS_CLONE_HELPER void linear(walk *w, double ra, double rb, double da, double db)
{
    const double fa = da - (w->zc + ra * w->zs), fb = db - (w->zc + rb * w->zs);
    if (fa > 0 && fb > 0) add(w, ra, rb);
    else if (fa > 0) add(w, ra, ra + (rb - ra) * fa / (fa - fb));
    else if (fb > 0) add(w, ra + (rb - ra) * fa / (fa - fb), rb);
}

/* Segment i (samples i and i + 1) over [ra, rb]: the depth linear between the samples; where a
 * sample holds no object, each sample's depth over its nearer half. */
ATMOS_CLONE_HELPER void leaf(walk *w, int i, double ra, double rb)
{
    const double mi = w->m[i], mj = w->m[i + 1], ri = w->k0 + i;
    if (mi < INFINITY && mj < INFINITY) {
        linear(w, ra, rb, mi + (ra - ri) * (mj - mi), mi + (rb - ri) * (mj - mi));
        return;
    }
    const double half = ri + 0.5;
    if (ra < half) {
        const double b = fmin(rb, half);
        if (mi < INFINITY) linear(w, ra, b, mi, mi);
        else add(w, ra, b);
    }
    if (rb > half) {
        const double a = fmax(ra, half);
        if (mj < INFINITY) linear(w, a, rb, mj, mj);
        else add(w, a, rb);
    }
}

ATMOS_CLONES static void node(walk *w, int l, int q, int nseg)
{
    const int s0 = (q << l) * LEAF, s1 = ((q + 1) << l) * LEAF < nseg ? ((q + 1) << l) * LEAF : nseg;
    const double a = w->k0 + s0, b = w->k0 + s1, ra = a > w->r0 ? a : w->r0, rb = b < w->r1 ? b : w->r1;
    if (!(ra < rb)) return;
    const double za = w->zc + ra * w->zs, zb = w->zc + rb * w->zs;
    const double zlo = za < zb ? za : zb, zhi = za < zb ? zb : za;
    const float lo = w->lh[2 * (w->off[l] + q)], hi = w->lh[2 * (w->off[l] + q) + 1];
    if (zhi < lo) add(w, ra, rb);
    else if (zlo >= hi) return;
    else if (l == 0)
        for (int i = s0; i < s1; i++) {
            const double u = w->k0 + i, v = u + 1;
            if (v > ra && u < rb) leaf(w, i, u > ra ? u : ra, v < rb ? v : rb);
        }
    else node(w, l - 1, 2 * q, nseg), node(w, l - 1, 2 * q + 1, nseg);
}

void atmos__beams_epi_walk(const atmos__beams_epi *e, int j, double zc, double zs, double rT,
                           void (*lit)(void *u, double ra, double rb), void *u)
{
    if (!(rT > 0)) return;
    const int nseg = e->cnt[j] - 1;
    walk w = {.m = e->m + e->at[j], .lh = e->lh + 2 * e->tat[j], .k0 = e->k0[j], .zc = zc, .zs = zs,
              .r0 = 0, .r1 = rT, .lit = lit, .u = u};
    if (nseg <= 0) {
        add(&w, 0, rT);
    } else {
        int levels;
        tree_cells(nseg, &levels);
        size_t off = 0;
        for (int l = 0, c = (nseg + LEAF - 1) / LEAF; l < levels; l++, c = (c + 1) / 2) w.off[l] = off, off += (size_t)c;
        if (w.k0 > 0) add(&w, 0, fmin(w.k0, rT));
        node(&w, levels - 1, 0, nseg);
        if (rT > w.k0 + nseg) add(&w, w.k0 + nseg, rT);
    }
    if (w.open) lit(u, w.a, w.b);
}
