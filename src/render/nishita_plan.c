/* The Nishita renderer's plan (nishita_internal.h): the render grid and the optics once, the
 * sunlight's attenuation per render voxel once per sun direction, the light field of orders 2
 * and 3 and of the sky once per sun and eye direction (Nishita et al. 1996 §3.4 step 2:
 * "the attenuation ratio for the sunlight at each voxel is stored"). */
#include "atmosphere/atmosphere_ops.h"
#include "core/clones.h"
#include "core/vec.h"
#include "render/nishita_internal.h"

#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#define GRID_CAP 256 /* render voxels per axis at most */
#define COL_PAR_MIN 65536 /* a columns' sweep of fewer values (all its planes): one thread */

void atmos__nishita_plan_destroy(atmos__nishita_plan *s)
{
    if (!s) return;
    if (!s->g_borrowed) atmos__sgrid_free(&s->g);
    free(s->col), free(s->fdens), free(s->edge);
    atmos__lmedium_free(&s->med);
    atmos__lfield_free(&s->field);
    atmos__dfield_free(&s->df);
    atmos__stables_free(&s->tab);
    atmos__nishita_mc_free(s->mc);
    free(s);
}

/* The mean density of each field over the s^3 render voxels of every cell, and the cells'
 * extinction and scattering per wavelength. */
static void cell_medium(atmos__nishita_plan *np)
{
    const sgrid *g = &np->g;
    atmos__lmedium *m = &np->med;
    const int nf = np->nf, n = np->n, s = np->s;
    for (size_t cell = 0; cell < atmos__lmedium_cells(m); cell++) {
        const int I = (int)(cell % (size_t)m->c[0]), J = (int)(cell / (size_t)m->c[0] % (size_t)m->c[1]),
                  K = (int)(cell / ((size_t)m->c[0] * m->c[1]));
        double sum[ATMOS_VOLUME_MAX_FIELDS] = {0};
        int cnt = 0;
        for (int k = K * s; k < (K + 1) * s && k < g->c[2]; k++)
            for (int j = J * s; j < (J + 1) * s && j < g->c[1]; j++)
                for (int i = I * s; i < (I + 1) * s && i < g->c[0]; i++, cnt++)
                    for (int f = 0; f < nf; f++) sum[f] += g->v[(((size_t)k * g->c[1] + j) * g->c[0] + i) * nf + f];
        float *d = np->fdens + cell * nf;
        for (int f = 0; f < nf; f++) d[f] = cnt ? (float)(sum[f] / cnt) : 0.0f;
        for (int w = 0; w < n; w++) {
            double st = 0, ss = 0;
            for (int f = 0; f < nf; f++) st += d[f] * np->sig[f][w], ss += d[f] * np->sca[f][w];
            m->sig_t[cell * n + w] = (float)st, m->sig_s[cell * n + w] = (float)ss;
        }
    }
}

/* What every use of the plan shares: its settings, the optics, the render grid (at most cap
 * voxels per axis, or grid borrowed when not NULL) and the storage of the sunlight's columns.
 * *out is set whenever it was allocated (the caller destroys it on an error). */
static atmos_status plan_base(atmos_plan *p, const atmos_scene_nishita *opt, int cap, const sgrid *grid,
                              atmos__nishita_plan **out)
{
    atmos_context *ctx = p->ctx;
    atmos__nishita_plan *np = calloc(1, sizeof *np);
    *out = np;
    if (!np) return atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory");
    np->opt = *opt;
    np->nf = atmos_volume_field_count(p->volume), np->n = p->wl.count;
    atmos__vol_xform_init(p->volume, p->offset, &np->x);
    for (int f = 0; f < np->nf; f++) {
        np->phase[f] = p->optics->phase[f];
        for (int w = 0; w < np->n; w++) {
            double se, ss;
            atmos_phase_table_cross_sections(np->phase[f], w, &se, &ss);
            np->sig[f][w] = (float)se, np->sca[f][w] = (float)ss;
        }
    }
    atmos_status st = ATMOS_OK;
    if (grid)
        np->g = *grid, np->g_borrowed = 1;
    else
        st = atmos__sgrid_build(ctx, p->volume, p->scene.volume.density_scale, cap, &np->g);
    if (st == ATMOS_OK && np->g.v &&
        !(np->col = malloc(sizeof(float) * (size_t)np->g.c[0] * np->g.c[1] * np->g.c[2] * np->nf)))
        st = atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the sunlight");
    return st;
}

atmos_status atmos__nishita_do_plan_create(atmos_plan *p, const sgrid *grid, atmos__nishita_plan **out)
{
    atmos_scene_nishita o = p->scene.nishita;
    /* sky 1: the sky's and the ground's light enter the field's solve (no sky elements here) */
    o.orders = 1, o.sky = 1, o.diffuse = 0, o.mc_kphotons = 0, o.mc_lmax = 3, o.mc_delta_m = 1, o.do_field = 1;
    o.mc_dm_clip = 0;
    atmos__nishita_plan *np;
    atmos_status st = plan_base(p, &o, 0, grid, &np);
    if (st == ATMOS_OK && np->g.v) st = atmos__nishita_mc_create(p, np);
    if (st != ATMOS_OK) {
        atmos__nishita_plan_destroy(np);
        return st;
    }
    *out = np;
    return ATMOS_OK;
}

/* The settings a field of every order leaves without a use (the discrete-ordinates field, do, or
 * photons, mc_kphotons: nishita_render.c then draws neither the orders 2-3 by reference patterns
 * nor the diffuse field), warned of when they differ from their defaults (the scene cannot tell a
 * default given from one left out). */
static void warn_unused(atmos_context *ctx, const atmos_scene_nishita *sn)
{
    atmos_scene d;
    atmos_scene_defaults(&d);
    const atmos_scene_nishita *dn = &d.nishita;
    const char *field = sn->do_field ? "do (the discrete-ordinates field gives every order >= 2; "
                                       "\"do\": false for the paper's method)"
                                     : "mc_kphotons (the photons' field gives every order >= 2)";
    if (!sn->do_field && sn->mc_kphotons <= 0) return;
    if (sn->do_field && sn->mc_kphotons > 0)
        atmos__log(ctx, ATMOS_LOG_WARN, "nishita: mc_kphotons does nothing with do (the discrete-ordinates field "
                                        "takes the photons' place; \"do\": false to trace them)");
    if (sn->orders != dn->orders || sn->ratio != dn->ratio || sn->paths != dn->paths)
        atmos__log(ctx, ATMOS_LOG_WARN, "nishita: orders, ratio and paths (the orders 2-3 by reference patterns) "
                                        "do nothing with %s", field);
    if (sn->diffuse) atmos__log(ctx, ATMOS_LOG_WARN, "nishita: diffuse does nothing with %s", field);
}

atmos_status atmos__nishita_plan_create(atmos_plan *p, atmos__nishita_plan **out)
{
    atmos_context *ctx = p->ctx;
    atmos__nishita_plan *np;
    atmos_status st = plan_base(p, &p->scene.nishita, GRID_CAP, NULL, &np);
    if (!np) return st;
    if (st == ATMOS_OK && np->g.v) {
        const sgrid *g = &np->g;
        int big = g->c[0] > g->c[1] ? g->c[0] : g->c[1];
        big = big > g->c[2] ? big : g->c[2];
        const int cap = p->scene.nishita.cells > 0 ? p->scene.nishita.cells : 32;
        np->s = (big + cap - 1) / cap;
        const int cx = (g->c[0] + np->s - 1) / np->s, cy = (g->c[1] + np->s - 1) / np->s,
                  cz = (g->c[2] + np->s - 1) / np->s;
        np->fdens = malloc(sizeof(float) * (size_t)cx * cy * cz * np->nf);
        if (!np->fdens || !atmos__lmedium_alloc(&np->med, cx, cy, cz, np->n, np->s / (double)g->sc))
            st = atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the light field");
        else
            cell_medium(np), atmos__nishita_truncate(np);
    }
    /* the diffuse field is drawn only without a field of every order (nishita_render.c) */
    np->diffuse = p->scene.nishita.diffuse && !p->scene.nishita.do_field && p->scene.nishita.mc_kphotons <= 0;
    if (st == ATMOS_OK && np->g.v && np->diffuse) {
        /* Ams_2 for the scattered beam (nishita_render.c); F_n and B_n for the field's source */
        st = atmos__stables_build(ctx, p->optics, np->n, 2, &np->tab);
        if (st == ATMOS_OK) st = atmos__dfield_prepare(ctx, &np->df, &np->g, &np->tab, &np->x, p->optics, "render nishita");
    }
    const atmos_scene_nishita *sn = &p->scene.nishita;
    if (st == ATMOS_OK && np->g.v && (sn->mc_kphotons > 0 || sn->do_field)) st = atmos__nishita_mc_create(p, np);
    /* (on by default for the do field: without any field, as the paper's method, it is not used) */
    if (sn->mc_delta_m && sn->mc_kphotons > 0 && sn->mc_lmax < 0 && !sn->do_field)
        atmos__log(ctx, ATMOS_LOG_WARN, "nishita: mc_delta_m does nothing with a Monte Carlo field toward the view "
                                        "alone (mc_lmax -1): it needs spherical harmonics (mc_lmax >= 0)");
    if (sn->mc_dm_clip && !sn->mc_delta_m)
        atmos__log(ctx, ATMOS_LOG_WARN, "nishita: mc_dm_clip does nothing without mc_delta_m (it clips the photons' "
                                        "delta-M scaled phase)");
    else if (sn->mc_dm_clip && sn->do_field)
        atmos__log(ctx, ATMOS_LOG_WARN, "nishita: mc_dm_clip does nothing with do (discrete ordinates trace no "
                                        "photons)");
    warn_unused(ctx, sn);
    if (st != ATMOS_OK) {
        atmos__nishita_plan_destroy(np);
        return st;
    }
    *out = np;
    return ATMOS_OK;
}

/* One axis's bilinear taps at the points m + off, m = 0 .. n - 1, each clamped to the axis: the
 * offsets (stride floats a point) of the lower and upper point and the upper's weight, as a
 * per-point bilinear read finds them (the same bits: m + off rounded as a double before the
 * fraction is taken). */
static void axis_taps(int n, double off, size_t stride, size_t *lo, size_t *hi, double *u)
{
    for (int m = 0; m < n; m++) {
        double x = m + off;
        x = x < 0 ? 0 : x > n - 1 ? n - 1 : x;
        int i = (int)x;
        if (i > n - 2) i = n - 2 < 0 ? 0 : n - 2;
        lo[m] = (size_t)i * stride, hi[m] = (size_t)(i + 1 < n ? i + 1 : i) * stride, u[m] = x - i;
    }
}

/* Row n's points of plane_lerp (its taps lb, hb, ub along the row, the row's r0, r1 and v),
 * nf a constant where inlined. */
ATMOS_CLONE_HELPER void lerp_row(const float *r0, const float *r1, double v, int nb,
                                 int nf, const size_t *lb, const size_t *hb,
                                 const double *ub, float *o, size_t ob)
{
    for (int m = 0; m < nb; m++, o += ob) {
        const double u = ub[m], w00 = (1 - u) * (1 - v), w10 = u * (1 - v), w01 = (1 - u) * v, w11 = u * v;
        const float *p00 = r0 + lb[m], *p10 = r0 + hb[m], *p01 = r1 + lb[m], *p11 = r1 + hb[m];
        for (int f = 0; f < nf; f++) o[f] = (float)(w00 * p00[f] + w10 * p10[f] + w01 * p01[f] + w11 * p11[f]);
    }
}

#define LERP_BLOCK 64 /* lerp_rows' points a block */

/* Rows n0 .. n1 - 1 of plane_lerp (the taps lc, hc, uc across the rows). One field's rows in
 * blocks: the four taps gathered, then the weights and the sums in one vector loop (lerp_row's
 * operations in its order: the same bits), then stored; built for AVX2 as well as the baseline. */
ATMOS_CLONES static void lerp_rows(const float *a, int n0, int n1, int nb, int nf, const size_t *lb, const size_t *hb,
                                   const double *ub, const size_t *lc, const size_t *hc, const double *uc, float *out,
                                   const size_t on[2])
{
    for (int n = n0; n < n1; n++) {
        const float *r0 = a + lc[n], *r1 = a + hc[n];
        float *o = out + n * on[1];
        if (nf > 1) {
            lerp_row(r0, r1, uc[n], nb, nf, lb, hb, ub, o, on[0]);
            continue;
        }
        const double v = uc[n];
        for (int m0 = 0; m0 < nb; m0 += LERP_BLOCK) {
            const int mm = nb - m0 < LERP_BLOCK ? nb - m0 : LERP_BLOCK;
            float p00[LERP_BLOCK], p10[LERP_BLOCK], p01[LERP_BLOCK], p11[LERP_BLOCK], r[LERP_BLOCK];
            for (int i = 0; i < mm; i++)
                p00[i] = r0[lb[m0 + i]], p10[i] = r0[hb[m0 + i]], p01[i] = r1[lb[m0 + i]], p11[i] = r1[hb[m0 + i]];
            for (int i = 0; i < mm; i++) {
                const double u = ub[m0 + i], w00 = (1 - u) * (1 - v), w10 = u * (1 - v), w01 = (1 - u) * v, w11 = u * v;
                r[i] = (float)(w00 * p00[i] + w10 * p10[i] + w01 * p01[i] + w11 * p11[i]);
            }
            for (int i = 0; i < mm; i++) o[(size_t)(m0 + i) * on[0]] = r[i];
        }
    }
}

/* The bilinear interpolant of nf fields on a plane of nb x nc points, a's point (m, n) at
 * a + m in[0] + n in[1] (its fields contiguous), at the lattice points (m + ob, n + oc) of the
 * rows n0 <= n < n1, written to out + m on[0] + n on[1]. tap: 3 (nb + nc) slots of scratch. */
static void plane_lerp(const float *a, const size_t in[2], int nb, int nc, int nf, double ob, double oc, float *out,
                       const size_t on[2], int n0, int n1, double *tap)
{
    double *ub = tap, *uc = ub + nb;
    size_t *lb = (size_t *)(uc + nc), *hb = lb + nb, *lc = hb + nb, *hc = lc + nc;
    axis_taps(nb, ob, in[0], lb, hb, ub);
    axis_taps(nc, oc, in[1], lc, hc, uc);
    lerp_rows(a, n0, n1, nb, nf, lb, hb, ub, lc, hc, uc, out, on);
}

/* A ray's first step's column, qc[e] for e in [from, to): the trapezoid from 0 at the grid's face. */
static inline void first_step(float *qc, const float *qd, size_t from, size_t to, double len)
{
    for (size_t e = from; e < to; e++) qc[e] = (float)(0.5 * len * qd[e]);
}

/* The columns' sweep (atmos__nishita_columns): the planes across axis a, na of nb x nc points,
 * from the sun's side (step), db, dc the sun's slope, len the metres a plane; the grid's and the
 * rays' strides. */
typedef struct {
    const float *v;
    float *col;
    int nf, a, na, nb, nc, step;
    double db, dc, len;
    size_t str[3], sv[2], sq[2], pl;
} col_sweep;

static inline int clampi(long x, int lo, int hi) { return x < lo ? lo : x > hi ? hi : (int)x; }

/* The rays of the lattice lines r0 <= r < r1 through every plane, and the voxels' columns of
 * the rows they own (buf: 4 pl floats, tap: plane_lerp's scratch, both this caller's own). A ray
 * moves by whole rows between planes (plane k's row n continues the last plane's row n - sc),
 * so lattice line r is row r + C(k) of plane k, C(k) = floor(-k dc), and its column depends on
 * its own points alone: the lines of one call are swept without the others'. A voxel's column
 * reads the rays of its row and the rows either side, so the rays of one line more each side are
 * swept too (again, by the neighbour's call), and the voxels' rows are those of [r0, r1); r0, r1
 * beyond the lattice (INT_MIN, INT_MAX) take every line entering on that side. */
static void sweep_lines(const col_sweep *S, long r0, long r1, float *buf, double *tap)
{
    const int nf = S->nf, nb = S->nb, nc = S->nc;
    float *rc = buf, *rd = rc + S->pl, *qc = rd + S->pl, *qd = qc + S->pl;
    /* plane k's rays at lattice point (m, n) lie at (m + fb, n + fc): fb, fc the fractions of the
       offsets -k db, -k dc (the rays move away from the sun, the last plane's points at +db, +dc) */
    double ob = 0, oc = 0;
    for (int k = 0; k < S->na; k++) {
        const int ia = S->step > 0 ? k : S->na - 1 - k;
        const double nb_ = -k * S->db, nc_ = -k * S->dc;
        const int sb = (int)(floor(nb_) - floor(ob)), sc = (int)(floor(nc_) - floor(oc)), C = (int)floor(nc_);
        const double fb = nb_ - floor(nb_), fc = nc_ - floor(nc_);
        ob = nb_, oc = nc_;
        /* the rays' rows [n0, n1) and the voxels' [v0, v1) */
        const int v0 = clampi(r0 + C, 0, nc), v1 = clampi(r1 + C, 0, nc);
        const int n0 = v0 > 0 ? v0 - 1 : 0, n1 = v1 < nc ? v1 + 1 : nc;
        plane_lerp(S->v + ia * S->str[S->a], S->sv, nb, nc, nf, fb, fc, qd, S->sq, n0, n1, tap);
        for (int n = n0; n < n1; n++) {
            /* the row's rays whose last point (m - sb, n - sc) was on the plane: m in [m0, m1) */
            const int pn = n - sc, row = k > 0 && pn >= 0 && pn < nc;
            int m0 = sb > 0 ? sb : 0, m1 = sb < 0 ? nb + sb : nb;
            m0 = !row || m0 > nb ? nb : m0, m1 = m1 < m0 ? m0 : m1;
            const size_t e0 = (size_t)n * nb * nf, e1 = e0 + (size_t)m0 * nf, e2 = e0 + (size_t)m1 * nf;
            const ptrdiff_t pe = -((ptrdiff_t)sc * nb + sb) * nf; /* the last point's offset */
            first_step(qc, qd, e0, e1, S->len);
            for (size_t e = e1; e < e2; e++) qc[e] = rc[e + pe] + (float)(0.5 * S->len * (qd[e] + rd[e + pe]));
            first_step(qc, qd, e2, e0 + (size_t)nb * nf, S->len);
        }
        plane_lerp(qc, S->sq, nb, nc, nf, -fb, -fc, S->col + ia * S->str[S->a], S->sv, v0, v1, tap);
        float *t = rc;
        rc = qc, qc = t;
        t = rd, rd = qd, qd = t;
    }
}

/* The column density toward the sun at every render voxel, by rays along the sun: one ray per
 * point of a lattice of the plane's spacing, the planes across the axis nearest to the sun's
 * direction one after another from the sun's side. Between two planes each ray moves by the
 * sun's slope, so the lattice is the last one shifted by a whole number of points and a
 * fraction: a ray's column is its own (the trapezoid of the densities, bilinear at its points,
 * over the step), carried without interpolation, and a voxel's column is interpolated once
 * from the four rays about its centre. (Interpolating the last plane's columns at every plane
 * instead blurred them sideways, more with every plane: in a cloud textured at the voxel's scale
 * the sunlight through the thin gaps was lost, the field's source too shallow; docs/lightfield.md,
 * "The sun's columns".) The threads each sweep a band of the rays (sweep_lines). */
void atmos__nishita_columns(atmos__nishita_plan *np, const double sun_g[3], int threads)
{
    if (np->col_valid && !memcmp(np->col_sun, sun_g, sizeof np->col_sun)) return;
    const double t0 = atmos__now();
    const sgrid *g = &np->g;
    const int nf = np->nf;
    int a = 0;
    for (int q = 1; q < 3; q++)
        if (fabs(sun_g[q]) > fabs(sun_g[a])) a = q;
    const int b = (a + 1) % 3, c = (a + 2) % 3, nb = g->c[b], nc = g->c[c];
    col_sweep S = {g->v, np->col, nf, a, g->c[a], nb, nc, sun_g[a] > 0 ? -1 : 1, /* from the sun's side */
                   sun_g[b] / fabs(sun_g[a]), sun_g[c] / fabs(sun_g[a]),
                   1.0 / fabs(sun_g[a]) / g->sc, /* metres per plane along the sun */
                   {(size_t)nf, (size_t)g->c[0] * nf, (size_t)g->c[0] * g->c[1] * nf},
                   {0, 0}, {(size_t)nf, (size_t)nb * nf}, (size_t)nb * nc * nf};
    /* the grid's strides along the plane's axes */
    S.sv[0] = S.str[b], S.sv[1] = S.str[c];
    /* each thread its band of lattice lines through all the planes, with no meeting: a plane of
       the Disney cloud's grid (128 x 88 x 156) is 0.1-0.2 ms of work, and a parallel region a
       plane cost more CPU in the waiting thread's spinning than it saved (the same numbers either
       way); the bands split the middle plane's rows */
    int par = S.pl * S.na >= COL_PAR_MIN ? threads : 1;
    par = par > nc / 4 ? nc / 4 : par;
    par = par < 1 ? 1 : par; /* a band of 4 rows at least */
    /* plane_lerp's scratch, a thread's: its doubles, rounded up */
    const size_t ntap =
        ((sizeof(double) + 2 * sizeof(size_t)) * (size_t)(nb + nc) + sizeof(double) - 1) / sizeof(double);
    float *buf = malloc(sizeof(float) * S.pl * 4 * par);
    double *tap = malloc(sizeof(double) * ntap * par);
    if (!buf || !tap) {
        free(buf), free(tap);
        return;
    }
    const long mid = (long)floor(-(S.na / 2) * S.dc); /* the middle plane's C (sweep_lines) */
#pragma omp parallel num_threads(par)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const long r0 = t == 0 ? INT_MIN : (long)nc * t / nt - mid,
                   r1 = t == nt - 1 ? INT_MAX : (long)nc * (t + 1) / nt - mid;
        sweep_lines(&S, r0, r1, buf + S.pl * 4 * t, tap + ntap * t);
    }
    free(buf), free(tap);
    memcpy(np->col_sun, sun_g, sizeof np->col_sun);
    np->col_valid = 1;
    np->col_s = atmos__now() - t0;
}
