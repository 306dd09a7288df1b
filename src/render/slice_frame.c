/* One frame of the slice renderer (Riley et al. 2004 §4.2-§5; half-angle slicing after
 * Kniss et al.): the job's geometry, the per-pixel and per-texel set-up, and the slices.
 *
 * Everything geometric happens in the volume's grid frame (metres, axes of the voxel grid,
 * origin at the grid's corner): g = R^T (world - origin - offset). The frame is rigid, so
 * distances and angles are those of the world.
 *
 * Per slice k (planes perpendicular to the half vector h, advancing away from the sun):
 *  1. eye pass: every pixel's ray meets slice k at one point; the light buffer gives I and n
 *     there; Eq. 26 is accumulated front-to-back (eye and light within 90 degrees) or
 *     back-to-front (otherwise);
 *  2. light pass: every light texel's ray meets slice k at one point; I is attenuated by
 *     Eq. 25 (or Eq. 24) and n grows by Eq. 21.
 * Both passes write only their own pixel/texel, so rows are split over threads and the image
 * does not depend on the thread count. */
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "render/slice_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Sunlight arriving at the grid-frame point g. */
static void sunlight_at(const atmos_atmosphere *atm, const atmos__vol_xform *x, const double g[3], const double sun[3],
                        double *out)
{
    double w[3];
    atmos__vol_frame_to_point(x, g, w);
    atmos_atmosphere_sunlight(atm, w, sun, out);
}

/* The light frame of the sun direction sun_w (slight), kept until the sun moves: the buffer's
 * axes and extent across the light, and per texel where its ray crosses the box and the
 * sunlight entering there (Eq. 12, at the point where the ray enters the box). */
static void light_frame(atmos__slice_plan *sp, const atmos_atmosphere *atm, const double sun_w[3], int L, int threads)
{
    slight *lf = &sp->light;
    const sgrid *g = &sp->g;
    double sun_g[3];
    atmos__vol_dir_to_frame(&sp->x, sun_w, sun_g);
    for (int a = 0; a < 3; a++) lf->lt[a] = -sun_g[a];
    double ax[3] = {1, 0, 0};
    if (fabs(lf->lt[0]) > 0.9) ax[0] = 0, ax[1] = 1;
    atmos__cross3(ax, lf->lt, lf->e1);
    atmos__normalize3(lf->e1);
    atmos__cross3(lf->lt, lf->e1, lf->e2);
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? g->box_hi[0] : g->box_lo[0], c & 2 ? g->box_hi[1] : g->box_lo[1],
                       c & 4 ? g->box_hi[2] : g->box_lo[2]};
        double uv = atmos__dot3(p, lf->e1), vv = atmos__dot3(p, lf->e2);
        umin = fmin(umin, uv), umax = fmax(umax, uv);
        vmin = fmin(vmin, vv), vmax = fmax(vmax, vv);
    }
    const int n = sp->n;
    lf->L = L;
    lf->u0 = umin, lf->v0 = vmin;
    lf->du = (umax - umin) / L, lf->dv = (vmax - vmin) / L;
    if (!(lf->du > 0)) lf->du = 1;
    if (!(lf->dv > 0)) lf->dv = 1;
    const double cen[3] = {0.5 * (g->box_lo[0] + g->box_hi[0]), 0.5 * (g->box_lo[1] + g->box_hi[1]),
                           0.5 * (g->box_lo[2] + g->box_hi[2])};
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int b = 0; b < L; b++)
        for (int a = 0; a < L; a++) {
            const size_t q = (size_t)b * L + a;
            double u = lf->u0 + (a + 0.5) * lf->du, v = lf->v0 + (b + 0.5) * lf->dv;
            double o[3] = {u * lf->e1[0] + v * lf->e2[0], u * lf->e1[1] + v * lf->e2[1], u * lf->e1[2] + v * lf->e2[2]};
            lf->hit[q] = (unsigned char)atmos__ray_box(o, lf->lt, g->box_lo, g->box_hi, &lf->ta[q], &lf->tb[q]);
        }
    /* The sunlight entering each texel's ray (timed apart: the atmosphere's share). */
    const double t_sun = atmos__now();
    double sl_miss[ATMOS_MAX_WAVELENGTHS];
    sunlight_at(atm, &sp->x, cen, sun_w, sl_miss);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int b = 0; b < L; b++)
        for (int a = 0; a < L; a++) {
            const size_t q = (size_t)b * L + a;
            double u = lf->u0 + (a + 0.5) * lf->du, v = lf->v0 + (b + 0.5) * lf->dv, sl[ATMOS_MAX_WAVELENGTHS];
            double o[3] = {u * lf->e1[0] + v * lf->e2[0], u * lf->e1[1] + v * lf->e2[1], u * lf->e1[2] + v * lf->e2[2]};
            if (lf->hit[q]) {
                double entry[3];
                for (int i = 0; i < 3; i++) entry[i] = o[i] + lf->ta[q] * lf->lt[i];
                sunlight_at(atm, &sp->x, entry, sun_w, sl);
            } else {
                memcpy(sl, sl_miss, sizeof sl);
            }
            for (int c = 0; c < n; c++) lf->sl[q * n + c] = (float)sl[c];
        }
    sp->sunlight_s = atmos__now() - t_sun;
    memcpy(lf->sun, sun_w, sizeof lf->sun);
    lf->valid = 1;
}

/* The slice count when the scene leaves it to the renderer ("slices": 0, the default;
 * docs/slice.md, "Slice count"). A ray through a thin layer meets only the planes of the
 * layer's own thickness along h, so a wide, flat volume sampled by a count fixed for the
 * whole extent gets a few samples per ray, that count changing from pixel to pixel in
 * diagonal bands. The planes are therefore spaced so that the box's thinnest extent
 * measured along h, min_a E_a / |h_a|, holds SLICE_AUTO_ACROSS of them, with at least
 * SLICE_AUTO_MIN slices (compact volumes keep that count) and at most SLICE_AUTO_MAX
 * (*needed then tells how many the rule asked for). And a ray must not step over a render
 * voxel: the planes' spacing along the eye's and the light's rays, ds / (h . l) (h lies
 * halfway between the two, so one figure serves both), stays within half a render voxel
 * (SLICE_AUTO_PER_VOXEL samples a voxel). Without that a wide domain seen at a slant (a WRF
 * run: 300 km across, a cloud layer a few 1.2 km render voxels thick) took 256 planes 1.5 km
 * apart and drew the layer in stripes; at one sample a voxel faint stripes stayed. */
#define SLICE_AUTO_MIN 256
#define SLICE_AUTO_MAX 2048
#define SLICE_AUTO_ACROSS 64.0
#define SLICE_AUTO_PER_VOXEL 2.0
static int auto_slices(const sgrid *g, const double h[3], double hl, double extent, int *needed)
{
    double k = 0; /* max_a |h_a| / E_a: the inverse of the thinnest extent along h */
    for (int a = 0; a < 3; a++) {
        const double E = g->box_hi[a] - g->box_lo[a];
        if (E > 0) k = fmax(k, fabs(h[a]) / E);
    }
    const double across = SLICE_AUTO_ACROSS * extent * k, voxel = 1.0 / g->sc;
    const double want = ceil(fmax(across, SLICE_AUTO_PER_VOXEL * extent / (voxel * hl)));
    *needed = want > 1e9 ? 1000000000 : (int)want;
    if (*needed <= SLICE_AUTO_MIN) return SLICE_AUTO_MIN;
    return *needed < SLICE_AUTO_MAX ? *needed : SLICE_AUTO_MAX;
}

/* The half vector, the slices and the buffers' sizes of the frame (everything but the
 * per-pixel and per-texel data). */
static void job_geometry(const atmos__slice_plan *sp, const atmos__view *v, sjob *j, int *needed)
{
    const atmos_camera *cam = &v->cam;
    const sgrid *g = &sp->g;
    const slight *lf = &sp->light;
    double rel[3] = {cam->position[0] - sp->x.org[0], cam->position[1] - sp->x.org[1], cam->position[2] - sp->x.org[2]};
    atmos__vol_dir_to_frame(&sp->x, rel, j->eye);
    memcpy(j->lt, lf->lt, sizeof j->lt), memcpy(j->e1, lf->e1, sizeof j->e1), memcpy(j->e2, lf->e2, sizeof j->e2);
    double view_g[3];
    atmos__vol_dir_to_frame(&sp->x, cam->forward, view_g);
    /* Half-angle slicing (Kniss et al.; Riley §5): h halfway between the view and the
     * light's travel when they are within 90° (front-to-back for the eye), else between
     * the inverted view and the light (back-to-front). The slices always advance along
     * h, away from the sun. */
    j->btf = atmos__dot3(view_g, j->lt) < 0;
    for (int a = 0; a < 3; a++) j->h[a] = (j->btf ? -view_g[a] : view_g[a]) + j->lt[a];
    if (atmos__dot3(j->h, j->h) < 1e-20) memcpy(j->h, j->lt, sizeof j->h);
    atmos__normalize3(j->h);
    j->hl = atmos__dot3(j->h, j->lt);
    if (j->hl < 1e-6) j->hl = 1e-6;
    double smin = INFINITY, smax = -INFINITY;
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? g->box_hi[0] : g->box_lo[0], c & 2 ? g->box_hi[1] : g->box_lo[1],
                       c & 4 ? g->box_hi[2] : g->box_lo[2]};
        double sv = atmos__dot3(p, j->h);
        smin = fmin(smin, sv), smax = fmax(smax, sv);
    }
    j->n = sp->n, j->nf = sp->nf;
    /* The eye buffer: the image, or eye_scale of it per axis (eye pixel x covers image
     * pixels x sx .. (x + 1) sx; its ray goes through the centre of that area). At 2 the
     * composite's bilinear taps at an image pixel's centre fall midway between its four
     * eye pixels: their mean, the pixel's 2 x 2 box filter. */
    j->W = cam->width, j->H = cam->height, j->L = lf->L;
    j->sx = j->sy = 1.0;
    if (v->eye_scale != 1.0) {
        int we = (int)lround(v->eye_scale * cam->width), he = (int)lround(v->eye_scale * cam->height);
        we = we < 1 ? 1 : we, he = he < 1 ? 1 : he;
        if (we != j->W || he != j->H) {
            j->sx = (double)cam->width / we, j->sy = (double)cam->height / he;
            j->W = we, j->H = he;
        }
    } else if (atmos__slice_edge_mode(sp, v)) { /* edge_aa: four rays at the edges (slice_edges.c) */
        j->W = 2 * cam->width, j->H = 2 * cam->height;
        j->sx = j->sy = 0.5;
    }
    j->nslices = v->slices > 0 ? v->slices : auto_slices(g, j->h, j->hl, smax - smin, needed);
    j->s0 = smin;
    j->ds = (smax - smin) / j->nslices;
    j->he = atmos__dot3(j->h, j->eye);
    j->u0 = lf->u0, j->v0 = lf->v0, j->du = lf->du, j->dv = lf->dv;
    /* with "do" the passes are low albedo's in the delta-M scaled medium (slice_do.c) */
    j->low_albedo = sp->low_albedo || sp->do_field;
    j->eq24 = sp->eq24;
    j->xi = sp->do_field ? 0.0f : sp->xi;
    j->g = g;
    j->t = sp->do_field ? &sp->tab_dm : &sp->tab;
}

/* Points the job's per-pixel planes and spans into the plan's buffers, growing them when
 * this frame needs more. The planes are padded by two cache lines so that the same pixel
 * of different planes does not fall in one cache set. */
static int job_buffers(atmos__slice_plan *sp, sjob *j)
{
    const size_t npix = (size_t)j->W * j->H, pst = npix + 32, nplanes = (size_t)14 + 2 * (size_t)j->nf + 2 * (size_t)j->n;
    if (pst * nplanes > sp->pix_cap) {
        free(sp->pixblock);
        sp->pix_cap = 0;
        if (!(sp->pixblock = atmos__big_alloc(sizeof(float) * pst * nplanes))) return 0;
        sp->pix_cap = pst * nplanes;
    }
    const size_t K = (size_t)j->nslices, nspan = K * j->H + 2 * K * j->L + j->H + j->L;
    if (nspan > sp->span_cap) { /* a quarter more: the slices' count changes as the sun moves */
        const size_t cap = nspan + nspan / 4;
        free(sp->spans);
        sp->span_cap = 0;
        if (!(sp->spans = malloc(sizeof(sspan) * cap))) return 0;
        sp->span_cap = cap;
    }
    j->pst = pst;
    float *b = sp->pixblock;
    for (int a = 0; a < 3; a++) j->pU0[a] = b, b += pst, j->pdU[a] = b, b += pst;
    for (int a = 0; a < 2; a++) j->pF0[a] = b, b += pst, j->pdF[a] = b, b += pst;
    j->pdelta = b, b += pst;
    j->pinv = b, b += pst;
    j->pk0 = (int *)b, j->pk1 = (int *)(b + pst), b += 2 * pst;
    j->pa = (int *)b, b += pst * j->nf;
    j->pw = b, b += pst * j->nf;
    j->L_eye = b, b += pst * j->n;
    j->T_eye = b;
    j->espan = sp->spans;
    j->lspan = j->espan + K * j->H;
    j->wspan = j->lspan + K * j->L;
    j->erow = j->wspan + K * j->L;
    j->lrow = j->erow + j->H;
    j->lk0 = sp->lk, j->lk1 = sp->lk + (size_t)j->L * j->L;
    j->ring = sp->ring, j->I = sp->I, j->nsc = sp->nsc, j->batch = sp->batch;
    return 1;
}

/* Per pixel: ray, slices it crosses inside the box (in front of the eye and of the ground),
 * its sample on slice k as a linear function of k, and the Ams angle (scattering angle
 * between the sun's light and the direction to the eye: cos theta = d . sun). */
static void setup_pixels(const atmos__slice_plan *sp, const atmos_atmosphere *atm, const atmos__view *v, sjob *j,
                         int threads)
{
    const atmos_camera *cam = &v->cam;
    const sgrid *g = j->g;
    const stables *tab = j->t;
    const double ee1 = atmos__dot3(j->eye, j->e1), ee2 = atmos__dot3(j->eye, j->e2);
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int y = 0; y < j->H; y++) {
        int hint[ATMOS_VOLUME_MAX_FIELDS] = {0};
        for (int x = j->erow[y].x0; x <= j->erow[y].x1; x++) {
            size_t p = (size_t)y * j->W + x;
            for (int c = 0; c < j->n; c++) j->L_eye[c * j->pst + p] = 0.0f, j->T_eye[c * j->pst + p] = 1.0f;
            /* edge_aa: outside the edges eye pixel (2x, 2y) takes the image pixel's centre ray
             * and its three neighbours none */
            double ix = (x + 0.5) * j->sx, iy = (y + 0.5) * j->sy;
            const int one = j->edge && !j->edge[(size_t)(y >> 1) * cam->width + (x >> 1)];
            if (one) ix = (x >> 1) + 0.5, iy = (y >> 1) + 0.5;
            double dw[3], d[3];
            atmos_camera_ray(cam, ix, iy, dw);
            atmos__vol_dir_to_frame(&sp->x, dw, d);
            double hd = atmos__dot3(j->h, d);
            j->pk0[p] = 1, j->pk1[p] = 0;
            j->pinv[p] = 0;
            for (int a = 0; a < 3; a++) j->pU0[a][p] = j->pdU[a][p] = 0;
            for (int a = 0; a < 2; a++) j->pF0[a][p] = j->pdF[a][p] = 0;
            j->pdelta[p] = 0;
            for (int f = 0; f < j->nf; f++) j->pa[p * j->nf + f] = 0, j->pw[p * j->nf + f] = 0;
            if (one && ((x | y) & 1)) continue;
            double ta, tb;
            int ok = j->btf ? hd <= -SLICE_HD_EPS : hd >= SLICE_HD_EPS;
            if (!ok || !atmos__ray_box(j->eye, d, g->box_lo, g->box_hi, &ta, &tb)) continue;
            if (ta < 0) ta = 0;
            double tg = atmos_atmosphere_ground_distance(atm, cam->position, dw);
            if (tb > tg) tb = tg;
            if (!(ta < tb)) continue;
            double sa = j->he + ta * hd, sb = j->he + tb * hd;
            if (sa > sb) {
                double q = sa;
                sa = sb, sb = q;
            }
            atmos__slice_range(sa, sb, j->s0, j->ds, j->nslices, &j->pk0[p], &j->pk1[p]);
            if (j->pk0[p] > j->pk1[p]) continue;
            j->pinv[p] = (float)(1.0 / hd);
            /* t_k = (s0 + (k + 0.5) ds - h.eye) / (h.d) */
            const double t0 = (j->s0 + 0.5 * j->ds - j->he) / hd, dt = j->ds / hd;
            for (int a = 0; a < 3; a++) {
                j->pU0[a][p] = (float)((j->eye[a] + t0 * d[a]) * g->sc + g->off[a]);
                j->pdU[a][p] = (float)(dt * d[a] * g->sc);
            }
            const double de1 = atmos__dot3(d, j->e1), de2 = atmos__dot3(d, j->e2);
            j->pF0[0][p] = (float)((ee1 + t0 * de1 - j->u0) / j->du - 0.5);
            j->pdF[0][p] = (float)(dt * de1 / j->du);
            j->pF0[1][p] = (float)((ee2 + t0 * de2 - j->v0) / j->dv - 0.5);
            j->pdF[1][p] = (float)(dt * de2 / j->dv);
            j->pdelta[p] = (float)(j->ds * fabs(1.0 / hd));
            double c = atmos__dot3(dw, v->sun);
            double th = acos(c > 1 ? 1 : (c < -1 ? -1 : c)) * ATMOS_RAD2DEG;
            for (int f = 0; f < j->nf; f++) {
                atmos__angle_locate(tab->grid[f], tab->ng[f], th, &hint[f], &j->pw[p * j->nf + f]);
                j->pa[p * j->nf + f] = hint[f] * tab->no * j->n;
            }
        }
    }
}

/* Per light texel: the slices its ray crosses inside the box, and the sunlight entering
 * (from the light frame). Texel (a, b)'s ray is u e1 + v e2 + w lt; on slice k,
 * w = (s_k - u h.e1 - v h.e2) / h.lt. Every slot of the light ring starts with that light.
 * Only the texels of each row's union of light spans (lrow) are set: the passes read and
 * write no other (the spans are widened by a texel for the bilinear taps, slice_spans.c). */
static void setup_texels(const atmos__slice_plan *sp, sjob *j, int threads)
{
    const sgrid *g = j->g;
    const slight *lf = &sp->light;
    const double he1 = atmos__dot3(j->h, j->e1), he2 = atmos__dot3(j->h, j->e2);
    for (int a = 0; a < 3; a++) {
        double E1 = j->e1[a] - he1 / j->hl * j->lt[a], E2 = j->e2[a] - he2 / j->hl * j->lt[a];
        j->lA[a] = ((j->u0 + 0.5 * j->du) * E1 + (j->v0 + 0.5 * j->dv) * E2 + (j->s0 + 0.5 * j->ds) / j->hl * j->lt[a]) *
                       g->sc +
                   g->off[a];
        j->lEa[a] = j->du * E1 * g->sc;
        j->lEb[a] = j->dv * E2 * g->sc;
        j->lEk[a] = j->ds / j->hl * j->lt[a] * g->sc;
    }
    j->ldelta = (float)(j->ds / j->hl);
    const int L = j->L, n = j->n, nslot = j->batch + 1;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int b = 0; b < L; b++) {
        const sspan row = j->lrow[b];
        for (int a = row.x0; a <= row.x1; a++) {
            const size_t q = (size_t)b * L + a;
            j->lk0[q] = 1, j->lk1[q] = 0;
            if (lf->hit[q]) {
                double u = j->u0 + (a + 0.5) * j->du, v = j->v0 + (b + 0.5) * j->dv;
                double o[3] = {u * j->e1[0] + v * j->e2[0], u * j->e1[1] + v * j->e2[1], u * j->e1[2] + v * j->e2[2]};
                double ho = atmos__dot3(j->h, o);
                atmos__slice_range(ho + lf->ta[q] * j->hl, ho + lf->tb[q] * j->hl, j->s0, j->ds, j->nslices, &j->lk0[q],
                                   &j->lk1[q]);
            }
            for (int c = 0; c < n; c++) j->I[0][q * (n + 1) + c] = lf->sl[q * n + c];
            j->nsc[0][q * (n + 1)] = 0.0f;
        }
        if (row.x0 > row.x1) continue;
        const size_t first = ((size_t)b * L + row.x0) * (n + 1), len = (size_t)(row.x1 - row.x0 + 1) * (n + 1);
        for (int s = 1; s < nslot; s++) memcpy(j->I[s] + first, j->I[0] + first, sizeof(float) * len);
    }
}

/* The eye-buffer pixels that the image region r reads: itself at full resolution, else the
 * bilinear taps of its pixel centres (slice_composite.c). */
static void eye_rect(const sjob *j, const atmos__rect *r, int e[4])
{
    if (j->sx == 1.0 && j->sy == 1.0) {
        e[0] = r->x0, e[1] = r->y0, e[2] = r->x1, e[3] = r->y1;
        return;
    }
    const double f[4] = {(r->x0 + 0.5) / j->sx - 0.5, (r->y0 + 0.5) / j->sy - 0.5, (r->x1 - 0.5) / j->sx - 0.5,
                         (r->y1 - 0.5) / j->sy - 0.5};
    const int lim[2] = {j->W, j->H};
    for (int i = 0; i < 4; i++) {
        int t = (int)floor(f[i]) + (i >= 2 ? 2 : 0);
        if (t < 0) t = 0;
        if (t > lim[i & 1]) t = lim[i & 1];
        e[i] = t;
    }
}

atmos_status atmos__slice_frame_setup(atmos_context *ctx, atmos__slice_plan *sp, const atmos_atmosphere *atm,
                                      const atmos__view *v, const atmos__rect *r, sjob *j)
{
    const int threads = atmos__threads(ctx);
    memset(j, 0, sizeof *j);
    sp->sunlight_s = 0;
    /* a frame's smaller light buffer (the viewer's preview) fits in the plan's */
    const int L = v->light_size > 0 && v->light_size < sp->L ? v->light_size : sp->L;
    if (!sp->light.valid || sp->light.L != L || memcmp(sp->light.sun, v->sun, sizeof v->sun) != 0)
        light_frame(sp, atm, v->sun, L, threads);
    int needed = 0;
    job_geometry(sp, v, j, &needed);
    if (needed > j->nslices)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "render slice: this view of the volume would need %d slices to sample its thinnest extent "
                   "without banding; using %d (set \"slices\" / --slices to choose)",
                   needed, j->nslices);
    if (v->eye_scale < 1 && (j->W < 16 || j->H < 16) && (j->W < v->cam.width || j->H < v->cam.height))
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "render slice: eye_scale %g makes an eye buffer of %d x %d for the %d x %d image, which is that "
                   "buffer's few pixels enlarged (eye_scale 1: a ray for every pixel)",
                   v->eye_scale, j->W, j->H, v->cam.width, v->cam.height);
    sp->slices_used = j->nslices;
    if (!job_buffers(sp, j)) return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the buffers");
    double cf[3], cr[3], cu[3];
    atmos__vol_dir_to_frame(&sp->x, v->cam.forward, cf);
    atmos__vol_dir_to_frame(&sp->x, v->cam.right, cr);
    atmos__vol_dir_to_frame(&sp->x, v->cam.up, cu);
    if (!atmos__slice_build_spans(j, &v->cam, cf, cr, cu, threads))
        return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the spans");
    if (atmos__slice_edge_mode(sp, v) && !atmos__slice_edges(sp, atm, v, j, threads))
        return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the edge pixels");
    if (r->x0 > 0 || r->y0 > 0 || r->x1 < v->cam.width || r->y1 < v->cam.height) {
        int e[4];
        eye_rect(j, r, e);
        atmos__slice_clip_spans(j, e[0], e[1], e[2], e[3]);
    }
    setup_pixels(sp, atm, v, j, threads);
    setup_texels(sp, j, threads);
    return ATMOS_OK;
}

/* The slices, in batches of B (one parallel region, three barriers per batch). Slot s of the
 * light ring holds the light arriving at slice k0 + s. The light of a texel on slice k
 * depends only on that texel on slice k - 1, so each light row runs through the batch on
 * its own (phase A); then each image row runs through the batch reading slot k - k0 (phase
 * B). Each pixel and texel is written by one work item only and sees the same sequence of
 * operations as in a slice-by-slice order, so the image does not depend on the thread
 * count, the schedule or B. After a batch the ring rotates (the last slot becomes slot 0),
 * so a slot written for slice k held the light of B + 1 slices earlier: only texels some
 * light span of slices k - B..k covers can differ, and only those are copied or updated. */
atmos_status atmos__slice_passes(atmos_context *ctx, const atmos__slice_plan *sp, sjob *j, atmos_slice_timing *tm)
{
    long long (*const eye_pass)(const sjob *, int, int, int, int, const float *, const float *, const float *) =
        sp->reference ? atmos__slice_eye_span_ref : atmos__slice_eye_span;
    long long (*const light_pass)(const sjob *, int, int, int, int, int, int, const float *, const float *, float *,
                                  float *) = sp->reference ? atmos__slice_light_span_ref : atmos__slice_light_span;
    const int K = j->nslices, nbatch = j->batch, threads = atmos__threads(ctx);
    long long eye_samples = 0, light_samples = 0;
    double t_light = 0, t_eye = 0;
    int cancelled = 0;
#pragma omp parallel num_threads(threads) reduction(+ : eye_samples, light_samples)
    for (int k0 = 0; k0 < K; k0 += nbatch) {
        if (cancelled) break; /* set before the previous barrier: every thread sees the same value */
        const int nb = K - k0 < nbatch ? K - k0 : nbatch;
        double ta = 0;
#pragma omp master
        ta = atmos__now();
#pragma omp for schedule(dynamic, 4)
        for (int b = 0; b < j->L; b++)
            for (int q = 0; q < nb; q++) {
                const int k = k0 + q;
                const sspan ls = j->lspan[(size_t)k * j->L + b], ws = j->wspan[(size_t)k * j->L + b];
                if (ws.x0 <= ws.x1)
                    light_samples += light_pass(j, k, b, ws.x0, ws.x1, ls.x0, ls.x1, j->I[q], j->nsc[q], j->I[q + 1],
                                                j->nsc[q + 1]);
            }
#pragma omp master
        {
            double tb = atmos__now();
            t_light += tb - ta;
            ta = tb;
        }
#pragma omp for schedule(dynamic, 2)
        for (int y = 0; y < j->H; y++)
            for (int q = 0; q < nb; q++) {
                const int k = k0 + q;
                const sspan es = j->espan[(size_t)k * j->H + y];
                if (es.x0 <= es.x1) eye_samples += eye_pass(j, k, y, es.x0, es.x1, j->I[q], j->nsc[q], j->I[q + 1]);
            }
#pragma omp master
        {
            t_eye += atmos__now() - ta;
            float *last = j->I[nb], *lastn = j->nsc[nb];
            for (int q = nb; q > 0; q--) j->I[q] = j->I[q - 1], j->nsc[q] = j->nsc[q - 1];
            j->I[0] = last, j->nsc[0] = lastn;
            if (atmos__progress(ctx, "render slice", (double)(k0 + nb) / K)) cancelled = 1;
        }
#pragma omp barrier
    }
    tm->light = t_light, tm->eye = t_eye;
    tm->eye_samples = eye_samples, tm->light_samples = light_samples;
    if (cancelled) return atmos__error(ctx, ATMOS_E_CANCELLED, "render slice: cancelled");
    return ATMOS_OK;
}
