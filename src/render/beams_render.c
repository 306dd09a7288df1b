/* The beam renderer's frame (Dobashi, Yamamoto and Nishita 2002 §4): per pixel, the sky
 * behind (dimmed by the fog), or the nearest object's Lambertian surface (the triangle the
 * meshes rasterised from the camera put there, beams_primary.h) lit by every light
 * it sees (Dobashi's I_b, attenuated by the fog on both legs) and by the sky (beams_sky.h),
 * plus per light the light the
 * fog scatters toward the eye (Eq. 2):
 *   - the ray is cut by sampling planes perpendicular to the view direction, spaced evenly
 *     in depth across the sphere the light reaches (the same planes for every pixel);
 *   - between two planes the scattering of an unshadowed light of unit intensity is two
 *     look-ups of the pre-integrated table (f_l, Eq. 8-9; beams_table.c);
 *   - the visibility H and the spot's falloff (f_h, Eq. 10) are averaged over sub-planes
 *     between the planes, m_k of them where f_l could add more than epsilon of the pixel's
 *     unshadowed airlight (Dobashi §4.2.2's criterion, per pixel over all its lights: m_k =
 *     ceil(I_i f_l,k / (epsilon sum_j I_j sum_k f_l,k)) up to max_subplanes, I the lights' mean
 *     intensities), at the midpoints of m_k equal parts; a point light's neighbouring
 *     intervals each below a quarter of that share one sample while their sum stays below it
 *     (merged());
 *   - the interval adds I f_h f_l (Eq. 6); an interval along which H cannot change (clear of
 *     every depth the shadow map's tiles there hold, or beyond them all) samples the falloff
 *     alone, or nothing when it is in shadow or inside the inner cone: the value its samples
 *     would all have.
 * With interleaved sampling (beams/interleave N > 1, beams_interleave.h) the samples between
 * the planes sit at a pixel's own offset, and the airlight is filtered over N x N pixels.
 * With beams/screen_step k > 1 (beams_screen.h) the airlight (the lights' and the sun's) is
 * evaluated on a lattice of every k-th pixel and interpolated across the cells where that is
 * safe (a cell that a light's screen span crosses is always cut, unless the span is many cells
 * wide there: the lit cones' hint; the spots on a lattice of their own when there are other lights
 * or the sun, air_layers; a point light's stretches between two planes taken as lit or dark where
 * all four corners of a cut cell saw them so, shared_interval), the surfaces
 * still per pixel, the sky behind from the sky renderer's grid of every k-th pixel (at most 4).
 * Rows go to the threads; each pixel depends on nothing but its own ray (or its band of the
 * lattice), so the image does not depend on the thread count. */
#include "render/beams_internal.h"
#include "render/beams_interleave.h"
#include "render/beams_primary.h"
#include "render/beams_screen.h"
#include "render/beams_sky.h"
#include "core/clones.h"
#include "core/pinhole.h"
#include "core/vec.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Intervals per light along one ray at most: planes closer than 2 range / this are spread. */
#define MAX_INTERVALS 4096
/* A surface point within this share of a light's sampled radius squared, seen from a pixel
 * outside the light's span, is outside its cone (the span's margins cover the radius itself). */
#ifndef SPAN_SAFE
#define SPAN_SAFE 0.98
#endif
/* A point light's interval of at most this many sub-planes reads them without the tiles' test
 * (docs/beams.md, *Twenty-third round*: 8 since the 2 x 2 tiles, 3 before). */
#ifndef POINT_READ_MAX
#define POINT_READ_MAX 8
#endif

/* Every light (lights()' mask). */
#define ALL_LIGHTS 0xffffffffu

/* A point light's neighbouring intervals whose f_l sum to less than this share of a sub-plane's
 * (epsilon of the pixel's airlight) share one sample (merged()). */
#ifndef POINT_MERGE
#define POINT_MERGE 0.25
#endif

typedef struct job {
    const atmos__beams_plan *b;
    const atmos_camera *cam;
    const double *eye;
    double fwd[3];
    int nw, cx, cy;
    double *z_lo, *dz, *reach; /* per light: the first plane's depth, the spacing, the sampled radius */
    double *weight;            /* per light: its mean intensity over the wavelengths */
    atmos__beams_ray *from_eye; /* per light: the eye's part of its rays' views (atmos__beams_ray_eye) */
    int *span;                 /* per light and row: the columns [x0, x1) outside which its airlight is 0 */
    double epsilon;
    int max_sub;
    int centre_planes, centre_subplanes;
    int centre_now;            /* subsampling: the air_pixel() being evaluated is the centre's */
    const atmos__beams_sky *sky; /* the sky's light on surfaces (none in a vacuum or without objects) */
    const atmos__beams_primary *prim; /* what each pixel sees, rasterised (NULL: no objects) */
    double *ru, *rv;           /* a pinhole camera's image-plane coordinates per column and row (else NULL) */
    const double *dir;         /* subsampling, a pinhole camera: the eye's rays over dir_r (x, y, z; else NULL) */
    atmos__rect dir_r;
    double (*alb_pi)[ATMOS_MAX_WAVELENGTHS]; /* per object and wavelength: its albedo over pi */
} job;

/* The eye's ray through pixel (x, y)'s centre: atmos_camera_ray's, from the coordinates kept
 * per column and row (the same bits, without its two divisions) for a pinhole camera. */
static void eye_ray(const job *J, int x, int y, double d[3])
{
    if (J->ru) atmos__camera_pinhole_dir(J->cam, J->ru[x], J->rv[y], d);
    else atmos_camera_ray(J->cam, x + 0.5, y + 0.5, d);
}

/* The coordinates per column and row of a pinhole camera (J->ru, J->rv; one block). Returns 1
 * when out of memory. */
static int eye_coordinates(job *J)
{
    const atmos_camera *c = J->cam;
    J->ru = J->rv = NULL;
    if (c->type != ATMOS_CAMERA_PINHOLE) return 0;
    if (!(J->ru = malloc(sizeof(double) * ((size_t)c->width + c->height)))) return 1;
    J->rv = J->ru + c->width;
    for (int x = 0; x < c->width; x++) J->ru[x] = atmos__camera_pinhole_u(c, x + 0.5);
    for (int y = 0; y < c->height; y++) J->rv[y] = atmos__camera_pinhole_v(c, y + 0.5);
    return 0;
}

/* Whether x is within the columns [r[0], r[1]) of a light's span on a row. */
static int in_columns(const int *r, int x) { return x >= r[0] && x < r[1]; }

static int in_span(const job *J, int i, int x, int y)
{
    return in_columns(J->span + 2 * ((size_t)i * J->cam->height + y), x);
}

/* Per pixel x of a row of n (its rays (dx, dy, dz)[x], the distances T[x] to the surfaces they
 * hit), the lights that may reach the point seen, as bits (light i: bit i; at most 32 lights):
 * all but the spots whose cone surely leaves it out, the cosine of its offset from the light
 * with the axis below cos_outer by more than rounding can blur (atmos__lamp_falloff then
 * returns 0), told without a root or a division. The point and its offset are shade_surface's
 * (the same operations); one loop a light, vectorised across the row (an AVX2 clone). */
_Static_assert(ATMOS_SCENE_MAX_LIGHTS <= 32, "row_cones: a light a bit of 32");
ATMOS_CLONES static void row_cones(const job *J, const double *dx, const double *dy, const double *dz, const double *T,
                                   int n, uint32_t *cones)
{
    const double e0 = J->eye[0], e1 = J->eye[1], e2 = J->eye[2];
    for (int x = 0; x < n; x++) cones[x] = 0;
    for (int i = 0; i < J->b->nlights; i++) {
        const atmos__lamp *L = &J->b->lights[i].L;
        const uint32_t bit = (uint32_t)1 << i;
        if (L->type != ATMOS_LIGHT_SPOT || !(L->cos_outer > 0)) {
            for (int x = 0; x < n; x++) cones[x] |= bit;
            continue;
        }
        const double p0 = L->pos[0], p1 = L->pos[1], p2 = L->pos[2], a0 = L->axis[0], a1 = L->axis[1], a2 = L->axis[2];
        const double c2 = L->cos_outer * L->cos_outer * (1 - 1e-9);
        for (int x = 0; x < n; x++) {
            const double t = T[x];
            const double w0 = p0 - (e0 + t * dx[x]), w1 = p1 - (e1 + t * dy[x]), w2 = p2 - (e2 + t * dz[x]);
            const double r2 = w0 * w0 + w1 * w1 + w2 * w2, s = -(w0 * a0 + w1 * a1 + w2 * a2);
            cones[x] |= s <= 0 || s * s <= c2 * r2 ? 0 : bit;
        }
    }
}

/* The sky's irradiance on the surface hit along d (memo's or E), through a height-dependent
 * fog's layer above the point; NULL when no sky lights surfaces (J->sky NULL in a uniform fog). */
static const double *sky_light(const job *J, const double d[3], const atmos_mesh_hit *h, double *E,
                               atmos__beams_sky_memo *memo)
{
    static const double up[3] = {0, 1, 0};
    if (!(J->sky && J->sky->nw)) return NULL;
    const double P[3] = {0, J->eye[1] + h->t * d[1], 0}; /* the fog's depth above reads the height alone */
    return atmos__beams_sky_irradiance_memo(J->sky, h->normal, atmos__beams_sun_fog_in(&J->b->fog, up, P), E, memo);
}

/* The object's surface at the eye's ray's hit through pixel (x, y), lit by the lights and the
 * sky, into L before the fog on the way to the eye (the caller's factor, the last of the
 * product). Each light's shadow there from its shadow map where the map settles it
 * (atmos__beams_surface_visible), else (or with beams/exact_shadows) by an exact ray. A pixel
 * outside a light's span (screen_spans) sees no point that the light reaches within the
 * sampled radius: a surface point nearer the light than that is outside its cone (falloff 0),
 * so the light is skipped there before its distance's root and the falloff are evaluated; so
 * is a light not in cones (row_cones: a spot whose cone surely leaves the point out). Returns
 * 0 when no light and no sky reach the point (L all zeros: the fog need not be evaluated). */
static int shade_surface(const job *J, int x, int y, const double d[3], const atmos_mesh_hit *h, int m, uint32_t cones,
                         double *L, atmos__beams_sky_memo *memo)
{
    const atmos__beams_plan *b = J->b;
    double P[3], sum[ATMOS_MAX_WAVELENGTHS], E[ATMOS_MAX_WAVELENGTHS];
    if (!cones) { /* no light can reach it: the sky alone (0 + E: the sums' bits), else zeros */
        const double *e = sky_light(J, d, h, E, memo), *a = J->alb_pi[m];
        if (e)
            for (int k = 0; k < J->nw; k++) L[k] = a[k] * (0.0 + e[k]);
        else
            for (int k = 0; k < J->nw; k++) L[k] = a[k] * 0.0;
        return e != NULL;
    }
    for (int a = 0; a < 3; a++) P[a] = J->eye[a] + h->t * d[a];
    int any = 0;
    for (int k = 0; k < J->nw; k++) sum[k] = 0; /* the wavelengths in use only: not 1 kB a pixel */
    const double off = 1e-4 * (1 + h->t);
    for (int i = 0; i < b->nlights; i++) {
        if (!(cones >> i & 1)) continue;
        const atmos__beams_light *l = &b->lights[i];
        double w[3] = {l->L.pos[0] - P[0], l->L.pos[1] - P[1], l->L.pos[2] - P[2]};
        const double r2 = atmos__dot3(w, w);
        if (r2 < SPAN_SAFE * J->reach[i] * J->reach[i] && !in_span(J, i, x, y)) continue;
        const double r = sqrt(r2);
        if (r <= 0) continue;
        for (int a = 0; a < 3; a++) w[a] /= r;
        const double c = atmos__dot3(h->normal, w);
        if (c <= 0) continue; /* facing away: no falloff, map or tint to look up */
        const double fall = atmos__lamp_falloff(&l->L, P);
        if (fall <= 0) continue;
        const double o[3] = {P[0] + off * h->normal[0], P[1] + off * h->normal[1], P[2] + off * h->normal[2]};
        const int lit = b->exact_shadows ? -1 : atmos__beams_surface_visible(l, P, c); /* the map, or an exact ray */
        if (lit == 0 || (lit < 0 && atmos__objects_hit(&b->obj, o, w, 0, r - off, NULL, NULL))) continue;
        const double e = fall * c / (r * r) * exp(-b->sigma_t * r);
        any = 1;
        if (!l->L.tex) {
            for (int k = 0; k < J->nw; k++) sum[k] += l->L.I[k] * e;
            continue;
        }
        double tint[3];
        atmos__lamp_tint(&l->L, P, tint);
        for (int k = 0; k < J->nw; k++) sum[k] += l->L.I[k] * e * tint[k < 3 ? k : 2];
    }
    const double *e = sky_light(J, d, h, E, memo);
    if (e) {
        for (int k = 0; k < J->nw; k++) sum[k] += e[k];
        any = 1;
    }
    for (int k = 0; k < J->nw; k++) L[k] = J->alb_pi[m][k] * sum[k];
    return any;
}

/* The fog's transmittance from the eye along d to t (INFINITY: the sky behind). */
static double fog_to(const job *J, const double d[3], double t) { return exp(-atmos__beams_fog_tau(&J->b->fog, J->eye, d, t)); }

/* The light of pixel (x, y) without the airlight, into L: the surface hit h (of object m) lit
 * by the lights and the sky, or (h NULL) the sky behind bg, dimmed by the fog on the way to the
 * eye. Returns the fog's transmittance to the hit, which is evaluated only where something is
 * lit or when fog_needed (an unlit surface is 0 whatever it is: the same bits; then 1). */
static double base_light(const job *J, int x, int y, const double d[3], const atmos_mesh_hit *h, int m, uint32_t cones,
                         const float *bg, int fog_needed, double *L, atmos__beams_sky_memo *memo)
{
    if (h && !shade_surface(J, x, y, d, h, m, cones, L, memo) && !fog_needed) return 1;
    /* 0 to the sky behind endless fog */
    const double fog_t = fog_to(J, d, h ? h->t : INFINITY);
    if (h)
        for (int k = 0; k < J->nw; k++) L[k] *= fog_t;
    else
        for (int k = 0; k < J->nw; k++) L[k] = bg[k] * fog_t;
    return fog_t;
}

/* The sub-planes of a light with an image (stained glass): as in airlight() below, with the
 * image's tint at every sample (atmos__beams_ray_tinted, beams_tint.c: where it is one colour
 * along a run of them, that colour times the light's sum), so no interval is taken as uniform by
 * its f_l alone: its colour varies. */
static void tinted(job *J, const atmos__beams_light *l, const atmos__beams_ray *ray, const double *f, int n, double unit,
                   double *L, int centre, double o)
{
    double sum[3];
    const int m = atmos__beams_ray_tinted(ray, f, n, unit, J->max_sub, o, sum);
    if (centre) J->centre_subplanes += m;
    for (int k = 0; k < J->nw; k++) L[k] += l->L.I[k] * sum[k < 3 ? k : 2];
}

/* A subsampled frame's point light whose rays share what the corners of a cut cell saw
 * (beams_screen.h's known): per stretch j of a ray between its planes j and j + 1 (j < 64),
 * bit j of known[0] where every corner's was lit all along, of known[1] where dark; seen, the
 * ray's own, for the cells it is a corner of (the stretches whole between two planes). */
typedef struct shared_ray {
    int light;             /* the light (-1: none) */
    const uint64_t *known; /* NULL: nothing agreed */
    uint64_t *seen;
    double *unread; /* the count of stretches that a run took without their W looked up, then
                     * that of the stretches a merged sample told lit or dark */
} shared_ray;

/* Light i's part of the ray d within its reach and before T: [t0, t1), the table's column, the
 * factor of its W differences and the ray's nearest point to the light tQ at distance v.
 * Returns 0 where the ray misses it. */
typedef struct reach_part {
    double t0, t1, tQ, v, scale, cosf;
    atmos__beams_column col;
} reach_part;

static int reach_part_of(const job *J, int i, const double d[3], double T, reach_part *r)
{
    const atmos__beams_plan *b = J->b;
    const atmos__beams_light *l = &b->lights[i];
    const double R = J->reach[i], sig = b->sigma_t;
    const double Lp[3] = {l->L.pos[0] - J->eye[0], l->L.pos[1] - J->eye[1], l->L.pos[2] - J->eye[2]};
    const double tQ = atmos__dot3(Lp, d);
    const double q[3] = {Lp[0] - tQ * d[0], Lp[1] - tQ * d[1], Lp[2] - tQ * d[2]};
    const double v = atmos__maxd(sqrt(atmos__dot3(q, q)), 1e-6 * R);
    if (v >= R) return 0;
    const double hh = sqrt(R * R - v * v);
    r->t0 = atmos__maxd(0, tQ - hh), r->t1 = atmos__mind(T, tQ + hh);
    if (!(r->t0 < r->t1) || !atmos__lamp_clip(&l->L, J->eye, d, &r->t0, &r->t1)) return 0;
    atmos__beams_table_column(&b->table, sig * v, &r->col);
    r->tQ = tQ, r->v = v, r->scale = exp(-sig * tQ) / v, r->cosf = atmos__dot3(d, J->fwd);
    return 1;
}

/* W (the table's) at t along the part r. */
static inline double W_at(const job *J, const reach_part *r, double t)
{
    return atmos__beams_table_at(&J->b->table, &r->col, atmos__beams_table_s(t - r->tQ, r->v));
}

/* The bit of the stretch of [a, e) between two of light i's planes (0: past the 64th). */
static uint64_t stretch_bit(const job *J, int i, double a, double e, double cosf)
{
    const double j = floor((0.5 * (a + e) * cosf - J->z_lo[i]) / J->dz[i]);
    return j >= 0 && j < 64 ? (uint64_t)1 << (int)j : 0;
}

/* The run of stretches from stretch b on (its bit set in m) whose bits are all set in m, up to
 * where the part r ends: its end *e, the stretches it crosses, returned (at least 1). */
static int agreed_run(const job *J, int i, const reach_part *r, long b, uint64_t m, double *e)
{
    const uint64_t rest = ~(m >> b);
    const int len = rest ? __builtin_ctzll(rest) : 64 - (int)b;
    const double zl = J->z_lo[i], dz = J->dz[i], plane = (zl + (double)(b + len) * dz) / r->cosf;
    if (plane < r->t1) {
        *e = plane;
        return len;
    }
    *e = r->t1;
    const long last = (long)floor((r->t1 * r->cosf - zl) / dz);
    return last < b ? 1 : last - b + 1 < len ? (int)(last - b + 1) : len;
}

/* intervals() with sh->known: a run of stretches that the corners all saw lit or all dark is one
 * interval of f_l -1 (its W looked up at its end alone), the lit runs' f_l summed into f[2n + 1]
 * and their bits into sh->seen. The stretch between the planes j - 1 and j is bit j - 1. */
ATMOS_CLONE_HELPER int agreed_intervals(job *J, int i, const reach_part *r, double *f, double *sum, const shared_ray *sh)
{
    const double t1 = r->t1, cosf = r->cosf, dz = J->dz[i], zl = J->z_lo[i], W0 = W_at(J, r, r->t0);
    const uint64_t kl = sh->known[0], kd = sh->known[1];
    double a = r->t0, Wa = W0, S = 0, lit = 0;
    long j = (long)floor((a * cosf - zl) / dz) + 1;
    int n = 0, c = 0;
    while (a < t1) {
        const long b = j - 1;
        const uint64_t bit = b >= 0 && b < 64 && c < MAX_INTERVALS - 65 ? (uint64_t)1 << b : 0;
        if (bit & (kl | kd)) { /* a run the corners agree on */
            double e;
            const int len = agreed_run(J, i, r, b, bit & kl ? kl : kd, &e);
            const double We = W_at(J, r, e);
            if (bit & kl) lit += atmos__maxd(0, We - Wa) * r->scale;
            sh->seen[bit & kl ? 0 : 1] |= (len >= 64 ? ~(uint64_t)0 : ((uint64_t)1 << len) - 1) << b;
            *sh->unread += len - 1;
            f[2 * n] = a, f[2 * n + 1] = -1, n++;
            a = e, Wa = We, j += len, c += len;
            continue;
        }
        double e = c == MAX_INTERVALS - 1 ? t1 : atmos__mind(t1, (zl + j * dz) / cosf);
        if (e <= a) e = atmos__mind(t1, a + 1e-9 * (1 + a)); /* a plane at a itself */
        const double We = W_at(J, r, e);
        f[2 * n] = a, f[2 * n + 1] = atmos__maxd(0, We - Wa) * r->scale;
        a = e, Wa = We, j++, n++, c++;
    }
    f[2 * n] = t1, f[2 * n + 1] = lit;
    *sum = S = atmos__maxd(0, Wa - W0) * r->scale; /* what the f_l add up to */
    return S > 0 ? n : 0;
}

/* Light i's intervals along [0, T) of the ray d between the planes crossing it: f[2k] where
 * interval k starts, f[2k + 1] its f_l (an unshadowed light of unit intensity), f[2n] where the
 * last ends (f holds room for 2 MAX_INTERVALS + 2 values). Returns n (0: none), *sum the sum of
 * the f_l. With sh (its known not NULL), agreed_intervals(): *sum is then the W difference over
 * the whole part, and f[2n + 1] the lit runs' f_l. An AVX2 clone where the processor has it
 * (agreed_intervals and W_at inlined into it: the same IEEE operations, the same bits). */
ATMOS_CLONES static int intervals(job *J, int i, const double d[3], double T, double *f, double *sum, int centre,
                     const shared_ray *sh)
{
    reach_part r;
    *sum = 0;
    if (!reach_part_of(J, i, d, T, &r)) return 0;
    if (sh && sh->known && (sh->known[0] | sh->known[1])) return agreed_intervals(J, i, &r, f, sum, sh);
    const double t1 = r.t1, cosf = r.cosf, dz = J->dz[i], zl = J->z_lo[i];
    /* the intervals between the planes crossing [t0, t1], and their f_l */
    double a = r.t0, Wa = W_at(J, &r, a), S = 0;
    long j = (long)floor((a * cosf - zl) / dz) + 1;
    int n = 0;
    while (a < t1) {
        double e = n == MAX_INTERVALS - 1 ? t1 : atmos__mind(t1, (zl + j * dz) / cosf);
        if (e <= a) e = atmos__mind(t1, a + 1e-9 * (1 + a)); /* a plane at a itself */
        const double We = W_at(J, &r, e);
        f[2 * n] = a, f[2 * n + 1] = atmos__maxd(0, We - Wa) * r.scale;
        S += f[2 * n + 1];
        a = e, Wa = We, j++, n++;
    }
    f[2 * n] = t1, f[2 * n + 1] = 0;
    if (centre) J->centre_planes += n;
    *sum = S;
    return S > 0 ? n : 0;
}

/* The sum of light i's f_l along [0, T) of the ray d (intervals()'s *sum, from the W of the
 * part's two ends), for the criterion's weights of a light not evaluated here: 1 when it adds. */
static int interval_sum(job *J, int i, const double d[3], double T, double *f, double *sum, int centre)
{
    if (centre) return intervals(J, i, d, T, f, sum, centre, NULL) > 0; /* its planes counted */
    reach_part r;
    *sum = 0;
    if (!reach_part_of(J, i, d, T, &r)) return 0;
    *sum = atmos__maxd(0, W_at(J, &r, r.t1) - W_at(J, &r, r.t0)) * r.scale;
    return *sum > 0;
}

/* Interval k of the intervals f (its f_l > 0) scattered toward the eye, added to *sum: ceil(f_l /
 * unit) sub-planes, the samples at offset o of their parts. Returns 1 when every sample (or the
 * tiles' proof) gave H = 1 with no falloff, 0 when each gave 0, else -1. An AVX2 clone where the
 * processor has it (subplanes inlined into it: the same bits). */
ATMOS_CLONES static int interval(job *J, const atmos__beams_ray *ray, const double *f, int k, double unit, double *sum,
                                 int centre, double o)
{
    const double fl = f[2 * k + 1];
    const int m = atmos__beams_subplanes(fl, unit, J->max_sub);
    const double ta = f[2 * k], step = (f[2 * k + 2] - ta) / m;
    double h = 0, same = 0;
    int full = 0;
    /* a point light's few samples are read rather than tested: the tiles' test costs more, and
     * the samples give what it would (each exactly 0 or 1 where it would settle the span) */
    const int tested = m > 1 && (ray->l->L.type == ATMOS_LIGHT_SPOT || m > POINT_READ_MAX);
    const int uniform = tested && atmos__beams_ray_uniform(ray, ta, f[2 * k + 2], &same, &full);
    if (uniform && (full || same == 0)) { /* what every sample would say */
        *sum += same * fl;
        return same == 0 ? 0 : same == 1 ? 1 : -1;
    }
    if (uniform) /* lit all along: the falloff alone varies */
        h = atmos__beams_ray_falloff_sum(ray, ta, step, o, m);
    else if (tested) /* runs of the samples that the tiles prove alike, the rest one by one */
        h = atmos__beams_ray_light_sum_split(ray, ta, step, o, 0, m);
    else
        h = atmos__beams_ray_light_sum(ray, ta, step, o, 0, m);
    *sum += h / m * fl;
    if (centre) J->centre_subplanes += m;
    return h == 0 ? 0 : h == m && !uniform && ray->l->L.type == ATMOS_LIGHT_POINT ? 1 : -1;
}

/* Interval k of n of the shared light i (interval()'s) sampled, what it saw kept in sh->seen
 * (the stretches the corners agree on are taken by intervals() already: the planes are the same
 * for every pixel, and a pixel's stretch between two planes lies within the hull of its cell's
 * corners' stretches there: a heuristic, not a proof, since a shadow narrower than the cell can
 * pass between the corners, the blind spot the lattice's interpolation has too; measured in
 * docs/beams.md, the thirty-third round). */
static void shared_interval(job *J, int i, const atmos__beams_ray *ray, const double *f, int k, int n, double unit,
                            double *sum, int centre, double o, double cosf, const shared_ray *sh)
{
    const int lit = interval(J, ray, f, k, unit, sum, centre, o);
    if (k == 0 || k == n - 1 || lit < 0) return; /* a stretch cut by the reach or the surface tells nothing */
    sh->seen[lit ? 0 : 1] |= stretch_bit(J, i, f[2 * k], f[2 * k + 2], cosf);
}

/* A point light's intervals from k on (the first's f_l below POINT_MERGE unit) while their f_l
 * sum stays below POINT_MERGE unit (up to a run the corners agreed on, f_l -1), added to *sum as one sample: the visibility at the point
 * where the sum reaches o of itself (interpolated within its interval) times the sum. A sample
 * so carries at most POINT_MERGE epsilon of the pixel's airlight, where a sub-plane carries up to
 * epsilon (docs/beams.md, *Eleventh round*). With sh, a sample of a single interval (its
 * midpoint, as an interval of one sub-plane takes) tells its stretch lit or dark as
 * shared_interval does (not the first or the last interval, cut by the reach or the surface; a
 * sample placed by the sum of several is not its stretch's evidence: docs/beams.md, *Thirty-sixth
 * round*). Returns the interval after the last taken. */
static int merged(job *J, int i, const atmos__beams_ray *ray, const double *f, int k, int n, double unit, double *sum,
                  int centre, double o, double cosf, const shared_ray *sh)
{
    double acc = 0;
    int e = k, in = -1;
    while (e < n && f[2 * e + 1] >= 0 && acc + f[2 * e + 1] < POINT_MERGE * unit) acc += f[2 * e + 1], e++;
    double c = o * acc, t = f[2 * e];
    for (int q = k; q < e; q++) {
        if (c <= f[2 * q + 1]) {
            t = f[2 * q] + (f[2 * q + 1] > 0 ? c / f[2 * q + 1] : o) * (f[2 * q + 2] - f[2 * q]);
            in = q;
            break;
        }
        c -= f[2 * q + 1];
    }
    const double v = atmos__beams_ray_light(ray, t);
    *sum += v * acc;
    if (centre) J->centre_subplanes++;
    if (sh && e == k + 1 && in > 0 && in < n - 1 && (v == 0 || v == 1))
        sh->seen[v == 1 ? 0 : 1] |= stretch_bit(J, i, f[2 * in], f[2 * in + 2], cosf), sh->unread[1]++;
    return e;
}

/* Light i scattered toward the eye over its n intervals f (their f_l summing to S), added to
 * L: an interval whose f_l exceeds unit (epsilon of the pixel's airlight, in this light's
 * units) gets ceil(f_l / unit) sub-planes; the samples at offset o (0.5: the midpoints) of
 * their parts. */
static void airlight(job *J, int i, const double d[3], const double *f, int n, double S, double unit, double *L,
                     int centre, double o, const shared_ray *sh)
{
    const atmos__beams_light *l = &J->b->lights[i];
    if (!l->nfaces && l->L.type == ATMOS_LIGHT_POINT) { /* H = 1 and no falloff: the sum is exact */
        for (int k = 0; k < J->nw; k++) L[k] += l->L.I[k] * S;
        return;
    }
    atmos__beams_ray ray;
    atmos__beams_ray_from(&J->from_eye[i], d, &ray);
    if (l->L.tex) {
        tinted(J, l, &ray, f, n, unit, L, centre, o);
        return;
    }
    double sum = f[2 * n + 1]; /* the lit runs the corners agreed on (else 0) */
    const double cosf = atmos__dot3(d, J->fwd);
    for (int k = 0; k < n;)
        if (!(f[2 * k + 1] > 0))
            k++;
        else if (l->L.type == ATMOS_LIGHT_POINT && f[2 * k + 1] < POINT_MERGE * unit)
            k = merged(J, i, &ray, f, k, n, unit, &sum, centre, o, cosf, sh);
        else if (sh)
            shared_interval(J, i, &ray, f, k++, n, unit, &sum, centre, o, cosf, sh);
        else
            interval(J, &ray, f, k++, unit, &sum, centre, o);
    for (int k = 0; k < J->nw; k++) L[k] += l->L.I[k] * sum;
}

/* The sun's light on the surface hit (beams_sun.h): where a ray toward the sun is free (not
 * cast where the sun's map proves the point in shadow, atmos__beams_sun_dark), dimmed by a
 * height-dependent fog above it on the way in (its exp only where lit) and by fog_t on the way
 * out. sun_reaches: whether it adds, with the cosine c and the dimming in. */
static int sun_reaches(const job *J, const double d[3], const atmos_mesh_hit *h, double *c, double *in)
{
    const atmos__beams_plan *b = J->b;
    const atmos__beams_sun *s = &b->sun;
    const double off = 1e-4 * (1 + h->t);
    const double o[3] = {J->eye[0] + h->t * d[0] + off * h->normal[0], J->eye[1] + h->t * d[1] + off * h->normal[1],
                         J->eye[2] + h->t * d[2] + off * h->normal[2]};
    const int set = b->fog.height_m > 0 && !(s->dir[1] > 0); /* a layered fog's sun set: none in */
    *c = atmos__dot3(h->normal, s->dir);
    if (!(*c > 0) || set || atmos__beams_sun_dark(s, o) || atmos__objects_hit(&b->obj, o, s->dir, 0, INFINITY, NULL, NULL))
        return 0;
    *in = exp(-atmos__beams_sun_fog_in(&b->fog, s->dir, o)); /* dimmed on its way in */
    return *in > 0;
}

static void sun_surface(const job *J, const double d[3], const atmos_mesh_hit *h, int m, double fog_t, double *L)
{
    double c, in;
    if (sun_reaches(J, d, h, &c, &in))
        for (int k = 0; k < J->nw; k++) L[k] += J->alb_pi[m][k] * J->b->sun.E[k] * c * in * fog_t;
}

/* The fog's scattering of sunlight along [0, T) of the ray d. */
static void sun_air(const job *J, const double d[3], double T, double *L)
{
    const atmos__beams_plan *b = J->b;
    if (!(b->fog.sigma0 > 0)) return;
    const double a = atmos__beams_sun_airlight_lines(&b->sun, &b->epi, &b->fog, J->eye, d, T, J->epsilon, MAX_INTERVALS);
    for (int k = 0; k < J->nw; k++) L[k] += b->sun.E[k] * a;
}

/* The sun's share: on the surface hit (if any), and in the fog along [0, T). */
static void sunlight(const job *J, const double d[3], const atmos_mesh_hit *h, int m, double T, double fog_t, double *L)
{
    if (h) sun_surface(J, d, h, m, fog_t, L);
    sun_air(J, d, T, L);
}

/* The doubles of a thread's buffer for lights(): each light's intervals, then their sums and counts, then
 * the thread's counts of unread stretches and of merged samples' stretches told. */
#define LIGHT_STRIDE (2 * MAX_INTERVALS + 2)
static size_t buffer_size(int nlights) { return (size_t)(nlights > 0 ? nlights : 1) * (LIGHT_STRIDE + 2) + 2; }
/* The last two doubles of a thread's buffer: its counts of stretches unread and told by a merged
 * sample (shared_ray's). */
static double *unread_count(double *f, int nlights) { return f + buffer_size(nlights) - 2; }

/* Every light's airlight along [0, T) of the ray d through pixel (x, y) (the lights whose span
 * holds it), added to L, with Dobashi's criterion over all the lights of the pixel (§4.2.2): an
 * interval gets a sub-plane for every epsilon of the pixel's unshadowed airlight from all its
 * lights (each light's f_l sum weighted by its mean intensity) that it could add, so a light
 * whose airlight is a small share of the pixel's gets few; with one light, epsilon of its own. */
static void lights(job *J, int x, int y, const double d[3], double T, double *f, double *L, int centre, double o,
                   uint32_t mask, const shared_ray *sh)
{
    const int nl = J->b->nlights;
    double *S = f + (size_t)nl * LIGHT_STRIDE, *cnt = S + nl, tot = 0;
    int lit = 0;
    uint32_t adds = 0; /* the lights whose cnt > 0 */
    const uint32_t all = nl >= 32 ? ALL_LIGHTS : ((uint32_t)1 << nl) - 1;
    const int *span = J->span + 2 * (size_t)y; /* light i's on row y at i stride (in_span's) */
    const size_t stride = 2 * (size_t)J->cam->height;
    for (int pass = 0; pass < 2; pass++) { /* the lights of mask, then (if any of them adds) the others */
        for (uint32_t left = (pass ? ~mask : mask) & all; left; left &= left - 1) { /* their bits, lowest first */
            const int i = __builtin_ctz(left);
            double *fi = f + (size_t)i * LIGHT_STRIDE;
            cnt[i] = !in_columns(span + i * stride, x) ? 0
                     : pass ? interval_sum(J, i, d, T, fi, &S[i], centre) /* its weight alone */
                            : intervals(J, i, d, T, fi, &S[i], centre, sh && sh->light == i ? sh : NULL);
            adds |= cnt[i] > 0 ? (uint32_t)1 << i : 0;
        }
        if (!adds) return;
    }
    for (uint32_t left = adds; left; left &= left - 1) { /* in the lights' order */
        const int i = __builtin_ctz(left);
        tot += J->weight[i] * S[i], lit++;
    }
    for (uint32_t left = adds & mask; left; left &= left - 1) {
        const int i = __builtin_ctz(left);
        const double unit = J->epsilon * (lit == 1 || !(J->weight[i] > 0) ? S[i] : tot / J->weight[i]);
        airlight(J, i, d, f + (size_t)i * LIGHT_STRIDE, (int)cnt[i], S[i], unit, L, centre, o,
                 sh && sh->light == i ? sh : NULL);
    }
}

/* Pixel (x, y): the surface or the sky behind, the lights' airlight and the sun's, into px.
 * With interleaved sampling (il) the lights' airlight goes to il instead, with what the pixel
 * sees; px NULL: a pixel outside the frame's rectangle that the filter reads, its airlight
 * alone. */
static void pixel(job *J, int x, int y, float *px, double *f, atmos__beams_il *il)
{
    const atmos__beams_plan *b = J->b;
    double d[3], L[ATMOS_MAX_WAVELENGTHS], A[ATMOS_MAX_WAVELENGTHS];
    eye_ray(J, x, y, d);
    atmos_mesh_hit h = {0, 0, {0, 0, 0}};
    int m = -1;
    const int hit = J->prim ? atmos__beams_primary_hit(J->prim, &b->obj, x, y, J->eye, d, &h, &m) : 0;
    const double T = hit ? h.t : INFINITY;
    uint32_t cones = 0;
    if (hit) row_cones(J, &d[0], &d[1], &d[2], &T, 1, &cones);
    if (px) {
        const double fog_t = base_light(J, x, y, d, hit ? &h : NULL, m, cones, px, b->sun_on, L, NULL);
        if (il && b->sun_on) sunlight(J, d, hit ? &h : NULL, m, T, fog_t, L);
        if (!il) {
            if (b->sigma_t > 0) lights(J, x, y, d, T, f, L, x == J->cx && y == J->cy, 0.5, ALL_LIGHTS, NULL);
            if (b->sun_on) sunlight(J, d, hit ? &h : NULL, m, T, fog_t, L);
        }
        for (int k = 0; k < J->nw; k++) px[k] = (float)L[k];
    }
    if (!il) return;
    const long q = atmos__beams_il_index(il, x, y);
    const double o = atmos__beams_il_offset(il->n, x, y);
    for (int k = 0; k < J->nw; k++) A[k] = 0;
    if (b->sigma_t > 0) lights(J, x, y, d, T, f, A, px && x == J->cx && y == J->cy, o, ALL_LIGHTS, NULL);
    for (int k = 0; k < J->nw; k++) il->air[(size_t)q * J->nw + k] = (float)A[k];
    il->depth[q] = (float)T, il->object[q] = hit ? m : -1;
}

/* The least and greatest x of the convex hull of the n points q (x, y) over the band of
 * heights [b0, b1]: over every segment between two points, the part within the band (the
 * hull's edges are among them). lo > hi when the band misses the hull. */
static void band_span(const double (*q)[2], int n, double b0, double b1, double *lo, double *hi)
{
    *lo = INFINITY, *hi = -INFINITY;
    for (int i = 0; i < n; i++)
        for (int j = i; j < n; j++) {
            const double ya = q[i][1], yb = q[j][1], xa = q[i][0], xb = q[j][0];
            const double y0 = fmax(b0, fmin(ya, yb)), y1 = fmin(b1, fmax(ya, yb));
            if (y0 > y1) continue;
            double x0 = xa, x1 = xb;
            if (ya != yb) x0 = xa + (y0 - ya) / (yb - ya) * (xb - xa), x1 = xa + (y1 - ya) / (yb - ya) * (xb - xa);
            *lo = fmin(*lo, fmin(x0, x1)), *hi = fmax(*hi, fmax(x0, x1));
        }
}

/* The pixels whose rays may meet the part of light l that it lights within its reach R, as
 * per row y the columns [span[2y], span[2y + 1]): a pinhole camera's image of a hull of that
 * part (a spot's cone cut by the sphere lies within the pyramid of its apex and the octagon
 * around the cone's circle at R along the axis; a point light's sphere within its cube), when
 * every corner is in front of the camera (else, or for a wide spot or another camera, every
 * pixel). Each row takes the hull over the band of its pixels' centres widened by a pixel,
 * and a pixel of margin each side. */
static void screen_spans(const job *J, const atmos__beams_light *l, double R, int *span)
{
    const atmos_camera *c = J->cam;
    for (int y = 0; y < c->height; y++) span[2 * y] = 0, span[2 * y + 1] = c->width;
    const int spot = l->L.type == ATMOS_LIGHT_SPOT;
    if (c->type != ATMOS_CAMERA_PINHOLE || (spot && !(l->L.cos_outer > 0.2))) return;
    double P[9][3], q[9][2], e1[3], e2[3];
    int n = 0;
    if (spot) {
        const double *a = l->L.axis, ref[3] = {fabs(a[1]) < 0.9 ? 0 : 1, fabs(a[1]) < 0.9 ? 1 : 0, 0};
        const double w = R * sqrt(1 - l->L.cos_outer * l->L.cos_outer) / l->L.cos_outer / cos(ATMOS_PI / 8);
        atmos__cross3(a, ref, e1);
        atmos__normalize3(e1);
        atmos__cross3(a, e1, e2);
        memcpy(P[n++], l->L.pos, sizeof P[0]);
        for (int k = 0; k < 8; k++, n++) {
            const double cs = cos(k * ATMOS_PI / 4), sn = sin(k * ATMOS_PI / 4);
            for (int m = 0; m < 3; m++) P[n][m] = l->L.pos[m] + R * a[m] + w * (cs * e1[m] + sn * e2[m]);
        }
    } else
        for (int k = 0; k < 8; k++, n++)
            for (int m = 0; m < 3; m++) P[n][m] = l->L.pos[m] + (k >> m & 1 ? R : -R);
    for (int k = 0; k < n; k++) {
        const double v[3] = {P[k][0] - J->eye[0], P[k][1] - J->eye[1], P[k][2] - J->eye[2]};
        const double z = atmos__dot3(v, c->forward);
        if (!(z > 1e-9 * R)) return;
        q[k][0] = 0.5 * (c->width + atmos__dot3(v, c->right) / z / c->tan_half_fov * c->height);
        q[k][1] = 0.5 * c->height * (1 - atmos__dot3(v, c->up) / z / c->tan_half_fov);
    }
    for (int y = 0; y < c->height; y++) {
        double lo, hi;
        band_span((const double(*)[2])q, n, y - 0.5, y + 1.5, &lo, &hi);
        if (!(lo <= hi)) {
            span[2 * y] = span[2 * y + 1] = 0;
            continue;
        }
        span[2 * y] = (int)atmos__clampd(floor(lo) - 1, 0, c->width);
        span[2 * y + 1] = (int)atmos__clampd(ceil(hi) + 1, 0, c->width);
    }
}

/* Each object's albedo over pi (J->alb_pi); each light's planes: evenly spaced in depth along
 * the view across the sphere it reaches; the pixels it may light (screen_spans). */
static atmos_status planes(atmos_plan *p, job *J)
{
    const atmos__beams_plan *b = J->b;
    J->z_lo = malloc(sizeof(double) * 4 * (size_t)(b->nlights ? b->nlights : 1));
    J->span = malloc(sizeof(int) * 2 * (size_t)J->cam->height * (size_t)(b->nlights ? b->nlights : 1));
    J->alb_pi = malloc(sizeof *J->alb_pi * (size_t)(b->obj.n > 0 ? b->obj.n : 1));
    J->from_eye = malloc(sizeof *J->from_eye * (size_t)(b->nlights ? b->nlights : 1));
    if (!J->z_lo || !J->span || !J->alb_pi || !J->from_eye) {
        free(J->z_lo), free(J->span), free(J->alb_pi), free(J->from_eye);
        return atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory");
    }
    for (int m = 0; m < b->obj.n; m++)
        for (int k = 0; k < J->nw; k++) J->alb_pi[m][k] = b->obj.albedo[m][k] / ATMOS_PI;
    J->dz = J->z_lo + b->nlights, J->reach = J->dz + b->nlights, J->weight = J->reach + b->nlights;
    for (int i = 0; i < b->nlights; i++) {
        const atmos__beams_light *l = &b->lights[i];
        const double R = b->sigma_t > 0 ? fmin(l->L.range, ATMOS__BEAMS_MAX_OPTICAL_RANGE / b->sigma_t) : l->L.range;
        const double Lp[3] = {l->L.pos[0] - J->eye[0], l->L.pos[1] - J->eye[1], l->L.pos[2] - J->eye[2]};
        const double given = p->scene.beams.plane_spacing_m;
        J->reach[i] = R, J->weight[i] = 0;
        for (int k = 0; k < J->nw; k++) J->weight[i] += l->L.I[k] / J->nw;
        J->z_lo[i] = atmos__dot3(Lp, J->fwd) - R;
        J->dz[i] = fmax(given > 0 ? given : 2 * R / 40, 2 * R / (MAX_INTERVALS - 8));
        screen_spans(J, l, R, J->span + 2 * (size_t)i * J->cam->height);
        atmos__beams_ray_eye(l, J->eye, &J->from_eye[i]);
    }
    return ATMOS_OK;
}

/* The pixels of rows [y0, y1) over columns [x0, x1), each row to one thread (dynamically: a
 * pixel depends on its own ray alone, so the image is the same for any thread count); with
 * il, the pixels outside r get their airlight alone. Returns 1 when out of memory. */
static int rows(atmos_plan *p, job *J, const atmos__rect *r, const atmos__rect *e, atmos_image *out, atmos__beams_il *il,
                int *cancelled)
{
    const int W = out->width, C = out->channels, n = e->y1 - e->y0;
    int failed = 0, done = 0;
#pragma omp parallel num_threads(atmos__threads(p->ctx))
    {
        double *f = malloc(sizeof(double) * buffer_size(J->b->nlights));
        if (!f) {
#pragma omp atomic write
            failed = 1;
        }
#pragma omp for schedule(dynamic, 1)
        for (int y = e->y0; y < e->y1; y++) {
            if (atmos__cancelled(cancelled) || !f) continue;
            for (int x = e->x0; x < e->x1; x++) {
                const int inside = x >= r->x0 && x < r->x1 && y >= r->y0 && y < r->y1;
                pixel(J, x, y, inside ? out->pixels + ((size_t)y * W + x) * C : NULL, f, il);
            }
            atmos__progress_step(p->ctx, "render beams", &done, n, cancelled);
        }
        free(f);
    }
    return failed;
}

/* Subsampling's tolerances (docs/beams.md, *Subsampling the airlight*): the corners of a cell
 * may differ by SPREAD of their pixels' light, its centre from the interpolation by CURVE, its
 * depths by the ratio 1 + DEPTH. */
#ifndef SCREEN_SPREAD
#define SCREEN_SPREAD 0.1
#endif
#ifndef SCREEN_CURVE
#define SCREEN_CURVE 0.01
#endif
#ifndef SCREEN_DEPTH
#define SCREEN_DEPTH 0.5
#endif
/* The sky behind is read from the sky renderer's grid of every screen_step pixels, at most
 * this many (a grid of 8 misses more of the sky's bends than the lattice's tests let through). */
#ifndef SKY_STEP_MAX
#define SKY_STEP_MAX 4
#endif
/* 1: a cell that a light's span crosses is cut (the lit cones' hint, beams_screen.h). */
#ifndef SCREEN_HINT
#define SCREEN_HINT 1
#endif
/* 1: a subsampled frame's spots on a lattice of their own (air_layers). */
#ifndef SCREEN_LAYERS
#define SCREEN_LAYERS 1
#endif
/* A span this many cells' widths wide (or more) in every row of a cell is not its hint there. */
#ifndef SCREEN_WIDE
#define SCREEN_WIDE 8
#endif
/* A cut cell at most this many pixels wide and tall hands its corners' agreement on a point
 * light's stretches to the rays evaluated in it (shared_ray; 0: none). */
#ifndef SCREEN_SHARE
#define SCREEN_SHARE 16
#endif

/* The eye's ray through pixel (x, y) in a subsampled frame: kept from the first pass (J->dir) when
 * there is one, the same bits as eye_ray's. */
static inline void kept_ray(const job *J, int x, int y, double d[3])
{
    if (!J->dir) {
        eye_ray(J, x, y, d);
        return;
    }
    const size_t W = (size_t)(J->dir_r.x1 - J->dir_r.x0), n = W * (size_t)(J->dir_r.y1 - J->dir_r.y0);
    const size_t i = (size_t)(y - J->dir_r.y0) * W + (size_t)(x - J->dir_r.x0);
    d[0] = J->dir[i], d[1] = J->dir[n + i], d[2] = J->dir[2 * n + i];
}

/* The buffers of a subsampled frame over r (each NULL until made), the plan's (beams_kept.h), kept
 * for the next frame. */
typedef struct screen_buf {
    int *X, *Y, *obj;
    double *T, *node;
    float *base;
    double *dir;      /* the eye's rays (a pinhole camera; else NULL) */
    uint64_t *seen;   /* per layer and node: what its evaluation saw (two masks, air_pixel) */
} screen_buf;

/* Subsampling's first pass for a surface that no light reaches (no cones): the sky's light and
 * the sun's, dimmed by the fog to the eye, into B in one loop a pixel (the same operations in
 * the same order as shade_surface, base_light and sun_surface one after the other: the same bits). */
ATMOS_CLONE_HELPER void unlit_surface(const job *J, const double d[3], const atmos_mesh_hit *h, int m, float *B,
                                      atmos__beams_sky_memo *memo)
{
    const atmos__beams_plan *b = J->b;
    double E[ATMOS_MAX_WAVELENGTHS], c = 0, in = 0;
    const double *e = sky_light(J, d, h, E, memo), *a = J->alb_pi[m], *sE = b->sun.E;
    const int nw = J->nw;
    if (!e && !b->sun_on) { /* nothing reaches it: the zeros, no fog */
        for (int k = 0; k < nw; k++) B[k] = (float)(a[k] * 0.0);
        return;
    }
    const double fog_t = fog_to(J, d, h->t);
    const int sun = b->sun_on && sun_reaches(J, d, h, &c, &in);
    if (e && sun)
        for (int k = 0; k < nw; k++) B[k] = (float)(a[k] * (0.0 + e[k]) * fog_t + a[k] * sE[k] * c * in * fog_t);
    else if (e)
        for (int k = 0; k < nw; k++) B[k] = (float)(a[k] * (0.0 + e[k]) * fog_t);
    else if (sun)
        for (int k = 0; k < nw; k++) B[k] = (float)(a[k] * 0.0 * fog_t + a[k] * sE[k] * c * in * fog_t);
    else
        for (int k = 0; k < nw; k++) B[k] = (float)(a[k] * 0.0 * fog_t);
}

/* Subsampling's first pass, pixel (x, y) seeing h of object obj along the eye's ray d (-1: the
 * sky behind, bg), lit by the lights in cones (row_cones): its light without the airlight into B. */
ATMOS_CLONE_HELPER void surface_light(const job *J, int x, int y, const double d[3], const atmos_mesh_hit *h, int obj,
                                      uint32_t cones, const float *bg, float *B, atmos__beams_sky_memo *memo)
{
    const atmos__beams_plan *b = J->b;
    double L[ATMOS_MAX_WAVELENGTHS];
    const int hit = obj >= 0;
    if (hit && !cones) {
        unlit_surface(J, d, h, obj, B, memo);
        return;
    }
    if (!hit) { /* the sky behind through the fog (base_light's, in one loop); a black sky (every
                 * wavelength +-0) stays so with no fog evaluated: +-0 times a transmittance in [0, 1]
                 * is the same zero, the same bits */
        int black = 1;
        for (int k = 0; k < J->nw; k++) black &= bg[k] == 0;
        if (black) {
            for (int k = 0; k < J->nw; k++) B[k] = bg[k];
            return;
        }
        const double fog_t = fog_to(J, d, INFINITY);
        for (int k = 0; k < J->nw; k++) B[k] = (float)(bg[k] * fog_t);
        return;
    }
    const double fog_t = base_light(J, x, y, d, hit ? h : NULL, obj, cones, bg, hit && b->sun_on, L, memo);
    if (hit && b->sun_on) sun_surface(J, d, h, obj, fog_t, L);
    for (int k = 0; k < J->nw; k++) B[k] = (float)L[k];
}

/* Subsampling's first pass over row y (its rays made when kept): what each pixel sees (into T,
 * obj and hits), the lights that may reach it (cones: a row at a time where the rays are kept),
 * its light without the airlight (into base). Its wavelengths' loops (unlit_surface's, the sky
 * behind's) in vectors of four in the AVX2 clone: the same operations lane by lane, the same bits. */
ATMOS_CLONES static void surface_row(const job *J, const atmos__rect *r, int y, const screen_buf *q,
                                     atmos_mesh_hit *hits, uint32_t *cones, atmos_image *out)
{
    const int W = r->x1 - r->x0;
    const size_t n = (size_t)W * (size_t)(r->y1 - r->y0), row = (size_t)(y - r->y0) * W;
    double *T = q->T + row, d[3];
    int *obj = q->obj + row;
    for (int x = r->x0, i = 0; x < r->x1; x++, i++) {
        kept_ray(J, x, y, d);
        int m = -1;
        const int hit = J->prim ? atmos__beams_primary_hit(J->prim, &J->b->obj, x, y, J->eye, d, &hits[i], &m) : 0;
        T[i] = hit ? hits[i].t : INFINITY, obj[i] = hit ? m : -1;
        if (!q->dir) row_cones(J, &d[0], &d[1], &d[2], &T[i], 1, &cones[i]);
    }
    if (q->dir) row_cones(J, q->dir + row, q->dir + n + row, q->dir + 2 * n + row, T, W, cones);
    atmos__beams_sky_memo memo = {{0, 0, 0}, 0, 0, {0}}; /* the row's last sky irradiance (a flat ground's) */
    for (int x = r->x0, i = 0; x < r->x1; x++, i++) {
        kept_ray(J, x, y, d);
        float *px = out->pixels + ((size_t)y * out->width + x) * out->channels;
        surface_light(J, x, y, d, &hits[i], obj[i], cones[i], px, q->base + (row + i) * J->nw, &memo);
    }
}

/* One layer of a subsampled frame's airlight: the lights of mask (light i: bit i), and the sun's
 * if sun; each layer has its own lattice, its own cuts and its own hints (those of its lights). */
typedef struct air_layer {
    job *J;
    uint32_t mask;
    int sun;
    int shared; /* its point light whose rays share their corners' (shared_ray; -1: none) */
} air_layer;

/* The airlight of pixel (x, y) (atmos__beams_air_fn) of the layer user: its lights' and the sun's. */
static void air_pixel(void *user, double *f, int x, int y, double T, const uint64_t *known, uint64_t seen[2], double *A)
{
    const air_layer *a = user;
    job *J = a->J;
    double d[3];
    const shared_ray sh = {a->shared, known, seen, unread_count(f, J->b->nlights)};
    kept_ray(J, x, y, d);
    for (int k = 0; k < J->nw; k++) A[k] = 0;
    seen[0] = seen[1] = 0;
    if (J->b->sigma_t > 0) lights(J, x, y, d, T, f, A, J->centre_now, 0.5, a->mask, a->shared >= 0 ? &sh : NULL);
    if (a->sun && J->b->sun_on) sun_air(J, d, T, A);
}

/* A subsampled frame's layers into a (at most 2; returns how many): the spots apart from the
 * other lights and the sun when there are both, so that a spot's span, a hint that cuts the
 * cells along its beam down to single pixels, cuts only the spots' lattice, and the others'
 * airlight (a point light's glow, the sun's) is still interpolated there where it is smooth;
 * else one layer of everything. Either way a pixel evaluated in every layer gets the light it
 * would get in one (the sub-planes per light as before: lights() weighs all the pixel's lights). */
static int air_layers(job *J, air_layer a[2])
{
    uint32_t spots = 0;
    int points = 0, shared = -1; /* a layer's rays share their corners' view of its one shadowed point light */
    for (int i = 0; i < J->b->nlights; i++) {
        const atmos__beams_light *l = &J->b->lights[i];
        if (l->L.type == ATMOS_LIGHT_SPOT) spots |= (uint32_t)1 << i;
        else if (l->L.type == ATMOS_LIGHT_POINT && points++ == 0 && l->nfaces && !l->L.tex) shared = i;
    }
    if (points != 1 || !(SCREEN_SHARE > 0)) shared = -1;
    const uint32_t all = J->b->nlights >= 32 ? ALL_LIGHTS : ((uint32_t)1 << J->b->nlights) - 1, rest = all & ~spots;
    a[0] = (air_layer){J, ALL_LIGHTS, 1, shared};
    if (!SCREEN_LAYERS || !spots || (!rest && !J->b->sun_on)) return 1;
    a[0].mask = rest, a[1] = (air_layer){J, spots, 0, -1};
    return 2;
}

/* A row of W pixels of the frame: each wavelength's light without the airlight (base) plus
 * the layers' airlight (b0, and b1 unless NULL), into px (C channels a pixel); inlined into
 * compose_row, where a constant nw unrolls the loop over the wavelengths. */
ATMOS_CLONE_HELPER void compose_nw(int W, const int nw, int C, const float *restrict base, const double *restrict b0,
                                   const double *restrict b1, float *restrict px)
{
    for (int x = 0; x < W; x++) {
        const size_t i = (size_t)x * nw;
        float *restrict o = px + (size_t)x * C;
        if (b1)
            for (int k = 0; k < nw; k++) o[k] = (float)((double)base[i + k] + b0[i + k] + b1[i + k]);
        else
            for (int k = 0; k < nw; k++) o[k] = (float)((double)base[i + k] + b0[i + k]);
    }
}

/* compose_nw, unrolled for the rgb mode's three wavelengths and the spectral mode's 16, and
 * built for AVX2 as well (eight wavelengths at a time where the baseline takes four): the same
 * operations in the same order, the same bits. */
ATMOS_CLONES static void compose_row(int W, int nw, int C, const float *base, const double *b0, const double *b1,
                                     float *px)
{
    if (nw == 3) compose_nw(W, 3, C, base, b0, b1, px);
    else if (nw == 16) compose_nw(W, 16, C, base, b0, b1, px);
    else compose_nw(W, nw, C, base, b0, b1, px);
}

/* Band j of a subsampled frame (atmos__beams_screen_band) from the lattice's nodes, each of the
 * nl layers s[l] in its own band[l] and state[l], their sum added to the pixels' light (its last
 * row only in the last band: the next band's first). Returns the pixels evaluated (in each
 * layer: a pixel evaluated in two counts twice). */
static long screen_band(const atmos__beams_screen *s, int nl, const screen_buf *q, int nx, int ny, int j, double *f,
                        double *const *band, unsigned char *const *state, uint64_t *seen, long *shared,
                        atmos_image *out)
{
    const atmos__rect *r = &s->r;
    const int W = r->x1 - r->x0, nw = s->nw, y0 = q->Y[j], y1 = ny > 1 ? q->Y[j + 1] : y0;
    long ev = 0;
    for (int l = 0; l < nl; l++) {
        memset(state[l], 0, (size_t)W * (size_t)(y1 - y0 + 1));
        for (int e = 0; e < (ny > 1 ? 2 : 1); e++)
            for (int i = 0; i < nx; i++) {
                const size_t at = (size_t)(e ? y1 - y0 : 0) * W + (size_t)(q->X[i] - r->x0);
                const size_t node = l * (size_t)nx * ny + (size_t)(j + e) * nx + i;
                memcpy(band[l] + at * nw, q->node + node * nw, sizeof(double) * nw);
                memcpy(seen + 2 * at, q->seen + 2 * node, sizeof(uint64_t) * 2);
                state[l][at] = 2;
            }
        ev += atmos__beams_screen_band(&s[l], f, q->X, nx, y0, y1, band[l], state[l], seen, shared);
    }
    const int last = j + 2 >= ny ? y1 : y1 - 1;
    for (int y = y0; y <= last; y++) {
        const size_t a = (size_t)(y - y0) * W * nw, p = (size_t)(y - r->y0) * W * nw;
        compose_row(W, nw, out->channels, q->base + p, band[0] + a, nl > 1 ? band[1] + a : NULL,
                    out->pixels + ((size_t)y * out->width + r->x0) * out->channels);
    }
    return ev;
}

/* The frame over r with the airlight subsampled every k pixels (beams_screen.h): the pixels'
 * surfaces, the lattice's nodes, then its bands, each pass's rows to the threads (each value
 * depends on its own pixel or band alone: the image is the same for any thread count). Returns
 * 1 when out of memory; *evaluated: the pixels whose airlight was evaluated. */
static int subsampled(atmos_plan *p, job *J, const atmos__rect *r, atmos_image *out, int k, int *cancelled,
                      long *evaluated)
{
    const int W = r->x1 - r->x0, H = r->y1 - r->y0, nw = J->nw;
    const size_t n = (size_t)W * H;
    *evaluated = 0;
    if (W <= 0 || H <= 0) return 0;
    atmos__beams_kept *kept = p->beams->kept; /* the plan's, for the next frame too */
    screen_buf q = {atmos__beams_kept_get(&kept[ATMOS__BEAMS_KEPT_NODE_X], sizeof(int) * (size_t)((W - 1) / k + 2)),
                    atmos__beams_kept_get(&kept[ATMOS__BEAMS_KEPT_NODE_Y], sizeof(int) * (size_t)((H - 1) / k + 2)),
                    atmos__beams_kept_get(&kept[ATMOS__BEAMS_KEPT_OBJECT], sizeof(int) * n),
                    atmos__beams_kept_get(&kept[ATMOS__BEAMS_KEPT_DEPTH], sizeof(double) * n), NULL,
                    atmos__beams_kept_get(&kept[ATMOS__BEAMS_KEPT_BASE], sizeof(float) * n * nw), NULL, NULL};
    int failed = !q.X || !q.Y || !q.obj || !q.T || !q.base, done = 0;
    const int nx = failed ? 0 : atmos__beams_screen_nodes(r->x0, r->x1, k, q.X);
    const int ny = failed ? 0 : atmos__beams_screen_nodes(r->y0, r->y1, k, q.Y), nb = ny > 1 ? ny - 1 : 1;
    air_layer a[2];
    const int nl = air_layers(J, a);
    const size_t layer = (size_t)nx * ny * nw; /* the nodes of a layer */
    if (!failed) failed = !(q.node = atmos__beams_kept_get(&kept[ATMOS__BEAMS_KEPT_NODE], sizeof(double) * nl * layer));
    if (!failed)
        failed = !(q.seen = atmos__beams_kept_get(&kept[ATMOS__BEAMS_KEPT_SEEN], sizeof(uint64_t) * 2 * (size_t)nl * nx * ny));
    if (failed) return 1;
    /* none: each pass makes its rays */
    q.dir = J->ru ? atmos__beams_kept_get(&kept[ATMOS__BEAMS_KEPT_DIR], sizeof(double) * 3 * n) : NULL;
    J->dir = q.dir, J->dir_r = *r;
    atmos__beams_screen s[2];
    for (int l = 0; l < nl; l++)
        s[l] = (atmos__beams_screen){*r, k, nw, SCREEN_SPREAD, SCREEN_CURVE, SCREEN_DEPTH, q.T, q.obj, q.base,
                                     SCREEN_HINT ? J->span : NULL, SCREEN_HINT ? J->b->nlights : 0, J->cam->height,
                                     a[l].mask, !(a[l].sun && J->b->sun_on), SCREEN_WIDE,
                                     a[l].shared >= 0 ? SCREEN_SHARE : 0, air_pixel, &a[l]};
    long ev = 0, sh = 0, un = 0, told = 0;
#pragma omp parallel num_threads(atmos__threads(p->ctx)) reduction(+ : ev, sh, un, told)
    {
        const size_t bw = (size_t)W * (k + 1); /* a band's pixels */
        double *f = malloc(sizeof(double) * buffer_size(J->b->nlights)), *band = malloc(sizeof(double) * bw * nw * nl);
        unsigned char *state = malloc(bw * nl);
        uint64_t *seen = malloc(sizeof(uint64_t) * 2 * bw); /* a layer's band at a time */
        atmos_mesh_hit *hits = malloc(sizeof *hits * (size_t)W);
        uint32_t *cones = malloc(sizeof *cones * (size_t)W);
        const int ok = f && band && state && seen && hits && cones;
        if (f) unread_count(f, J->b->nlights)[0] = unread_count(f, J->b->nlights)[1] = 0;
        double *const bands[2] = {band, band ? band + bw * nw : NULL};
        unsigned char *const states[2] = {state, state ? state + bw : NULL};
        if (!ok) {
#pragma omp atomic write
            failed = 1;
        }
#pragma omp for schedule(dynamic, 1)
        for (int y = r->y0; y < r->y1; y++) {
            double *row = q.dir ? q.dir + (size_t)(y - r->y0) * W : NULL;
            if (row && ok) atmos__camera_pinhole_dirs(J->cam, J->ru + r->x0, W, J->rv[y], row, row + n, row + 2 * n);
            if (ok && !atmos__cancelled(cancelled)) surface_row(J, r, y, &q, hits, cones, out);
        }
        int any_failed; /* after the rows' barrier: a thread's failure leaves its rows' rays unset */
#pragma omp atomic read
        any_failed = failed;
#pragma omp for schedule(dynamic, 1)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx && ok && !any_failed && !atmos__cancelled(cancelled); i++)
                for (int l = 0; l < nl; l++, ev++) {
                    const size_t node = l * (size_t)nx * ny + (size_t)j * nx + i;
                    air_pixel(&a[l], f, q.X[i], q.Y[j], q.T[(size_t)(q.Y[j] - r->y0) * W + (size_t)(q.X[i] - r->x0)],
                              NULL, q.seen + 2 * node, q.node + node * nw);
                }
#pragma omp for schedule(dynamic, 1)
        for (int j = 0; j < nb; j++) {
            if (!ok || atmos__cancelled(cancelled)) continue;
            ev += screen_band(s, nl, &q, nx, ny, j, f, bands, states, seen, &sh, out);
            atmos__progress_step(p->ctx, "render beams", &done, nb, cancelled);
        }
        if (f) un += (long)unread_count(f, J->b->nlights)[0], told += (long)unread_count(f, J->b->nlights)[1];
        free(f), free(band), free(state), free(seen), free(hits), free(cones);
    }
    if (!failed && J->cx >= r->x0 && J->cx < r->x1 && J->cy >= r->y0 && J->cy < r->y1) { /* the centre ray's counts */
        double *f = malloc(sizeof(double) * buffer_size(J->b->nlights)), A[ATMOS_MAX_WAVELENGTHS];
        air_layer every = {J, ALL_LIGHTS, 1, -1};
        uint64_t seen[2];
        J->centre_now = 1;
        if (f) air_pixel(&every, f, J->cx, J->cy, q.T[(size_t)(J->cy - r->y0) * W + (size_t)(J->cx - r->x0)], NULL, seen, A);
        J->centre_now = 0;
        free(f);
    }
    J->dir = NULL;
    *evaluated = ev, p->beams->air_shared = sh, p->beams->air_unread = un, p->beams->air_told = told;
    return failed;
}

/* Interleaved sampling's second pass: each pixel of r gets its filtered airlight. */
static void filter(atmos_plan *p, const atmos__rect *r, atmos_image *out, const atmos__beams_il *il)
{
    const int W = out->width, C = out->channels;
#pragma omp parallel for schedule(static) num_threads(atmos__threads(p->ctx))
    for (int y = r->y0; y < r->y1; y++)
        for (int x = r->x0; x < r->x1; x++) atmos__beams_il_add(il, x, y, out->pixels + ((size_t)y * W + x) * C);
}

/* A frame's own buffers (a job is zeroed first: the ones not made yet are NULL). */
static void job_free(job *J)
{
    free(J->z_lo), free(J->span), free(J->alb_pi), free(J->from_eye), free(J->ru);
}

/* The sky behind into out over r, on the airlight's lattice too (the sky renderer's grid:
 * sky_render.c); where prim (may be NULL) holds a triangle for a pixel, its surface hides the
 * sky, which is then read from the grid rather than evaluated (the sky renderer's hidden). */
static atmos_status sky_behind(atmos_plan *p, const atmos__view *v, const atmos__rect *r, const atmos__beams_primary *prim,
                               atmos_image *out)
{
    atmos__view sv = *v;
    const int sky_step = p->scene.beams.screen_step < SKY_STEP_MAX ? p->scene.beams.screen_step : SKY_STEP_MAX;
    if (p->scene.beams.interleave <= 1 && sky_step > sv.sky_step) sv.sky_step = sky_step;
    const size_t n = (size_t)(r->x1 - r->x0) * (size_t)(r->y1 - r->y0);
    unsigned char *hidden = NULL; /* none when out of memory: every pixel's sky evaluated */
    if (prim && prim->mesh && !memcmp(&prim->r, r, sizeof *r) &&
        (hidden = atmos__beams_kept_get(&p->beams->kept[ATMOS__BEAMS_KEPT_HIDDEN], n)) != NULL)
        for (size_t i = 0; i < n; i++) hidden[i] = prim->mesh[i] >= 0;
    return atmos__sky_render_hidden(p->ctx, p->atm, &sv, r, out, p->sky_keep, hidden);
}

atmos_status atmos__beams_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out)
{
    atmos__beams_plan *b = p->beams;
    atmos_status st;
    job J;
    memset(&J, 0, sizeof J);
    J.b = b, J.cam = &v->cam, J.eye = v->cam.position, J.nw = p->wl.count;
    memcpy(J.fwd, v->cam.forward, sizeof J.fwd);
    J.cx = v->cam.width / 2, J.cy = v->cam.height / 2;
    J.epsilon = p->scene.beams.epsilon, J.max_sub = p->scene.beams.max_subplanes;
    if ((st = planes(p, &J)) != ATMOS_OK) return st;
    if (eye_coordinates(&J)) {
        job_free(&J);
        return atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory");
    }
    /* the sky seen from the ground under the eye, kept while that stays within its quantum; as
     * the eye's sky behind, none through a uniform fog (it has no top: the sky is not seen) */
    const int layered = b->fog.sigma0 > 0 && b->fog.height_m > 0, sky_seen = !(b->fog.sigma0 > 0) || layered;
    if ((b->sun_on && (st = atmos__beams_sun_frame(p, v)) != ATMOS_OK) ||
        (b->obj.n > 0 && sky_seen &&
         (st = atmos__beams_sky_keep(p->ctx, p->atm, J.eye, v->sun, J.nw, layered, &b->sky)) != ATMOS_OK)) {
        job_free(&J);
        return st;
    }
    atmos__beams_fog_eye(&b->fog, J.eye, b->sun.dir); /* the eye's factors, once a frame, after the sun's */
    atmos__beams_il il = {0}, *ilp = NULL;
    atmos__beams_primary prim = {{0, 0, 0, 0}, NULL, NULL, 0, 0};
    int failed = 0, cancelled = 0;
    if (p->scene.beams.interleave > 1) {
        ilp = &il;
        failed = atmos__beams_il_init(&il, p->scene.beams.interleave, J.nw, r, out->width, out->height);
    }
    if (!failed && b->obj.n > 0) {
        if ((st = atmos__beams_primary_build_kept(p->ctx, &b->obj, &v->cam, ilp ? &il.e : r, &b->kept[ATMOS__BEAMS_KEPT_PRIMARY],
                                                  &prim)) != ATMOS_OK) {
            atmos__beams_il_free(&il), job_free(&J);
            return st;
        }
        J.prim = &prim;
        J.sky = sky_seen ? &b->sky : NULL;
    }
    if (!failed && (st = sky_behind(p, v, r, ilp ? NULL : J.prim, out)) != ATMOS_OK) {
        atmos__beams_primary_free(&prim), atmos__beams_il_free(&il), job_free(&J);
        return st;
    }
    const int step = p->scene.beams.screen_step;
    b->air_shared = b->air_unread = b->air_told = 0; /* set by a subsampled frame */
    long evaluated = (long)(r->x1 - r->x0) * (r->y1 - r->y0);
    if (!failed && step > 1 && !ilp) failed = subsampled(p, &J, r, out, step, &cancelled, &evaluated);
    else if (!failed) failed = rows(p, &J, r, ilp ? &il.e : r, out, ilp, &cancelled);
    atmos__beams_primary_free(&prim);
    if (ilp && !failed && !cancelled) filter(p, r, out, &il);
    atmos__beams_il_free(&il);
    job_free(&J);
    b->centre_planes = J.centre_planes, b->centre_subplanes = J.centre_subplanes;
    b->air_evaluated = evaluated, b->air_pixels = (long)(r->x1 - r->x0) * (r->y1 - r->y0);
    if (failed) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render beams: out of memory");
    if (cancelled) return atmos__error(p->ctx, ATMOS_E_CANCELLED, "render beams: cancelled");
    atmos__progress(p->ctx, "render beams", 1.0);
    return ATMOS_OK;
}
