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
#include "volume/volume_grid.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SLICE_OCC_B 4          /* occupancy block edge, render-grid voxels */
#define SLICE_F_ORDERS 256     /* F_n and S(n) tabulated at integer n = 0..SLICE_F_ORDERS */
#define SLICE_HD_EPS 0.02      /* rays within ~89° of the slice planes are not sliced */
#define SLICE_MAX_GRID_BYTES ((uint64_t)2 << 30)

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

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
}

/* ------------------------------------------------------------------ optics */

void atmos_slice_optics_free(atmos_slice_optics *o)
{
    if (!o) return;
    if (o->owned)
        for (int i = 0; i < o->count; i++) {
            atmos_msphase_destroy((atmos_msphase *)o->ms[i]);
            atmos_phase_table_destroy((atmos_phase_table *)o->phase[i]);
        }
    memset(o, 0, sizeof *o);
}

atmos_status atmos_slice_optics_build(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                      atmos_slice_optics *out)
{
    if (!scene || !volume || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice optics: missing argument");
    memset(out, 0, sizeof *out);
    out->owned = 1;
    atmos_wavelengths wl;
    atmos_status st = atmos_scene_wavelengths(ctx, scene, &wl);
    if (st != ATMOS_OK) return st;
    int nf = atmos_volume_field_count(volume);
    for (int i = 0; i < nf; i++) {
        atmos_particle_desc pd;
        const char *name = atmos_volume_field_particle(volume, i);
        if ((st = atmos_scene_particle(ctx, scene, name, &pd)) != ATMOS_OK) goto fail;
        atmos_phase_table *t = NULL;
        atmos_phase_table_desc td = {0};
        if ((st = atmos_phase_table_build(ctx, &pd, &wl, &td, &t)) != ATMOS_OK) goto fail;
        out->phase[i] = t;
        out->count = i + 1;
        atmos_msphase *m = NULL;
        atmos_msphase_desc md = {0};
        md.max_order = 64;
        if ((st = atmos_msphase_build(ctx, t, &md, &m)) != ATMOS_OK) goto fail;
        out->ms[i] = m;
    }
    out->count = nf;
    return ATMOS_OK;
fail:
    atmos_slice_optics_free(out);
    return st;
}

/* ------------------------------------------------------------------ render grid */

/* The volume box-filtered onto a dense grid (integer factor f native voxels per
 * render voxel), fields interleaved per voxel, with one empty voxel of padding on
 * every side so that the trilinear interpolant falls to zero at the edges, and a
 * coarse occupancy grid (Riley §3.2's majorant idea: blocks that are exactly empty
 * are skipped without interpolating). */
typedef struct {
    int nf;
    int c[3];             /* render voxels per axis, padding included */
    float *v;             /* c0*c1*c2*nf */
    int ob[3];
    unsigned char *occ;   /* ob0*ob1*ob2 */
    float sc, off[3];     /* u = g * sc + off: grid-frame metres -> render-voxel coordinate */
    double box_lo[3], box_hi[3]; /* grid-frame metres where the interpolant may be nonzero */
} sgrid;

static void sgrid_free(sgrid *g)
{
    free(g->v);
    free(g->occ);
    memset(g, 0, sizeof *g);
}

static atmos_status sgrid_build(atmos_context *ctx, const atmos_volume *vol, double scale, int cap, sgrid *g)
{
    memset(g, 0, sizeof *g);
    const int nf = vol->nfields;
    g->nf = nf;
    int blo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, bhi[3] = {-1, -1, -1};
    for (int f = 0; f < nf; f++) {
        const vol_field *fl = &vol->field[f];
        if (!fl->table || fl->count == 0) continue;
        for (uint64_t b = 0; b < vol->nbricks; b++) {
            if (!fl->table[b]) continue;
            int bx = (int)(b % (uint64_t)vol->nb[0]);
            int by = (int)((b / (uint64_t)vol->nb[0]) % (uint64_t)vol->nb[1]);
            int bz = (int)(b / ((uint64_t)vol->nb[0] * (uint64_t)vol->nb[1]));
            int bb[3] = {bx, by, bz};
            for (int a = 0; a < 3; a++) {
                if (bb[a] < blo[a]) blo[a] = bb[a];
                if (bb[a] > bhi[a]) bhi[a] = bb[a];
            }
        }
    }
    if (bhi[0] < 0) return ATMOS_OK; /* empty volume: g->v stays NULL */
    int lo[3], ext[3], emax = 1;
    for (int a = 0; a < 3; a++) {
        lo[a] = blo[a] * VOL_BRICK;
        int hi = (bhi[a] + 1) * VOL_BRICK;
        if (hi > vol->desc.dims[a]) hi = vol->desc.dims[a];
        ext[a] = hi - lo[a];
        if (ext[a] > emax) emax = ext[a];
    }
    int fac = (emax + (cap - 2) - 1) / (cap - 2);
    if (fac < 1) fac = 1;
    uint64_t nvox = 1;
    for (int a = 0; a < 3; a++) {
        g->c[a] = (ext[a] + fac - 1) / fac + 2;
        nvox *= (uint64_t)g->c[a];
    }
    if (nvox * (uint64_t)nf * sizeof(float) > SLICE_MAX_GRID_BYTES)
        return atmos__error(ctx, ATMOS_E_LIMIT, "slice: render grid %dx%dx%d x %d fields exceeds %llu bytes", g->c[0],
                            g->c[1], g->c[2], nf, (unsigned long long)SLICE_MAX_GRID_BYTES);
    g->v = calloc(nvox * (uint64_t)nf, sizeof(float));
    for (int a = 0; a < 3; a++) g->ob[a] = (g->c[a] - 2) / SLICE_OCC_B + 1;
    g->occ = calloc((size_t)g->ob[0] * g->ob[1] * g->ob[2], 1);
    if (!g->v || !g->occ) {
        sgrid_free(g);
        return atmos__error(ctx, ATMOS_E_NOMEM, "slice: out of memory for the render grid");
    }
    /* Box filter: every native voxel of every occupied brick adds to its render voxel. */
    for (int f = 0; f < nf; f++) {
        const vol_field *fl = &vol->field[f];
        if (!fl->table) continue;
        for (uint64_t b = 0; b < vol->nbricks; b++) {
            uint32_t s = fl->table[b];
            if (!s) continue;
            const float *br = fl->bricks[s - 1];
            int bx = (int)(b % (uint64_t)vol->nb[0]) * VOL_BRICK;
            int by = (int)((b / (uint64_t)vol->nb[0]) % (uint64_t)vol->nb[1]) * VOL_BRICK;
            int bz = (int)(b / ((uint64_t)vol->nb[0] * (uint64_t)vol->nb[1])) * VOL_BRICK;
            for (int k = 0; k < VOL_BRICK; k++)
                for (int j = 0; j < VOL_BRICK; j++)
                    for (int i = 0; i < VOL_BRICK; i++) {
                        float val = br[(k * VOL_BRICK + j) * VOL_BRICK + i];
                        if (val == 0.0f) continue;
                        int ci = (bx + i - lo[0]) / fac + 1, cj = (by + j - lo[1]) / fac + 1,
                            ck = (bz + k - lo[2]) / fac + 1;
                        if (ci >= g->c[0] - 1 || cj >= g->c[1] - 1 || ck >= g->c[2] - 1) continue;
                        g->v[(((size_t)ck * g->c[1] + cj) * g->c[0] + ci) * nf + f] += val;
                    }
        }
    }
    const float norm = (float)(scale / ((double)fac * fac * fac));
    for (uint64_t p = 0; p < nvox; p++) {
        int any = 0;
        for (int f = 0; f < nf; f++) {
            g->v[p * nf + f] *= norm;
            any |= g->v[p * nf + f] > 0.0f;
        }
        if (!any) continue;
        int ci = (int)(p % (uint64_t)g->c[0]), cj = (int)((p / (uint64_t)g->c[0]) % (uint64_t)g->c[1]),
            ck = (int)(p / ((uint64_t)g->c[0] * g->c[1]));
        /* A sample whose lower corner is i0 reads voxels i0 and i0+1: mark i0 = c-1, c. */
        for (int dk = -1; dk <= 0; dk++)
            for (int dj = -1; dj <= 0; dj++)
                for (int di = -1; di <= 0; di++) {
                    int a = ci + di, bq = cj + dj, cq = ck + dk;
                    if (a < 0 || bq < 0 || cq < 0 || a > g->c[0] - 2 || bq > g->c[1] - 2 || cq > g->c[2] - 2) continue;
                    g->occ[((size_t)(cq / SLICE_OCC_B) * g->ob[1] + bq / SLICE_OCC_B) * g->ob[0] + a / SLICE_OCC_B] = 1;
                }
    }
    /* Render voxel c covers native [lo + (c-1) fac, lo + c fac); its centre is u = c. */
    const double vs = vol->desc.voxel_size_m;
    g->sc = (float)(1.0 / (vs * fac));
    for (int a = 0; a < 3; a++) {
        g->off[a] = (float)(0.5 - (double)lo[a] / fac);
        /* u = (q - lo)/fac + 0.5 with q = g/vs; nonzero for u in (0, c-1). */
        g->box_lo[a] = ((double)lo[a] - 0.5 * fac) * vs;
        g->box_hi[a] = ((double)lo[a] + (g->c[a] - 1.5) * fac) * vs;
    }
    return ATMOS_OK;
}

/* Trilinear densities of all fields at grid-frame point (x, y, z). Returns 0 if the
 * point is outside the grid or in an empty occupancy block (dens untouched). */
static inline int sgrid_sample(const sgrid *g, float x, float y, float z, float *dens)
{
    float u = x * g->sc + g->off[0], v = y * g->sc + g->off[1], w = z * g->sc + g->off[2];
    if (!(u >= 0.0f && v >= 0.0f && w >= 0.0f)) return 0;
    int i = (int)u, j = (int)v, k = (int)w;
    if (i > g->c[0] - 2 || j > g->c[1] - 2 || k > g->c[2] - 2) return 0;
    if (!g->occ[((size_t)(k / SLICE_OCC_B) * g->ob[1] + j / SLICE_OCC_B) * g->ob[0] + i / SLICE_OCC_B]) return 0;
    float fu = u - i, fv = v - j, fw = w - k;
    const int nf = g->nf;
    const size_t sx = (size_t)nf, sy = (size_t)g->c[0] * nf, sz = (size_t)g->c[0] * g->c[1] * nf;
    const float *p = g->v + (((size_t)k * g->c[1] + j) * g->c[0] + i) * nf;
    float w000 = (1 - fu) * (1 - fv) * (1 - fw), w100 = fu * (1 - fv) * (1 - fw), w010 = (1 - fu) * fv * (1 - fw),
          w110 = fu * fv * (1 - fw), w001 = (1 - fu) * (1 - fv) * fw, w101 = fu * (1 - fv) * fw,
          w011 = (1 - fu) * fv * fw, w111 = fu * fv * fw;
    for (int f = 0; f < nf; f++)
        dens[f] = w000 * p[f] + w100 * p[sx + f] + w010 * p[sy + f] + w110 * p[sx + sy + f] + w001 * p[sz + f] +
                  w101 * p[sx + sz + f] + w011 * p[sy + sz + f] + w111 * p[sx + sy + sz + f];
    return 1;
}

/* ------------------------------------------------------------------ optics tables */

typedef struct {
    int n;                     /* wavelengths */
    int nf;                    /* fields */
    float sig[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* sigma_ext, m^2 */
    float sca[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* albedo * sigma_ext */
    int no;                    /* Ams orders tabulated: 1..no */
    int ng[ATMOS_VOLUME_MAX_FIELDS];
    const double *grid[ATMOS_VOLUME_MAX_FIELDS];  /* theta, degrees */
    float *ams[ATMOS_VOLUME_MAX_FIELDS];          /* [(k * ng + a) * no + (order - 1)] */
    float *F[ATMOS_VOLUME_MAX_FIELDS];            /* [k * (SLICE_F_ORDERS+1) + n]: F_n (Eq. 23) */
    float *S[ATMOS_VOLUME_MAX_FIELDS];            /* same layout: S(n) = sum_{i<=n} ln F_i */
} stables;

static void stables_free(stables *t)
{
    for (int f = 0; f < ATMOS_VOLUME_MAX_FIELDS; f++) free(t->ams[f]), free(t->F[f]), free(t->S[f]);
}

static atmos_status stables_build(atmos_context *ctx, const atmos_slice_optics *o, int n, int max_order, stables *t)
{
    memset(t, 0, sizeof *t);
    t->n = n;
    t->nf = o->count;
    t->no = max_order < 2 ? 2 : max_order;
    for (int f = 0; f < o->count; f++) {
        if (!o->phase[f] || !o->ms[f]) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "slice: optics of field %d missing", f);
        if (atmos_phase_table_wavelength_count(o->phase[f]) != n || atmos_msphase_wavelength_count(o->ms[f]) != n)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "slice: optics of field %d have %d wavelengths, the scene %d", f,
                                atmos_phase_table_wavelength_count(o->phase[f]), n);
        const atmos_msphase *m = o->ms[f];
        int mo = atmos_msphase_max_order(m);
        t->ng[f] = atmos_msphase_grid(m, &t->grid[f]);
        const int ng = t->ng[f];
        t->ams[f] = malloc(sizeof(float) * (size_t)n * ng * t->no);
        t->F[f] = malloc(sizeof(float) * (size_t)n * (SLICE_F_ORDERS + 1));
        t->S[f] = malloc(sizeof(float) * (size_t)n * (SLICE_F_ORDERS + 1));
        if (!t->ams[f] || !t->F[f] || !t->S[f]) {
            stables_free(t);
            return atmos__error(ctx, ATMOS_E_NOMEM, "slice: out of memory for Ams tables");
        }
        for (int k = 0; k < n; k++) {
            double se = atmos_phase_table_sigma_ext(o->phase[f], k), al = atmos_phase_table_albedo(o->phase[f], k);
            if (!(se >= 0) || !isfinite(se)) se = 0;
            if (!(al >= 0)) al = 0;
            if (al > 1) al = 1;
            t->sig[f][k] = (float)se;
            t->sca[f][k] = (float)(se * al);
            for (int ord = 1; ord <= t->no; ord++) {
                /* Orders past the table's last are isotropic (Riley §4.2.1). */
                const double *vals = ord <= mo ? atmos_msphase_values(m, k, ord) : NULL;
                for (int a = 0; a < ng; a++)
                    t->ams[f][((size_t)k * ng + a) * t->no + (ord - 1)] =
                        (float)(vals ? vals[a] : 1.0 / (4.0 * ATMOS_PI));
            }
            for (int i = 0; i <= SLICE_F_ORDERS; i++) {
                t->F[f][(size_t)k * (SLICE_F_ORDERS + 1) + i] = (float)atmos_msphase_forward(m, k, i);
                t->S[f][(size_t)k * (SLICE_F_ORDERS + 1) + i] = (float)atmos_msphase_log_forward_sum(m, k, i);
            }
        }
    }
    return ATMOS_OK;
}

/* Index a and weight w (of grid point a+1) of angle theta on an increasing grid. */
static void angle_locate(const double *grid, int ng, double theta_deg, int *a, float *w)
{
    int lo = 0, hi = ng - 1;
    if (theta_deg <= grid[0]) {
        *a = 0, *w = 0;
        return;
    }
    if (theta_deg >= grid[ng - 1]) {
        *a = ng - 2, *w = 1;
        return;
    }
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (grid[mid] <= theta_deg) lo = mid;
        else hi = mid;
    }
    *a = lo;
    *w = (float)((theta_deg - grid[lo]) / (grid[lo + 1] - grid[lo]));
}

/* Ams_m (sr^-1) at fractional order m >= 1 at the pixel's angle (index a, weight wa). */
static inline float ams_lookup(const stables *t, int f, int k, int a, float wa, float m)
{
    const int no = t->no;
    float mm = m < 1.0f ? 1.0f : (m > (float)no ? (float)no : m);
    int oi = (int)(mm - 1.0f);
    if (oi > no - 2) oi = no - 2;
    float fo = mm - 1.0f - (float)oi;
    const float *p = t->ams[f] + ((size_t)k * t->ng[f] + a) * no + oi;
    float lo = p[0] + fo * (p[1] - p[0]);
    float hi = p[no] + fo * (p[no + 1] - p[no]);
    return lo + wa * (hi - lo);
}

/* Linear interpolation in a per-order table at fractional n >= 0; past the last order,
 * F is held (F_n -> 1/2) and S grows by ln F of the last order per order. */
static inline float order_lerp(const float *tab, float n, int extend)
{
    if (!(n > 0.0f)) return tab[0];
    if (n >= (float)SLICE_F_ORDERS) {
        if (!extend) return tab[SLICE_F_ORDERS];
        float slope = tab[SLICE_F_ORDERS] - tab[SLICE_F_ORDERS - 1];
        return tab[SLICE_F_ORDERS] + slope * (n - (float)SLICE_F_ORDERS);
    }
    int i = (int)n;
    float f = n - (float)i;
    return tab[i] + f * (tab[i + 1] - tab[i]);
}

/* ------------------------------------------------------------------ geometry helpers */

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void normalize3(double a[3])
{
    double l = sqrt(dot3(a, a));
    if (l > 0) a[0] /= l, a[1] /= l, a[2] /= l;
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* Slab intersection of o + t d with a box; returns 0 if missed. */
static int ray_box(const double o[3], const double d[3], const double lo[3], const double hi[3], double *t0, double *t1)
{
    double a = -INFINITY, b = INFINITY;
    for (int i = 0; i < 3; i++) {
        if (fabs(d[i]) < 1e-300) {
            if (o[i] < lo[i] || o[i] > hi[i]) return 0;
            continue;
        }
        double ta = (lo[i] - o[i]) / d[i], tb = (hi[i] - o[i]) / d[i];
        if (ta > tb) {
            double s = ta;
            ta = tb, tb = s;
        }
        if (ta > a) a = ta;
        if (tb < b) b = tb;
    }
    if (a > b) return 0;
    *t0 = a, *t1 = b;
    return 1;
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

/* ------------------------------------------------------------------ the render */

typedef struct {
    int n, nf;
    int W, H, L;                 /* image, light buffer side */
    int nslices;
    int btf;                     /* back-to-front */
    int low_albedo, eq24;
    float xi;
    double h[3], lt[3], e1[3], e2[3]; /* half vector, light propagation, light basis */
    double s0, ds;               /* slice planes s_k = s0 + (k + 0.5) ds along h */
    double eye[3], he;           /* eye in grid frame, h . eye */
    double u0, v0, du, dv;       /* light buffer: texel (a, b) centre at u0 + (a+0.5) du, ... */
    double hl;                   /* h . lt */
    const sgrid *g;
    const stables *t;
    /* per pixel */
    float *pdx, *pdy, *pdz, *pinv; /* direction, 1 / (h . d) */
    int *pk0, *pk1;
    int *pa;                     /* [pix * nf + f] angle index */
    float *pw;
    float *L_eye, *T_eye;        /* [k * npix + pix] */
    /* per light texel */
    int *lk0, *lk1;
    float *I, *nsc;              /* light arriving at the current slice: [c * L*L + texel], [texel] */
    float *I_next, *nsc_next;    /* light leaving it (written by the light pass) */
} sjob;

/* Light buffer lookup at grid-frame point (x, y, z): bilinear I per wavelength and n. */
static inline void light_lookup(const sjob *j, double x, double y, double z, float *I, float *n)
{
    double u = x * j->e1[0] + y * j->e1[1] + z * j->e1[2], v = x * j->e2[0] + y * j->e2[1] + z * j->e2[2];
    double fu = (u - j->u0) / j->du - 0.5, fv = (v - j->v0) / j->dv - 0.5;
    const int L = j->L;
    if (fu < 0) fu = 0;
    if (fv < 0) fv = 0;
    if (fu > L - 1) fu = L - 1;
    if (fv > L - 1) fv = L - 1;
    int a = (int)fu, b = (int)fv;
    if (a > L - 2) a = L - 2;
    if (b > L - 2) b = L - 2;
    if (a < 0) a = 0;
    if (b < 0) b = 0;
    float wa = (float)(fu - a), wb = (float)(fv - b);
    if (L == 1) wa = wb = 0;
    size_t t00 = (size_t)b * L + a, t10 = t00 + (L > 1), t01 = t00 + (L > 1 ? L : 0), t11 = t01 + (L > 1);
    float w00 = (1 - wa) * (1 - wb), w10 = wa * (1 - wb), w01 = (1 - wa) * wb, w11 = wa * wb;
    const size_t LL = (size_t)L * L;
    for (int k = 0; k < j->n; k++) {
        const float *p = j->I + k * LL;
        I[k] = w00 * p[t00] + w10 * p[t10] + w01 * p[t01] + w11 * p[t11];
    }
    *n = w00 * j->nsc[t00] + w10 * j->nsc[t10] + w01 * j->nsc[t01] + w11 * j->nsc[t11];
}

/* Eye pass of slice k over image row y (Eq. 26). Returns the samples evaluated. */
static long long eye_row(const sjob *j, int k, int y)
{
    const int n = j->n, nf = j->nf;
    const size_t npix = (size_t)j->W * j->H;
    const double sk = j->s0 + (k + 0.5) * j->ds;
    float dens[ATMOS_VOLUME_MAX_FIELDS], I[ATMOS_MAX_WAVELENGTHS], nsc;
    long long count = 0;
    for (int x = 0; x < j->W; x++) {
        size_t p = (size_t)y * j->W + x;
        if (k < j->pk0[p] || k > j->pk1[p]) continue;
        double t = (sk - j->he) * j->pinv[p];
        float px = (float)(j->eye[0] + t * j->pdx[p]), py = (float)(j->eye[1] + t * j->pdy[p]),
              pz = (float)(j->eye[2] + t * j->pdz[p]);
        if (!sgrid_sample(j->g, px, py, pz, dens)) continue;
        count++;
        light_lookup(j, px, py, pz, I, &nsc);
        const float delta = (float)(j->ds * fabs(j->pinv[p])); /* eye-ray length of the slab */
        /* One more scattering than the light has had turns it to the eye (Eq. 26). */
        const float m = j->low_albedo ? 1.0f : nsc + 1.0f;
        for (int c = 0; c < n; c++) {
            float bext = 0, src = 0;
            for (int f = 0; f < nf; f++) {
                if (dens[f] <= 0.0f) continue;
                bext += dens[f] * j->t->sig[f][c];
                float bs = dens[f] * j->t->sca[f][c];
                if (bs > 0.0f) {
                    float a = ams_lookup(j->t, f, c, j->pa[p * nf + f], j->pw[p * nf + f], m);
                    src += bs * (a + j->xi);
                }
            }
            if (bext <= 0.0f) continue;
            float tau = bext * delta;
            float Tslab = expf(-tau);
            /* beta_sca Delta of Eq. 26, integrated over the slab with its own
             * attenuation: (1 - T)/beta_ext (-> Delta when thin). */
            float len = tau < 1e-4f ? delta * (1.0f - 0.5f * tau) : (1.0f - Tslab) / bext;
            float contrib = I[c] * src * len;
            float *Lp = j->L_eye + c * npix + p, *Tp = j->T_eye + c * npix + p;
            if (j->btf) *Lp = *Lp * Tslab + contrib; /* back-to-front: over */
            else *Lp += *Tp * contrib;               /* front-to-back: under */
            *Tp *= Tslab;
        }
    }
    return count;
}

/* Light pass of slice k over light-buffer row b (Eq. 21, 25 / 24). */
static long long light_row(const sjob *j, int k, int b)
{
    const int n = j->n, nf = j->nf, L = j->L;
    const size_t LL = (size_t)L * L;
    const double sk = j->s0 + (k + 0.5) * j->ds;
    const float delta = (float)(j->ds / j->hl); /* light-ray length of the slab */
    float dens[ATMOS_VOLUME_MAX_FIELDS];
    long long count = 0;
    const double v = j->v0 + (b + 0.5) * j->dv;
    for (int a = 0; a < L; a++) {
        size_t q = (size_t)b * L + a;
        for (int c = 0; c < n; c++) j->I_next[c * LL + q] = j->I[c * LL + q];
        j->nsc_next[q] = j->nsc[q];
        if (k < j->lk0[q] || k > j->lk1[q]) continue;
        const double u = j->u0 + (a + 0.5) * j->du;
        double w = (sk - u * dot3(j->h, j->e1) - v * dot3(j->h, j->e2)) / j->hl;
        float px = (float)(u * j->e1[0] + v * j->e2[0] + w * j->lt[0]);
        float py = (float)(u * j->e1[1] + v * j->e2[1] + w * j->lt[1]);
        float pz = (float)(u * j->e1[2] + v * j->e2[2] + w * j->lt[2]);
        if (!sgrid_sample(j->g, px, py, pz, dens)) continue;
        count++;
        const float n0 = j->nsc[q];
        float dn = 0;
        for (int c = 0; c < n; c++) {
            float bext = 0, bsca = 0;
            for (int f = 0; f < nf; f++) {
                bext += dens[f] * j->t->sig[f][c];
                bsca += dens[f] * j->t->sca[f][c];
            }
            dn += bsca * delta;
            if (bext <= 0.0f) continue;
            float tau = bext * delta, T = expf(-tau);
            float keep; /* fraction of the scattered light (1 - T) still going forward */
            if (j->low_albedo) {
                keep = 0.0f;
            } else {
                /* The number of scatterings in the slab, ceil(beta Delta) in Eq. 24, taken
                 * continuously as max(1, beta Delta); Eq. 25 raises its worst-case factor to
                 * the same power (see docs/slice.md). */
                float msl = tau > 1.0f ? tau : 1.0f;
                if (bsca <= 0.0f) {
                    keep = 0.0f;
                } else if (!j->eq24) {
                    /* Eq. 25: (alpha F_{floor(n + 1 + beta Delta)})^{beta Delta}. */
                    float idx = floorf(n0 + 1.0f + tau);
                    float aF = 0;
                    for (int f = 0; f < nf; f++)
                        if (dens[f] > 0.0f)
                            aF += dens[f] * j->t->sca[f][c] *
                                  order_lerp(j->t->F[f] + (size_t)c * (SLICE_F_ORDERS + 1), idx, 0);
                    aF /= bext;
                    keep = aF > 0.0f ? expf(msl * logf(aF)) : 0.0f;
                } else {
                    /* Eq. 24: prod_{i=n+1}^{n+m} alpha F_i = alpha^m exp(S(n+m) - S(n)); fields
                     * mixed geometrically by their share of beta_sca. */
                    float lnk = msl * logf(bsca / bext);
                    for (int f = 0; f < nf; f++) {
                        float bs = dens[f] * j->t->sca[f][c];
                        if (bs <= 0.0f) continue;
                        const float *S = j->t->S[f] + (size_t)c * (SLICE_F_ORDERS + 1);
                        lnk += bs / bsca * (order_lerp(S, n0 + msl, 1) - order_lerp(S, n0, 1));
                    }
                    keep = expf(lnk);
                }
            }
            j->I_next[c * LL + q] = j->I[c * LL + q] * (T + (1.0f - T) * keep);
        }
        /* Eq. 21: n grows by alpha beta_ext Delta = beta_sca Delta (mean over wavelengths). */
        j->nsc_next[q] = n0 + dn / (float)n;
    }
    return count;
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
    if (in->grid_max_dim) s->grid_max_dim = in->grid_max_dim;
    if (in->max_order) s->max_order = in->max_order;
    if (in->density_scale != 0) s->density_scale = in->density_scale;
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
    const double t_start = now_seconds();
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

    atmos_slice_optics own_optics;
    memset(&own_optics, 0, sizeof own_optics);
    const atmos_slice_optics *optics = s.optics;
    if (!optics) {
        if ((st = atmos_slice_optics_build(ctx, scene, volume, &own_optics)) != ATMOS_OK) return st;
        optics = &own_optics;
    }
    if (optics->count != volume->nfields) {
        atmos_slice_optics_free(&own_optics);
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render slice: optics for %d fields, the volume has %d",
                            optics->count, volume->nfields);
    }

    /* The sky behind everything: exactly atmos_render_sky's image (sun disk included). */
    atmos_image *img = NULL;
    const double t_sky0 = now_seconds();
    if ((st = atmos_render_sky(ctx, scene, &img, NULL)) != ATMOS_OK) {
        atmos_slice_optics_free(&own_optics);
        return st;
    }
    double t_sky = now_seconds() - t_sky0;
    const double t_prep0 = now_seconds();

    sgrid g;
    stables tab;
    memset(&tab, 0, sizeof tab);
    sjob j;
    memset(&j, 0, sizeof j);
    atmos_sky *sky = NULL;
    long long eye_samples = 0, light_samples = 0;
    double t_light = 0, t_eye = 0;
    if ((st = sgrid_build(ctx, volume, s.density_scale, s.grid_max_dim, &g)) != ATMOS_OK) goto done;
    if (!g.v) goto finish; /* empty volume: the sky alone */
    if ((st = stables_build(ctx, optics, wl.count, s.max_order, &tab)) != ATMOS_OK) goto done;
    if ((st = atmos_sky_create(ctx, &scene->atmosphere, &wl, &sky)) != ATMOS_OK) goto done;

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
    j.btf = dot3(view_g, j.lt) < 0;
    for (int a = 0; a < 3; a++) j.h[a] = (j.btf ? -view_g[a] : view_g[a]) + j.lt[a];
    if (dot3(j.h, j.h) < 1e-20) memcpy(j.h, j.lt, sizeof j.h);
    normalize3(j.h);
    j.hl = dot3(j.h, j.lt);
    if (j.hl < 1e-6) j.hl = 1e-6;
    {
        double ax[3] = {1, 0, 0};
        if (fabs(j.lt[0]) > 0.9) ax[0] = 0, ax[1] = 1;
        cross3(ax, j.lt, j.e1);
        normalize3(j.e1);
        cross3(j.lt, j.e1, j.e2);
    }
    /* Extents of the box along h (slices) and across the light (light buffer). */
    double smin = INFINITY, smax = -INFINITY, umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? g.box_hi[0] : g.box_lo[0], c & 2 ? g.box_hi[1] : g.box_lo[1],
                       c & 4 ? g.box_hi[2] : g.box_lo[2]};
        double sv = dot3(p, j.h), uv = dot3(p, j.e1), vv = dot3(p, j.e2);
        smin = fmin(smin, sv), smax = fmax(smax, sv);
        umin = fmin(umin, uv), umax = fmax(umax, uv);
        vmin = fmin(vmin, vv), vmax = fmax(vmax, vv);
    }
    j.n = wl.count;
    j.nf = volume->nfields;
    j.W = cam.width, j.H = cam.height, j.L = s.light_size;
    j.nslices = s.slices;
    j.s0 = smin;
    j.ds = (smax - smin) / s.slices;
    j.he = dot3(j.h, j.eye);
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
    j.pdx = malloc(sizeof(float) * npix * 4);
    j.pk0 = malloc(sizeof(int) * npix * 2);
    j.pa = malloc(sizeof(int) * npix * j.nf);
    j.pw = malloc(sizeof(float) * npix * j.nf);
    j.L_eye = calloc(npix * j.n, sizeof(float));
    j.T_eye = malloc(sizeof(float) * npix * j.n);
    j.lk0 = malloc(sizeof(int) * LL * 2);
    j.I = malloc(sizeof(float) * LL * j.n);
    j.nsc = calloc(LL, sizeof(float));
    j.I_next = malloc(sizeof(float) * LL * j.n);
    j.nsc_next = calloc(LL, sizeof(float));
    if (!j.pdx || !j.pk0 || !j.pa || !j.pw || !j.L_eye || !j.T_eye || !j.lk0 || !j.I || !j.nsc || !j.I_next ||
        !j.nsc_next) {
        st = atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the buffers");
        goto done;
    }
    j.pdy = j.pdx + npix, j.pdz = j.pdx + 2 * npix, j.pinv = j.pdx + 3 * npix;
    j.pk1 = j.pk0 + npix;
    j.lk1 = j.lk0 + LL;
    for (size_t i = 0; i < npix * j.n; i++) j.T_eye[i] = 1.0f;
    const int threads = atmos__threads(ctx);

    /* Per pixel: ray, slices it crosses inside the box (in front of the eye and of
     * the ground), and the Ams angle (scattering angle between the sun's light and
     * the direction to the eye: cos theta = d . sun). */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < j.H; y++)
        for (int x = 0; x < j.W; x++) {
            size_t p = (size_t)y * j.W + x;
            double dw[3], d[3];
            atmos_camera_ray(&cam, x + 0.5, y + 0.5, dw);
            TO_GRID(dw, d);
            j.pdx[p] = (float)d[0], j.pdy[p] = (float)d[1], j.pdz[p] = (float)d[2];
            double hd = dot3(j.h, d);
            j.pk0[p] = 1, j.pk1[p] = 0;
            j.pinv[p] = 0;
            double ta, tb;
            int ok = j.btf ? hd <= -SLICE_HD_EPS : hd >= SLICE_HD_EPS;
            if (ok && ray_box(j.eye, d, g.box_lo, g.box_hi, &ta, &tb)) {
                if (ta < 0) ta = 0;
                double tg = atmos_sky_ground_distance(cam.position[1], dw);
                if (tb > tg) tb = tg;
                if (ta < tb) {
                    double sa = j.he + ta * hd, sb = j.he + tb * hd;
                    if (sa > sb) {
                        double q = sa;
                        sa = sb, sb = q;
                    }
                    slice_range(sa, sb, j.s0, j.ds, j.nslices, &j.pk0[p], &j.pk1[p]);
                    j.pinv[p] = (float)(1.0 / hd);
                }
            }
            double c = dot3(dw, sun_w);
            double th = acos(c > 1 ? 1 : (c < -1 ? -1 : c)) * ATMOS_RAD2DEG;
            for (int f = 0; f < j.nf; f++) angle_locate(tab.grid[f], tab.ng[f], th, &j.pa[p * j.nf + f], &j.pw[p * j.nf + f]);
        }
    /* Per light texel: slices its ray crosses inside the box, and the sunlight arriving
     * there through the air (Eq. 12, at the altitude where the ray enters the box). */
    {
        double cen[3] = {0.5 * (g.box_lo[0] + g.box_hi[0]), 0.5 * (g.box_lo[1] + g.box_hi[1]),
                         0.5 * (g.box_lo[2] + g.box_hi[2])};
        const double *Rm = R;
#pragma omp parallel for schedule(static) num_threads(threads)
        for (int b = 0; b < j.L; b++)
            for (int a = 0; a < j.L; a++) {
                size_t q = (size_t)b * j.L + a;
                double u = j.u0 + (a + 0.5) * j.du, v = j.v0 + (b + 0.5) * j.dv;
                double o[3] = {u * j.e1[0] + v * j.e2[0], u * j.e1[1] + v * j.e2[1], u * j.e1[2] + v * j.e2[2]};
                double ta, tb, entry[3];
                memcpy(entry, cen, sizeof entry);
                j.lk0[q] = 1, j.lk1[q] = 0;
                if (ray_box(o, j.lt, g.box_lo, g.box_hi, &ta, &tb)) {
                    double ho = dot3(j.h, o);
                    slice_range(ho + ta * j.hl, ho + tb * j.hl, j.s0, j.ds, j.nslices, &j.lk0[q], &j.lk1[q]);
                    for (int i = 0; i < 3; i++) entry[i] = o[i] + ta * j.lt[i];
                }
                double yw = org[1] + Rm[3] * entry[0] + Rm[4] * entry[1] + Rm[5] * entry[2];
                double sl[ATMOS_MAX_WAVELENGTHS];
                atmos_sky_sunlight(sky, yw > 0 ? yw : 0, sun_w, sl);
                for (int c = 0; c < j.n; c++) j.I[c * LL + q] = (float)sl[c];
            }
    }
    const double t_prep = now_seconds() - t_prep0;

    /* The slices. The eye pass reads the light arriving at slice k while the light
     * pass writes the light leaving it into the other buffer, so both run in one
     * parallel loop (one barrier per slice). Rows are interleaved in chunks of 4 with
     * a static schedule; per-thread CPU time in each pass gives the breakdown. */
    int cancelled = 0;
    double cpu_eye = 0, cpu_light = 0, t_slices = 0;
    const int rows = j.H + j.L;
    for (int k = 0; k < j.nslices && !cancelled; k++) {
        long long ce = 0, cl = 0;
        double ta = now_seconds(), de = 0, dl = 0;
#pragma omp parallel for schedule(static, 4) num_threads(threads) reduction(+ : ce, cl, de, dl)
        for (int r = 0; r < rows; r++) {
            double t0 = now_seconds();
            if (r < j.H) {
                ce += eye_row(&j, k, r);
                de += now_seconds() - t0;
            } else {
                cl += light_row(&j, k, r - j.H);
                dl += now_seconds() - t0;
            }
        }
        t_slices += now_seconds() - ta;
        cpu_eye += de, cpu_light += dl;
        eye_samples += ce, light_samples += cl;
        float *sw = j.I;
        j.I = j.I_next, j.I_next = sw;
        sw = j.nsc;
        j.nsc = j.nsc_next, j.nsc_next = sw;
        if (atmos__progress(ctx, "render slice", (double)(k + 1) / j.nslices)) cancelled = 1;
    }
    if (cpu_eye + cpu_light > 0) {
        t_eye = t_slices * cpu_eye / (cpu_eye + cpu_light);
        t_light = t_slices - t_eye;
    }
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
        const double t_c0 = now_seconds();
        double cen[3] = {0.5 * (g.box_lo[0] + g.box_hi[0]), 0.5 * (g.box_lo[1] + g.box_hi[1]),
                         0.5 * (g.box_lo[2] + g.box_hi[2])};
        const double hc = dot3(j.h, cen);
        const int C = img->channels;
#pragma omp parallel for schedule(static) num_threads(threads)
        for (int y = 0; y < j.H; y++)
            for (int x = 0; x < j.W; x++) {
                size_t p = (size_t)y * j.W + x;
                int touched = 0;
                for (int c = 0; c < j.n; c++)
                    touched |= j.L_eye[c * npix + p] != 0.0f || j.T_eye[c * npix + p] != 1.0f;
                if (!touched) continue;
                double dw[3];
                atmos_camera_ray(&cam, x + 0.5, y + 0.5, dw);
                double th = j.pinv[p] != 0.0f ? (hc - j.he) * j.pinv[p] : 0.0;
                if (!(th > 0)) th = 0;
                double tg = atmos_sky_ground_distance(cam.position[1], dw);
                if (th > tg) th = tg;
                double front[ATMOS_MAX_WAVELENGTHS], Tf[ATMOS_MAX_WAVELENGTHS];
                atmos_sky_inscatter(sky, cam.position, dw, th, sun_w, front);
                atmos_sky_transmittance(sky, cam.position[1], dw, th, Tf);
                float *px = img->pixels + p * C;
                for (int c = 0; c < j.n; c++) {
                    double B = px[c], Lv = j.L_eye[c * npix + p], Tv = j.T_eye[c * npix + p];
                    double r = front[c] + Tf[c] * Lv + Tv * (B - front[c]);
                    px[c] = (float)(isfinite(r) && r > 0 ? r : 0.0);
                }
            }
        t_sky += now_seconds() - t_c0;
    }
    if (s.timing) {
        s.timing->prepare = t_prep;
        s.timing->light = t_light;
        s.timing->eye = t_eye;
    }

finish:
    {
        char buf[256];
        atmos_image_set_meta(img, "atmos:renderer", "slice (Riley et al. 2004, half-angle slicing)");
        snprintf(buf, sizeof buf, "%d slices, light buffer %d, xi %g, %s%s", s.slices, s.light_size, s.xi,
                 s.update == ATMOS_SLICE_EQ24 ? "eq24" : "eq25", s.low_albedo ? ", low albedo" : "");
        atmos_image_set_meta(img, "atmos:slice", buf);
        double secs = now_seconds() - t_start;
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
            if (!g.v) s.timing->prepare = s.timing->light = s.timing->eye = 0;
        }
    }
    st = ATMOS_OK;
done:
#undef TO_GRID
    free(j.pdx), free(j.pk0), free(j.pa), free(j.pw), free(j.L_eye), free(j.T_eye), free(j.lk0), free(j.I), free(j.nsc);
    free(j.I_next), free(j.nsc_next);
    atmos_sky_destroy(sky);
    stables_free(&tab);
    sgrid_free(&g);
    atmos_slice_optics_free(&own_optics);
    if (st != ATMOS_OK) {
        atmos_image_destroy(img);
        return st;
    }
    *out = img;
    return ATMOS_OK;
}
