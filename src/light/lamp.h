/* The scene's point lights and spotlights as every renderer sees them (docs/beams.md,
 * docs/path.md): position, axis, the spot's cone with its smooth falloff, the spectral
 * intensity on the axis (a black body's or an rgb colour's). One evaluation for the beam
 * renderer and the path tracer, so that both see the same light. Not part of the API. */
#ifndef ATMOS_LIGHT_LAMP_H
#define ATMOS_LIGHT_LAMP_H

#include "core/clones.h"
#include "core/internal.h"
#include "atmos/scene.h"

#include <math.h>

typedef struct atmos__lamp {
    atmos_light_type type;
    double pos[3], axis[3];
    double cos_inner, cos_outer; /* spot: full within cos_inner, zero beyond cos_outer */
    double range;
    double I[ATMOS_MAX_WAVELENGTHS]; /* spectral intensity on the axis, W sr^-1 nm^-1 */
    double I_max;                /* the largest of I */
    /* a spot's projected image (stained glass; NULL: none): tw x th linear rgb texels, row 0
     * at the top, spanning [-tan_max, tan_max]^2 of the plane at unit distance along the axis
     * (right, up: the image's axes there), in a border of a texel that repeats the edges' (so
     * that a bilinear look-up need not clamp: atmos__lamp_texel); each the float of the linear
     * value, kept as a double (a look-up's products then read it without a conversion) */
    double *tex;
    int tw, th;
    double tan_max, right[3], up[3];
    /* the image's edges, for atmos__lamp_tint_same: (th + 1) x (tw + 1) running sums over the
     * texels above and left of each of those differing from their right neighbour (one table),
     * then from the one below (the next) */
    int *edges;
    /* the texel coordinates outside which the tint is 0 (the image's non-black texels' box,
     * a texel wider each side for the bilinear look-ups): fx in (box[0], box[1]), fy in
     * (box[2], box[3]); an empty box when the image is all black */
    double box[4];
} atmos__lamp;

/* The intensity at wavelength k of a scene light (W sr^-1 nm^-1): intensity_w_sr is the
 * radiant intensity over 380-780 nm, the spectrum a black body's normalised over that band,
 * or for an rgb colour a flat 1/400 nm^-1 per channel times the channel's weight. */
double atmos__lamp_spectrum(const atmos_scene_light *l, const atmos_wavelengths *wl, int k);

/* The reach of a light with no range_m (0) in a fog of extinction sigma_t (per m) about the
 * light: the distance r at which the airlight of a ray passing the light at r, about
 * exp(-sigma_t r) / r, falls to 1e-3 of that of a ray passing at 1 m (sigma_t r + ln r =
 * ln 1000 + sigma_t); 1000 m without fog, less in a denser one, at least 1 m. */
double atmos__lamp_auto_range(double sigma_t);

/* The lamp of a scene light for the wavelength set (range: range_m, 0 when auto: the caller
 * sets it from the fog with atmos__lamp_auto_range). */
void atmos__lamp_make(const atmos_scene_light *s, const atmos_wavelengths *wl, atmos__lamp *l);

/* The spot's smooth falloff for a point whose offset from the light has cosine c with the
 * axis: 1 within cos_inner, 0 beyond cos_outer, a smoothstep in c between (1 for a point
 * light). */
static inline double atmos__lamp_falloff_cos(const atmos__lamp *l, double c)
{
    if (l->type != ATMOS_LIGHT_SPOT || c >= l->cos_inner) return 1;
    if (c <= l->cos_outer) return 0;
    const double s = (c - l->cos_outer) / (l->cos_inner - l->cos_outer);
    return s * s * (3 - 2 * s);
}

/* The light's image (scene light s's "image", a PNG of sRGB values, linearised) read into l
 * (made by atmos__lamp_make); a missing or malformed file is an error naming its key
 * (/lights/INDEX/image) and the file. */
atmos_status atmos__lamp_load_image(atmos_context *ctx, const atmos_scene *scene, int index, atmos__lamp *l);
void atmos__lamp_free(atmos__lamp *l);

/* The image's tint toward point p (rgb, bilinear; 0 outside the image; 1, 1, 1 without an
 * image). */
void atmos__lamp_tint(const atmos__lamp *l, const double p[3], double rgb[3]);
/* The image's texel coordinates toward a point at (x, y, z) in the light's (right, up, axis)
 * frame, z > 0 (those atmos__lamp_tint_at reads). */
static inline void atmos__lamp_tint_coords(const atmos__lamp *l, double x, double y, double z, double *fx, double *fy)
{
    x /= z * l->tan_max, y /= z * l->tan_max;
    *fx = 0.5 * (x + 1) * l->tw - 0.5, *fy = 0.5 * (1 - y) * l->th - 0.5;
}
/* Texel (x, y) of the image, x in [-1, tw], y in [-1, th] (the border: the edges' texels). */
static inline const double *atmos__lamp_texel(const atmos__lamp *l, int x, int y)
{
    return l->tex + 3 * ((size_t)(y + 1) * (l->tw + 2) + x + 1);
}
/* floor(x) for x in (-2, INT_MAX) (the texel coordinates inside the image and its border):
 * the truncation toward zero, one less below it (floor's own value, in fewer instructions). */
static inline int atmos__lamp_floor(double x)
{
    const int i = (int)x;
    return i - (x < i);
}
/* What a look-up reads of the image, in locals: a loop's look-ups take them once (the lamp's
 * fields, read through a pointer, would be loaded and converted again at every look-up). */
typedef struct atmos__lamp_image {
    const double *tex; /* atmos__lamp's, with its border */
    int stride;        /* tw + 2 */
    double w, h;       /* tw, th */
} atmos__lamp_image;
static inline atmos__lamp_image atmos__lamp_image_of(const atmos__lamp *l)
{
    return (atmos__lamp_image){l->tex, l->tw + 2, l->tw, l->th};
}
/* atmos__lamp_tint_at from the image's locals. */
ATMOS_CLONE_HELPER void atmos__lamp_image_tint(const atmos__lamp_image *m, double fx, double fy, double rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0;
    if (!(fx > -1 && fx < m->w && fy > -1 && fy < m->h)) return;
    const int x0 = atmos__lamp_floor(fx), y0 = atmos__lamp_floor(fy); /* in [-1, tw - 1], [-1, th - 1] */
    const double ax = fx - x0, ay = fy - y0;
    const double w00 = (1 - ax) * (1 - ay), w01 = ax * (1 - ay), w10 = (1 - ax) * ay, w11 = ax * ay;
    /* the border stands for the clamped edge (atmos__lamp_texel) */
    const double *t00 = m->tex + 3 * ((size_t)(y0 + 1) * m->stride + x0 + 1), *t10 = t00 + 3 * (size_t)m->stride;
    rgb[0] = w00 * t00[0] + w01 * t00[3] + w10 * t10[0] + w11 * t10[3]; /* in this order, left to right */
    rgb[1] = w00 * t00[1] + w01 * t00[4] + w10 * t10[1] + w11 * t10[4];
    rgb[2] = w00 * t00[2] + w01 * t00[5] + w10 * t10[2] + w11 * t10[5];
}
/* The tint at texel coordinates (fx, fy) of the image (bilinear; 0 outside it). */
ATMOS_CLONE_HELPER void atmos__lamp_tint_at(const atmos__lamp *l, double fx, double fy, double rgb[3])
{
    const atmos__lamp_image m = atmos__lamp_image_of(l);
    atmos__lamp_image_tint(&m, fx, fy, rgb);
}
/* Whether the tint is the same all over the box [fx0, fx1] x [fy0, fy1] of texel coordinates
 * (every texel the bilinear look-ups there read alike, or the box wholly outside the image:
 * 0), with a margin for the rounding of the coordinates; that tint into rgb (the texel's, to
 * which the look-ups' weights add up within rounding). */
int atmos__lamp_tint_same(const atmos__lamp *l, double fx0, double fx1, double fy0, double fy1, double rgb[3]);

/* The falloff toward point p (1 at the light itself). */
double atmos__lamp_falloff(const atmos__lamp *l, const double p[3]);

/* The light's spectral intensity toward p for the wavelengths k[0..m-1] (I[k] times the
 * falloff, times the image's tint) into out; returns the falloff (0: p is dark). */
double atmos__lamp_toward(const atmos__lamp *l, const double p[3], int m, const int *k, double *out);

/* Narrows [*t0, *t1] of the ray e + t d to the part inside a spot's outer cone (Dobashi's
 * bounding pyramid, exactly): the roots of ((P - L).a)^2 = cos^2 |P - L|^2 cut the span
 * into at most three pieces; the hull of those whose middle is lit. 0 if none is; a point
 * light keeps the span. */
int atmos__lamp_clip(const atmos__lamp *l, const double e[3], const double d[3], double *t0, double *t1);

#endif
