/* Point lights and spotlights (lamp.h): their spectra and their falloff, shared by the beam
 * renderer and the path tracer. */
#include "light/lamp.h"
#include "scene/scene_internal.h"
#include "core/vec.h"
#include "image/png_size.h"

#include "atmos/image.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

/* A light's image at most this many texels: held as doubles with a border, its edges' counts
 * and the decoded floats, about 36 bytes a texel; and the counts stay within an int. */
#define LAMP_IMAGE_MAX_TEXELS (4096 * 4096)

/* Planck's law up to constants: the spectral radiance of a black body at T (K), nm. */
static double planck(double nm, double T)
{
    const double c2 = 1.438776877e7; /* h c / k, nm K */
    const double l = nm * 1e-3;      /* micrometres, to keep the numbers moderate */
    return 1.0 / (l * l * l * l * l * expm1(c2 / (nm * T)));
}

double atmos__lamp_spectrum(const atmos_scene_light *l, const atmos_wavelengths *wl, int k)
{
    if (l->colour_temperature_k > 0) {
        double band = 0;
        for (int i = 0; i < 400; i++) band += planck(380.5 + i, l->colour_temperature_k);
        return l->intensity_w_sr * planck(wl->nm[k], l->colour_temperature_k) / band;
    }
    const double c = wl->mode == ATMOS_WAVELENGTHS_RGB ? l->colour[k < 3 ? k : 2] : l->colour[0];
    return l->intensity_w_sr * c / 400.0;
}

double atmos__lamp_auto_range(double sigma_t)
{
    const double s = sigma_t > 0 ? sigma_t : 0, goal = log(1000.0) + s;
    double lo = 1, hi = 1000; /* g(r) = s r + ln r rises with r: g(1) = s < goal <= g(1000) */
    for (int i = 0; i < 60; i++) {
        const double m = 0.5 * (lo + hi);
        if (s * m + log(m) < goal) lo = m;
        else hi = m;
    }
    return hi;
}

void atmos__lamp_make(const atmos_scene_light *s, const atmos_wavelengths *wl, atmos__lamp *l)
{
    memset(l, 0, sizeof *l);
    l->type = s->type;
    memcpy(l->pos, s->position_m, sizeof l->pos);
    memcpy(l->axis, s->direction, sizeof l->axis);
    atmos__normalize3(l->axis);
    l->cos_inner = cos(s->cone_deg * ATMOS_DEG2RAD);
    l->cos_outer = cos((s->cone_deg + s->edge_deg) * ATMOS_DEG2RAD);
    if (l->cos_inner <= l->cos_outer) l->cos_outer = l->cos_inner - 1e-9; /* a hard edge */
    l->range = s->range_m;
    for (int k = 0; k < wl->count; k++) {
        l->I[k] = atmos__lamp_spectrum(s, wl, k);
        l->I_max = fmax(l->I_max, l->I[k]);
    }
}

double atmos__lamp_falloff(const atmos__lamp *l, const double p[3])
{
    if (l->type != ATMOS_LIGHT_SPOT) return 1;
    const double d[3] = {p[0] - l->pos[0], p[1] - l->pos[1], p[2] - l->pos[2]};
    const double r = sqrt(atmos__dot3(d, d));
    if (r == 0) return 1;
    return atmos__lamp_falloff_cos(l, atmos__dot3(d, l->axis) / r);
}

double atmos__lamp_toward(const atmos__lamp *l, const double p[3], int m, const int *k, double *out)
{
    const double f = atmos__lamp_falloff(l, p);
    double tint[3] = {1, 1, 1};
    if (l->tex && f > 0) atmos__lamp_tint(l, p, tint);
    for (int i = 0; i < m; i++) out[i] = f * l->I[k[i]] * tint[k[i] < 3 ? k[i] : 2];
    return f;
}

static double srgb_linear(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

/* The box of the image's texels that are not black (atmos__lamp's box). */
static void lit_box(atmos__lamp *l)
{
    int x0 = l->tw, x1 = -1, y0 = l->th, y1 = -1;
    for (int y = 0; y < l->th; y++)
        for (int x = 0; x < l->tw; x++) {
            const double *t = atmos__lamp_texel(l, x, y);
            if (t[0] != 0 || t[1] != 0 || t[2] != 0)
                x0 = x < x0 ? x : x0, x1 = x > x1 ? x : x1, y0 = y < y0 ? y : y0, y1 = y > y1 ? y : y1;
        }
    /* a look-up at fx reads the texels floor(fx) and floor(fx) + 1 (the border repeats the edges') */
    l->box[0] = x0 == 0 ? -1 : x0 - 1, l->box[1] = x1 == l->tw - 1 ? l->tw : x1 + 1;
    l->box[2] = y0 == 0 ? -1 : y0 - 1, l->box[3] = y1 == l->th - 1 ? l->th : y1 + 1;
    if (x1 < 0) l->box[0] = l->box[2] = 1, l->box[1] = l->box[3] = 0;
}

/* The running sums of the image's edges (atmos__lamp's edges): texel (x, y) differs from its
 * neighbour (x + dx, y + dy). */
static void edge_sums(const atmos__lamp *l, int dx, int dy, int *S)
{
    const int W = l->tw + 1;
    for (int x = 0; x < W; x++) S[x] = 0;
    for (int y = 0; y < l->th; y++) {
        S[(y + 1) * W] = 0;
        for (int x = 0; x < l->tw; x++) {
            int e = 0;
            if (x + dx < l->tw && y + dy < l->th) {
                const double *a = atmos__lamp_texel(l, x, y), *b = atmos__lamp_texel(l, x + dx, y + dy);
                e = a[0] != b[0] || a[1] != b[1] || a[2] != b[2];
            }
            S[(y + 1) * W + x + 1] = e + S[y * W + x + 1] + S[(y + 1) * W + x] - S[y * W + x];
        }
    }
}

atmos_status atmos__lamp_load_image(atmos_context *ctx, const atmos_scene *scene, int index, atmos__lamp *l)
{
    const atmos_scene_light *s = &scene->lights[index];
    if (!s->image[0]) return ATMOS_OK;
    uint32_t w = 0, h = 0;
    atmos_image *img = NULL;
    atmos_status st = ATMOS_OK;
    if (atmos__png_size(s->image, &w, &h) && (uint64_t)w * h > LAMP_IMAGE_MAX_TEXELS)
        st = atmos__error(ctx, ATMOS_E_LIMIT,
                          "%s: %u x %u texels; a light's image may have at most %d (4096 x 4096, about 0.6 GB as the "
                          "renderers hold it): scale it down", s->image, (unsigned)w, (unsigned)h, LAMP_IMAGE_MAX_TEXELS);
    else
        st = atmos_read_png(ctx, s->image, &img);
    if (st != ATMOS_OK) {
        /* the message names the file; the scene file and its key go in front, and a relative
         * path says where it was looked for */
        char key[48];
        snprintf(key, sizeof key, "/lights/%d/image", index);
        return atmos__scene_file_error(ctx, st, scene, s->image, key, 1);
    }
    const int W = img->width + 2, H = img->height + 2; /* a border of the edges' texels */
    l->tex = malloc(sizeof(double) * 3 * (size_t)W * H);
    if (!l->tex) {
        atmos_image_destroy(img);
        return atmos__error(ctx, ATMOS_E_NOMEM, "/lights/%d/image: %s: out of memory for a light's image", index, s->image);
    }
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const int xi = x < 1 ? 0 : x > img->width ? img->width - 1 : x - 1;
            const int yi = y < 1 ? 0 : y > img->height ? img->height - 1 : y - 1;
            const size_t i = (size_t)yi * img->width + xi;
            for (int c = 0; c < 3; c++) {
                const int ch = img->channels < 3 ? 0 : c;
                l->tex[3 * ((size_t)y * W + x) + c] = (float)srgb_linear(img->pixels[i * img->channels + ch]);
            }
        }
    l->tw = img->width, l->th = img->height;
    atmos_image_destroy(img);
    /* the image's frame: its up toward +y's side of the axis, or north for a vertical axis */
    const double ref[3] = {0, fabs(l->axis[1]) < 0.9 ? 1 : 0, fabs(l->axis[1]) < 0.9 ? 0 : -1};
    atmos__cross3(l->axis, ref, l->right);
    atmos__normalize3(l->right);
    atmos__cross3(l->right, l->axis, l->up);
    l->tan_max = tan(acos(atmos__clampd(l->cos_outer, -1, 1)));
    const size_t cells = (size_t)(l->tw + 1) * (l->th + 1);
    if (!(l->edges = malloc(sizeof(int) * 2 * cells))) {
        atmos__lamp_free(l);
        return atmos__error(ctx, ATMOS_E_NOMEM, "/lights/%d/image: %s: out of memory for a light's image", index, s->image);
    }
    lit_box(l);
    edge_sums(l, 1, 0, l->edges);
    edge_sums(l, 0, 1, l->edges + cells);
    return ATMOS_OK;
}

void atmos__lamp_free(atmos__lamp *l)
{
    free(l->tex);
    free(l->edges);
    l->tex = NULL, l->edges = NULL;
}

void atmos__lamp_tint(const atmos__lamp *l, const double p[3], double rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 1;
    if (!l->tex) return;
    const double w[3] = {p[0] - l->pos[0], p[1] - l->pos[1], p[2] - l->pos[2]};
    const double z = atmos__dot3(w, l->axis);
    rgb[0] = rgb[1] = rgb[2] = 0;
    if (!(z > 0)) return;
    double fx, fy;
    atmos__lamp_tint_coords(l, atmos__dot3(w, l->right), atmos__dot3(w, l->up), z, &fx, &fy);
    atmos__lamp_tint_at(l, fx, fy, rgb);
}

/* The edges counted in columns [x0, x1], rows [y0, y1] of the running sums S. */
static int edges_in(const atmos__lamp *l, const int *S, int x0, int x1, int y0, int y1)
{
    if (x1 < x0 || y1 < y0) return 0;
    const int W = l->tw + 1;
    return S[(y1 + 1) * W + x1 + 1] - S[y0 * W + x1 + 1] - S[(y1 + 1) * W + x0] + S[y0 * W + x0];
}

int atmos__lamp_tint_same(const atmos__lamp *l, double fx0, double fx1, double fy0, double fy1, double rgb[3])
{
    const double m = 1e-6; /* texels: the coordinates' rounding along a run is far smaller */
    rgb[0] = rgb[1] = rgb[2] = 0;
    if (!l->tex || fx1 < -1 - m || fx0 > l->tw + m || fy1 < -1 - m || fy0 > l->th + m) return l->tex != NULL;
    if (!(fx0 > -1 + m && fx1 < l->tw - m && fy0 > -1 + m && fy1 < l->th - m)) return 0; /* across the image's edge */
    const int x0 = (int)floor(fx0 - m), x1 = (int)floor(fx1 + m) + 1, y0 = (int)floor(fy0 - m), y1 = (int)floor(fy1 + m) + 1;
    const int ca = x0 < 0 ? 0 : x0, cb = x1 >= l->tw ? l->tw - 1 : x1, ra = y0 < 0 ? 0 : y0, rb = y1 >= l->th ? l->th - 1 : y1;
    const int cells = (l->tw + 1) * (l->th + 1);
    if (edges_in(l, l->edges, ca, cb - 1, ra, rb) || edges_in(l, l->edges + cells, ca, cb, ra, rb - 1)) return 0;
    const double *t = atmos__lamp_texel(l, ca, ra);
    for (int c = 0; c < 3; c++) rgb[c] = t[c];
    return 1;
}

int atmos__lamp_clip(const atmos__lamp *l, const double e[3], const double d[3], double *t0, double *t1)
{
    if (l->type != ATMOS_LIGHT_SPOT) return 1;
    const double w[3] = {e[0] - l->pos[0], e[1] - l->pos[1], e[2] - l->pos[2]}, c2 = l->cos_outer * l->cos_outer;
    const double wa = atmos__dot3(w, l->axis), da = atmos__dot3(d, l->axis);
    const double A = da * da - c2, B = 2 * (wa * da - c2 * atmos__dot3(w, d)), C = wa * wa - c2 * atmos__dot3(w, w);
    /* the cuts: the quadric's two roots and where the ray crosses the light's plane (w.a = 0,
     * which parts the quadric's two nappes: a cone of 90 deg is the plane itself, its quadric
     * the plane counted twice, whose roots are rounding noise) */
    double cut[5] = {*t0, *t0, *t0, *t1, *t1};
    const double disc = B * B - 4 * A * C;
    if (disc > 0 && A != 0) {
        const double q = -0.5 * (B + copysign(sqrt(disc), B)), r1 = q / A, r2 = C / q;
        cut[1] = atmos__clampd(fmin(r1, r2), *t0, *t1), cut[3] = atmos__clampd(fmax(r1, r2), *t0, *t1);
    }
    cut[2] = da != 0 ? atmos__clampd(-wa / da, *t0, *t1) : *t0;
    for (int k = 2; k > 0 && cut[k] < cut[k - 1]; k--) { /* in order */
        const double x = cut[k];
        cut[k] = cut[k - 1], cut[k - 1] = x;
    }
    if (cut[2] > cut[3]) {
        const double x = cut[2];
        cut[2] = cut[3], cut[3] = x;
    }
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < 4; k++) {
        if (!(cut[k + 1] > cut[k])) continue;
        const double tm = 0.5 * (cut[k] + cut[k + 1]);
        const double P[3] = {e[0] + tm * d[0], e[1] + tm * d[1], e[2] + tm * d[2]};
        if (atmos__lamp_falloff(l, P) > 0) lo = fmin(lo, cut[k]), hi = fmax(hi, cut[k + 1]);
    }
    if (!(lo < hi)) return 0;
    *t0 = lo, *t1 = hi;
    return 1;
}
