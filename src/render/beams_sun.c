/* The sun of the beam renderer (beams_sun.h): the fog's optical depth along a ray, the sun's
 * orthographic shadow map of the meshes, and the sunlight the fog scatters along a ray. */
#include "render/beams_sun.h"
#include "render/beams_raster.h"
#include "core/fastmath.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* exp(-(y - base) / H), the eye's kept where y is its height (the same value). */
static double density_factor(const atmos__beams_fog *f, double y)
{
    return f->eye_set && y == f->eye_y ? f->eye_e : exp(-(y - f->base_m) / f->height_m);
}

/* Along o + t d the fog is A exp(-k t): A at the eye, k = d_y / H (0 for uniform fog). */
static void fog_line(const atmos__beams_fog *f, const double o[3], const double d[3], double *A, double *k)
{
    *A = f->height_m > 0 ? f->sigma0 * density_factor(f, o[1]) : f->sigma0;
    *k = f->height_m > 0 ? d[1] / f->height_m : 0;
}

/* int_0^t A exp(-k s) ds */
static double line_tau(double A, double k, double t)
{
    if (t == INFINITY) return k > 0 ? A / k : A > 0 ? INFINITY : 0;
    return fabs(k * t) < 1e-9 ? A * t : A * -expm1(-k * t) / k;
}

double atmos__beams_fog_tau(const atmos__beams_fog *f, const double o[3], const double d[3], double t)
{
    double A, k;
    fog_line(f, o, d, &A, &k);
    return line_tau(A, k, t);
}

void atmos__beams_sun_free(atmos__beams_sun *s)
{
    free(s->depth);
    atmos__beams_tiles_free(&s->tiles);
    s->depth = NULL, s->n = 0;
}

#define SUN_BANDS 32 /* the map drawn in bands of rows, one thread a band */

/* The vertices of the meshes in the map's frame: u, v in texels, the depth (one array, each
 * mesh's from at[m]); NULL out of memory. */
static double *map_vertices(const atmos__beams_sun *s, atmos_mesh *const *mesh, int nmesh, size_t *at)
{
    size_t total = 0;
    for (int m = 0; m < nmesh; m++) at[m] = total, total += (size_t)mesh[m]->vertex_count;
    double *w = malloc(sizeof(double) * 3 * (total ? total : 1));
    if (!w) return NULL;
    for (int m = 0; m < nmesh; m++)
        for (int i = 0; i < mesh[m]->vertex_count; i++) {
            const float *p = mesh[m]->positions + 3 * i;
            const double q[3] = {p[0], p[1], p[2]};
            double *o = w + 3 * (at[m] + (size_t)i);
            o[0] = (atmos__dot3(q, s->right) - s->u0) / s->texel;
            o[1] = (atmos__dot3(q, s->up) - s->v0) / s->texel;
            o[2] = atmos__dot3(q, s->fwd);
        }
    return w;
}

/* The first row of band b of an n-row map. */
static int band_row(int n, int b) { return (int)((long)n * b / SUN_BANDS); }

/* The band of row y (0 <= y < n). */
static int row_band(int n, int y)
{
    int b = (int)((long)y * SUN_BANDS / n);
    while (b + 1 < SUN_BANDS && band_row(n, b + 1) <= y) b++;
    while (b > 0 && band_row(n, b) > y) b--;
    return b;
}

/* The triangles in the map's bands: each triangle (numbered over the meshes one after the
 * other) listed in every band its rows meet, in order: band b's in list[at[b] .. at[b + 1]).
 * A triangle whose rows lie beside the map or are not finite draws nothing (the rasteriser's
 * own rule) and is left out. w, vat: map_vertices'. Returns the list, NULL out of memory. */
static size_t *band_lists(const atmos__beams_sun *s, atmos_mesh *const *mesh, int nmesh, const double *w,
                       const size_t *vat, size_t *at, int threads)
{
    size_t total = 0;
    for (int m = 0; m < nmesh; m++) total += (size_t)mesh[m]->triangle_count;
    unsigned char *span = malloc(2 * (total ? total : 1));
    if (!span) return NULL;
    const int n = s->n;
    size_t t0 = 0;
    for (int m = 0; m < nmesh; m++) {
        const atmos_mesh *M = mesh[m];
#pragma omp parallel for schedule(static) num_threads(threads)
        for (int t = 0; t < M->triangle_count; t++) {
            double lo = INFINITY, hi = -INFINITY;
            for (int k = 0; k < 3; k++) {
                const double y = w[3 * (vat[m] + (size_t)M->indices[3 * t + k]) + 1];
                lo = fmin(lo, y), hi = fmax(hi, y);
            }
            unsigned char *sp = span + 2 * (t0 + (size_t)t);
            if (!(isfinite(lo) && isfinite(hi)) || ceil(hi) < 0 || floor(lo) > n - 1) sp[0] = 1, sp[1] = 0;
            else sp[0] = (unsigned char)row_band(n, (int)fmax(0, floor(lo))),
            sp[1] = (unsigned char)row_band(n, (int)fmin(n - 1, ceil(hi)));
        }
        t0 += (size_t)M->triangle_count;
    }
    for (int b = 0; b <= SUN_BANDS; b++) at[b] = 0;
    for (size_t t = 0; t < total; t++)
        for (int b = span[2 * t]; b <= span[2 * t + 1]; b++) at[b + 1]++;
    for (int b = 0; b < SUN_BANDS; b++) at[b + 1] += at[b];
    size_t fill[SUN_BANDS];
    for (int b = 0; b < SUN_BANDS; b++) fill[b] = at[b];
    size_t *list = malloc(sizeof(size_t) * (at[SUN_BANDS] ? at[SUN_BANDS] : 1));
    if (list)
        for (size_t t = 0; t < total; t++)
            for (int b = span[2 * t]; b <= span[2 * t + 1]; b++) list[fill[b]++] = t;
    free(span);
    return list;
}

/* Band b of the map: cleared, then its triangles, in order (depth is linear in an
 * orthographic view). */
static void draw_band(atmos__beams_sun *s, atmos_mesh *const *mesh, int nmesh, const double *w, const size_t *vat,
                      const size_t *list, const size_t *at, int b)
{
    const size_t n = (size_t)s->n;
    const int row0 = band_row(s->n, b), row1 = band_row(s->n, b + 1) - 1;
    for (size_t i = (size_t)row0 * n; i < (size_t)(row1 + 1) * n; i++) s->depth[i] = INFINITY;
    int m = 0;
    size_t t0 = 0; /* the first triangle of mesh m */
    for (size_t i = at[b]; i < at[b + 1]; i++) {
        while (m + 1 < nmesh && list[i] >= t0 + (size_t)mesh[m]->triangle_count) t0 += (size_t)mesh[m++]->triangle_count;
        const size_t t = list[i] - t0;
        double x[3], y[3], z[3];
        for (int k = 0; k < 3; k++) {
            const double *o = w + 3 * (vat[m] + (size_t)mesh[m]->indices[3 * t + k]);
            x[k] = o[0], y[k] = o[1], z[k] = o[2];
        }
        atmos__beams_raster_rows(s->depth, s->n, x, y, z, 0, row0, row1);
    }
}

atmos_status atmos__beams_sun_build(atmos_context *ctx, atmos__beams_sun *s, const double dir[3], atmos_mesh *const *mesh,
                                    int nmesh, int size)
{
    atmos__beams_sun_free(s);
    s->gen++;
    for (int a = 0; a < 3; a++) s->dir[a] = dir[a], s->fwd[a] = -dir[a];
    const double ref[3] = {fabs(s->fwd[1]) < 0.9 ? 0 : 1, fabs(s->fwd[1]) < 0.9 ? 1 : 0, 0};
    atmos__cross3(s->fwd, ref, s->right);
    atmos__normalize3(s->right);
    atmos__cross3(s->right, s->fwd, s->up);
    if (nmesh == 0) return ATMOS_OK;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int m = 0; m < nmesh; m++)
        for (int i = 0; i < mesh[m]->vertex_count; i++) {
            const float *p = mesh[m]->positions + 3 * i;
            const double q[3] = {p[0], p[1], p[2]}, u = atmos__dot3(q, s->right), v = atmos__dot3(q, s->up);
            lo[0] = fmin(lo[0], u), hi[0] = fmax(hi[0], u), lo[1] = fmin(lo[1], v), hi[1] = fmax(hi[1], v);
        }
    const double ext = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), 1e-6);
    s->n = size, s->texel = ext / (size - 2); /* a texel of margin on each side */
    s->u0 = lo[0] - s->texel, s->v0 = lo[1] - s->texel;
    s->bias = 0.5 * s->texel;
    /* the objects lie within [1, 1 + (hi - lo) / texel] texels, [0.5, ...] in look-up coordinates */
    s->box[0] = -1, s->box[1] = fmin(size, 2 + (hi[0] - lo[0]) / s->texel);
    s->box[2] = -1, s->box[3] = fmin(size, 2 + (hi[1] - lo[1]) / s->texel);
    const int threads = atmos__threads(ctx);
    size_t *vat = malloc(sizeof(size_t) * (size_t)nmesh), at[SUN_BANDS + 1];
    double *w = vat ? map_vertices(s, mesh, nmesh, vat) : NULL;
    size_t *list = w ? band_lists(s, mesh, nmesh, w, vat, at, threads) : NULL;
    if (!list || !(s->depth = atmos__big_alloc(sizeof(float) * (size_t)size * size))) {
        free(vat), free(w), free(list);
        s->n = 0;
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for a %dx%d sun shadow map", size, size);
    }
    /* each band of rows on its own, its triangles in the meshes' order: the same bits with
     * any number of threads */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int b = 0; b < SUN_BANDS; b++) draw_band(s, mesh, nmesh, w, vat, list, at, b);
    free(vat), free(w), free(list);
    if (atmos__beams_tiles_build(&s->tiles, s->depth, size, ATMOS__BEAMS_SUN_TILE_SHIFT, threads)) {
        atmos__beams_sun_free(s);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for a %dx%d sun shadow map's tiles", size, size);
    }
    return ATMOS_OK;
}

/* H at texel coordinates (fx, fy) and depth z (the bias taken off): the four nearest
 * comparisons, blended; 1 beside the map. */
static double lookup(const atmos__beams_sun *s, double fx, double fy, double z)
{
    const int n = s->n;
    if (!(fx > -1 && fx < n && fy > -1 && fy < n)) return 1; /* beside every object */
    return atmos__beams_depth_blend(s->depth, n, fx, fy, (int)(fx + 1) - 1, (int)(fy + 1) - 1, z);
}

double atmos__beams_sun_visibility(const atmos__beams_sun *s, const double p[3])
{
    if (!s->n) return 1;
    return lookup(s, (atmos__dot3(p, s->right) - s->u0) / s->texel - 0.5, (atmos__dot3(p, s->up) - s->v0) / s->texel - 0.5,
                  atmos__dot3(p, s->fwd) - s->bias);
}

int atmos__beams_sun_dark(const atmos__beams_sun *s, const double p[3])
{
    if (!s->n) return 0;
    const double fx = (atmos__dot3(p, s->right) - s->u0) / s->texel - 0.5, fy = (atmos__dot3(p, s->up) - s->v0) / s->texel - 0.5;
    if (!(fx >= 0 && fx < s->n - 1 && fy >= 0 && fy < s->n - 1)) return 0; /* beside the map: it cannot tell */
    /* its ring holds the texels round p */
    const int tile = atmos__beams_tiles_at(&s->tiles, (int)fx, (int)fy, ATMOS__BEAMS_SUN_TILE_SHIFT);
    return s->tiles.max[tile] < atmos__dot3(p, s->fwd) - 2 * s->texel;
}

double atmos__beams_sun_fog_in(const atmos__beams_fog *f, const double sun[3], const double p[3])
{
    if (!(f->height_m > 0)) return 0; /* a uniform fog has no top: lit as it is */
    if (!(sun[1] > 0)) return INFINITY;
    return f->sigma0 * density_factor(f, p[1]) * f->height_m / sun[1];
}

void atmos__beams_fog_eye(atmos__beams_fog *f, const double o[3], const double sun[3])
{
    f->eye_set = 0;
    const double e = f->height_m > 0 ? exp(-(o[1] - f->base_m) / f->height_m) : 1;
    const double C = atmos__beams_sun_fog_in(f, sun, o);
    f->eye_y = o[1], f->eye_e = e, f->eye_C = C, f->eye_expC = exp(-C), f->eye_set = 1;
}

/* One ray's steps (atmos__beams_sun_airlight): sample i at t(i), the map's coordinates and
 * depth linear in t (x0 + t x1, ...). */
typedef struct sun_ray {
    const atmos__beams_sun *s;
    double A, k, gamma, whole, T;
    double step, inv_gamma, k_over_A, inv_A, inv_k; /* whole / n and the reciprocals share_t uses */
    int n, flat;
    double x0, x1, y0, y1, z0, z1;
} sun_ray;

/* Where the integral reaches the share u of its whole (u in [0, n]: step i spans [i, i + 1],
 * its sample at i + 0.5): the eye's optical depth tau there, then the t where the fog's
 * A exp(-k t) integrates to tau (INFINITY if it never does). Divisions by per-ray constants
 * are products with their reciprocals. */
static double share_t(const sun_ray *r, double u)
{
    const double q = u * r->step, tau = r->flat ? q : -atmos__log1p_fast(-r->gamma * q) * r->inv_gamma;
    double t;
    if (!(r->A > 0)) t = INFINITY;
    else if (fabs(r->k) * tau < 1e-9 * r->A) t = tau * r->inv_A;
    else {
        const double x = tau * r->k_over_A;
        t = x >= 1 ? INFINITY : -atmos__log1p_fast(-x) * r->inv_k;
    }
    return t < r->T ? t : r->T; /* fmin, inlined (no NaN here) */
}

static double sample(const sun_ray *r, double t)
{
    return t < INFINITY ? lookup(r->s, r->x0 + t * r->x1, r->y0 + t * r->y1, r->z0 + t * r->z1) : 1;
}

/* The texel (a look-up's floor) of coordinate f, clamped to [-1, n - 1]. */
static int texel(double f, int n)
{
    return f < 0 ? -1 : f > n - 1 ? n - 1 : (int)f;
}

/* The sum of H over the samples of steps [i0, i1), ta and tb where the first begins and the
 * last ends: the count, or 0, when the tiles the segment [ta, tb] crosses hold its depths all
 * below (or all at or beyond) their bounds (a look-up beside the map says 1: only lit runs
 * may leave it); else the two halves, down to runs of a few samples read one by one. */
static double run(const sun_ray *r, int i0, int i1, double ta, double tb)
{
    const int n = r->s->n;
    if (tb < INFINITY) {
        const double xa = r->x0 + ta * r->x1, xb = r->x0 + tb * r->x1, ya = r->y0 + ta * r->y1, yb = r->y0 + tb * r->y1;
        const double za = r->z0 + ta * r->z1, zb = r->z0 + tb * r->z1;
        const int inside = xa > -1 && xa < n && xb > -1 && xb < n && ya > -1 && ya < n && yb > -1 && yb < n;
        float lo, hi;
        /* the ends ordered by comparisons: fmin and fmax are calls of the library here */
        const int xs = xa < xb, ys = ya < yb, zs = za < zb;
        atmos__beams_tiles_range(&r->s->tiles, texel(xs ? xa : xb, n), texel(xs ? xb : xa, n), texel(ys ? ya : yb, n),
                                 texel(ys ? yb : ya, n), &lo, &hi);
        if ((zs ? zb : za) < lo) return i1 - i0;
        if (inside && (zs ? za : zb) >= hi) return 0;
    }
    if (i1 - i0 <= 4) {
        double sum = 0;
        for (int i = i0; i < i1; i++) sum += sample(r, share_t(r, i + 0.5));
        return sum;
    }
    const int mid = i0 + (i1 - i0) / 2;
    const double tm = share_t(r, mid);
    return run(r, i0, mid, ta, tm) + run(r, mid, i1, tm, tb);
}

/* The fog along a ray from o in direction d up to T: its line (A, k: fog_line), gamma and the
 * eye's optical depth tauT at T, flat where gamma tauT is nil; returns C, the sunlight's optical
 * depth in at the eye (700 or more: no light). The sunlight at t is dimmed by C exp(-k t): with
 * the eye's optical depth tau as the variable (d tau = sigma dt, exp(-k t) = 1 - k tau / A) the
 * integrand is exp(-C) exp(-gamma tau), gamma = 1 - d_y / sun_y (1 in uniform fog). */
static double sun_fog_ray(const atmos__beams_sun *s, const atmos__beams_fog *f, const double o[3], const double d[3],
                          double T, double *A, double *k, double *gamma, double *tauT, int *flat)
{
    fog_line(f, o, d, A, k);
    const double C = atmos__beams_sun_fog_in(f, s->dir, o);
    *gamma = f->height_m > 0 ? 1 - d[1] / s->dir[1] : 1;
    *tauT = line_tau(*A, *k, T);
    *flat = !(fabs(*gamma * *tauT) > 1e-9);
    return C;
}

/* The sunlight the fog scatters toward -d per unit of the ray's lit integral, exp(-C) dimmed. */
static double sun_fog_light(const atmos__beams_sun *s, const atmos__beams_fog *f, const double d[3], double C)
{
    const double c = atmos__dot3(s->dir, d);
    const double in = f->eye_set && C == f->eye_C ? f->eye_expC : exp(-C); /* the eye's kept */
    return f->albedo * (f->phase ? atmos__fog_phase(f->phase, c) : atmos_phase_hg(c, f->g)) * in;
}

double atmos__beams_sun_airlight(const atmos__beams_sun *s, const atmos__beams_fog *f, const double o[3],
                                 const double d[3], double T, double epsilon, int max_steps)
{
    sun_ray r = {.s = s, .T = T};
    double tauT;
    const double C = sun_fog_ray(s, f, o, d, T, &r.A, &r.k, &r.gamma, &tauT, &r.flat);
    if (!(C < 700)) return 0;
    r.whole = r.flat ? tauT : -expm1(-r.gamma * tauT) / r.gamma; /* int_0^tau(T) exp(-gamma tau) */
    if (!(r.whole > 0)) return 0;
    int n = (int)ceil(1 / fmax(epsilon, 1e-9));
    r.n = n = n < 1 ? 1 : n > max_steps ? max_steps : n;
    r.step = r.whole / n, r.inv_gamma = r.flat ? 0 : 1 / r.gamma, r.inv_k = r.k != 0 ? 1 / r.k : 0;
    r.inv_A = r.A > 0 ? 1 / r.A : 0, r.k_over_A = r.k * r.inv_A;
    double sum = n;
    if (s->n) {
        /* the map's coordinates along the ray, linear in t */
        r.x0 = (atmos__dot3(o, s->right) - s->u0) / s->texel - 0.5, r.x1 = atmos__dot3(d, s->right) / s->texel;
        r.y0 = (atmos__dot3(o, s->up) - s->v0) / s->texel - 0.5, r.y1 = atmos__dot3(d, s->up) / s->texel;
        r.z0 = atmos__dot3(o, s->fwd) - s->bias, r.z1 = atmos__dot3(d, s->fwd);
        sum = run(&r, 0, n, 0, T);
    }
    return sun_fog_light(s, f, d, C) * r.whole * sum / n;
}

/* A ray's closed form over its lit stretches (atmos__beams_sun_airlight_lines): r texels
 * along its line is t = r / p; W(t) = int_0^tau(t) exp(-gamma tau) d tau. */
typedef struct lit_sum {
    double A, k, gamma, inv_p, T, sum;
    int flat;
} lit_sum;

static double lit_w(const lit_sum *l, double t)
{
    const double tau = line_tau(l->A, l->k, t < l->T ? t : l->T);
    return l->flat ? tau : -expm1(-l->gamma * tau) / l->gamma;
}

static void lit_add(void *u, double ra, double rb)
{
    lit_sum *l = u;
    l->sum += lit_w(l, rb * l->inv_p) - (ra > 0 ? lit_w(l, ra * l->inv_p) : 0);
}

double atmos__beams_sun_airlight_lines(const atmos__beams_sun *s, const atmos__beams_epi *e, const atmos__beams_fog *f,
                                       const double o[3], const double d[3], double T, double epsilon, int max_steps)
{
    const double x1 = atmos__dot3(d, s->right) / s->texel, y1 = atmos__dot3(d, s->up) / s->texel, p = hypot(x1, y1);
    const double ex = (atmos__dot3(o, s->right) - s->u0) / s->texel - 0.5, ey = (atmos__dot3(o, s->up) - s->v0) / s->texel - 0.5;
    if (!s->n || !e || !e->lines || !(p > 1e-9) || ex != e->ex || ey != e->ey)
        return atmos__beams_sun_airlight(s, f, o, d, T, epsilon, max_steps);
    lit_sum l = {.T = T, .inv_p = 1 / p};
    double tauT;
    const double C = sun_fog_ray(s, f, o, d, T, &l.A, &l.k, &l.gamma, &tauT, &l.flat);
    if (!(C < 700)) return 0;
    /* the line nearest the ray's angle */
    double a = atan2(y1, x1) / e->dth;
    int j = (int)floor(a + 0.5);
    j = j < 0 ? j + e->lines : j >= e->lines ? j - e->lines : j;
    atmos__beams_epi_walk(e, j, atmos__dot3(o, s->fwd) - s->bias, atmos__dot3(d, s->fwd) / p, T * p, lit_add, &l);
    return sun_fog_light(s, f, d, C) * l.sum;
}
