/* A point light's cube map along epipolar lines (beams_epipoint.h): the half-planes' samples and
 * trees, made once a frame, and a ray's lit stretches from one half-plane's three pieces. */
#include "render/beams_epipoint.h"
#include "render/beams_epipolar.h"
#include "render/beams_internal.h"
#include "core/internal.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PIECES 3
/* The steps in q and in psi, in texels of a cube face at its centre (2 / n radians): the
 * samples and the neighbouring half-planes at most a texel apart there (closer toward its edges). */
#ifndef PL_Q
#define PL_Q 1.0
#endif
#ifndef PL_PSI
#define PL_PSI 1.0
#endif
/* The ray taken as nearer the light than an object by this share of -1/x: its own surface
 * (the ray's end) is not its own shadow. */
#define PL_BIAS 1e-5

void atmos__beams_pl_free(atmos__beams_pl *pl)
{
    free(pl->m);
    memset(pl, 0, sizeof *pl);
}

/* Piece k's centre direction (cos c, sin c) in a half-plane: c = (2k + 1) pi / 6. */
static void centre(int k, double *c, double *s)
{
    const double a = (2 * k + 1) * ATMOS_PI / 6;
    *c = cos(a), *s = sin(a);
}

/* Half-plane j's piece k: its samples and its tree. */
static void fill(atmos__beams_pl *pl, const atmos__beams_light *l, int j, int k)
{
    const double psi = j * pl->dpsi, cp = cos(psi), sp = sin(psi);
    double b[3], u[3], v[3], cc, sc;
    centre(k, &cc, &sc);
    for (int i = 0; i < 3; i++) {
        b[i] = cp * pl->e1[i] + sp * pl->e2[i];
        u[i] = cc * pl->a[i] + sc * b[i], v[i] = -sc * pl->a[i] + cc * b[i];
    }
    float *m = pl->m + (size_t)(PIECES * j + k) * pl->cnt;
    for (int i = 0; i < pl->cnt; i++) {
        const double q = pl->qmin + i * pl->dq, w[3] = {u[0] + q * v[0], u[1] + q * v[1], u[2] + q * v[2]};
        m[i] = atmos__beams_shadow_inverse(l, w);
    }
    float *lh = pl->m + (size_t)pl->lines * PIECES * pl->cnt + 2 * (size_t)(PIECES * j + k) * pl->cells;
    atmos__beams_epi_tree(m, pl->cnt, lh);
}

int atmos__beams_pl_build(atmos__beams_pl *pl, const atmos__beams_light *l, const double eye[3], size_t max_samples,
                          int threads)
{
    if (l->nfaces != 6) {
        pl->lines = 0;
        return 0;
    }
    if (pl->lines && !memcmp(pl->eye, eye, sizeof pl->eye)) return 0; /* the same lines */
    pl->lines = 0;
    memcpy(pl->eye, eye, sizeof pl->eye);
    double w[3] = {eye[0] - l->L.pos[0], eye[1] - l->L.pos[1], eye[2] - l->L.pos[2]};
    pl->e = sqrt(atmos__dot3(w, w));
    if (!(pl->e > 1e-6)) return 0;
    for (int i = 0; i < 3; i++) pl->a[i] = w[i] / pl->e;
    const double ref[3] = {fabs(pl->a[1]) < 0.9 ? 0 : 1, fabs(pl->a[1]) < 0.9 ? 1 : 0, 0};
    atmos__cross3(pl->a, ref, pl->e1);
    atmos__normalize3(pl->e1);
    atmos__cross3(pl->a, pl->e1, pl->e2);
    const double texel = 2 * l->face[0].tan_half / l->face[0].n;
    const int lines = (int)ceil(2 * ATMOS_PI / (PL_PSI * texel));
    pl->dpsi = 2 * ATMOS_PI / lines;
    pl->qmin = -tan(ATMOS_PI / 6), pl->dq = PL_Q * texel;
    pl->cnt = (int)ceil(-2 * pl->qmin / pl->dq) + 1;
    pl->cells = atmos__beams_epi_cells(pl->cnt - 1, NULL);
    const size_t per = PIECES * ((size_t)pl->cnt + 2 * pl->cells), want = per * (size_t)lines;
    if ((size_t)lines * PIECES * pl->cnt > max_samples) return 0;
    if (want > pl->cap) {
        free(pl->m);
        pl->cap = 0;
        if (!(pl->m = malloc(sizeof(float) * want))) return -1;
        pl->cap = want;
    }
    pl->lines = lines;
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads > 0 ? threads : 1)
    for (int jk = 0; jk < lines * PIECES; jk++) fill(pl, l, jk / PIECES, jk % PIECES);
    return 0;
}

/* A ray's walk along one piece: its plane's 2-D frame (the eye at (e, 0), the ray (dx, dy)), the
 * line's normal n (n . P = c all along it), the piece's centre (cc, sc). */
typedef struct pwalk {
    const atmos__beams_pl *pl;
    double dy, n0, n1, c, cc, sc, ta, tb;
    double weight;
    void (*lit)(void *u, double ta, double tb, double weight);
    void *u;
} pwalk;

/* The ray's t at the piece's sample coordinate r. */
static double t_at(const pwalk *w, double r)
{
    const double q = w->pl->qmin + r * w->pl->dq;
    const double Dx = w->cc - q * w->sc, Dy = w->sc + q * w->cc; /* the direction u + q v in the plane */
    const double s = w->c / (w->n0 * Dx + w->n1 * Dy);
    const double t = s * Dy / w->dy;
    return t < w->ta ? w->ta : t > w->tb ? w->tb : t;
}

static void piece_lit(void *u, double ra, double rb)
{
    pwalk *w = u;
    const double a = t_at(w, ra), b = t_at(w, rb);
    if (b > a) w->lit(w->u, a, b, w->weight);
}

/* The ray's coordinate r on the piece (sample units) at t. */
static double r_at(const pwalk *w, double e, double dx, double t)
{
    const double px = e + t * dx, py = t * w->dy;
    const double q = (-w->sc * px + w->cc * py) / (w->cc * px + w->sc * py);
    return (q - w->pl->qmin) / w->pl->dq;
}

/* The ray's walk along half-plane j's three pieces, each lit stretch weighted by weight. */
static void plane_walk(const atmos__beams_pl *pl, int j, double x1, double x2, double dx, double t0, double t1,
                       double weight, void (*lit)(void *u, double ta, double tb, double weight), void *u)
{
    const double psj = j * pl->dpsi, dy = cos(psj) * x1 + sin(psj) * x2;
    pwalk w = {.pl = pl, .dy = dy, .n0 = dy, .n1 = -dx, .c = pl->e * dy, .weight = weight, .lit = lit, .u = u};
    double tk = 0; /* where the ray enters piece k */
    for (int k = 0; k < PIECES && tk < t1; k++) {
        /* where it leaves the piece: at the direction (k + 1) pi / 3 */
        double tn = INFINITY;
        if (k < PIECES - 1) {
            const double be = (k + 1) * ATMOS_PI / 3, den = dy * cos(be) - dx * sin(be);
            if (den > 0) tn = pl->e * sin(be) / den;
        }
        w.ta = fmax(t0, tk), w.tb = fmin(t1, tn);
        tk = tn;
        if (!(w.tb > w.ta)) continue;
        centre(k, &w.cc, &w.sc);
        const double ra = r_at(&w, pl->e, dx, w.ta), rb = r_at(&w, pl->e, dx, w.tb);
        /* the ray's -1/x along the piece, q = qmin + r dq: -(n . u + q n . v) / c */
        const double nu = w.n0 * w.cc + w.n1 * w.sc, nv = -w.n0 * w.sc + w.n1 * w.cc;
        const double zc = -(nu + pl->qmin * nv) / w.c * (1 + PL_BIAS), zs = -pl->dq * nv / w.c * (1 + PL_BIAS);
        const size_t at = (size_t)(PIECES * j + k);
        const float *m = pl->m + at * pl->cnt, *lh = pl->m + (size_t)pl->lines * PIECES * pl->cnt + 2 * at * pl->cells;
        atmos__beams_epi_walk_line(m, lh, pl->cnt, 0, zc, zs, fmax(ra, 0), fmin(rb, pl->cnt - 1), piece_lit, &w);
    }
}

int atmos__beams_pl_walk(const atmos__beams_pl *pl, const double d[3], double t0, double t1,
                         void (*lit)(void *u, double ta, double tb, double weight), void *u)
{
    const double x1 = atmos__dot3(d, pl->e1), x2 = atmos__dot3(d, pl->e2), dx = atmos__dot3(d, pl->a);
    double psi = atan2(x2, x1);
    if (psi < 0) psi += 2 * ATMOS_PI;
    const double f = psi / pl->dpsi;
    int j0 = (int)floor(f);
    const double a = f - j0;
    j0 = j0 < 0 ? 0 : j0 >= pl->lines ? pl->lines - 1 : j0;
    const int j1 = j0 + 1 == pl->lines ? 0 : j0 + 1;
    /* both half-planes must hold the ray's direction on their side of the axis */
    if (!(cos(j0 * pl->dpsi) * x1 + sin(j0 * pl->dpsi) * x2 > 1e-9) ||
        !(cos(j1 * pl->dpsi) * x1 + sin(j1 * pl->dpsi) * x2 > 1e-9) || !(t1 > t0))
        return -1;
    plane_walk(pl, j0, x1, x2, dx, t0, t1, 1 - a, lit, u);
    plane_walk(pl, j1, x1, x2, dx, t0, t1, a, lit, u);
    return 0;
}
