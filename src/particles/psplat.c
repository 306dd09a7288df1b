/* The particles' eye pass (pcloud.h, atmos__pcloud_splat): Harris's back-to-front splatting
 * on the CPU. The particles are sorted far to near, binned into tiles of the image, and each
 * tile composites its own list in that order, so a tile's pixels see every particle in the
 * same order whatever thread draws it. */
#include "particles/pcloud.h"
#include "core/fastmath.h"
#include "core/internal.h"
#include "optics/optics_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TILE 32
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
        if (o->ms[fi]) atmos__msphase_eval_all(o->ms[fi], o->nw, L->order[j][p] + 1.0, mu, ph);
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

/* Composites splat q over the pixels of its box inside tile (tx, ty). Pixel (x, y)'s ray is
 * d = F + u R + v U (u, v: the pixel's place on the image plane at unit distance); its squared
 * distance from the centre is b^2 = |rel x d|^2 / |d|^2, and along a row both are quadratics in
 * u: b^2 = (a0 + a1 u + a2 u^2) / (e0 + e1 u + e2 u^2), the coefficients once per row (double:
 * a0 is |rel|^2 |d|^2, b^2 a small difference). The row's column depths go through a
 * branch-free loop first (vectorised), then the pixels inside the cut are composited. */
__attribute__((target_clones("avx2", "default"))) static void draw(const sp *q, int nw, const atmos_camera *cam, int tx,
                                                                    int ty, atmos_image *img)
{
    const int x0 = q->bb[0] > tx ? q->bb[0] : tx, x1 = q->bb[1] < tx + TILE ? q->bb[1] : tx + TILE;
    const int y0 = q->bb[2] > ty ? q->bb[2] : ty, y1 = q->bb[3] < ty + TILE ? q->bb[3] : ty + TILE;
    const double W = cam->width, H = cam->height, t = cam->tan_half_fov, k2 = 1.0 / (q->s * q->s);
    const float *tc = q->tc, *col = q->col;
    const double rc2 = ATMOS__PCLOUD_CUT * ATMOS__PCLOUD_CUT * q->s * q->s;
    const double *F = cam->forward, *R = cam->right, *U = cam->up;
    double rel[3], Q[3];
    for (int i = 0; i < 3; i++) rel[i] = q->c[i] - cam->position[i];
    cross(rel, R, Q);
    const double a2 = dot(Q, Q), e2 = dot(R, R), du = 2.0 * t / H, u0 = (2.0 * x0 + 1.0 - W) / H * t;
    /* the row's loops run over whole vectors of 8 (nn: n rounded up, at most TILE; the values
     * past n are not used): no scalar remainder loops */
    const int C = img->channels, n = x1 - x0, nn = (n + 7) & ~7;
    double b2[TILE];
    float g[TILE], T[ATMOS_MAX_WAVELENGTHS][TILE];
    for (int y = y0; y < y1; y++) {
        const double v = (H - 2.0 * (y + 0.5)) / H * t;
        double D[3], P[3];
        for (int i = 0; i < 3; i++) D[i] = F[i] + v * U[i];
        cross(rel, D, P);
        const double a0 = dot(P, P), a1 = 2.0 * dot(P, Q), e0 = dot(D, D), e1 = 2.0 * dot(D, R);
        for (int j = 0; j < nn; j++) {
            const double u = u0 + j * du;
            b2[j] = (a0 + u * (a1 + u * a2)) / (e0 + u * (e1 + u * e2));
        }
        for (int j = 0; j < nn; j++) g[j] = atmos__pcloud_column((float)(b2[j] * k2));
        /* the transmittances wavelength by wavelength over the row (vectorised), then the
         * pixels within the cut composited with them */
        for (int k = 0; k < nw; k++)
            for (int j = 0; j < nn; j++) T[k][j] = atmos__expf_fast(-tc[k] * g[j]);
        float *row = img->pixels + ((size_t)y * cam->width + x0) * C;
        if (nw == 3 && C == 4) {
            /* three wavelengths and coverage: every value v of the row becomes v t + c (1 - t),
             * t = 1 (the pixel left as it is, exactly) beyond the cut, the coverage's t the
             * mean transmittance and c = 1 (1 - (1 - v) t); one loop over the row's values */
            float TT[4 * TILE];
            const float c4[4] = {col[0], col[1], col[2], 1.0f};
            for (int j = 0; j < n; j++) {
                const int in = b2[j] <= rc2;
                const float t0 = in ? T[0][j] : 1.0f, t1 = in ? T[1][j] : 1.0f, t2 = in ? T[2][j] : 1.0f;
                TT[4 * j] = t0, TT[4 * j + 1] = t1, TT[4 * j + 2] = t2, TT[4 * j + 3] = in ? (t0 + t1 + t2) / 3.0f : 1.0f;
            }
            for (int i = 0; i < 4 * n; i++) row[i] = row[i] * TT[i] + c4[i & 3] * (1.0f - TT[i]);
            continue;
        }
        for (int j = 0; j < n; j++) {
            if (b2[j] > rc2) continue;
            float *px = row + (size_t)j * C, tm = 0;
            for (int k = 0; k < nw; k++) {
                px[k] = px[k] * T[k][j] + col[k] * (1.0f - T[k][j]);
                tm += T[k][j];
            }
            px[nw] = 1.0f - (1.0f - px[nw]) * tm / nw;
        }
    }
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
    int n = 0;
    if (!s || !ord || !cnt || !pool) goto nomem;
    for (int q = 0; q < count; q++) {
        s[n].col = pool + 2 * (size_t)o->nw * n, s[n].tc = s[n].col + o->nw;
        if (prepare(pc, idx ? idx[q] : q, o, L, cam, rect, &s[n])) ord[n].key = s[n].z, ord[n].index = n, n++;
    }
    atmos__keyed_sort(ord, (size_t)n, 1);
    /* tile lists: counts, offsets, then the splats in far-to-near order */
    for (int q = 0; q < n; q++) {
        const sp *a = &s[ord[q].index];
        for (int ty = (a->bb[2] - rect[1]) / TILE; ty <= (a->bb[3] - 1 - rect[1]) / TILE; ty++)
            for (int tx = (a->bb[0] - rect[0]) / TILE; tx <= (a->bb[1] - 1 - rect[0]) / TILE; tx++) cnt[ty * ntx + tx + 1]++;
    }
    for (int t = 0; t < ntx * nty; t++) cnt[t + 1] += cnt[t];
    int *list = malloc(sizeof(int) * (size_t)(cnt[ntx * nty] ? cnt[ntx * nty] : 1)), *fill = calloc((size_t)ntx * nty, sizeof(int));
    if (!list || !fill) {
        free(list), free(fill);
        goto nomem;
    }
    for (int q = 0; q < n; q++) {
        const sp *a = &s[ord[q].index];
        for (int ty = (a->bb[2] - rect[1]) / TILE; ty <= (a->bb[3] - 1 - rect[1]) / TILE; ty++)
            for (int tx = (a->bb[0] - rect[0]) / TILE; tx <= (a->bb[1] - 1 - rect[0]) / TILE; tx++)
                list[cnt[ty * ntx + tx] + fill[ty * ntx + tx]++] = ord[q].index;
    }
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
    free(list), free(fill), free(s), free(ord), free(cnt), free(pool);
    if (drawn) *drawn = n;
    return ATMOS_OK;
nomem:
    free(s), free(ord), free(cnt), free(pool);
    return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for the splats");
}
