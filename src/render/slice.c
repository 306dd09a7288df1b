/* Riley et al. 2004 §4.2-§5: half-angle slicing (Kniss et al.) with multiple-scattering
 * phase functions. See include/atmos/slice.h and docs/slice.md.
 *
 * Everything geometric happens in the volume's grid frame (metres, axes of the voxel
 * grid, origin at the grid's corner): g = R^T (world - origin - offset). The frame is
 * rigid, so distances and angles are those of the world.
 *
 * Per slice k (planes perpendicular to the half vector h, advancing away from the sun):
 *  1. eye pass: every pixel's ray meets slice k at one point; the light buffer gives
 *     I and n there; Eq. 26 is accumulated front-to-back (eye and light within 90°)
 *     or back-to-front (otherwise);
 *  2. light pass: every light texel's ray meets slice k at one point; I is attenuated
 *     by Eq. 25 (or Eq. 24) and n grows by Eq. 21.
 * Both passes write only their own pixel/texel, so rows are split over threads with a
 * static schedule and the image does not depend on the thread count.
 */
#define _POSIX_C_SOURCE 200809L
#include "core/internal.h"
#include "core/vec.h"
#include "render/slice_internal.h"
#include "atmosphere/atmosphere_ops.h"
#include "volume/volume_grid.h"

#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SLICE_HD_EPS 0.02      /* rays within ~89° of the slice planes are not sliced */

void atmos_slice_defaults(atmos_slice_settings *s)
{
    memset(s, 0, sizeof *s);
    s->slices = 256;
    s->light_size = 256;
    s->xi = 0.1 / (4.0 * ATMOS_PI);
    s->update = ATMOS_SLICE_EQ25;
    s->grid_max_dim = 256;
    s->max_order = 64;
    s->density_scale = 1.0;
    s->eye_scale = 1.0;
}

/* ------------------------------------------------------------------ geometry helpers */

/* Sunlight arriving at the grid-frame point g (Eq. 12 in Riley's air): the world point is
 * org + R g. */
static void sunlight_at(const atmos_atmosphere *atm, const double org[3], const double *R, const double g[3],
                        const double sun[3], double *out)
{
    double w[3];
    for (int a = 0; a < 3; a++) w[a] = org[a] + R[3 * a] * g[0] + R[3 * a + 1] * g[1] + R[3 * a + 2] * g[2];
    atmos_atmosphere_sunlight(atm, w, sun, out);
}

/* Slice indices k whose plane s_k = s0 + (k + 0.5) ds lies in [sa, sb]. */
static void slice_range(double sa, double sb, double s0, double ds, int nslices, int *k0, int *k1)
{
    double a = ceil((sa - s0) / ds - 0.5), b = floor((sb - s0) / ds - 0.5);
    if (a < 0) a = 0;
    if (b > nslices - 1) b = nslices - 1;
    if (!(a <= b)) {
        *k0 = 1, *k1 = 0;
        return;
    }
    *k0 = (int)a, *k1 = (int)b;
}

/* §5 composite of one image pixel along direction dw (world): the air from the eye
 * to the halfway plane at distance th is in front of the volume, the rest (with the
 * ground and the sun's disk) behind it. px holds the sky image B (= front + T_front *
 * back) and receives front + T_front * L_vol + T_vol * (B - front). */
static void composite_pixel(const atmos_atmosphere *atm, const atmos_camera *cam, const double dw[3], double th,
                            const double sun_w[3], int n, const float *Lv, const float *Tv, float *px)
{
    if (!(th > 0)) th = 0;
    double front[ATMOS_MAX_WAVELENGTHS], Tf[ATMOS_MAX_WAVELENGTHS];
    double tg = atmos_atmosphere_ground_distance(atm, cam->position, dw);
    if (th > tg) th = tg;
    atmos_atmosphere_inscatter(atm, cam->position, dw, th, sun_w, front);
    atmos_atmosphere_transmittance(atm, cam->position, dw, th, Tf);
    for (int c = 0; c < n; c++) {
        double B = px[c], L = Lv[c], T = Tv[c];
        double r = front[c] + Tf[c] * L + T * (B - front[c]);
        px[c] = (float)(isfinite(r) && r > 0 ? r : 0.0);
    }
}

/* The two eye-buffer pixels (of n) around fractional eye coordinate f (pixel centres at
 * integers) and the weight of the second; clamped at the edges. */
static void eye_taps(double f, int n, int t[2], float *w)
{
    if (!(f > 0)) f = 0;
    if (f > n - 1) f = n - 1;
    int i = (int)f;
    if (i > n - 2) i = n - 2 < 0 ? 0 : n - 2;
    t[0] = i, t[1] = i + 1 < n ? i + 1 : i;
    *w = t[1] == t[0] ? 0.0f : (float)(f - i);
}

/* ------------------------------------------------------------------ the render */


/* Per-slice spans. Every occupied block (a cube of SLICE_OCC_B render voxels, widened
 * by a small margin for rounding) meets the slices between the planes through its
 * nearest and farthest corners; a sample of slice k can fall in it only at the pixels
 * inside the projection of its corners (and the texels inside their orthographic
 * projection along the light), widened by one pixel. The spans of a row are the union
 * of those footprints, so the passes visit what the occupied volume covers instead of
 * the whole image and light buffer. */
typedef struct {
    int k0, k1;          /* slices */
    int ex0, ex1, ey0, ey1; /* pixels (ex0 > ex1: none) */
    int lx0, lx1, ly0, ly1; /* light texels */
} sfoot;

static int clampi_d(double v, int lo, int hi)
{
    if (!(v > lo)) return lo; /* NaN too */
    if (v > hi) return hi;
    return (int)v;
}

static void block_footprint(const sjob *j, const atmos_camera *cam, const double cf[3], const double cr[3],
                            const double cu[3], int bi, int bj, int bk, sfoot *o)
{
    const sgrid *g = j->g;
    const double mg = 0.05; /* render voxels: float rounding of the sample positions */
    double lo[3], hi[3];
    const int b[3] = {bi, bj, bk};
    for (int a = 0; a < 3; a++) {
        double u0 = (double)b[a] * SLICE_OCC_B - mg, u1 = fmin((double)(b[a] + 1) * SLICE_OCC_B, g->c[a] - 1.0) + mg;
        lo[a] = (u0 - g->off[a]) / g->sc;
        hi[a] = (u1 - g->off[a]) / g->sc;
    }
    double smin = INFINITY, smax = -INFINITY, xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    int behind = 0;
    const double th = cam->tan_half_fov, W = cam->width, H = cam->height;
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        double sv = atmos__dot3(p, j->h);
        smin = fmin(smin, sv), smax = fmax(smax, sv);
        double uv = atmos__dot3(p, j->e1), vv = atmos__dot3(p, j->e2);
        umin = fmin(umin, uv), umax = fmax(umax, uv);
        vmin = fmin(vmin, vv), vmax = fmax(vmax, vv);
        double r[3] = {p[0] - j->eye[0], p[1] - j->eye[1], p[2] - j->eye[2]};
        double z = atmos__dot3(r, cf);
        if (!(z > 1e-6)) {
            behind++;
            continue;
        }
        /* Image position (pixels; centres at +0.5) as atmos_camera_ray inverts it, in
         * eye-buffer pixels. */
        double px = 0.5 * (W + atmos__dot3(r, cr) / (z * th) * H) / j->sx, py = 0.5 * (H - atmos__dot3(r, cu) / (z * th) * H) / j->sy;
        xmin = fmin(xmin, px), xmax = fmax(xmax, px);
        ymin = fmin(ymin, py), ymax = fmax(ymax, py);
    }
    slice_range(smin, smax, j->s0, j->ds, j->nslices, &o->k0, &o->k1);
    if (behind == 8) {
        o->ex0 = o->ey0 = 1, o->ex1 = o->ey1 = 0; /* rays only go forwards */
    } else if (behind) {
        o->ex0 = o->ey0 = 0, o->ex1 = j->W - 1, o->ey1 = j->H - 1; /* straddles the eye: everywhere */
    } else {
        o->ex0 = clampi_d(floor(xmin - 0.5) - 1, 0, j->W), o->ex1 = clampi_d(ceil(xmax - 0.5) + 1, -1, j->W - 1);
        o->ey0 = clampi_d(floor(ymin - 0.5) - 1, 0, j->H), o->ey1 = clampi_d(ceil(ymax - 0.5) + 1, -1, j->H - 1);
    }
    /* Texel a's ray is at u = u0 + (a + 0.5) du. */
    o->lx0 = clampi_d(floor((umin - j->u0) / j->du - 0.5) - 1, 0, j->L);
    o->lx1 = clampi_d(ceil((umax - j->u0) / j->du - 0.5) + 1, -1, j->L - 1);
    o->ly0 = clampi_d(floor((vmin - j->v0) / j->dv - 0.5) - 1, 0, j->L);
    o->ly1 = clampi_d(ceil((vmax - j->v0) / j->dv - 0.5) + 1, -1, j->L - 1);
}

/* Fills j->espan and j->lspan. Returns 0 if out of memory. */
static int build_spans(sjob *j, const atmos_camera *cam, const double cf[3], const double cr[3], const double cu[3],
                       int threads)
{
    const sgrid *g = j->g;
    size_t nb = (size_t)g->ob[0] * g->ob[1] * g->ob[2], nocc = 0;
    for (size_t i = 0; i < nb; i++) nocc += g->occ[i] != 0;
    sfoot *fp = malloc(sizeof *fp * (nocc ? nocc : 1));
    size_t *idx = malloc(sizeof *idx * (nocc ? nocc : 1));
    if (!fp || !idx) {
        free(fp), free(idx);
        return 0;
    }
    nocc = 0;
    for (size_t i = 0; i < nb; i++)
        if (g->occ[i]) idx[nocc++] = i;
    const long long no = (long long)nocc;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long i = 0; i < no; i++) {
        size_t b = idx[i];
        int bi = (int)(b % (size_t)g->ob[0]), bj = (int)((b / (size_t)g->ob[0]) % (size_t)g->ob[1]),
            bk = (int)(b / ((size_t)g->ob[0] * g->ob[1]));
        block_footprint(j, cam, cf, cr, cu, bi, bj, bk, &fp[i]);
    }
    free(idx);
    const int K = j->nslices, H = j->H, L = j->L;
    /* Each thread owns a contiguous range of slices, so the min/max updates do not race. */
#pragma omp parallel num_threads(threads)
    {
        int nt = omp_get_num_threads(), tid = omp_get_thread_num();
        int k0 = (int)((long long)K * tid / nt), k1 = (int)((long long)K * (tid + 1) / nt) - 1;
        for (int k = k0; k <= k1; k++) {
            for (int y = 0; y < H; y++) j->espan[(size_t)k * H + y] = (sspan){j->W, -1};
            for (int b = 0; b < L; b++) j->lspan[(size_t)k * L + b] = (sspan){L, -1};
        }
        for (size_t i = 0; i < nocc; i++) {
            const sfoot *f = &fp[i];
            int a = f->k0 > k0 ? f->k0 : k0, z = f->k1 < k1 ? f->k1 : k1;
            for (int k = a; k <= z; k++) {
                for (int y = f->ey0; y <= f->ey1 && f->ex0 <= f->ex1; y++) {
                    sspan *s = &j->espan[(size_t)k * H + y];
                    if (f->ex0 < s->x0) s->x0 = f->ex0;
                    if (f->ex1 > s->x1) s->x1 = f->ex1;
                }
                for (int y = f->ly0; y <= f->ly1 && f->lx0 <= f->lx1; y++) {
                    sspan *s = &j->lspan[(size_t)k * L + y];
                    if (f->lx0 < s->x0) s->x0 = f->lx0;
                    if (f->lx1 > s->x1) s->x1 = f->lx1;
                }
            }
        }
    }
    free(fp);
    for (int y = 0; y < H; y++) {
        sspan u = {j->W, -1};
        for (int k = 0; k < K; k++) {
            const sspan *e = &j->espan[(size_t)k * H + y];
            if (e->x0 < u.x0) u.x0 = e->x0;
            if (e->x1 > u.x1) u.x1 = e->x1;
        }
        j->erow[y] = u;
    }
    /* Light spans of slices k - batch..k (the texels a ring slot may hold stale). */
    for (int b = 0; b < L; b++)
        for (int k = 0; k < K; k++) {
            sspan u = {L, -1};
            for (int q = k - j->batch < 0 ? 0 : k - j->batch; q <= k; q++) {
                const sspan *e = &j->lspan[(size_t)q * L + b];
                if (e->x0 < u.x0) u.x0 = e->x0;
                if (e->x1 > u.x1) u.x1 = e->x1;
            }
            j->wspan[(size_t)k * L + b] = u;
        }
    for (int b = 0; b < L; b++) {
        sspan u = {L, -1};
        for (int k = 0; k < K; k++) {
            const sspan *e = &j->lspan[(size_t)k * L + b];
            if (e->x0 < u.x0) u.x0 = e->x0;
            if (e->x1 > u.x1) u.x1 = e->x1;
        }
        j->lrow[b] = u;
    }
    return 1;
}

static atmos_status check_settings(atmos_context *ctx, const atmos_slice_settings *in, atmos_slice_settings *s)
{
    atmos_slice_defaults(s);
    if (!in) return ATMOS_OK;
    if (in->slices) s->slices = in->slices;
    if (in->light_size) s->light_size = in->light_size;
    if (in->xi != 0) s->xi = in->xi < 0 ? 0 : in->xi;
    s->update = in->update;
    s->low_albedo = in->low_albedo;
    s->reference = in->reference;
    if (in->grid_max_dim) s->grid_max_dim = in->grid_max_dim;
    if (in->max_order) s->max_order = in->max_order;
    if (in->density_scale != 0) s->density_scale = in->density_scale;
    if (in->eye_scale != 0) s->eye_scale = in->eye_scale;
    memcpy(s->offset_m, in->offset_m, sizeof s->offset_m);
    s->optics = in->optics;
    s->timing = in->timing;
    if (s->slices < 1 || s->slices > 8192)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/slices: must be in [1, 8192], got %d", s->slices);
    if (s->light_size < 8 || s->light_size > 8192)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/light_size: must be in [8, 8192], got %d", s->light_size);
    if (!isfinite(in->xi) || s->xi > 1e3)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/xi: must be finite and at most 1000 sr^-1, got %g", in->xi);
    if (s->update != ATMOS_SLICE_EQ25 && s->update != ATMOS_SLICE_EQ24)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/update: unknown rule %d", (int)s->update);
    if (s->grid_max_dim < 8 || s->grid_max_dim > 2048)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/grid_max_dim: must be in [8, 2048], got %d",
                            s->grid_max_dim);
    if (s->max_order < 1 || s->max_order > 1000)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/max_order: must be in [1, 1000], got %d", s->max_order);
    if (!(s->density_scale > 0) || !isfinite(s->density_scale))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/density_scale: must be positive and finite, got %g",
                            s->density_scale);
    if (!(s->eye_scale > 0 && s->eye_scale <= 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/eye_scale: must be in (0, 1], got %g", s->eye_scale);
    for (int i = 0; i < 3; i++)
        if (!isfinite(s->offset_m[i]))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice/offset_m[%d]: must be finite", i);
    return ATMOS_OK;
}

atmos_status atmos_render_slice(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                const atmos_slice_settings *settings, atmos_image **out, atmos_render_info *info)
{
    if (!scene || !volume || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render slice: missing scene, volume or output");
    *out = NULL;
    if (!volume->finalized) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render slice: volume is not finalized");
    const double t_start = atmos__now();
    atmos_slice_settings s;
    atmos_status st = check_settings(ctx, settings, &s);
    if (st != ATMOS_OK) return st;
    if ((st = atmos_scene_validate(ctx, scene, "scene")) != ATMOS_OK) return st;
    if (scene->camera.type != ATMOS_CAMERA_PINHOLE)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED, "render slice: only pinhole cameras are supported");
    atmos_wavelengths wl;
    if ((st = atmos_scene_wavelengths(ctx, scene, &wl)) != ATMOS_OK) return st;
    atmos_camera cam;
    if ((st = atmos_camera_init(ctx, &scene->camera, scene->width, scene->height, &cam)) != ATMOS_OK) return st;
    double sun_w[3], sun_el = 0, sun_az = 0;
    if ((st = atmos_scene_sun_direction(ctx, scene, sun_w, &sun_el, &sun_az)) != ATMOS_OK) return st;

    atmos_volume_optics own_optics;
    memset(&own_optics, 0, sizeof own_optics);
    const atmos_volume_optics *optics = s.optics;
    if (!optics) {
        if ((st = atmos_volume_optics_build(ctx, scene, volume, 1, &own_optics)) != ATMOS_OK) return st;
        optics = &own_optics;
    }
    if (optics->count != volume->nfields) {
        atmos_volume_optics_free(&own_optics);
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render slice: optics for %d fields, the volume has %d",
                            optics->count, volume->nfields);
    }

    /* The sky behind everything: exactly atmos_render_sky's image (sun disk included). */
    atmos_image *img = NULL;
    const double t_sky0 = atmos__now();
    if ((st = atmos_render_sky(ctx, scene, &img, NULL)) != ATMOS_OK) {
        atmos_volume_optics_free(&own_optics);
        return st;
    }
    double t_sky = atmos__now() - t_sky0;
    const double t_prep0 = atmos__now();

    sgrid g;
    stables tab;
    memset(&tab, 0, sizeof tab);
    sjob j;
    memset(&j, 0, sizeof j);
    atmos_atmosphere *sky = NULL;
    long long eye_samples = 0, light_samples = 0;
    double t_light = 0, t_eye = 0;
    if ((st = atmos__sgrid_build(ctx, volume, s.density_scale, s.grid_max_dim, &g)) != ATMOS_OK) goto done;
    if (!g.v) goto finish; /* empty volume: the sky alone */
    if ((st = atmos__stables_build(ctx, optics, wl.count, s.max_order, &tab)) != ATMOS_OK) goto done;
    if ((st = atmos_atmosphere_create(ctx, &scene->atmosphere, &wl, &sky)) != ATMOS_OK) goto done;

    /* World <-> grid frame. */
    const double *R = volume->desc.rotation;
    double org[3];
    for (int a = 0; a < 3; a++) org[a] = volume->desc.origin_m[a] + s.offset_m[a];
#define TO_GRID(w, o) /* rotation only: o = R^T w */                                                       \
    do {                                                                                                   \
        (o)[0] = R[0] * (w)[0] + R[3] * (w)[1] + R[6] * (w)[2];                                            \
        (o)[1] = R[1] * (w)[0] + R[4] * (w)[1] + R[7] * (w)[2];                                            \
        (o)[2] = R[2] * (w)[0] + R[5] * (w)[1] + R[8] * (w)[2];                                            \
    } while (0)
    double rel[3] = {cam.position[0] - org[0], cam.position[1] - org[1], cam.position[2] - org[2]};
    TO_GRID(rel, j.eye);
    double sun_g[3], view_g[3];
    TO_GRID(sun_w, sun_g);
    TO_GRID(cam.forward, view_g);
    for (int a = 0; a < 3; a++) j.lt[a] = -sun_g[a];
    /* Half-angle slicing (Kniss et al.; Riley §5): h halfway between the view and the
     * light's travel when they are within 90° (front-to-back for the eye), else between
     * the inverted view and the light (back-to-front). The slices always advance along
     * h, away from the sun. */
    j.btf = atmos__dot3(view_g, j.lt) < 0;
    for (int a = 0; a < 3; a++) j.h[a] = (j.btf ? -view_g[a] : view_g[a]) + j.lt[a];
    if (atmos__dot3(j.h, j.h) < 1e-20) memcpy(j.h, j.lt, sizeof j.h);
    atmos__normalize3(j.h);
    j.hl = atmos__dot3(j.h, j.lt);
    if (j.hl < 1e-6) j.hl = 1e-6;
    {
        double ax[3] = {1, 0, 0};
        if (fabs(j.lt[0]) > 0.9) ax[0] = 0, ax[1] = 1;
        atmos__cross3(ax, j.lt, j.e1);
        atmos__normalize3(j.e1);
        atmos__cross3(j.lt, j.e1, j.e2);
    }
    /* Extents of the box along h (slices) and across the light (light buffer). */
    double smin = INFINITY, smax = -INFINITY, umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? g.box_hi[0] : g.box_lo[0], c & 2 ? g.box_hi[1] : g.box_lo[1],
                       c & 4 ? g.box_hi[2] : g.box_lo[2]};
        double sv = atmos__dot3(p, j.h), uv = atmos__dot3(p, j.e1), vv = atmos__dot3(p, j.e2);
        smin = fmin(smin, sv), smax = fmax(smax, sv);
        umin = fmin(umin, uv), umax = fmax(umax, uv);
        vmin = fmin(vmin, vv), vmax = fmax(vmax, vv);
    }
    j.n = wl.count;
    j.nf = volume->nfields;
    /* The eye buffer: the image, or eye_scale of it per axis (eye pixel x covers image
     * pixels x sx .. (x + 1) sx; its ray goes through the centre of that area). */
    j.W = cam.width, j.H = cam.height, j.L = s.light_size;
    j.sx = j.sy = 1.0;
    if (s.eye_scale < 1.0) {
        int we = (int)lround(s.eye_scale * cam.width), he = (int)lround(s.eye_scale * cam.height);
        we = we < 1 ? 1 : we, he = he < 1 ? 1 : he;
        if (we != j.W || he != j.H) {
            j.sx = (double)cam.width / we, j.sy = (double)cam.height / he;
            j.W = we, j.H = he;
        }
    }
    j.nslices = s.slices;
    j.s0 = smin;
    j.ds = (smax - smin) / s.slices;
    j.he = atmos__dot3(j.h, j.eye);
    j.u0 = umin, j.v0 = vmin;
    j.du = (umax - umin) / j.L, j.dv = (vmax - vmin) / j.L;
    if (!(j.du > 0)) j.du = 1;
    if (!(j.dv > 0)) j.dv = 1;
    j.low_albedo = s.low_albedo;
    j.eq24 = s.update == ATMOS_SLICE_EQ24;
    j.xi = (float)s.xi;
    j.g = &g;
    j.t = &tab;
    const size_t npix = (size_t)j.W * j.H, LL = (size_t)j.L * j.L;
    const int K = j.nslices;
    /* The per-pixel planes in one block; planes are padded by two cache lines so
     * that the same pixel of different planes does not fall in one cache set. */
    const size_t pst = npix + 32, nplanes = (size_t)14 + 2 * (size_t)j.nf + 2 * (size_t)j.n;
    j.pst = pst;
    j.pixblock = atmos__big_alloc(sizeof(float) * pst * nplanes);
    if (j.pixblock) {
        float *b = j.pixblock;
        for (int a = 0; a < 3; a++) j.pU0[a] = b, b += pst, j.pdU[a] = b, b += pst;
        for (int a = 0; a < 2; a++) j.pF0[a] = b, b += pst, j.pdF[a] = b, b += pst;
        j.pdelta = b, b += pst;
        j.pinv = b, b += pst;
        j.pk0 = (int *)b, j.pk1 = (int *)(b + pst), b += 2 * pst;
        j.pa = (int *)b, b += pst * j.nf;
        j.pw = b, b += pst * j.nf;
        j.L_eye = b, b += pst * j.n;
        j.T_eye = b;
    }
    j.lk0 = malloc(sizeof(int) * LL * 2);
    /* The light ring: B + 1 slots of L^2 texels of n + 1 floats (I per wavelength, then
     * n: one cache line serves all of a texel), B up to 16 within 32 MB. Slots are
     * padded by three cache lines so that they do not alias in the caches. */
    const size_t slotf = LL * (size_t)(j.n + 1) + 48;
    {
        size_t slot = sizeof(float) * slotf;
        size_t fit = ((size_t)32 << 20) / slot;
        j.batch = fit > 17 ? 16 : (fit > 2 ? (int)fit - 1 : 1);
        j.ring = atmos__big_alloc(slot * (size_t)(j.batch + 1));
        j.I = malloc(sizeof(float *) * (size_t)(j.batch + 1));
        j.nsc = malloc(sizeof(float *) * (size_t)(j.batch + 1));
        if (j.ring && j.I && j.nsc)
            for (int q = 0; q <= j.batch; q++) {
                j.I[q] = j.ring + (size_t)q * slotf;
                j.nsc[q] = j.I[q] + j.n;
            }
    }
    j.espan = malloc(sizeof(sspan) * (size_t)K * j.H);
    j.lspan = malloc(sizeof(sspan) * (size_t)K * j.L);
    j.wspan = malloc(sizeof(sspan) * (size_t)K * j.L);
    j.erow = malloc(sizeof(sspan) * (size_t)j.H);
    j.lrow = malloc(sizeof(sspan) * (size_t)j.L);
    int nomem = !j.pixblock || !j.lk0 || !j.espan ||
                !j.lspan || !j.wspan || !j.erow || !j.lrow;
    nomem |= !j.ring || !j.I || !j.nsc;
    if (nomem) {
        st = atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the buffers");
        goto done;
    }
    j.lk1 = j.lk0 + LL;
    const int threads = atmos__threads(ctx);
    const double t_setup0 = atmos__now();

    {
        double cf[3], cr[3], cu[3];
        TO_GRID(cam.forward, cf);
        TO_GRID(cam.right, cr);
        TO_GRID(cam.up, cu);
        if (!build_spans(&j, &cam, cf, cr, cu, threads)) {
            st = atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the spans");
            goto done;
        }
    }
    /* Per pixel: ray, slices it crosses inside the box (in front of the eye and of
     * the ground), its sample on slice k as a linear function of k, and the Ams angle
     * (scattering angle between the sun's light and the direction to the eye:
     * cos theta = d . sun). */
    const double ee1 = atmos__dot3(j.eye, j.e1), ee2 = atmos__dot3(j.eye, j.e2);
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int y = 0; y < j.H; y++) {
        int hint[ATMOS_VOLUME_MAX_FIELDS] = {0};
        for (int x = j.erow[y].x0; x <= j.erow[y].x1; x++) {
            size_t p = (size_t)y * j.W + x;
            for (int c = 0; c < j.n; c++) j.L_eye[c * j.pst + p] = 0.0f, j.T_eye[c * j.pst + p] = 1.0f;
            double dw[3], d[3];
            atmos_camera_ray(&cam, (x + 0.5) * j.sx, (y + 0.5) * j.sy, dw);
            TO_GRID(dw, d);
            double hd = atmos__dot3(j.h, d);
            j.pk0[p] = 1, j.pk1[p] = 0;
            j.pinv[p] = 0;
            for (int a = 0; a < 3; a++) j.pU0[a][p] = j.pdU[a][p] = 0;
            for (int a = 0; a < 2; a++) j.pF0[a][p] = j.pdF[a][p] = 0;
            j.pdelta[p] = 0;
            for (int f = 0; f < j.nf; f++) j.pa[p * j.nf + f] = 0, j.pw[p * j.nf + f] = 0;
            double ta, tb;
            int ok = j.btf ? hd <= -SLICE_HD_EPS : hd >= SLICE_HD_EPS;
            if (!ok || !atmos__ray_box(j.eye, d, g.box_lo, g.box_hi, &ta, &tb)) continue;
            if (ta < 0) ta = 0;
            double tg = atmos_atmosphere_ground_distance(sky, cam.position, dw);
            if (tb > tg) tb = tg;
            if (!(ta < tb)) continue;
            double sa = j.he + ta * hd, sb = j.he + tb * hd;
            if (sa > sb) {
                double q = sa;
                sa = sb, sb = q;
            }
            slice_range(sa, sb, j.s0, j.ds, j.nslices, &j.pk0[p], &j.pk1[p]);
            if (j.pk0[p] > j.pk1[p]) continue;
            j.pinv[p] = (float)(1.0 / hd);
            /* t_k = (s0 + (k + 0.5) ds - h.eye) / (h.d) */
            const double t0 = (j.s0 + 0.5 * j.ds - j.he) / hd, dt = j.ds / hd;
            for (int a = 0; a < 3; a++) {
                j.pU0[a][p] = (float)((j.eye[a] + t0 * d[a]) * g.sc + g.off[a]);
                j.pdU[a][p] = (float)(dt * d[a] * g.sc);
            }
            const double de1 = atmos__dot3(d, j.e1), de2 = atmos__dot3(d, j.e2);
            j.pF0[0][p] = (float)((ee1 + t0 * de1 - j.u0) / j.du - 0.5);
            j.pdF[0][p] = (float)(dt * de1 / j.du);
            j.pF0[1][p] = (float)((ee2 + t0 * de2 - j.v0) / j.dv - 0.5);
            j.pdF[1][p] = (float)(dt * de2 / j.dv);
            j.pdelta[p] = (float)(j.ds * fabs(1.0 / hd));
            double c = atmos__dot3(dw, sun_w);
            double th = acos(c > 1 ? 1 : (c < -1 ? -1 : c)) * ATMOS_RAD2DEG;
            for (int f = 0; f < j.nf; f++) {
                atmos__angle_locate(tab.grid[f], tab.ng[f], th, &hint[f], &j.pw[p * j.nf + f]);
                j.pa[p * j.nf + f] = hint[f] * tab.no * j.n;
            }
        }
    }
    /* Per light texel: slices its ray crosses inside the box, and the sunlight arriving
     * there through the air (Eq. 12, at the altitude where the ray enters the box).
     * Texel (a, b)'s ray is u e1 + v e2 + w lt; on slice k, w = (s_k - u h.e1 - v h.e2)/h.lt. */
    {
        double cen[3] = {0.5 * (g.box_lo[0] + g.box_hi[0]), 0.5 * (g.box_lo[1] + g.box_hi[1]),
                         0.5 * (g.box_lo[2] + g.box_hi[2])};
        const double *Rm = R;
        const double he1 = atmos__dot3(j.h, j.e1), he2 = atmos__dot3(j.h, j.e2);
        for (int a = 0; a < 3; a++) {
            double E1 = j.e1[a] - he1 / j.hl * j.lt[a], E2 = j.e2[a] - he2 / j.hl * j.lt[a];
            j.lA[a] = ((j.u0 + 0.5 * j.du) * E1 + (j.v0 + 0.5 * j.dv) * E2 + (j.s0 + 0.5 * j.ds) / j.hl * j.lt[a]) * g.sc +
                      g.off[a];
            j.lEa[a] = j.du * E1 * g.sc;
            j.lEb[a] = j.dv * E2 * g.sc;
            j.lEk[a] = j.ds / j.hl * j.lt[a] * g.sc;
        }
        j.ldelta = (float)(j.ds / j.hl);
        /* Texels whose ray misses the box all get the sunlight at the box centre. */
        double sl_miss[ATMOS_MAX_WAVELENGTHS];
        {
            sunlight_at(sky, org, Rm, cen, sun_w, sl_miss);
        }
#pragma omp parallel for schedule(static) num_threads(threads)
        for (int b = 0; b < j.L; b++)
            for (int a = 0; a < j.L; a++) {
                size_t q = (size_t)b * j.L + a;
                j.lk0[q] = 1, j.lk1[q] = 0;
                if (a < j.lrow[b].x0 || a > j.lrow[b].x1) { /* never read */
                    for (int c = 0; c < j.n; c++) j.I[0][q * (j.n + 1) + c] = (float)sl_miss[c];
                    j.nsc[0][q * (j.n + 1)] = 0.0f;
                    continue;
                }
                double u = j.u0 + (a + 0.5) * j.du, v = j.v0 + (b + 0.5) * j.dv;
                double o[3] = {u * j.e1[0] + v * j.e2[0], u * j.e1[1] + v * j.e2[1], u * j.e1[2] + v * j.e2[2]};
                double ta, tb, sl[ATMOS_MAX_WAVELENGTHS];
                j.lk0[q] = 1, j.lk1[q] = 0;
                if (atmos__ray_box(o, j.lt, g.box_lo, g.box_hi, &ta, &tb)) {
                    double ho = atmos__dot3(j.h, o);
                    slice_range(ho + ta * j.hl, ho + tb * j.hl, j.s0, j.ds, j.nslices, &j.lk0[q], &j.lk1[q]);
                    double entry[3];
                    for (int i = 0; i < 3; i++) entry[i] = o[i] + ta * j.lt[i];
                    sunlight_at(sky, org, Rm, entry, sun_w, sl);
                } else {
                    memcpy(sl, sl_miss, sizeof sl);
                }
                for (int c = 0; c < j.n; c++) j.I[0][q * (j.n + 1) + c] = (float)sl[c];
                j.nsc[0][q * (j.n + 1)] = 0.0f;
            }
    }
    {
        const int nslot = j.batch + 1;
#pragma omp parallel for schedule(static) num_threads(threads)
        for (int q = 1; q < nslot; q++) memcpy(j.I[q], j.I[0], sizeof(float) * LL * (size_t)(j.n + 1));
    }
    const double t_setup = atmos__now() - t_setup0;
    const double t_prep = atmos__now() - t_prep0;

    /* The slices, in batches of B (one parallel region, three barriers per batch).
     * Slot s of the light ring holds the light arriving at slice k0 + s. The light of
     * a texel on slice k depends only on that texel on slice k - 1, so each light row
     * runs through the batch on its own (phase A); then each image row runs through
     * the batch reading slot k - k0 (phase B). Each pixel and texel is written by one
     * work item only and sees the same sequence of operations as in a slice-by-slice
     * order, so the image does not depend on the thread count, the schedule or B.
     * After a batch the ring rotates (the last slot becomes slot 0), so a slot written
     * for slice k held the light of B + 1 slices earlier: only texels some light span
     * of slices k - B..k covers can differ, and only those are copied or updated. */
    long long (*const eye_pass)(const sjob *, int, int, int, int, const float *, const float *) =
        s.reference ? atmos__slice_eye_span_ref : atmos__slice_eye_span;
    long long (*const light_pass)(const sjob *, int, int, int, int, int, int, const float *, const float *, float *,
                                  float *) = s.reference ? atmos__slice_light_span_ref : atmos__slice_light_span;
    int cancelled = 0;
    const int nbatch = j.batch;
    const double t_sl0 = atmos__now();
#pragma omp parallel num_threads(threads) reduction(+ : eye_samples, light_samples)
    for (int k0 = 0; k0 < K; k0 += nbatch) {
        if (cancelled) break; /* set before the previous barrier: every thread sees the same value */
        const int nb = K - k0 < nbatch ? K - k0 : nbatch;
        double ta = 0;
#pragma omp master
        ta = atmos__now();
#pragma omp for schedule(dynamic, 1)
        for (int b = 0; b < j.L; b++)
            for (int q = 0; q < nb; q++) {
                const int k = k0 + q;
                const sspan ls = j.lspan[(size_t)k * j.L + b], ws = j.wspan[(size_t)k * j.L + b];
                if (ws.x0 <= ws.x1)
                    light_samples += light_pass(&j, k, b, ws.x0, ws.x1, ls.x0, ls.x1, j.I[q], j.nsc[q], j.I[q + 1],
                                                j.nsc[q + 1]);
            }
#pragma omp master
        {
            double tb = atmos__now();
            t_light += tb - ta;
            ta = tb;
        }
#pragma omp for schedule(dynamic, 2)
        for (int y = 0; y < j.H; y++)
            for (int q = 0; q < nb; q++) {
                const int k = k0 + q;
                const sspan es = j.espan[(size_t)k * j.H + y];
                if (es.x0 <= es.x1) eye_samples += eye_pass(&j, k, y, es.x0, es.x1, j.I[q], j.nsc[q]);
            }
#pragma omp master
        {
            t_eye += atmos__now() - ta;
            float *last = j.I[nb], *lastn = j.nsc[nb];
            for (int q = nb; q > 0; q--) j.I[q] = j.I[q - 1], j.nsc[q] = j.nsc[q - 1];
            j.I[0] = last, j.nsc[0] = lastn;
            if (atmos__progress(ctx, "render slice", (double)(k0 + nb) / K)) cancelled = 1;
        }
#pragma omp barrier
    }
    const double t_slices = atmos__now() - t_sl0;
    (void)t_slices;
    if (cancelled) {
        st = atmos__error(ctx, ATMOS_E_CANCELLED, "render slice: cancelled");
        goto done;
    }

    /* §5: air from the eye to the volume's halfway plane is in front of the volume,
     * the rest (with the ground and the sun's disk, §4.2.4) behind it. With B the sky
     * image (= front + T_front * back), the pixel is
     *   front + T_front * L_vol + T_vol * (B - front).
     * Pixels the volume does not touch keep B exactly. */
    {
        const double t_c0 = atmos__now();
        double cen[3] = {0.5 * (g.box_lo[0] + g.box_hi[0]), 0.5 * (g.box_lo[1] + g.box_hi[1]),
                         0.5 * (g.box_lo[2] + g.box_hi[2])};
        const double hc = atmos__dot3(j.h, cen);
        const int C = img->channels;
        if (j.sx == 1.0 && j.sy == 1.0) {
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
            for (int y = 0; y < j.H; y++)
                for (int x = j.erow[y].x0; x <= j.erow[y].x1; x++) {
                    size_t p = (size_t)y * j.W + x;
                    int touched = 0;
                    for (int c = 0; c < j.n; c++)
                        touched |= j.L_eye[c * j.pst + p] != 0.0f || j.T_eye[c * j.pst + p] != 1.0f;
                    if (!touched) continue;
                    double dw[3];
                    atmos_camera_ray(&cam, x + 0.5, y + 0.5, dw);
                    double th = j.pinv[p] != 0.0f ? (hc - j.he) * j.pinv[p] : 0.0;
                    float Lv[ATMOS_MAX_WAVELENGTHS], Tv[ATMOS_MAX_WAVELENGTHS];
                    for (int c = 0; c < j.n; c++) Lv[c] = j.L_eye[c * j.pst + p], Tv[c] = j.T_eye[c * j.pst + p];
                    composite_pixel(sky, &cam, dw, th, sun_w, j.n, Lv, Tv, img->pixels + p * C);
                }
        } else {
            /* Eye buffer smaller than the image: L_vol and T_vol bilinear between the
             * four eye pixels around the image pixel's centre (both are premultiplied by
             * the volume's coverage, so this blurs the silhouette by one eye pixel but
             * does not tint it). Eye pixels outside their row's union of spans were
             * never reached (L = 0, T = 1). An image pixel whose four eye pixels are all
             * untouched keeps the sky image exactly; the halfway plane is met along the
             * image pixel's own ray. */
            const int W = cam.width, H = cam.height;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
            for (int y = 0; y < H; y++) {
                int ey[2];
                float wy;
                eye_taps((y + 0.5) / j.sy - 0.5, j.H, ey, &wy);
                int xa = INT32_MAX, xb = -1;
                for (int r = 0; r < 2; r++) {
                    const sspan e = j.erow[ey[r]];
                    if (e.x0 > e.x1) continue;
                    int a = (int)floor((e.x0 - 0.5) * j.sx), b = (int)ceil((e.x1 + 1.5) * j.sx);
                    xa = a < xa ? a : xa, xb = b > xb ? b : xb;
                }
                xa = xa < 0 ? 0 : xa, xb = xb > W - 1 ? W - 1 : xb;
                for (int x = xa; x <= xb; x++) {
                    int ex[2];
                    float wx;
                    eye_taps((x + 0.5) / j.sx - 0.5, j.W, ex, &wx);
                    const float wt[4] = {(1 - wx) * (1 - wy), wx * (1 - wy), (1 - wx) * wy, wx * wy};
                    float Lv[ATMOS_MAX_WAVELENGTHS], Tv[ATMOS_MAX_WAVELENGTHS];
                    for (int c = 0; c < j.n; c++) Lv[c] = 0.0f, Tv[c] = 0.0f;
                    int touched = 0;
                    for (int q = 0; q < 4; q++) {
                        const int tx = ex[q & 1], ty = ey[q >> 1];
                        const size_t p = (size_t)ty * j.W + tx;
                        const int in = tx >= j.erow[ty].x0 && tx <= j.erow[ty].x1;
                        for (int c = 0; c < j.n; c++) {
                            const float L = in ? j.L_eye[c * j.pst + p] : 0.0f, T = in ? j.T_eye[c * j.pst + p] : 1.0f;
                            touched |= L != 0.0f || T != 1.0f;
                            Lv[c] += wt[q] * L, Tv[c] += wt[q] * T;
                        }
                    }
                    if (!touched) continue;
                    double dw[3], d[3];
                    atmos_camera_ray(&cam, x + 0.5, y + 0.5, dw);
                    TO_GRID(dw, d);
                    const double hd = atmos__dot3(j.h, d);
                    double th = fabs(hd) >= SLICE_HD_EPS ? (hc - j.he) / hd : 0.0;
                    composite_pixel(sky, &cam, dw, th, sun_w, j.n, Lv, Tv, img->pixels + ((size_t)y * W + x) * C);
                }
            }
        }
        t_sky += atmos__now() - t_c0;
    }
    if (s.timing) {
        s.timing->prepare = t_prep;
        s.timing->light = t_light;
        s.timing->eye = t_eye;
        s.timing->setup = t_setup;
    }

finish:
    {
        char buf[256];
        atmos_image_set_meta(img, "atmos:renderer", "slice (Riley et al. 2004, half-angle slicing)");
        snprintf(buf, sizeof buf, "%d slices, light buffer %d, eye buffer %dx%d, xi %g, %s%s", s.slices, s.light_size,
                 j.W ? j.W : cam.width, j.H ? j.H : cam.height, s.xi, s.update == ATMOS_SLICE_EQ24 ? "eq24" : "eq25",
                 s.low_albedo ? ", low albedo" : "");
        atmos_image_set_meta(img, "atmos:slice", buf);
        double secs = atmos__now() - t_start;
        snprintf(buf, sizeof buf, "%.6f", secs);
        atmos_image_set_meta(img, "atmos:render_seconds", buf);
        if (info) {
            info->seconds = secs;
            info->sun_elevation_deg = sun_el;
            info->sun_azimuth_deg = sun_az;
        }
        if (s.timing) {
            s.timing->sky = t_sky;
            s.timing->total = secs;
            s.timing->eye_samples = eye_samples;
            s.timing->light_samples = light_samples;
            memcpy(s.timing->grid_dims, g.c, sizeof g.c);
            s.timing->eye_dims[0] = j.W, s.timing->eye_dims[1] = j.H;
            if (!g.v) s.timing->prepare = s.timing->light = s.timing->eye = 0;
        }
    }
    st = ATMOS_OK;
done:
#undef TO_GRID
    free(j.pixblock), free(j.ring), free(j.I), free(j.nsc), free(j.lk0);
    free(j.espan), free(j.lspan), free(j.wspan), free(j.erow), free(j.lrow);
    atmos_atmosphere_destroy(sky);
    atmos__stables_free(&tab);
    atmos__sgrid_free(&g);
    atmos_volume_optics_free(&own_optics);
    if (st != ATMOS_OK) {
        atmos_image_destroy(img);
        return st;
    }
    *out = img;
    return ATMOS_OK;
}
