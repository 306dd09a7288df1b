/* A spot's projected image (stained glass) along one eye ray's sub-planes (beams_internal.h,
 * docs/beams.md *Thirty-first round*): the image's texels come in panes of one colour, and a
 * straight segment of the ray projects from the light onto a straight segment of the image, so
 * a run of samples whose segment's box of texels holds one colour is that colour times the
 * light's own sum (its tiles' tests, its falloff's runs); a run in a black part of the image, or
 * outside it, adds nothing. */
#include "render/beams_internal.h"
#include "render/beams_lookup.h"
#include "core/clones.h"
#include "core/vec.h"

#include <math.h>

/* What the runs know of atmos__beams_ray_light along them. */
enum { LIGHT_UNKNOWN, LIGHT_FULL /* 1 all along */, LIGHT_FALLOFF /* H = 1: the falloff alone */ };

/* The texel coordinates of the image toward the ray's point at t; 0 behind the light (inlined:
 * a call cost 1.7 % of a frame's instructions). */
ATMOS_CLONE_HELPER int coords(const atmos__beams_ray *r, double t, double *fx,
                              double *fy)
{
    const double z = r->a0 + t * r->a1;
    if (!(z > 0)) return 0;
    const double iz = 1 / z;
    *fx = (r->u0 + t * r->u1) * iz + (0.5 * r->l->L.tw - 0.5);
    *fy = (r->v0 + t * r->v1) * iz + (0.5 * r->l->L.th - 0.5);
    return 1;
}

/* The samples [s0, s1) one by one, added to h (the sums, the image's fields and its centre held
 * in locals: coords() computes the same). */
ATMOS_CLONE_HELPER void read_tinted(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1,
                                    int known, double h[3])
{
    const atmos__lamp_image m = atmos__lamp_image_of(&r->l->L);
    const double u0 = r->u0, u1 = r->u1, v0 = r->v0, v1 = r->v1, a0 = r->a0, a1 = r->a1;
    const double cx = 0.5 * r->l->L.tw - 0.5, cy = 0.5 * r->l->L.th - 0.5;
    double h0 = h[0], h1 = h[1], h2 = h[2];
    for (int s = s0; s < s1; s++) {
        const double t = ta + (s + o) * step, z = a0 + t * a1;
        if (!(z > 0)) continue; /* behind the light */
        const double iz = 1 / z;
        double tint[3];
        atmos__lamp_image_tint(&m, (u0 + t * u1) * iz + cx, (v0 + t * v1) * iz + cy, tint); /* first: a black
                                                                  * texel spares the shadow map's */
        if (tint[0] == 0 && tint[1] == 0 && tint[2] == 0) continue;
        const double v = known == LIGHT_FULL ? 1 : known == LIGHT_FALLOFF ? ray_falloff(r, t) : ray_light(r, t);
        if (v > 0) h0 += v * tint[0], h1 += v * tint[1], h2 += v * tint[2];
    }
    h[0] = h0, h[1] = h1, h[2] = h2;
}

/* The light's own sum over [s0, s1) as far as the run knows it. */
static double light_sum(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1, int known)
{
    if (known == LIGHT_FULL) return s1 - s0;
    if (known == LIGHT_FALLOFF) return atmos__beams_ray_falloff_sum(r, ta, step, o + s0, s1 - s0);
    return atmos__beams_ray_light_sum(r, ta, step, o, s0, s1);
}

/* atmos__beams_ray_tinted_sum over [s0, s1), knowing what known says of the light there. A run
 * of 8 samples or fewer is read without its box's colour test: its segment spans less than 3 of
 * the stained glass's texels, whose panes are about 4 across, and the test settled 6 % of them
 * for about 230 instructions each (docs/beams.md *Forty-first round*). An AVX2 clone: the same
 * operations (C11 contracts none into FMAs), fewer instructions; read_tinted and the look-up
 * always inlined, else the clone calls the baseline's copies (docs/beams.md *Forty-seventh
 * round*). */
ATMOS_CLONES static void tinted_sum(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1,
                                    int known, double h[3])
{
    const double t0 = ta + (s0 + o) * step, t1 = ta + (s1 - 1 + o) * step;
    double xa, ya, xb, yb, tint[3];
    if (s1 - s0 > 8 && coords(r, t0, &xa, &ya) && coords(r, t1, &xb, &yb) &&
        atmos__lamp_tint_same(&r->l->L, atmos__mind(xa, xb), atmos__maxd(xa, xb), atmos__mind(ya, yb),
                              atmos__maxd(ya, yb), tint)) {
        if (tint[0] == 0 && tint[1] == 0 && tint[2] == 0) return; /* lead, or outside the window */
        const double v = light_sum(r, ta, step, o, s0, s1, known);
        for (int c = 0; c < 3; c++) h[c] += v * tint[c];
        return;
    }
    if (known == LIGHT_UNKNOWN && s1 - s0 > 1) { /* the shadow map's tiles: a run in a wall's shadow adds nothing */
        double same;
        int full;
        if (ray_uniform(r, t0, t1, &same, &full)) {
            if (same == 0) return; /* in shadow all along */
            known = full ? LIGHT_FULL : LIGHT_FALLOFF;
        }
    }
    if (s1 - s0 <= 8) {
        read_tinted(r, ta, step, o, s0, s1, known, h);
        return;
    }
    const int mid = s0 + (s1 - s0) / 2;
    tinted_sum(r, ta, step, o, s0, mid, known, h);
    tinted_sum(r, ta, step, o, mid, s1, known, h);
}

/* [*t0, *t1] narrowed by g0 + t g1 > 0 (a margin of 1e-9 of the span each way for rounding). */
static void half_line(double g0, double g1, double *t0, double *t1)
{
    const double m = 1e-9 * (fabs(*t0) + fabs(*t1));
    if (g1 > 0) *t0 = atmos__maxd(*t0, -g0 / g1 - m);
    else if (g1 < 0) *t1 = atmos__mind(*t1, -g0 / g1 + m);
    else if (!(g0 > 0)) *t1 = -INFINITY;
}

int atmos__beams_ray_tint_span(const atmos__beams_ray *r, double *t0, double *t1)
{
    const atmos__lamp *L = &r->l->L;
    const double cx = 0.5 * L->tw - 0.5, cy = 0.5 * L->th - 0.5;
    /* fx = u / z + cx > box[0] <=> u + (cx - box[0]) z > 0 where z > 0; the others alike: the
     * pyramid of the box's four planes through the light, each a half-line of the ray */
    half_line(r->a0, r->a1, t0, t1);
    half_line(r->u0 + (cx - L->box[0]) * r->a0, r->u1 + (cx - L->box[0]) * r->a1, t0, t1);
    half_line((L->box[1] - cx) * r->a0 - r->u0, (L->box[1] - cx) * r->a1 - r->u1, t0, t1);
    half_line(r->v0 + (cy - L->box[2]) * r->a0, r->v1 + (cy - L->box[2]) * r->a1, t0, t1);
    half_line((L->box[3] - cy) * r->a0 - r->v0, (L->box[3] - cy) * r->a1 - r->v1, t0, t1);
    return *t0 < *t1;
}

void atmos__beams_ray_tinted_sum(const atmos__beams_ray *r, double ta, double step, double o, int s0, int s1,
                                 double h[3])
{
    tinted_sum(r, ta, step, o, s0, s1, LIGHT_UNKNOWN, h);
}

/* An AVX2 clone (the same operations: ceil and floor a rounding instruction each there, where the
 * baseline spells them out; the call to tinted_sum a direct one). */
ATMOS_CLONES int atmos__beams_ray_tinted(const atmos__beams_ray *r, const double *f, int n, double unit, int max_sub,
                                         double o, double sum[3])
{
    double p0 = f[0], p1 = f[2 * n];
    const int some = atmos__beams_ray_tint_span(r, &p0, &p1); /* outside [p0, p1] the image is black */
    int count = 0;
    sum[0] = sum[1] = sum[2] = 0;
    for (int k = 0; k < n; k++) {
        const double fl = f[2 * k + 1];
        if (fl <= 0) continue;
        const int m = atmos__beams_subplanes(fl, unit, max_sub);
        count += m;
        if (!some || f[2 * k + 2] < p0 || f[2 * k] > p1) continue; /* black all along: counted, not sampled */
        const double ta = f[2 * k], step = (f[2 * k + 2] - ta) / m;
        /* the samples within [p0, p1], and one more each side for the rounding */
        const double a = ceil((p0 - ta) / step - o) - 1, b = floor((p1 - ta) / step - o) + 2;
        const int s0 = a > 0 ? (a < m ? (int)a : m) : 0, s1 = b < m ? (b > 0 ? (int)b : 0) : m;
        double h[3] = {0, 0, 0};
        tinted_sum(r, ta, step, o, s0, s1, LIGHT_UNKNOWN, h);
        sum[0] += h[0] / m * fl, sum[1] += h[1] / m * fl, sum[2] += h[2] / m * fl; /* written out: not a loop */
    }
    return count;
}
