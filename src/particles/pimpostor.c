/* Harris 2002 §3's dynamically generated impostors (pcloud.h): a cloud drawn once into a
 * texture from the eye, shown on a plane through its centre facing where it was made from,
 * made again when the eye has moved too far round it (the translation error) or too near to
 * it (the resolution error). */
#include "particles/pcloud.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int atmos__pimpostor_res(double r, double d, double f, int max_res)
{
    const double px = d > r ? 2.0 * r * f / d : max_res;
    int res = 8 * (int)ceil(fmax(px, 8.0) / 8.0);
    return res < max_res ? res : max_res;
}

int atmos__pimpostor_max_res(double r, double smin, int max_res)
{
    if (!(smin > 0)) return max_res;
    const double res = 8.0 * ceil(2.0 * r * ATMOS__PIMPOSTOR_TEXELS_PER_WIDTH / smin / 8.0);
    return res < 8.0 ? 8 : (res < max_res ? (int)res : max_res);
}

int atmos__pimpostor_serves(const atmos__pimpostor *im, const double c[3], double r, const double e[3], double tol,
                            double f, int max_res)
{
    if (!im->valid) return 0;
    double a[3], b[3], la = 0, lb = 0, ab = 0;
    for (int i = 0; i < 3; i++) a[i] = im->view[i] - c[i], b[i] = e[i] - c[i];
    for (int i = 0; i < 3; i++) la += a[i] * a[i], lb += b[i] * b[i], ab += a[i] * b[i];
    if (lb <= r * r) return 0; /* the eye inside the cloud's sphere */
    const double cosang = ab / sqrt(la * lb);
    if (cosang < cos(tol)) return 0;
    return atmos__pimpostor_res(r, sqrt(lb), f, max_res) <= im->res;
}

double atmos__pimpostor_error(const atmos__pimpostor *im, const double c[3], double r, const double e[3], double tol,
                              double f, int max_res)
{
    if (!im->valid) return INFINITY;
    double a[3], b[3], la = 0, lb = 0, ab = 0;
    for (int i = 0; i < 3; i++) a[i] = im->view[i] - c[i], b[i] = e[i] - c[i];
    for (int i = 0; i < 3; i++) la += a[i] * a[i], lb += b[i] * b[i], ab += a[i] * b[i];
    if (lb <= r * r) return INFINITY;
    const double ang = acos(fmax(-1.0, fmin(1.0, ab / sqrt(la * lb))));
    const double texels = (double)atmos__pimpostor_res(r, sqrt(lb), f, max_res) / im->res;
    return fmax(tol > 0 ? ang / tol : (ang > 0 ? INFINITY : 0.0), texels);
}

/* im->box: the texels of im's image with any value other than 0 (empty: x0 = x1 = 0). */
static void texel_box(atmos__pimpostor *im)
{
    const int R = im->res, C = im->img->channels;
    int x0 = R, x1 = 0, y0 = R, y1 = 0;
    for (int y = 0; y < R; y++) {
        const float *row = im->img->pixels + (size_t)y * R * C;
        int a = 0, b = R * C;
        while (a < b && row[a] == 0.0f) a++;
        if (a == b) continue;
        while (row[b - 1] == 0.0f) b--;
        x0 = a / C < x0 ? a / C : x0, x1 = (b - 1) / C + 1 > x1 ? (b - 1) / C + 1 : x1;
        y0 = y < y0 ? y : y0, y1 = y + 1;
    }
    im->has_box = 1;
    im->box[0] = x0 < x1 ? x0 : 0, im->box[1] = x0 < x1 ? x1 : 0, im->box[2] = y0, im->box[3] = y1;
}

atmos_status atmos__pimpostor_make_rows(atmos_context *ctx, atmos__pimpostor *im, const atmos__pcloud *pc,
                                        const atmos__poptics *o, const atmos__plights *L, const int *idx, int nidx,
                                        const double c[3], double r, const double e[3], int res, int y0, int y1)
{
    atmos_status st = ATMOS_OK;
    if (y0 == 0) {
        double d = 0;
        for (int i = 0; i < 3; i++) d += (c[i] - e[i]) * (c[i] - e[i]);
        d = sqrt(d);
        if (!(d > r)) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "particles: an impostor seen from inside its cloud");
        atmos_camera_desc cd;
        memset(&cd, 0, sizeof cd);
        cd.type = ATMOS_CAMERA_PINHOLE;
        memcpy(cd.position, e, sizeof cd.position), memcpy(cd.look_at, c, sizeof cd.look_at);
        const double fwd_y = (c[1] - e[1]) / d;
        cd.up[0] = 0, cd.up[1] = fabs(fwd_y) > 0.99 ? 0 : 1, cd.up[2] = fabs(fwd_y) > 0.99 ? -1 : 0;
        cd.fov_deg = 2.0 * asin(r / d) * 180.0 / ATMOS_PI;
        im->valid = 0;
        st = atmos_camera_init(ctx, &cd, res, res, &im->cam);
        if (st == ATMOS_OK && (!im->img || im->img->width != res)) {
            atmos_image_destroy(im->img), im->img = NULL;
            st = atmos_image_create(ctx, res, res, o->nw + 1, &im->img);
        }
        if (st != ATMOS_OK) return st;
        memset(im->img->pixels, 0, sizeof(float) * (size_t)res * res * (o->nw + 1));
    }
    const int rect[4] = {0, y0, res, y1};
    if ((st = atmos__pcloud_splat(ctx, pc, o, L, idx, nidx, &im->cam, rect, im->img, NULL)) != ATMOS_OK) return st;
    if (y1 < res) return ATMOS_OK;
    memcpy(im->view, e, sizeof im->view);
    im->res = res, im->valid = 1;
    texel_box(im);
    return ATMOS_OK;
}

atmos_status atmos__pimpostor_make(atmos_context *ctx, atmos__pimpostor *im, const atmos__pcloud *pc,
                                   const atmos__poptics *o, const atmos__plights *L, const int *idx, int nidx,
                                   const double c[3], double r, const double e[3], int res)
{
    return atmos__pimpostor_make_rows(ctx, im, pc, o, L, idx, nidx, c, r, e, res, 0, res);
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* A frame row's rays against an impostor: the point where pixel x's ray F + v U + u R meets the
 * impostor's plane (through c, normal nrm), at s = ce / (d . nrm) along it, seen from the
 * impostor's camera is a quotient of functions linear in u, these its coefficients. */
typedef struct row_coef {
    double W, H, t, R, fk, ce, bn, rn, px, py, pz, bx, by, bz, rx, ry, rz;
} row_coef;

enum { ROW_CHUNK = 128 };

/* The texel coordinates (tx, ty) of pixels [x0, x0 + n) of the row (n <= ROW_CHUNK), and ok[i]
 * 0 where the pixel's ray misses the texture (parallel to the plane, the plane behind the eye or
 * behind the impostor's camera, outside the texels). Every pixel's values computed, then
 * selected: one vector loop (4 pixels a vector in the AVX2 clone), the same operations in the
 * same order, so the same bits, as a pixel at a time. */
ATMOS_CLONES
static void row_texels(const row_coef *k, int x0, int n, double *restrict tx, double *restrict ty, double *restrict ok)
{
    const double W = k->W, H = k->H, t = k->t, R = k->R, fk = k->fk, ce = k->ce, bn = k->bn, rn = k->rn;
    const double px = k->px, py = k->py, pz = k->pz, bx = k->bx, by = k->by, bz = k->bz, rx = k->rx, ry = k->ry,
                 rz = k->rz;
    for (int i = 0; i < n; i++) {
        const double u = (2.0 * (x0 + i + 0.5) - W) / H * t, dn = bn + u * rn;
        const double s = ce / dn, Z = pz + s * (bz + u * rz), q = fk / Z;
        const double a = 0.5 * R + q * (px + s * (bx + u * rx)) - 0.5, b = 0.5 * R - q * (py + s * (by + u * ry)) - 0.5;
        const int in = fabs(dn) > 1e-12 && !(s <= 0) && Z > 0 && !(a < -0.5 || b < -0.5 || a > R - 0.5 || b > R - 0.5);
        tx[i] = a, ty[i] = b, ok[i] = in ? 1.0 : 0.0;
    }
}

/* Pixel row y of the frame: the impostor over [x0, x1), a chunk of pixels' texel coordinates at
 * a time (row_texels), then each pixel that reads the texture composited. */
static void draw_row(const atmos__pimpostor *im, const double c[3], const double nrm[3], const atmos_camera *cam, int y,
                     int x0, int x1, atmos_image *img)
{
    const int C = img->channels, R = im->res;
    const atmos_camera *k = &im->cam;
    const double H = cam->height, t = cam->tan_half_fov, v = (H - 2.0 * (y + 0.5)) / H * t;
    double B[3], P[3], cr[3];
    for (int i = 0; i < 3; i++)
        B[i] = cam->forward[i] + v * cam->up[i], P[i] = cam->position[i] - k->position[i], cr[i] = c[i] - cam->position[i];
    const row_coef rc = {cam->width, H, t, R, k->height / (2.0 * k->tan_half_fov), dot3(cr, nrm), dot3(B, nrm),
                         dot3(cam->right, nrm), dot3(P, k->right), dot3(P, k->up), dot3(P, k->forward),
                         dot3(B, k->right), dot3(B, k->up), dot3(B, k->forward), dot3(cam->right, k->right),
                         dot3(cam->right, k->up), dot3(cam->right, k->forward)};
    double tx[ROW_CHUNK], ty[ROW_CHUNK], ok[ROW_CHUNK];
    float *row = img->pixels + (size_t)y * cam->width * C;
    for (int xa = x0; xa < x1; xa += ROW_CHUNK) {
        const int n = x1 - xa < ROW_CHUNK ? x1 - xa : ROW_CHUNK;
        row_texels(&rc, xa, n, tx, ty, ok);
        for (int i = 0; i < n; i++)
            if (ok[i] != 0.0) atmos__pcloud_over(im->img->pixels, R, R, C, tx[i], ty[i], row + (size_t)(xa + i) * C);
    }
}

/* Shrinks bb (cam's pixels) to those whose rays read a texel of im's box: the box widened by
 * two texels (a bilinear read takes the texels on both sides, and one clamped at the texture's
 * edge the one before the last) is a quad on the impostor's plane
 * (through c, normal nrm), and its corners' pixels bound it. Returns 0 when im holds nothing;
 * bb is kept as it was when a corner is not in front of the eye. */
static int shrink_to_texels(const atmos__pimpostor *im, const double c[3], const double nrm[3], const atmos_camera *cam,
                            int bb[4])
{
    if (!im->has_box) return 1;
    if (im->box[0] >= im->box[1]) return 0;
    const atmos_camera *k = &im->cam;
    const double R = im->res, fk = k->height / (2.0 * k->tan_half_fov), W = cam->width, H = cam->height;
    const double t = cam->tan_half_fov;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, ck[3];
    for (int i = 0; i < 3; i++) ck[i] = c[i] - k->position[i];
    for (int corner = 0; corner < 4; corner++) {
        const double tx = corner & 1 ? im->box[1] + 1 : im->box[0] - 2, ty = corner & 2 ? im->box[3] + 1 : im->box[2] - 2;
        const double a = (tx + 0.5 - 0.5 * R) / fk, b = (0.5 * R - 0.5 - ty) / fk;
        double dir[3], rel[3];
        for (int i = 0; i < 3; i++) dir[i] = k->forward[i] + a * k->right[i] + b * k->up[i];
        const double dn = dot3(dir, nrm);
        if (!(fabs(dn) > 1e-12)) return 1;
        const double s = dot3(ck, nrm) / dn;
        for (int i = 0; i < 3; i++) rel[i] = k->position[i] + s * dir[i] - cam->position[i];
        const double Z = dot3(rel, cam->forward);
        if (!(Z > 1e-9 * sqrt(dot3(rel, rel)))) return 1;
        const double x = 0.5 * (dot3(rel, cam->right) / Z * H / t + W) - 0.5;
        const double y = 0.5 * (H - dot3(rel, cam->up) / Z * H / t) - 0.5;
        lo[0] = fmin(lo[0], x), hi[0] = fmax(hi[0], x), lo[1] = fmin(lo[1], y), hi[1] = fmax(hi[1], y);
    }
    /* a pixel's whole index range round the corners' bounds, and one more on each side */
    for (int a = 0; a < 2; a++) {
        const double l = floor(lo[a]) - 1, h = ceil(hi[a]) + 2;
        if (l > bb[2 * a]) bb[2 * a] = l < bb[2 * a + 1] ? (int)l : bb[2 * a + 1];
        if (h < bb[2 * a + 1]) bb[2 * a + 1] = h > bb[2 * a] ? (int)h : bb[2 * a];
    }
    return bb[0] < bb[1] && bb[2] < bb[3];
}

void atmos__pimpostor_draw(atmos_context *ctx, int n, const atmos__pimpostor *const *ims, const double *const *c,
                           const double *r, const atmos_camera *cam, const int rect[4], atmos_image *img)
{
    /* in chunks of 64 impostors (far to near, so the order holds), each chunk one pass over its
     * rows on the threads: a row draws every impostor it meets in order, so a pixel sees the
     * same order whatever thread draws it */
    enum { CHUNK = 64 };
    for (int q0 = 0; q0 < n; q0 += CHUNK) {
        int bb[CHUNK][4], use[CHUNK], m = 0, y0 = rect[3], y1 = rect[1];
        double nrm[CHUNK][3];
        for (int q = q0; q < n && q < q0 + CHUNK; q++) {
            double l = 0, Z;
            /* (the caller splats clouds near or behind the eye) */
            if (!atmos__pcloud_screen_box(cam, c[q], r[q], rect, bb[m], &Z)) continue;
            for (int i = 0; i < 3; i++) nrm[m][i] = ims[q]->view[i] - c[q][i], l += nrm[m][i] * nrm[m][i];
            for (int i = 0; i < 3; i++) nrm[m][i] /= sqrt(l);
            if (!shrink_to_texels(ims[q], c[q], nrm[m], cam, bb[m])) continue;
            y0 = bb[m][2] < y0 ? bb[m][2] : y0, y1 = bb[m][3] > y1 ? bb[m][3] : y1;
            use[m++] = q;
        }
#pragma omp parallel for schedule(dynamic, 8) num_threads(atmos__threads(ctx))
        for (int y = y0; y < y1; y++)
            for (int j = 0; j < m; j++)
                if (y >= bb[j][2] && y < bb[j][3]) draw_row(ims[use[j]], c[use[j]], nrm[j], cam, y, bb[j][0], bb[j][1], img);
    }
}

void atmos__pimpostor_free(atmos__pimpostor *im)
{
    atmos_image_destroy(im->img);
    memset(im, 0, sizeof *im);
}
