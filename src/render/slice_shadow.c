/* The volume's shadow on the air for the slice renderer ("air_shadows"; docs/slice.md, "Light
 * shafts"): the sky image lights the air as if the volume were not there, so where the air
 * lies in the volume's shadow (below and behind a cloud, crepuscular rays between clouds) it
 * scatters less than the sky image says. Per pixel this takes away
 *
 *   D = integral over the eye ray of sigma_s,air(x) p(theta) E_sun(x) T_eye(x) (1 - T_vol(x)) dx
 *
 * (single scattering: sigma_s,air p E_sun T_eye dx is what the air at x adds to the sky image's
 * single scattering, T_vol(x) the volume's transmittance from x toward the sun).
 *
 * T_vol comes from a deep optical-depth map made once per sun direction (sshadow in
 * slice_internal.h): over a plane across the sun's light, per texel the volume's optical depth
 * from the box's sun side to each of D depths along the light (inside the box: the light's own
 * attenuation down to that depth; past the box: its total). The air's part, sigma_s,air p
 * E_sun T_eye, comes from the atmosphere through an aerial-perspective table over the pixels
 * whose rays can be shadowed (atmosphere_ops.h, atmos__aerial_single_profile: the
 * single-scattered in-scatter S(t) from the eye to each distance t), so that the piece of
 * ray [t_i, t_i+1] contributes (S(t_i+1) - S(t_i)) (1 - T_vol) and no kind's insides are read.
 * The ray's part that can be shadowed (its points whose way to the sun crosses the map, and
 * not upstream of the box) is found in closed form per pixel and cut into steps of at most
 * half a map cell, the shadow sampled at a point jittered per pixel by a hash of its position
 * (noise instead of bands; the same for any thread count). */
#include "atmosphere/atmosphere_ops.h"
#include "core/rng.h"
#include "core/vec.h"
#include "render/slice_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SHADOW_N 128          /* map texels per side */
#define SHADOW_D 64           /* depth nodes along the light */
#define SHADOW_STEPS_MIN 8
#define SHADOW_PER_CELL 1.0 /* samples a map cell along a ray */
#define SHADOW_STEPS_MAX 192
#define SHADOW_RANGE_M 200e3  /* the farthest the shadow is followed along a ray */
#define SHADOW_SMOOTH 0.01    /* interpolated where the lattice's values agree within this share of the pixel */

void atmos__slice_shadow_free(atmos__slice_plan *sp)
{
    free(sp->shadow.T), free(sp->air_front), free(sp->air_lattice);
    atmos__aerial_free(&sp->shadow_ap);
    sp->shadow.T = NULL, sp->air_front = NULL, sp->air_cap = 0, sp->shadow.valid = 0;
    sp->air_lattice = NULL, sp->air_lattice_cap = 0;
}

/* The volume's grey extinction (m^-1: each field's cross-section averaged over the
 * wavelengths) at grid-frame point p. */
static double grey_extinction(const sgrid *g, const float *sig, const double p[3])
{
    float dens[ATMOS_VOLUME_MAX_FIELDS];
    if (!sgrid_sample_u(g, (float)(p[0] * g->sc + g->off[0]), (float)(p[1] * g->sc + g->off[1]),
                        (float)(p[2] * g->sc + g->off[2]), dens))
        return 0.0;
    double b = 0;
    for (int f = 0; f < g->nf; f++) b += (double)dens[f] * sig[f];
    return b;
}

/* The map for the light frame sp->light (built for the current sun): per texel a march along
 * the light through the box, midpoint steps of at most half a render voxel. */
static int shadow_build(atmos__slice_plan *sp, int threads)
{
    sshadow *sh = &sp->shadow;
    const slight *lf = &sp->light;
    const sgrid *g = &sp->g;
    const int N = SHADOW_N, D = SHADOW_D, P = SHADOW_N + 2;
    const size_t cells = (size_t)P * P * D;
    if (!sh->T && !(sh->T = malloc(sizeof(float) * cells))) return 0;
    for (size_t i = 0; i < cells; i++) sh->T[i] = 1.0f;
    sh->N = N, sh->D = D;
    memcpy(sh->lt, lf->lt, sizeof sh->lt), memcpy(sh->e1, lf->e1, sizeof sh->e1), memcpy(sh->e2, lf->e2, sizeof sh->e2);
    sh->u0 = lf->u0, sh->v0 = lf->v0;
    sh->du = lf->du * lf->L / N, sh->dv = lf->dv * lf->L / N;
    double wmin = INFINITY, wmax = -INFINITY;
    for (int c = 0; c < 8; c++) {
        const double p[3] = {c & 1 ? g->box_hi[0] : g->box_lo[0], c & 2 ? g->box_hi[1] : g->box_lo[1],
                             c & 4 ? g->box_hi[2] : g->box_lo[2]};
        const double w = atmos__dot3(p, sh->lt);
        wmin = fmin(wmin, w), wmax = fmax(wmax, w);
    }
    sh->w0 = wmin, sh->dw = (wmax - wmin) / (D - 1);
    if (!(sh->dw > 0)) sh->dw = 1;
    float sig[ATMOS_VOLUME_MAX_FIELDS];
    for (int f = 0; f < sp->nf; f++) {
        double s = 0;
        for (int c = 0; c < sp->n; c++) s += sp->tab.sig[f][c];
        sig[f] = (float)(s / sp->n);
    }
    const int m = (int)ceil(sh->dw * g->sc / 0.5);
    const double h = sh->dw / (m < 1 ? 1 : m);
    int amin = N, amax = -1, bmin = N, bmax = -1, kmin = D;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads) reduction(min : amin, bmin, kmin) reduction(max : amax, bmax)
    for (int b = 0; b < N; b++)
        for (int a = 0; a < N; a++) {
            const double u = sh->u0 + (a + 0.5) * sh->du, v = sh->v0 + (b + 0.5) * sh->dv;
            const double o[3] = {u * sh->e1[0] + v * sh->e2[0], u * sh->e1[1] + v * sh->e2[1],
                                 u * sh->e1[2] + v * sh->e2[2]};
            double ta, tb; /* o lies in the plane w = 0, so a point's t along lt is its w */
            if (!atmos__ray_box(o, sh->lt, g->box_lo, g->box_hi, &ta, &tb)) continue;
            float *col = sh->T + ((size_t)(b + 1) * P + a + 1) * D;
            double acc = 0;
            for (int k = 1; k < D; k++) {
                const double wa = sh->w0 + (k - 1) * sh->dw;
                if (wa + sh->dw > ta && wa < tb)
                    for (int s = 0; s < m; s++) {
                        const double w = wa + (s + 0.5) * h;
                        if (w < ta || w > tb) continue;
                        const double p[3] = {o[0] + w * sh->lt[0], o[1] + w * sh->lt[1], o[2] + w * sh->lt[2]};
                        acc += grey_extinction(g, sig, p) * h;
                    }
                col[k] = (float)exp(-acc);
                if (col[k] < 1.0f && k < kmin) kmin = k;
            }
            if (col[D - 1] < 1.0f)
                amin = a < amin ? a : amin, amax = a > amax ? a : amax, bmin = b < bmin ? b : bmin, bmax = b > bmax ? b : bmax;
        }
    /* where a ray can meet the shadow: within one texel of the texels that cast one (their
     * taps reach one padded index either side), from the node before the first that does */
    sh->lo[0] = amin, sh->hi[0] = amax + 2.0, sh->lo[1] = bmin, sh->hi[1] = bmax + 2.0;
    sh->lo[2] = kmin - 1.0;
    if (amax < 0) sh->lo[0] = sh->lo[1] = 1, sh->hi[0] = sh->hi[1] = 0; /* no shadow at all */
    return 1;
}

#define SHADOW_CLONES ATMOS_CLONES

/* What the volume's shadow takes at ns points of a ray, 1 - T_vol, the points' map
 * coordinates (fa, fb: padded texel index, centres at integers; fj: depth node) linear in
 * i: fa = a0 + i ad, ... T_vol trilinear in the map's transmittances (1 outside the map across
 * the light and before the first node; past the last node a texel's total): interpolating
 * transmittance rather than optical depth keeps an opaque shadow's edge as sharp as a texel.
 * A loop of gathers and arithmetic the compiler vectorises (an AVX2 clone). */
SHADOW_CLONES static void shadow_samples(const float *T, int P, int D, float a0, float ad, float b0, float bd,
                                         float j0, float jd, int ns, float *q)
{
    const float lim = (float)(P - 1), dl = (float)(D - 1);
    const int sa = D, sb = P * D;
    for (int i = 0; i < ns; i++) {
        const float fi = (float)i;
        float fa = a0 + fi * ad, fb = b0 + fi * bd, fj = j0 + fi * jd;
        fa = fa < 0.0f ? 0.0f : (fa > lim ? lim : fa);
        fb = fb < 0.0f ? 0.0f : (fb > lim ? lim : fb);
        fj = fj < 0.0f ? 0.0f : (fj > dl ? dl : fj);
        int a = (int)fa, b = (int)fb, k = (int)fj;
        a = a > P - 2 ? P - 2 : a, b = b > P - 2 ? P - 2 : b, k = k > D - 2 ? D - 2 : k;
        const float wa = fa - (float)a, wb = fb - (float)b, wk = fj - (float)k;
        const int o = (b * P + a) * D + k;
        const float z0 = (1 - wb) * ((1 - wa) * T[o] + wa * T[o + sa]) + wb * ((1 - wa) * T[o + sb] + wa * T[o + sa + sb]);
        const float z1 = (1 - wb) * ((1 - wa) * T[o + 1] + wa * T[o + sa + 1]) +
                         wb * ((1 - wa) * T[o + sb + 1] + wa * T[o + sa + sb + 1]);
        q[i] = 1.0f - (z0 + wk * (z1 - z0));
    }
}

/* A ray E + t d (grid frame) in the map's coordinates: fa(t) = q0[0] + t qd[0], ... */
typedef struct {
    double q0[3], qd[3];
} mray;

static void map_ray(const sshadow *sh, const double E[3], const double d[3], mray *m)
{
    m->q0[0] = (atmos__dot3(E, sh->e1) - sh->u0) / sh->du + 0.5, m->qd[0] = atmos__dot3(d, sh->e1) / sh->du;
    m->q0[1] = (atmos__dot3(E, sh->e2) - sh->v0) / sh->dv + 0.5, m->qd[1] = atmos__dot3(d, sh->e2) / sh->dv;
    m->q0[2] = (atmos__dot3(E, sh->lt) - sh->w0) / sh->dw, m->qd[2] = atmos__dot3(d, sh->lt) / sh->dw;
}

/* t in (*ta, *tb) with lo <= x0 + t dx <= hi; 0 when empty. */
static int clip_axis(double x0, double dx, double lo, double hi, double *ta, double *tb)
{
    if (dx == 0.0) return x0 >= lo && x0 <= hi && *ta < *tb;
    double t1 = (lo - x0) / dx, t2 = (hi - x0) / dx;
    if (t1 > t2) {
        const double s = t1;
        t1 = t2, t2 = s;
    }
    *ta = fmax(*ta, t1), *tb = fmin(*tb, t2);
    return *ta < *tb;
}

/* The part [ta, tb] of [0, tlim] where the ray's points may be in the volume's shadow: across
 * the light within reach of the texels that cast one, along it not upstream of the first depth
 * where one begins. */
static int shadow_span(const sshadow *sh, const mray *m, double tlim, double *ta, double *tb)
{
    *ta = 0, *tb = tlim;
    if (!(sh->hi[0] >= sh->lo[0])) return 0; /* no texel casts a shadow */
    return clip_axis(m->q0[0], m->qd[0], sh->lo[0], sh->hi[0], ta, tb) &&
           clip_axis(m->q0[1], m->qd[1], sh->lo[1], sh->hi[1], ta, tb) &&
           clip_axis(m->q0[2], m->qd[2], sh->lo[2], INFINITY, ta, tb);
}

/* What the shadow takes from the air along one ray's span [ta, tb]: in front of the halfway
 * plane th (Df) and behind it (Db), per wavelength. tt/S: the ray's in-scatter profile. */
static void span_shadow(const sshadow *sh, const mray *m, double ta, double tb, double th, double xi, int nd,
                        const double *tt, const float *S, int n, double *Df, double *Db)
{
    float q[SHADOW_STEPS_MAX];
    /* a sample a map cell (jittered: noise, not bands, at a shadow's edge): across the light
     * over the whole span, along it only where the span is within the box's depth (past it a
     * texel's depth is its total) */
    double ja = ta, jb = tb;
    const double along = clip_axis(m->q0[2], m->qd[2], 0.0, sh->D - 1.0, &ja, &jb) ? (jb - ja) * fabs(m->qd[2]) : 0.0;
    const double want = ceil(SHADOW_PER_CELL * fmax((tb - ta) * fmax(fabs(m->qd[0]), fabs(m->qd[1])), along));
    const int ns = want < SHADOW_STEPS_MIN ? SHADOW_STEPS_MIN : (want > SHADOW_STEPS_MAX ? SHADOW_STEPS_MAX : (int)want);
    const double h = (tb - ta) / ns;
    const float a0 = (float)(m->q0[0] + (ta + xi * h) * m->qd[0]), ad = (float)(h * m->qd[0]);
    const float b0 = (float)(m->q0[1] + (ta + xi * h) * m->qd[1]), bd = (float)(h * m->qd[1]);
    const float j0 = (float)(m->q0[2] + (ta + xi * h) * m->qd[2]), jd = (float)(h * m->qd[2]);
    shadow_samples(sh->T, sh->N + 2, sh->D, a0, ad, b0, bd, j0, jd, ns, q);
    /* the in-scatter at the steps' ends, linear between the profile's distances */
    float Sb[(SHADOW_STEPS_MAX + 1) * ATMOS_MAX_WAVELENGTHS];
    int k = 0;
    for (int i = 0; i <= ns; i++) {
        const double t = ta + i * h;
        while (k < nd - 2 && tt[k + 1] < t) k++;
        double w = tt[k + 1] > tt[k] ? (t - tt[k]) / (tt[k + 1] - tt[k]) : 0.0;
        const float wf = (float)(w < 0 ? 0 : (w > 1 ? 1 : w));
        const float *s0 = S + (size_t)k * n, *s1 = s0 + n;
        for (int c = 0; c < n; c++) Sb[i * n + c] = s0[c] + wf * (s1[c] - s0[c]);
    }
    /* steps whose shadow sample lies before the halfway plane are in front of the volume */
    const double f = (th - ta) / h - xi;
    const int nf = !(f > 0) ? 0 : (f >= ns ? ns : (int)ceil(f));
    for (int c = 0; c < n; c++) {
        float a = 0.0f, b = 0.0f;
        for (int i = 0; i < nf; i++) a += (Sb[(i + 1) * n + c] - Sb[i * n + c]) * q[i];
        for (int i = nf; i < ns; i++) b += (Sb[(i + 1) * n + c] - Sb[i * n + c]) * q[i];
        Df[c] = a, Db[c] = b;
    }
}

/* The frame's geometry: the eye, the halfway plane and the range the shadow is followed to
 * (past the box's corners to where their shadows meet the ground, at most SHADOW_RANGE_M). */
typedef struct {
    const atmos_atmosphere *atm;
    const atmos_camera *cam;
    const atmos__vol_xform *xf;
    const sshadow *sh;
    double hc, tfar;
    const sjob *j;
    int ground; /* the atmosphere has a ground that the sun lights (not a vacuum) */
} sframe;

/* Pixel (x, y)'s ray: its world and grid-frame directions, its map ray, its span and the
 * distance to the ground (*tg, INFINITY: none). */
static int pixel_span(const sframe *f, int x, int y, double dw[3], double d[3], mray *m, double *ta, double *tb,
                      double *tg)
{
    atmos_camera_ray(f->cam, x + 0.5, y + 0.5, dw);
    atmos__vol_dir_to_frame(f->xf, dw, d);
    map_ray(f->sh, f->j->eye, d, m);
    *tg = atmos_atmosphere_ground_distance(f->atm, f->cam->position, dw);
    return shadow_span(f->sh, m, fmin(*tg, f->tfar), ta, tb);
}

/* The ground's direct sunlight that the volume's shadow takes from a ray (world direction dw)
 * meeting the ground at tg: (1 - T_vol) times the sunlit ground the sky image holds there
 * (albedo / pi cos E T_eye, atmos__atm_ground_sunlit: the flat ground or a planet's, with
 * its maps). */
static void ground_shadow(const sframe *f, const mray *m, const double dw[3], double tg, const double sun[3], int n,
                          double *G)
{
    for (int c = 0; c < n; c++) G[c] = 0.0;
    if (!f->ground || !(tg < f->tfar)) return;
    const sshadow *sh = f->sh;
    float q = 0.0f;
    shadow_samples(sh->T, sh->N + 2, sh->D, (float)(m->q0[0] + tg * m->qd[0]), 0.0f, (float)(m->q0[1] + tg * m->qd[1]),
                   0.0f, (float)(m->q0[2] + tg * m->qd[2]), 0.0f, 1, &q);
    if (!(q > 0.0f)) return;
    atmos__atm_ground_sunlit(f->atm, f->cam->position, dw, tg, sun, G);
    for (int c = 0; c < n; c++) G[c] *= q;
}

static double shadow_range(const sgrid *g, const atmos__vol_xform *xf, const atmos_camera *cam, const double sun[3])
{
    double far = 0;
    for (int c = 0; c < 8; c++) {
        const double p[3] = {c & 1 ? g->box_hi[0] : g->box_lo[0], c & 2 ? g->box_hi[1] : g->box_lo[1],
                             c & 4 ? g->box_hi[2] : g->box_lo[2]};
        double w[3], e[3];
        atmos__vol_frame_to_point(xf, p, w);
        for (int a = 0; a < 3; a++) e[a] = w[a] - cam->position[a];
        far = fmax(far, sqrt(atmos__dot3(e, e)));
        const double s = sun[1] > 0.02 ? fmax(w[1], 0.0) / sun[1] : SHADOW_RANGE_M; /* to the ground's level */
        for (int a = 0; a < 3; a++) e[a] -= s * sun[a];
        far = fmax(far, sqrt(atmos__dot3(e, e)));
    }
    return fmin(far + 1.0, SHADOW_RANGE_M);
}

/* The aerial-perspective table over the directions of the pixels whose rays may be shadowed
 * (the whole image's: a region's pixels get the values of the whole frame), to the farthest
 * point of their spans. NULL when no ray is shadowed (or out of memory: the air unshadowed). */
static const atmos__aerial *shadow_table(atmos__slice_plan *sp, const sframe *f, const double sun[3], int threads)
{
    const atmos_camera *cam = f->cam;
    const int W = cam->width, H = cam->height;
    double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY, tmax = 0;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(min : u0, v0) reduction(max : u1, v1, tmax)
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double dw[3], d[3], ta, tb, tg;
            mray m;
            if (!pixel_span(f, x, y, dw, d, &m, &ta, &tb, &tg)) continue;
            const double z = atmos__dot3(dw, cam->forward), u = atmos__dot3(dw, cam->right) / z,
                         v = atmos__dot3(dw, cam->up) / z;
            u0 = fmin(u0, u), u1 = fmax(u1, u), v0 = fmin(v0, v), v1 = fmax(v1, v), tmax = fmax(tmax, tb);
        }
    if (!(tmax > 0) || !(u1 >= u0)) return NULL;
    atmos__aerial_grid g;
    memset(&g, 0, sizeof g);
    memcpy(g.eye, cam->position, sizeof g.eye), memcpy(g.sun, sun, sizeof g.sun);
    memcpy(g.fwd, cam->forward, sizeof g.fwd), memcpy(g.right, cam->right, sizeof g.right);
    memcpy(g.up, cam->up, sizeof g.up);
    const double px = 2.0 * cam->tan_half_fov / H; /* one pixel, in u and v */
    g.u0 = u0 - px, g.u1 = u1 + px, g.v0 = v0 - px, g.v1 = v1 + px;
    g.tmin = 0, g.tmax = tmax * 1.001 + 1.0;
    g.nd = ATMOS__AERIAL_SLICES;
    atmos__aerial_nodes(f->atm, &g);
    return atmos__aerial_build(&sp->shadow_ap, f->atm, &g, threads) ? &sp->shadow_ap : NULL;
}

typedef struct { /* a pixel's ray (pixel_span) */
    double dw[3], d[3], ta, tb, tg;
    mray m;
} sray;

/* What the shadow takes from the air along pixel (x, y)'s ray R (its span found), per
 * wavelength: all of it into D, the part in front of the volume's halfway plane into Df. 0
 * (and zeros) when the air's profile along it is empty. */
static int ray_air(const sframe *f, const atmos__aerial *ap, const sjob *j, int n, int x, int y, const sray *R,
                   double *D, double *Df)
{
    for (int c = 0; c < n; c++) D[c] = Df[c] = 0.0;
    double tt[ATMOS__AERIAL_MAX_SLICES], Db[ATMOS_MAX_WAVELENGTHS];
    float S[ATMOS__AERIAL_MAX_SLICES * ATMOS_MAX_WAVELENGTHS];
    const double *dw = R->dw, *d = R->d, ta = R->ta, tb = R->tb;
    const mray m = R->m;
    const int nd = atmos__aerial_single_profile(ap, dw, ta, tb, tt, S);
    if (nd < 2) return 0;
    const double hd = atmos__dot3(j->h, d);
    const double th = fabs(hd) >= SLICE_HD_EPS ? (f->hc - j->he) / hd : 0.0;
    const double xi = atmos__u01(atmos__mix64(((uint64_t)(uint32_t)y << 32) | (uint32_t)x));
    span_shadow(f->sh, &m, ta, tb, th, xi, nd, tt, S, n, Df, Db);
    for (int c = 0; c < n; c++) D[c] = Df[c] + Db[c];
    return 1;
}

/* The same for pixel (x, y), its span found first; 0 when it has none. */
static int pixel_air(const sframe *f, const atmos__aerial *ap, const sjob *j, int n, int x, int y, double *D,
                     double *Df)
{
    sray R;
    for (int c = 0; c < n; c++) D[c] = Df[c] = 0.0;
    return pixel_span(f, x, y, R.dw, R.d, &R.m, &R.ta, &R.tb, &R.tg) && ray_air(f, ap, j, n, x, y, &R, D, Df);
}

/* The shadow on the air evaluated exactly at the pixels of even x and y (a lattice covering
 * the region: the values are the image's, whatever the region), in between interpolated
 * where the lattice's neighbours all have a shadowed span and agree within SHADOW_SMOOTH of
 * the pixel's value, else evaluated. The same values for any thread count or region. */
typedef struct {
    int a0, b0, na, nb, W, H;
    size_t stride;  /* doubles a lattice point: its flag, D[n], Df[n] */
    double *val;
} slattice;

static int lattice_make(atmos__slice_plan *sp, const atmos_camera *cam, const atmos__rect *r, int n, slattice *L)
{
    L->W = cam->width, L->H = cam->height;
    L->a0 = r->x0 / 2, L->b0 = r->y0 / 2;
    L->na = (r->x1 - 1) / 2 + 2 - L->a0, L->nb = (r->y1 - 1) / 2 + 2 - L->b0;
    if (2 * (L->a0 + L->na - 1) > L->W - 1) L->na--; /* lattice points inside the image only */
    if (2 * (L->b0 + L->nb - 1) > L->H - 1) L->nb--;
    L->stride = 1 + 2 * (size_t)n;
    const size_t need = (size_t)L->na * L->nb * L->stride;
    if (need > sp->air_lattice_cap) {
        double *b = realloc(sp->air_lattice, sizeof(double) * need);
        if (!b) return 0;
        sp->air_lattice = b, sp->air_lattice_cap = need;
    }
    L->val = sp->air_lattice;
    return 1;
}

/* The lattice point (a, b) (image lattice coordinates), NULL outside the computed ones. */
static const double *lattice_at(const slattice *L, int a, int b)
{
    if (a < L->a0 || b < L->b0 || a >= L->a0 + L->na || b >= L->b0 + L->nb) return NULL;
    return L->val + ((size_t)(b - L->b0) * L->na + (a - L->a0)) * L->stride;
}

/* D and Df of pixel (x, y) from the lattice (1), or 0 when it must be evaluated. px: the
 * pixel's value before the shadow is taken. */
static int lattice_value(const slattice *L, int x, int y, int n, const float *px, double *D, double *Df)
{
    const int a = x / 2, b = y / 2, da = x & 1, db = y & 1;
    const double *e[4];
    int k = 0;
    for (int q = 0; q <= db; q++)
        for (int p = 0; p <= da; p++)
            if (!(e[k++] = lattice_at(L, a + p, b + q)) || e[k - 1][0] == 0.0) return 0;
    const double w = 1.0 / k;
    for (int c = 0; c < n; c++) {
        double lo = INFINITY, hi = -INFINITY, lf = INFINITY, hf = -INFINITY, s = 0, sf = 0;
        for (int i = 0; i < k; i++) {
            const double vd = e[i][1 + c], vf = e[i][1 + n + c];
            lo = fmin(lo, vd), hi = fmax(hi, vd), lf = fmin(lf, vf), hf = fmax(hf, vf), s += vd, sf += vf;
        }
        const double tol = SHADOW_SMOOTH * px[c];
        if (!(hi - lo <= tol && hf - lf <= tol)) return 0;
        D[c] = w * s, Df[c] = w * sf;
    }
    return 1;
}

/* Pixel (x, y): the ground's lost sunlight and the air's, taken from the image; the front part
 * into air_front. */
static void air_pixel_apply(const sframe *f, const atmos__aerial *ap, const sjob *j, const slattice *L, atmos_image *img,
                            float *air_front, int x, int y, int n, const double sun[3])
{
    const size_t p = (size_t)y * L->W + x;
    float *fr = air_front + p * n, *px = img->pixels + p * img->channels;
    for (int c = 0; c < n; c++) fr[c] = 0.0f;
    double G[ATMOS_MAX_WAVELENGTHS], D[ATMOS_MAX_WAVELENGTHS], Df[ATMOS_MAX_WAVELENGTHS];
    sray R;
    if (!pixel_span(f, x, y, R.dw, R.d, &R.m, &R.ta, &R.tb, &R.tg)) return;
    ground_shadow(f, &R.m, R.dw, R.tg, sun, n, G);
    for (int c = 0; c < n; c++) px[c] = (float)fmax(px[c] - G[c], 0.0);
    const double *e = !(x & 1) && !(y & 1) ? lattice_at(L, x / 2, y / 2) : NULL;
    if (e) {
        if (e[0] == 0.0) return;
        for (int c = 0; c < n; c++) D[c] = e[1 + c], Df[c] = e[1 + n + c];
    } else if (!lattice_value(L, x, y, n, px, D, Df) && !ray_air(f, ap, j, n, x, y, &R, D, Df)) {
        return;
    }
    for (int c = 0; c < n; c++) {
        const double s = px[c] - D[c];
        px[c] = (float)(s > 0 ? s : 0.0);
        fr[c] = (float)Df[c];
    }
}

atmos_status atmos__slice_air_shadow(atmos_context *ctx, atmos__slice_plan *sp, const atmos_atmosphere *atm,
                                     const atmos__view *v, const atmos__rect *r, sjob *j, atmos_image *img,
                                     double *secs)
{
    const double t0 = atmos__now();
    const int threads = atmos__threads(ctx), n = sp->n;
    j->air_front = NULL;
    *secs = 0;
    if (atmos_atmosphere_get_kind(atm) == ATMOS_ATMOSPHERE_VACUUM || v->cam.type != ATMOS_CAMERA_PINHOLE) return ATMOS_OK;
    const sgrid *g = &sp->g;
    const double cen[3] = {0.5 * (g->box_lo[0] + g->box_hi[0]), 0.5 * (g->box_lo[1] + g->box_hi[1]),
                           0.5 * (g->box_lo[2] + g->box_hi[2])};
    { /* a volume the sun does not reach casts no shadow */
        double cw[3], E[ATMOS_MAX_WAVELENGTHS], e = 0;
        atmos__vol_frame_to_point(&sp->x, cen, cw);
        atmos_atmosphere_sunlight(atm, cw, v->sun, E);
        for (int c = 0; c < n; c++) e += E[c];
        if (!(e > 0)) return ATMOS_OK;
    }
    sshadow *sh = &sp->shadow;
    if (!sh->valid || memcmp(sh->sun, v->sun, sizeof sh->sun) != 0) {
        const double tb0 = atmos__now();
        if (!shadow_build(sp, threads)) return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the shadow map");
        memcpy(sh->sun, v->sun, sizeof sh->sun);
        sh->valid = 1;
        sh->build_s = atmos__now() - tb0;
    }
    sframe f = {atm, &v->cam, &sp->x, sh, atmos__dot3(j->h, cen), shadow_range(g, &sp->x, &v->cam, v->sun), j,
                atmos_atmosphere_get_kind(atm) != ATMOS_ATMOSPHERE_VACUUM};
    const atmos__aerial *ap = shadow_table(sp, &f, v->sun, threads);
    if (!ap) {
        *secs = atmos__now() - t0;
        return ATMOS_OK;
    }
    const size_t need = (size_t)v->cam.width * v->cam.height * n;
    if (need > sp->air_cap) {
        float *b = realloc(sp->air_front, sizeof(float) * need);
        if (!b) return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the air's shadow");
        sp->air_front = b, sp->air_cap = need;
    }
    slattice L;
    if (!lattice_make(sp, &v->cam, r, n, &L)) return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the air's shadow");
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int b = 0; b < L.nb; b++)
        for (int a = 0; a < L.na; a++) {
            double *e = L.val + ((size_t)b * L.na + a) * L.stride;
            e[0] = pixel_air(&f, ap, j, n, 2 * (L.a0 + a), 2 * (L.b0 + b), e + 1, e + 1 + n);
        }
#pragma omp parallel for schedule(dynamic, 2) num_threads(threads)
    for (int y = r->y0; y < r->y1; y++)
        for (int x = r->x0; x < r->x1; x++) air_pixel_apply(&f, ap, j, &L, img, sp->air_front, x, y, n, v->sun);
    j->air_front = sp->air_front;
    *secs = atmos__now() - t0;
    return ATMOS_OK;
}
