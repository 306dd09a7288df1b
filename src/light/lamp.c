/* Point lights and spotlights (lamp.h): their spectra and their falloff, shared by the beam
 * renderer and the path tracer. */
#include "light/lamp.h"
#include "scene/scene_internal.h"
#include "core/vec.h"

#include "atmos/image.h"

#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

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

atmos_status atmos__lamp_load_image(atmos_context *ctx, const atmos_scene *scene, int index, atmos__lamp *l)
{
    const atmos_scene_light *s = &scene->lights[index];
    if (!s->image[0]) return ATMOS_OK;
    atmos_image *img = NULL;
    atmos_status st = atmos_read_png(ctx, s->image, &img);
    if (st != ATMOS_OK) {
        /* the reader's message names the file; the scene file and its key go in front, and a
         * relative path says where it was looked for */
        char key[48];
        snprintf(key, sizeof key, "/lights/%d/image", index);
        return atmos__scene_file_error(ctx, st, scene, s->image, key, 1);
    }
    const size_t n = (size_t)img->width * img->height;
    l->tex = malloc(sizeof(float) * 3 * n);
    if (!l->tex) {
        atmos_image_destroy(img);
        return atmos__error(ctx, ATMOS_E_NOMEM, "/lights/%d/image: %s: out of memory for a light's image", index, s->image);
    }
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            const int ch = img->channels < 3 ? 0 : c;
            l->tex[3 * i + c] = (float)srgb_linear(img->pixels[i * img->channels + ch]);
        }
    l->tw = img->width, l->th = img->height;
    atmos_image_destroy(img);
    /* the image's frame: its up toward +y's side of the axis, or north for a vertical axis */
    const double ref[3] = {0, fabs(l->axis[1]) < 0.9 ? 1 : 0, fabs(l->axis[1]) < 0.9 ? 0 : -1};
    atmos__cross3(l->axis, ref, l->right);
    atmos__normalize3(l->right);
    atmos__cross3(l->right, l->axis, l->up);
    l->tan_max = tan(acos(atmos__clampd(l->cos_outer, -1, 1)));
    return ATMOS_OK;
}

void atmos__lamp_free(atmos__lamp *l)
{
    free(l->tex);
    l->tex = NULL;
}

void atmos__lamp_tint(const atmos__lamp *l, const double p[3], double rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 1;
    if (!l->tex) return;
    const double w[3] = {p[0] - l->pos[0], p[1] - l->pos[1], p[2] - l->pos[2]};
    const double z = atmos__dot3(w, l->axis);
    rgb[0] = rgb[1] = rgb[2] = 0;
    if (!(z > 0)) return;
    const double x = atmos__dot3(w, l->right) / (z * l->tan_max), y = atmos__dot3(w, l->up) / (z * l->tan_max);
    const double fx = 0.5 * (x + 1) * l->tw - 0.5, fy = 0.5 * (1 - y) * l->th - 0.5;
    if (!(fx > -1 && fx < l->tw && fy > -1 && fy < l->th)) return;
    const int x0 = (int)floor(fx), y0 = (int)floor(fy);
    const double ax = fx - x0, ay = fy - y0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            const int xi = x0 + i < 0 ? 0 : x0 + i >= l->tw ? l->tw - 1 : x0 + i;
            const int yj = y0 + j < 0 ? 0 : y0 + j >= l->th ? l->th - 1 : y0 + j;
            const double wt = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
            const float *t = l->tex + 3 * ((size_t)yj * l->tw + xi);
            for (int c = 0; c < 3; c++) rgb[c] += wt * t[c];
        }
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
