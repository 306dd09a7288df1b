/* The particles' eye pass (pcloud.h, atmos__pcloud_splat): Harris's back-to-front splatting
 * on the CPU. The particles are sorted far to near, binned into tiles of the image, and each
 * tile composites its own list in that order, so a tile's pixels see every particle in the
 * same order whatever thread draws it. */
#include "particles/pcloud.h"
#include "particles/pphase.h"
#include "core/fastmath.h"
#include "core/internal.h"
#include "optics/optics_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TILE 32
#define SPAN_SLACK 0.05 /* pixels */
#define LANES 64        /* a batch of row spans (draw) */
#define SQRT_2PI 2.5066282746310002

typedef struct sp {
    double c[3], s, z;       /* centre, width, depth along the camera's axis */
    int bb[4];               /* pixel box [x0, x1) x [y0, y1) */
    float *col, *tc;         /* colour and central depth per wavelength (nw each, in the splats'
                                shared pool: the records stay small, a tile's list in cache) */
} sp;

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2], out[2] = a[0] * b[1] - a[1] * b[0];
}

/* The splat of particle p as seen by cam; 0 when it is not drawn. Its depth z orders the
 * splats far to near: along a pinhole's axis, from the eye for the wide cameras. */
static int prepare(const atmos__pcloud *pc, int p, const atmos__poptics *o, const atmos__plights *L, const atmos_camera *cam,
                   const int rect[4], sp *out)
{
    const double c[3] = {pc->x[p], pc->y[p], pc->z[p]}, s = pc->s[p];
    double rel[3], Z;
    if (!atmos__pcloud_screen_box(cam, c, ATMOS__PCLOUD_CUT * s, rect, out->bb, &Z)) return 0;
    for (int i = 0; i < 3; i++) rel[i] = c[i] - cam->position[i];
    memcpy(out->c, c, sizeof out->c);
    out->s = s, out->z = Z;
    const double d = sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
    const int fi = pc->field[p];
    /* each light's phase functions at its scattering angle, every wavelength at once (one
     * angle lookup), summed over the lights in order per wavelength */
    double sums[ATMOS_MAX_WAVELENGTHS] = {0}, ph[ATMOS_MAX_WAVELENGTHS];
    for (int j = 0; j < L->n; j++) {
        /* scattering angle: the light travels along -dir, the eye is at -rel from the centre */
        const double mu = (L->dir[j][0] * rel[0] + L->dir[j][1] * rel[1] + L->dir[j][2] * rel[2]) / d;
        if (o->ph[fi]) atmos__pphase_eval(o->ph[fi], L->order[j][p] + 1.0, mu, ph);
        else if (o->ms[fi]) atmos__msphase_eval_all(o->ms[fi], o->nw, L->order[j][p] + 1.0, mu, ph);
        else
            for (int k = 0; k < o->nw; k++) ph[k] = 1.0 / (4.0 * ATMOS_PI);
        for (int k = 0; k < o->nw; k++) sums[k] += ph[k] * L->e[j][k] * L->light[j][(size_t)p * o->nw + k];
    }
    for (int k = 0; k < o->nw; k++) {
        const double sum = sums[k];
        out->col[k] = (float)(o->albedo[fi][k] * sum) + (L->diffuse ? L->diffuse[(size_t)p * o->nw + k] : 0.0f);
        if (L->air_t) { /* seen through the air: L_air + T_air colour (an opaque particle exactly) */
            const size_t at = (size_t)p * o->nw + k;
            out->col[k] = L->air_l[at] + L->air_t[at] * out->col[k];
        }
        out->tc[k] = (float)(o->sigma_ext[fi][k] * pc->n0[p] * s * SQRT_2PI);
    }
    return 1;
}

/* The columns [*ja, *jb) of a row (n pixels from u0, 1 / idu apart) that may lie within the cut:
 * b^2 <= rc2 is g(u) = (a2 - rc2 e2) u^2 + (a1 - rc2 e1) u + a0 - rc2 e0 <= 0 (the denominator
 * |d|^2 > 0), between g's roots, widened by SPAN_SLACK pixels on each side for the roots'
 * rounding (far below a pixel in double precision; the pixels' own test decides); none when
 * g has no root by far more than its terms' rounding; the whole row when g is not a parabola
 * open upwards (the eye within the cut's reach). */
ATMOS_CLONE_HELPER void row_span(double a0, double a1, double a2, double e0, double e1,
                                 double e2, double rc2, double u0, double idu, int n, int *ja,
                                 int *jb)
{
    const double A = a2 - rc2 * e2, B = a1 - rc2 * e1, C = a0 - rc2 * e0, disc = B * B - 4.0 * A * C;
    *ja = 0, *jb = n;
    if (!(A > 0) || !isfinite(disc)) return;
    if (disc < -1e-12 * (B * B + fabs(4.0 * A * C))) {
        *jb = 0;
        return;
    }
    const double sq = sqrt(disc > 0 ? disc : 0.0), h = 0.5 / A, lo = (-B - sq) * h, hi = (-B + sq) * h;
    /* both clamped to [-1, n] before the conversion (a root far off the row would overflow int) */
    const double jl = ceil(fmin(fmax((lo - u0) * idu - SPAN_SLACK, -1.0), n));
    const double jh = floor(fmin(fmax((hi - u0) * idu + SPAN_SLACK, -1.0), n)) + 1;
    *ja = jl > 0 ? (int)jl : 0, *jb = jh < n ? (int)jh : n;
    if (*jb < *ja) *jb = *ja;
}

/* A batch of a splat's row spans laid end to end (lanes), so that the columns and the
 * transmittances run over whole vectors of 8 for several short rows at once; lane off[r] + i
 * is pixel (ja[r] + i, y[r]) of the rows' box. */
typedef struct lanes {
    int n, rows;                                   /* lanes and rows held */
    int y[TILE], ja[TILE], len[TILE], off[TILE];   /* a piece has at most TILE rows */
    double b2[LANES + 8];                          /* squared distance from the centre */
    float g[LANES + 8], T[ATMOS_MAX_WAVELENGTHS][LANES + 8];
} lanes;

/* The batch's columns and transmittances (vector loops over its lanes rounded up to 8; the
 * lanes past n hold the centre; a lane beyond the cut gets transmittance 1, which leaves its
 * pixel as it is: v 1 + c 0 = v), then each row's pixels composited; empties the batch. */
ATMOS_CLONE_HELPER void flush(lanes *L, const sp *q, int nw, int x0, double rc2, double k2,
                              int width, atmos_image *img)
{
    const int nn = (L->n + 7) & ~7, C = img->channels;
    const float *tc = q->tc, *col = q->col;
    for (int i = L->n; i < nn; i++) L->b2[i] = 0.0;
    for (int i = 0; i < nn; i++) L->g[i] = L->b2[i] > rc2 ? -1.0f : atmos__pcloud_column((float)(L->b2[i] * k2));
    for (int k = 0; k < nw; k++)
        for (int i = 0; i < nn; i++) {
            const float T = atmos__expf_fast(-tc[k] * L->g[i]);
            L->T[k][i] = L->g[i] < 0.0f ? 1.0f : T;
        }
    if (nw == 3 && C == 4) {
        /* three wavelengths and coverage: every value v of a pixel becomes v t + c (1 - t), the
         * coverage's t the mean transmittance and c = 1; a pixel as one vector of four */
        typedef float v4 __attribute__((vector_size(16)));
        const v4 c = {col[0], col[1], col[2], 1.0f}, one = {1.0f, 1.0f, 1.0f, 1.0f};
        for (int r = 0; r < L->rows; r++) {
            const int n = L->len[r], o = L->off[r];
            float *row = img->pixels + ((size_t)L->y[r] * width + x0 + L->ja[r]) * C;
            const float *T0 = L->T[0] + o, *T1 = L->T[1] + o, *T2 = L->T[2] + o;
            for (int j = 0; j < n; j++) {
                const float t0 = T0[j], t1 = T1[j], t2 = T2[j];
                const v4 t = {t0, t1, t2, (t0 + t1 + t2) / 3.0f};
                v4 px;
                memcpy(&px, row + 4 * j, sizeof px);
                px = px * t + c * (one - t);
                memcpy(row + 4 * j, &px, sizeof px);
            }
        }
        L->n = L->rows = 0;
        return;
    }
    for (int r = 0; r < L->rows; r++) {
        const int n = L->len[r], o = L->off[r];
        float *row = img->pixels + ((size_t)L->y[r] * width + x0 + L->ja[r]) * C;
        for (int j = 0; j < n; j++) {
            if (L->g[o + j] < 0.0f) continue; /* beyond the cut (tm / nw need not be 1 exactly) */
            float *px = row + (size_t)j * C, tm = 0;
            for (int k = 0; k < nw; k++) {
                px[k] = px[k] * L->T[k][o + j] + col[k] * (1.0f - L->T[k][o + j]);
                tm += L->T[k][o + j];
            }
            px[nw] = 1.0f - (1.0f - px[nw]) * tm / nw;
        }
    }
    L->n = L->rows = 0;
}

/* Composites splat q over the pixels of its box inside tile (tx, ty). Pixel (x, y)'s ray is
 * d = F + u R + v U (u, v: the pixel's place on the image plane at unit distance); its squared
 * distance from the centre is b^2 = |rel x d|^2 / |d|^2, and along a row both are quadratics in
 * u: b^2 = (a0 + a1 u + a2 u^2) / (e0 + e1 u + e2 u^2), the coefficients once per row from
 * polynomials in v made once per splat (double: a0 is |rel|^2 |d|^2, b^2 a small difference;
 * the rows' recorded frames the same as with the cross products made per row). Only the row's columns that may lie within the
 * cut are visited (row_span: a small splat's box is mostly outside its cut), their b^2 laid in
 * a batch of lanes (flush) with the next rows'. A pixel beyond the cut is left as it is, so
 * the spans change no value. */
ATMOS_CLONES static void draw(const sp *q, int nw, const atmos_camera *cam, int tx,
                                                                    int ty, atmos_image *img)
{
    const int x0 = q->bb[0] > tx ? q->bb[0] : tx, x1 = q->bb[1] < tx + TILE ? q->bb[1] : tx + TILE;
    const int y0 = q->bb[2] > ty ? q->bb[2] : ty, y1 = q->bb[3] < ty + TILE ? q->bb[3] : ty + TILE;
    const double W = cam->width, H = cam->height, t = cam->tan_half_fov, k2 = 1.0 / (q->s * q->s);
    const double rc2 = ATMOS__PCLOUD_CUT * ATMOS__PCLOUD_CUT * q->s * q->s;
    const double *F = cam->forward, *R = cam->right, *U = cam->up;
    double rel[3], Q[3], PF[3], PU[3];
    for (int i = 0; i < 3; i++) rel[i] = q->c[i] - cam->position[i];
    cross(rel, R, Q), cross(rel, F, PF), cross(rel, U, PU);
    const double a2 = dot(Q, Q), e2 = dot(R, R), du = 2.0 * t / H, idu = 1.0 / du, u0 = (2.0 * x0 + 1.0 - W) / H * t;
    /* the rows' coefficients as polynomials in v (D = F + v U, P = rel x D = PF + v PU) */
    const double a00 = dot(PF, PF), a01 = 2.0 * dot(PF, PU), a02 = dot(PU, PU), a10 = 2.0 * dot(PF, Q), a11 = 2.0 * dot(PU, Q);
    const double e00 = dot(F, F), e01 = 2.0 * dot(F, U), e02 = dot(U, U), e10 = 2.0 * dot(F, R), e11 = 2.0 * dot(U, R);
    lanes L;
    L.n = L.rows = 0;
    for (int y = y0; y < y1; y++) {
        const double v = (H - 2.0 * (y + 0.5)) / H * t;
        const double a0 = a00 + v * (a01 + v * a02), a1 = a10 + v * a11, e0 = e00 + v * (e01 + v * e02), e1 = e10 + v * e11;
        int ja, jb;
        row_span(a0, a1, a2, e0, e1, e2, rc2, u0, idu, x1 - x0, &ja, &jb);
        if (ja >= jb) continue;
        if (L.n + (jb - ja) > LANES) flush(&L, q, nw, x0, rc2, k2, cam->width, img);
        /* whole vectors of 4 (the lanes past the span are the next row's or unused) */
        double *b2 = L.b2 + L.n;
        const int n4 = (jb - ja + 3) & ~3;
        for (int i = 0; i < n4; i++) {
            const double u = u0 + (ja + i) * du;
            b2[i] = (a0 + u * (a1 + u * a2)) / (e0 + u * (e1 + u * e2));
        }
        L.y[L.rows] = y, L.ja[L.rows] = ja, L.len[L.rows] = jb - ja, L.off[L.rows++] = L.n, L.n += jb - ja;
    }
    if (L.rows) flush(&L, q, nw, x0, rc2, k2, cam->width, img);
}

/* The rays of tile (tx, ty)'s pixels for a fisheye or equirectangular camera (atmos_camera_ray;
 * a zero ray outside a fisheye's circle): wide cameras have no image plane to take b^2 from. */
static void tile_rays(const atmos_camera *cam, int tx, int ty, double (*d)[3])
{
    for (int y = 0; y < TILE; y++)
        for (int x = 0; x < TILE; x++) {
            double *r = d[y * TILE + x];
            if (tx + x >= cam->width || ty + y >= cam->height || !atmos_camera_ray(cam, tx + x + 0.5, ty + y + 0.5, r))
                r[0] = r[1] = r[2] = 0.0;
        }
}

/* draw() for a wide camera: pixel ray d (unit) passes the centre at b^2 = |rel|^2 - (rel.d)^2,
 * in front of the eye when rel.d > 0 (a 360-degree fisheye sees behind it too). */
static void draw_wide(const sp *q, int nw, const atmos_camera *cam, int tx, int ty, const double (*d)[3], atmos_image *img)
{
    const int x0 = q->bb[0] > tx ? q->bb[0] : tx, x1 = q->bb[1] < tx + TILE ? q->bb[1] : tx + TILE;
    const int y0 = q->bb[2] > ty ? q->bb[2] : ty, y1 = q->bb[3] < ty + TILE ? q->bb[3] : ty + TILE;
    const double k2 = 1.0 / (q->s * q->s), rc2 = ATMOS__PCLOUD_CUT * ATMOS__PCLOUD_CUT * q->s * q->s;
    double rel[3];
    for (int i = 0; i < 3; i++) rel[i] = q->c[i] - cam->position[i];
    const double rr = dot(rel, rel);
    const int C = img->channels;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const double t = dot(rel, d[(y - ty) * TILE + (x - tx)]), b2 = rr - t * t;
            if (!(t > 0) || b2 > rc2) continue;
            const float g = atmos__pcloud_column((float)(b2 * k2));
            float *px = img->pixels + ((size_t)y * cam->width + x) * C, tm = 0;
            for (int k = 0; k < nw; k++) {
                const float T = atmos__expf_fast(-q->tc[k] * g);
                px[k] = px[k] * T + q->col[k] * (1.0f - T);
                tm += T;
            }
            px[nw] = 1.0f - (1.0f - px[nw]) * tm / nw;
        }
}

/* The splats' order cut into this many pieces for binning them on the threads. */
#define BIN_PIECES 8

/* The tiles (tx0..tx1, ty0..ty1, inclusive) that splat a's box covers. */
static void tile_range(const sp *a, const int rect[4], int t[4])
{
    t[0] = (a->bb[0] - rect[0]) / TILE, t[1] = (a->bb[1] - 1 - rect[0]) / TILE;
    t[2] = (a->bb[2] - rect[1]) / TILE, t[3] = (a->bb[3] - 1 - rect[1]) / TILE;
}

/* One pass over the pieces of the order on the threads: each piece counts its splats over each
 * tile into its row of at (list NULL), or puts them into list from its row's places. */
static void bin_pass(atmos_context *ctx, const sp *s, const atmos__keyed *ord, int n, const int rect[4], int ntx, int nt,
                     int *at, int *list)
{
#pragma omp parallel for schedule(static, 1) num_threads(atmos__threads(ctx)) if (n >= 4096)
    for (int c = 0; c < BIN_PIECES; c++) {
        int *k = at + (size_t)c * nt, t[4];
        for (int q = (int)((long long)n * c / BIN_PIECES); q < (int)((long long)n * (c + 1) / BIN_PIECES); q++) {
            tile_range(&s[ord[q].index], rect, t);
            for (int ty = t[2]; ty <= t[3]; ty++)
                for (int tx = t[0]; tx <= t[1]; tx++) {
                    if (list) list[k[ty * ntx + tx]] = ord[q].index;
                    k[ty * ntx + tx]++;
                }
        }
    }
}

/* The tile lists: list[cnt[t] .. cnt[t + 1]) the splats over tile t in the order of ord (far to
 * near). The order is cut into BIN_PIECES pieces, counted and then put in place on the threads,
 * each piece's entries in a tile's list after those of the pieces before it: the lists of one
 * pass in order, whatever the threads. Returns the list (NULL: no memory). */
static int *bin_tiles(atmos_context *ctx, const sp *s, const atmos__keyed *ord, int n, const int rect[4], int ntx,
                      int nty, int *cnt)
{
    const int nt = ntx * nty;
    int *at = calloc((size_t)BIN_PIECES * nt, sizeof(int)), *list = NULL;
    if (!at) return NULL;
    bin_pass(ctx, s, ord, n, rect, ntx, nt, at, NULL);
    int total = 0; /* each piece's start in each tile's list */
    for (int t = 0; t < nt; t++) {
        cnt[t] = total;
        for (int c = 0; c < BIN_PIECES; c++) {
            const int m = at[(size_t)c * nt + t];
            at[(size_t)c * nt + t] = total, total += m;
        }
    }
    cnt[nt] = total;
    if ((list = malloc(sizeof(int) * (size_t)(total ? total : 1)))) bin_pass(ctx, s, ord, n, rect, ntx, nt, at, list);
    free(at);
    return list;
}

atmos_status atmos__pcloud_splat(atmos_context *ctx, const atmos__pcloud *pc, const atmos__poptics *o,
                                 const atmos__plights *L, const int *idx, int nidx, const atmos_camera *cam,
                                 const int rect[4], atmos_image *img, int *drawn)
{
    if (drawn) *drawn = 0;
    const int ntx = (rect[2] - rect[0] + TILE - 1) / TILE, nty = (rect[3] - rect[1] + TILE - 1) / TILE;
    /* room for the particles asked for (a cloud's impostor: its own, not the whole field's) */
    const int count = idx ? nidx : pc->n;
    sp *s = malloc(sizeof *s * (size_t)(count > 0 ? count : 1));
    float *pool = malloc(sizeof(float) * 2 * (size_t)o->nw * (size_t)(count > 0 ? count : 1));
    atmos__keyed *ord = malloc(sizeof *ord * (size_t)(count > 0 ? count : 1));
    int *cnt = calloc((size_t)ntx * nty + 1, sizeof(int));
    unsigned char *kept = malloc((size_t)(count > 0 ? count : 1));
    int n = 0;
    if (!s || !ord || !cnt || !pool || !kept) goto nomem;
    /* the splats on the threads (each particle's own record), then those drawn in order */
#pragma omp parallel for schedule(dynamic, 256) num_threads(atmos__threads(ctx))
    for (int q = 0; q < count; q++) {
        s[q].col = pool + 2 * (size_t)o->nw * q, s[q].tc = s[q].col + o->nw;
        kept[q] = (unsigned char)prepare(pc, idx ? idx[q] : q, o, L, cam, rect, &s[q]);
    }
    for (int q = 0; q < count; q++)
        if (kept[q]) ord[n].key = s[q].z, ord[n].index = q, n++;
    free(kept), kept = NULL;
    atmos__keyed_sort(ord, (size_t)n, 1);
    int *list = bin_tiles(ctx, s, ord, n, rect, ntx, nty, cnt);
    if (!list) goto nomem;
    const int wide = cam->type != ATMOS_CAMERA_PINHOLE;
#pragma omp parallel for schedule(dynamic, 1) num_threads(atmos__threads(ctx))
    for (int t = 0; t < ntx * nty; t++) {
        const int tx = rect[0] + (t % ntx) * TILE, ty = rect[1] + (t / ntx) * TILE;
        double rays[TILE * TILE][3];
        if (wide && cnt[t + 1] > cnt[t]) tile_rays(cam, tx, ty, rays);
        for (int q = cnt[t]; q < cnt[t + 1]; q++) {
            if (wide) draw_wide(&s[list[q]], o->nw, cam, tx, ty, (const double(*)[3])rays, img);
            else draw(&s[list[q]], o->nw, cam, tx, ty, img);
        }
    }
    free(list), free(s), free(ord), free(cnt), free(pool);
    if (drawn) *drawn = n;
    return ATMOS_OK;
nomem:
    free(s), free(ord), free(cnt), free(pool), free(kept);
    return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for the splats");
}
