/* Harris 2002 §3.1, the head in the clouds (pcloud.h, atmos__pimpostor_screen): the cloud
 * holding the eye drawn as a screen-sized impostor at a reduced resolution, and, on request, its
 * nearer particles, whose splats are large on the image, in coarser depth layers still. Each
 * depth band along the view holds the same number of splats per pixel and metre, so without
 * layers every metre of cloud in view costs the same; a layer k times coarser costs k^2 less. */
#include "particles/pcloud.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { LAYERS = 4 }; /* 1/factor and up to three coarser, each half the last's resolution */

/* cam seen through ceil(W / F) x ceil(H / F) pixels F times its pitch about the same axis. */
static atmos_camera coarse(const atmos_camera *cam, int F)
{
    atmos_camera c = *cam;
    c.width = (cam->width + F - 1) / F, c.height = (cam->height + F - 1) / F;
    /* the same field of view over the rounded-up size: the small image covers the frame */
    c.tan_half_fov = cam->tan_half_fov * (double)c.height * F / cam->height;
    return c;
}

/* The layer of each particle idx[q] (lay[q]) among nl: layer l >= 1 holds the particles nearer
 * along the view than where the narrowest particle's splat is px pixels of layer l's image in
 * radius (at least: f CUT s / Z bounds it from below), the coarsest such layer. The bands are
 * by depth alone, so a layer lies wholly in front of the layers before it. */
static void bands(const atmos__pcloud *pc, const int *idx, int n, const atmos_camera *cam, int factor, double px, int nl,
                  unsigned char *lay)
{
    double smin = INFINITY, zc[LAYERS] = {0};
    for (int q = 0; q < n; q++) smin = fmin(smin, pc->s[idx ? idx[q] : q]);
    const double f = cam->height / (2.0 * cam->tan_half_fov);
    for (int l = 1; l < nl; l++) zc[l] = f / (double)(factor << l) * ATMOS__PCLOUD_CUT * smin / px;
    for (int q = 0; q < n; q++) {
        const int i = idx ? idx[q] : q;
        const double Z = (pc->x[i] - cam->position[0]) * cam->forward[0] + (pc->y[i] - cam->position[1]) * cam->forward[1] +
                         (pc->z[i] - cam->position[2]) * cam->forward[2];
        int l = 0;
        while (l + 1 < nl && Z <= zc[l + 1]) l++;
        lay[q] = (unsigned char)l;
    }
}

/* Lays the layers lo[1..nl) over lo[0] (1/factor), each pixel of lo[0] reading layer l
 * bilinearly at its own centre, the farther layers first. */
static void merge(atmos_context *ctx, atmos_image *const *lo, int nl)
{
    const int w = lo[0]->width, h = lo[0]->height, C = lo[0]->channels;
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (int y = 0; y < h; y++)
        for (int l = 1; l < nl; l++) {
            const double k = 1.0 / (1 << l), wl = lo[l]->width, hl = lo[l]->height;
            const double ty = (y + 0.5 - 0.5 * h) * k + 0.5 * hl - 0.5;
            for (int x = 0; x < w; x++)
                atmos__pcloud_over(lo[l]->pixels, lo[l]->width, lo[l]->height, C, (x + 0.5 - 0.5 * w) * k + 0.5 * wl - 0.5, ty,
                                   lo[0]->pixels + ((size_t)y * w + x) * C);
        }
}

/* Splats each layer's particles into its image: lo[l] for cam at 1/(factor 2^l). */
static atmos_status splat_layers(atmos_context *ctx, const atmos__pcloud *pc, const atmos__poptics *o,
                                 const atmos__plights *L, const int *idx, int nidx, const unsigned char *lay, int nl,
                                 const atmos_camera *cam, int factor, int C, atmos_image **lo)
{
    int *list = nl > 1 ? malloc(sizeof(int) * (size_t)(nidx ? nidx : 1)) : NULL;
    if (nl > 1 && !list) return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for the layers");
    atmos_status st = ATMOS_OK;
    for (int l = 0; l < nl && st == ATMOS_OK; l++) {
        const atmos_camera small = coarse(cam, factor << l);
        if ((st = atmos_image_create(ctx, small.width, small.height, C, &lo[l])) != ATMOS_OK) break;
        memset(lo[l]->pixels, 0, sizeof(float) * (size_t)small.width * small.height * C);
        const int all[4] = {0, 0, small.width, small.height};
        if (nl == 1) { /* one layer: every particle, in the caller's list */
            st = atmos__pcloud_splat(ctx, pc, o, L, idx, nidx, &small, all, lo[l], NULL);
            break;
        }
        int m = 0;
        for (int q = 0; q < nidx; q++)
            if (lay[q] == l) list[m++] = idx ? idx[q] : q;
        if (m) st = atmos__pcloud_splat(ctx, pc, o, L, list, m, &small, all, lo[l], NULL);
    }
    free(list);
    return st;
}

/* Lays lo (1/factor of img's pixels per axis) over img within rect, read bilinearly: what
 * atmos__pcloud_over does pixel by pixel, with the same arithmetic, but the columns' texels and
 * weights found once and three wavelengths' rows in a loop the compiler can unroll. */
static atmos_status lay_over(atmos_context *ctx, const atmos_image *lo, int factor, const int rect[4], atmos_image *img)
{
    const int w = lo->width, h = lo->height, C = img->channels, n = rect[2] - rect[0];
    int *i0 = malloc(sizeof(int) * (size_t)n);
    float *bx = malloc(sizeof(float) * (size_t)n);
    if (!i0 || !bx) {
        free(i0), free(bx);
        return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for the screen impostor");
    }
    for (int j = 0; j < n; j++) {
        double tx = (rect[0] + j + 0.5) / factor - 0.5;
        tx = tx > 0.0 ? (tx < w - 1.001 ? tx : w - 1.001) : 0.0;
        i0[j] = (int)tx, bx[j] = (float)(tx - i0[j]);
    }
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (int y = rect[1]; y < rect[3]; y++) {
        float *row = img->pixels + ((size_t)y * img->width + rect[0]) * C;
        if (C != 4) {
            for (int x = rect[0]; x < rect[2]; x++)
                atmos__pcloud_over(lo->pixels, w, h, C, (x + 0.5) / factor - 0.5, (y + 0.5) / factor - 0.5,
                                   row + (size_t)(x - rect[0]) * C);
            continue;
        }
        double ty = (y + 0.5) / factor - 0.5;
        ty = ty > 0.0 ? (ty < h - 1.001 ? ty : h - 1.001) : 0.0;
        const int j0 = (int)ty;
        const float by = (float)(ty - j0);
        const float *r0 = lo->pixels + (size_t)j0 * w * 4, *r1 = r0 + (size_t)w * 4;
        for (int j = 0; j < n; j++) {
            const float *t00 = r0 + (size_t)i0[j] * 4, *t10 = r1 + (size_t)i0[j] * 4, b = bx[j];
            float q[4], *px = row + (size_t)j * 4;
            for (int k = 0; k < 4; k++) q[k] = (1 - by) * ((1 - b) * t00[k] + b * t00[k + 4]) + by * ((1 - b) * t10[k] + b * t10[k + 4]);
            const float keep4 = 1.0f - q[3];
            for (int k = 0; k < 3; k++) px[k] = px[k] * keep4 + q[k];
            px[3] = 1.0f - (1.0f - px[3]) * keep4;
        }
    }
    free(i0), free(bx);
    return ATMOS_OK;
}

atmos_status atmos__pimpostor_screen(atmos_context *ctx, const atmos__pcloud *pc, const atmos__poptics *o,
                                     const atmos__plights *L, const int *idx, int nidx, const atmos_camera *cam,
                                     int factor, double layer_px, const int rect[4], atmos_image *img)
{
    const int C = img->channels;
    int nl = 1;
    if (layer_px > 0) /* as many layers as leave the coarsest at least 2 x 2 pixels */
        while (nl < LAYERS && (cam->width + (factor << nl) - 1) / (factor << nl) >= 2 &&
               (cam->height + (factor << nl) - 1) / (factor << nl) >= 2)
            nl++;
    unsigned char *lay = nl > 1 ? malloc((size_t)(nidx ? nidx : 1)) : NULL;
    if (nl > 1 && !lay) return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for the layers");
    if (nl > 1) bands(pc, idx, nidx, cam, factor, layer_px, nl, lay);
    atmos_image *lo[LAYERS] = {NULL};
    atmos_status st = splat_layers(ctx, pc, o, L, idx, nidx, lay, nl, cam, factor, C, lo);
    if (st == ATMOS_OK) {
        if (nl > 1) merge(ctx, lo, nl);
        st = lay_over(ctx, lo[0], factor, rect, img);
    }
    for (int l = 0; l < LAYERS; l++) atmos_image_destroy(lo[l]);
    free(lay);
    return st;
}
