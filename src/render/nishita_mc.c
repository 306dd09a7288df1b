/* The Nishita renderer's Monte Carlo field of the orders >= 2 (a bench option, "nishita":
 * {"mc_kphotons": K}; docs/lightfield.md, "A Monte Carlo field"): photons from the sun traced
 * through the path tracer's medium with its forward peak cut at 3 degrees (path_medium.c,
 * path_phase.c: the free flights, the phase sampling and the mixture's phase function are the
 * path tracer's own), and at every collision after the first the collision estimate of what
 * scatters toward the eye, sigma_s' p(d_in . omega) L, summed per cell of s render voxels with
 * the trilinear read's weights and divided by the cells' sigma_s' weighted alike: the radiance
 * of orders >= 2 per unit (truncated) scattering coefficient. Either toward one direction,
 * omega = -(the camera's central view direction) ("mc_lmax" -1: the "perfect-angle" field that
 * the P1 field approximates), or as real spherical harmonics of degree <= lmax of the emission
 * (p_l Y_lm(d_in) per collision, the addition theorem), turned toward the eye per cell and frame;
 * with "mc_delta_m" the photons traced in the delta-M scaled medium of that degree (delta_m();
 * with "mc_dm_clip" sampling its phase exactly, the cut phase's peak clipped further), the eye
 * rays then taking the field and the first order in it (TMS).
 * The sums are fixed point, one random stream per photon: the same field for a seed whatever
 * the threads. The eye pass adds sigma_s' times its trilinear value to the first order, both in
 * the truncated medium (nishita_render.c). With "do" the same coefficients come from a
 * discrete-ordinates solve instead of photons (solve(), nishita_do.c). */
#include "core/vec.h"
#include "light/lfield_do.h"
#include "render/nishita_do.h"
#include "render/nishita_internal.h"
#include "render/path_trace.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define MC_TRUNC_DEG 3.0 /* as the bench's references (--truncate 3) and the orders 2-3 */
#define MC_MAX_DEPTH 100000
#define MC_SS_FLOOR 1e-3
#define MC_FIX 16777216.0 /* 2^24: the sums are integers of this many units per 1 (exact, in any order) */
#define MC_KMAX 16        /* coefficients per cell and wavelength at most: degree 3 */

struct atmos__nishita_mc {
    path_medium med;
    path_phase ph;
    int lmax, K;         /* -1: the phase toward one direction (K = 1); else degree lmax, K = (lmax + 1)^2 */
    /* Legendre moments 2 pi int p P_l dmu of the cut phase (l <= 4); with delta-M those of the
     * scaled phase p* (ph_dm's table), l <= lmax, normalised */
    double pl[PATH_F][ATMOS_MAX_WAVELENGTHS][5];
    int delta_m;         /* the photons in the delta-M scaled medium, their phase HG of g* (hg) */
    float dm_f[PATH_F][ATMOS_MAX_WAVELENGTHS]; /* with delta_m: its share f of sigma_s' */
    atmos_phase_mixture hg[PATH_F][ATMOS_MAX_WAVELENGTHS];
    int clip;            /* with delta_m: their phase the clipped scaled phase (ph_dm) instead */
    path_phase ph_dm;
    float *coef;         /* [(cell * n + w) * K + k]: the emission of orders >= 2 per unit sigma_s' */
    double *do_phi;      /* with "do": the radiance moments per wavelength of the last sun (nishita_do.c) */
    int do_phi_valid;    /* do_phi holds a solve's: the start of the next sun's with a warm field */
    double do_kappa[2 * ATMOS_MAX_WAVELENGTHS]; /* with do_phi: the warm start's ratio (atmos__do_problem)
                                                   and the sunlight it was measured at */
    atmos__do_ws *do_ws; /* with "do": the solver's buffers, kept between suns */
    atmos__do_cells *do_cells; /* with "do": the cells' medium, kept between suns */
    double do_dens[PATH_F];    /* with "do": each field's density summed over the grid (do_dens_done) */
    int do_dens_done;
    atmos__lfield field; /* L: its radiance toward the eye (cells of s render voxels) */
    /* per cell and wavelength the kernel-weighted sigma_s' (cell_ss()): the medium's alone, the
     * same for every sun, so made at the plan's first trace and kept (ss_done; NULL: no scattering) */
    double *ss;
    int ss_done;
    double sun[3], out[3], eye[3];
    int valid, view_valid;
    /* with lmax >= 0: per cell the harmonics toward the eye at vy_eye (view(); NULL: none yet, or
     * no memory), the same while the eye stays and only the sun moves */
    double *vy, vy_eye[3];
    int vy_valid;
    int warm; /* 1: the field solved from an earlier sun's (the viewer's frames); a frame that asks
                 for no warm start (a save: atmos render's image) solves it afresh */
};

void atmos__nishita_mc_free(atmos__nishita_mc *mc)
{
    if (!mc) return;
    atmos__path_medium_free(&mc->med);
    atmos__path_phase_free(&mc->ph);
    atmos__path_phase_free(&mc->ph_dm);
    atmos__lfield_free(&mc->field);
    free(mc->coef), free(mc->do_phi), free(mc->ss), free(mc->vy);
    atmos__do_ws_free(mc->do_ws);
    atmos__do_cells_free(mc->do_cells);
    free(mc);
}

/* The Legendre moments p_l = 2 pi int p(mu) P_l(mu) dmu, l <= 4, of every field's cut phase
 * function (the path tracer's tables, p_0 = 1 up to their rounding). */
static void legendre_moments(atmos__nishita_mc *mc, int nf, int n)
{
    for (int f = 0; f < nf; f++)
        for (int k = 0; k < n; k++) atmos__path_phase_moments(&mc->ph, f, k, 4, mc->pl[f][k]);
}

/* Delta-M (Wiscombe 1977) of degree L = lmax on top of the 3-degree cut: per field and
 * wavelength f = chi_{L+1} (the cut phase's normalised moment) counts as not scattered,
 * sigma_t* = sigma_t' - f sigma_s', sigma_s* = (1 - f) sigma_s' (so omega* = (1 - f) omega /
 * (1 - f omega)). The scaled phase p*:
 * - by default its moments chi*_l = (chi_l - f) / (1 - f), l <= L, replace the cut phase's in
 *   the projection, and the photons sample it as Henyey-Greenstein with g* = chi*_1 (its higher
 *   moments g*^l, not chi*_l);
 * - with clip, the photons sample the cut phase with its peak clipped further until the fraction
 *   f is gone (atmos__path_phase_clip: a truncation, Potter 1970, J. Atmos. Sci. 27, 617, at the
 *   angle where the removed fraction is delta-M's f, 24 degrees for HG 0.85 and L 3), a positive
 *   function, exactly. The projection keeps delta-M's chi*_l: the clipped table's own moments
 *   exceed them by the removed peak's int (1 - P_l) / (1 - f) (+0.02, +0.05, +0.10 for HG 0.85),
 *   and projecting with those was worse on the bench (docs/lightfield.md). */
static atmos_status delta_m(atmos_context *ctx, atmos__nishita_mc *mc, int nf, int n)
{
    float f[PATH_F][ATMOS_MAX_WAVELENGTHS] = {{0}};
    const int L = mc->lmax;
    for (int i = 0; i < nf; i++)
        for (int k = 0; k < n; k++) {
            double *pl = mc->pl[i][k];
            const double p0 = pl[0], c = pl[L + 1] / p0, fk = c > 0 && c < 1 ? c : 0;
            f[i][k] = (float)fk, mc->dm_f[i][k] = (float)fk;
            for (int l = 0; l <= L; l++) pl[l] = (pl[l] / p0 - fk) / (1 - fk);
            atmos_phase_mixture *h = &mc->hg[i][k];
            memset(h, 0, sizeof *h);
            h->count = 1, h->kind[0] = ATMOS_PHASE_HG, h->weight[0] = 1;
            h->g[0] = L >= 1 ? pl[1] : 0;
        }
    if (mc->clip) {
        atmos_status st = atmos__path_phase_clip(ctx, &mc->ph, (const float(*)[ATMOS_MAX_WAVELENGTHS])f, &mc->ph_dm);
        if (st != ATMOS_OK) return st;
    }
    atmos__path_medium_truncate(&mc->med, n, (const float(*)[ATMOS_MAX_WAVELENGTHS])f);
    return ATMOS_OK;
}

atmos_status atmos__nishita_mc_create(atmos_plan *p, atmos__nishita_plan *np)
{
    atmos_context *ctx = p->ctx;
    atmos__nishita_mc *mc = calloc(1, sizeof *mc);
    if (!mc) return atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory");
    np->mc = mc;
    const int n = np->n;
    atmos_status st = atmos__path_phase_build(ctx, p->optics, n, MC_TRUNC_DEG, &mc->ph);
    if (st == ATMOS_OK)
        st = atmos__path_medium_build(ctx, p->volume, p->scene.volume.density_scale, p->offset, p->optics, n, &mc->med);
    if (st != ATMOS_OK) return st;
    atmos__path_medium_truncate(&mc->med, n, (const float(*)[ATMOS_MAX_WAVELENGTHS])mc->ph.trunc);
    mc->lmax = np->opt.mc_lmax < 0 && np->opt.do_field ? 3 : np->opt.mc_lmax;
    mc->K = mc->lmax < 0 ? 1 : (mc->lmax + 1) * (mc->lmax + 1);
    legendre_moments(mc, np->nf, n);
    for (int f = 0; f < np->nf; f++)
        for (int w = 0; w < n; w++) np->mc_sig[f][w] = mc->med.sig[f][w];
    mc->delta_m = np->opt.mc_delta_m && mc->lmax >= 0;
    mc->clip = mc->delta_m && np->opt.mc_dm_clip && !np->opt.do_field; /* do traces no photons */
    if (mc->delta_m && (st = delta_m(ctx, mc, np->nf, n)) != ATMOS_OK) return st;
    for (int f = 0; f < np->nf; f++)
        for (int w = 0; w < n; w++) np->mc_sig_ms[f][w] = mc->med.sig[f][w], np->mc_sca[f][w] = mc->med.sca[f][w];
    const int s = np->opt.mc_cell;
    const sgrid *g = &np->g;
    if (!atmos__lfield_alloc(&mc->field, ATMOS__LFIELD_NONE, (g->c[0] + s - 1) / s, (g->c[1] + s - 1) / s,
                             (g->c[2] + s - 1) / s, n, s) ||
        !(mc->coef = calloc((size_t)mc->field.c[0] * mc->field.c[1] * mc->field.c[2] * n * mc->K, sizeof(float))))
        return atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the Monte Carlo field");
    return ATMOS_OK;
}

const atmos__lfield *atmos__nishita_mc_field(const atmos__nishita_plan *np) { return &np->mc->field; }

int atmos__nishita_mc_dm_phase(const atmos__nishita_plan *np, double chi[][ATMOS_MAX_WAVELENGTHS][4],
                               float turn[][ATMOS_MAX_WAVELENGTHS])
{
    const atmos__nishita_mc *mc = np->mc;
    if (!mc || !mc->delta_m) return 0;
    for (int f = 0; f < np->nf; f++)
        for (int w = 0; w < np->n; w++) {
            for (int l = 0; l < 4; l++) chi[f][w][l] = l <= mc->lmax ? mc->pl[f][w][l] : 0;
            const double fk = mc->dm_f[f][w];
            turn[f][w] = fk < 1 ? (float)(np->mc_sca[f][w] * fk / (1 - fk)) : 0.0f; /* sigma_s' - sigma_s* */
        }
    return 1;
}

void atmos__nishita_do_describe(const atmos__nishita_plan *np, char *buf, size_t cap)
{
    const atmos__lfield *F = &np->mc->field;
    const size_t l = strlen(buf);
    /* an optically thin medium is solved by source iterations alone (no GMRES): no residual is
       computed then; the bound on the error is given instead */
    char res[64];
    if (np->do_source_its > 0)
        snprintf(res, sizeof res, "%d source iterations, relative error at most %.1e", np->do_source_its, np->do_resid);
    else
        snprintf(res, sizeof res, "residual %.1e", np->do_resid);
    snprintf(buf + l, cap - l,
             "; discrete-ordinates field, %d directions, %d GMRES iterations, %d sweeps (%s), "
             "%dx%dx%d cells of %d voxels, %.3f s, %.3f s CPU",
             np->do_dirs, np->do_iters, np->do_sweeps, res, F->c[0], F->c[1], F->c[2], F->s, np->mc_s, np->do_cpu);
}

/* The occupied box's faces lit by the sunlight travelling along lt (grid frame): each face's
 * area across the beam (area3, m^2) and their sum. */
static double box_area(const path_medium *m, const double lt[3], double *area3)
{
    double A = 0;
    for (int a = 0; a < 3; a++) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        area3[a] = fabs(lt[a]) * (m->box_hi[b] - m->box_lo[b]) * (m->box_hi[c] - m->box_lo[c]) * m->vs * m->vs;
        A += area3[a];
    }
    return A;
}

/* The photon's start: a point of those faces drawn in proportion to their area across the beam
 * (index space q). */
static void start_point(const path_medium *m, const double lt[3], const double *area3, double A, atmos__stream *r,
                        double q[3])
{
    double u = atmos__stream_u(r) * A;
    int a = 0;
    while (a < 2 && u >= area3[a]) u -= area3[a], a++;
    for (int b = 0; b < 3; b++) q[b] = m->box_lo[b] + atmos__stream_u(r) * (m->box_hi[b] - m->box_lo[b]);
    q[a] = lt[a] > 0 ? m->box_lo[a] : m->box_hi[a];
}

typedef struct {
    const atmos__nishita_plan *np;
    const atmos__nishita_mc *mc;
    path_job J;
    double lt[3], out[3]; /* world: the sunlight's travel, the direction toward the eye (lmax -1) */
    double area3[3], A;
} mc_job;

/* The trilinear read's 8 corners at render-voxel point u (atmos__lfield_sample's): each one's cell
 * indices ci and weight wt, in the order c = 0..7. */
static void corners(const atmos__lfield *F, const float u[3], int ci[8][3], double wt[8])
{
    int i[3];
    float f[3];
    for (int a = 0; a < 3; a++) atmos__lfield_axis(u[a], F->s, F->c[a], &i[a], &f[a]);
    for (int c = 0; c < 8; c++) {
        wt[c] = 1;
        for (int a = 2; a >= 0; a--) {
            const int hi = (c >> a) & 1;
            ci[c][a] = i[a] + hi < F->c[a] ? i[a] + hi : i[a];
            wt[c] *= hi ? f[a] : 1.0f - f[a];
        }
    }
}

static size_t cell_of(const atmos__lfield *F, const int ci[3])
{
    return ((size_t)ci[2] * F->c[1] + ci[1]) * F->c[0] + ci[0];
}

/* Adds v[0..K) times the trilinear read's weights at render-voxel point u to the 8 cells'
 * acc[((cell * n + w) * K + k]: reading the cells at x then returns the kernel estimate,
 * sum_c W_c(x) (sum of v W_c) / (integral of sigma_s' W_c). Fixed point, atomic: the same
 * integers whatever the threads' order. */
static void splat(const atmos__lfield *F, const float u[3], const double *v, int K, int w, int64_t *acc)
{
    int ci[8][3];
    double wt[8];
    corners(F, u, ci, wt);
    for (int c = 0; c < 8; c++) {
        if (!(wt[c] > 0)) continue;
        const size_t o = (cell_of(F, ci[c]) * F->n + w) * K;
        for (int k = 0; k < K; k++) {
            const int64_t x = (int64_t)llrint(wt[c] * v[k] * MC_FIX);
#pragma omp atomic
            acc[o + k] += x;
        }
    }
}

/* What a collision of the photon travelling along d scatters: toward M->out (K = 1), or the
 * spherical-harmonic coefficients of p(d . omega), p_l Y_lm(d) (the addition theorem). */
static void emission(const mc_job *M, const path_scatter *e, int k, const double d[3], double *v)
{
    const atmos__nishita_mc *mc = M->mc;
    const path_bundle b = {1, {k, 0, 0, 0}};
    if (mc->lmax < 0) {
        atmos__path_phase_mix(&mc->ph, &b, mc->med.nf, e, atmos__dot3(d, M->out), v);
        return;
    }
    double pl[4] = {0}, Y[MC_KMAX];
    for (int f = 0; f < mc->med.nf; f++)
        for (int l = 0; l <= mc->lmax; l++) pl[l] += e->ssf[f][0] * mc->pl[f][k][l] / e->ss[0];
    atmos__sh_eval(mc->lmax, d, Y);
    for (int l = 0; l <= mc->lmax; l++)
        for (int m = -l; m <= l; m++) v[l * l + l + m] = pl[l] * Y[l * l + l + m];
}

/* One photon of wavelength k: its collisions after the first add w times their emission. */
static void photon(const mc_job *M, int k, atmos__stream *r, int64_t *acc)
{
    const atmos__nishita_mc *mc = M->mc;
    const path_medium *m = &mc->med;
    const sgrid *g = &M->np->g;
    const path_bundle b = {1, {k, 0, 0, 0}};
    double q[3], qd[3], d[3], ltg[3], w[PATH_B] = {1, 0, 0, 0};
    atmos__vol_dir_to_frame(&m->x, M->lt, ltg);
    start_point(m, ltg, M->area3, M->A, r, q);
    memcpy(d, M->lt, sizeof d);
    atmos__vol_dir_to_index(&m->x, d, qd);
    long long tent = 0;
    for (int order = 1; order <= MC_MAX_DEPTH; order++) {
        double t0, t1, t;
        float dens[PATH_F];
        if (!atmos__path_clip(m, q, qd, INFINITY, &t0, &t1)) return;
        if (atmos__path_free_flight(m, q, qd, t0, t1, &b, w, r, &t, dens, &tent) <= 0) return;
        for (int a = 0; a < 3; a++) q[a] += t * qd[a];
        path_scatter e;
        int gi[PATH_B];
        if (!atmos__path_scatter_at(&M->J, &b, dens, &e, gi)) return;
        if (order >= 2) {
            double v[MC_KMAX];
            emission(M, &e, k, d, v);
            for (int c = 0; c < mc->K; c++) v[c] *= w[0];
            float u[3];
            for (int a = 0; a < 3; a++) u[a] = (float)(q[a] * m->vs * g->sc + g->off[a]);
            splat(&mc->field, u, v, mc->K, k, acc);
        }
        if (!atmos__path_roulette(w, 1, r)) return;
        const int f = atmos__path_pick_field(&e, 0, m->nf, r);
        const double mu = mc->delta_m && !mc->clip
                              ? atmos_phase_mixture_sample(&mc->hg[f][k], 0.5, atmos__stream_u(r))
                              : atmos__path_phase_sample(mc->clip ? &mc->ph_dm : &mc->ph, f, k, atmos__stream_u(r));
        double nd[3];
        atmos__path_around(d, mu, 2.0 * ATMOS_PI * atmos__stream_u(r), nd);
        memcpy(d, nd, sizeof d);
        atmos__vol_dir_to_index(&m->x, d, qd);
    }
}

/* One render voxel's SUB^3 points into cell_scattering()'s acc: their fixed-point terms summed
 * first in the 3 x 3 x 3 cells from the first point's (a voxel's points span at most 3 per axis),
 * then added atomically, 27 adds a wavelength instead of 8 SUB^3; the integer sums are exact, so
 * the same whatever the grouping. */
static void voxel_scattering(const atmos__nishita_plan *np, const path_medium *m, const atmos__lfield *F,
                             const int v[3], int sub, double unit, int64_t *acc)
{
    const sgrid *g = &np->g;
    const int nf = np->nf, n = np->n;
    int64_t loc[27][ATMOS_MAX_WAVELENGTHS];
    int base[3], used[27] = {0};
    for (int a = 0; a < 3; a++) { /* the cells of the voxel's first point, the lowest on every axis */
        float f;
        atmos__lfield_axis(v[a] + 0.5f / sub - 0.5f, F->s, F->c[a], &base[a], &f);
    }
    for (int l = 0; l < 27; l++) memset(loc[l], 0, sizeof(int64_t) * n);
    for (int c = 0; c < sub * sub * sub; c++) {
        const float u[3] = {v[0] + (c % sub + 0.5f) / sub - 0.5f, v[1] + (c / sub % sub + 0.5f) / sub - 0.5f,
                            v[2] + (c / (sub * sub) + 0.5f) / sub - 0.5f};
        double q[3];
        for (int a = 0; a < 3; a++) q[a] = (u[a] - g->off[a]) / g->sc * m->inv_vs;
        float dens[PATH_F];
        atmos__path_density(m, q[0], q[1], q[2], dens);
        double sums[ATMOS_MAX_WAVELENGTHS];
        int any = 0;
        for (int w = 0; w < n; w++) {
            double sum = 0;
            for (int f = 0; f < nf; f++) sum += (double)dens[f] * np->mc_sca[f][w];
            sums[w] = sum * unit, any |= sums[w] > 0;
        }
        if (!any) continue; /* the empty points, most of a cloud's box: no corners */
        int ci[8][3], lk[8]; /* lk: the corner's local cell, -1 outside them, -2 weight 0 */
        double wt[8];
        corners(F, u, ci, wt);
        for (int k = 0; k < 8; k++) {
            int d[3], inside = 1;
            for (int a = 0; a < 3; a++) d[a] = ci[k][a] - base[a], inside &= d[a] >= 0 && d[a] < 3;
            lk[k] = !(wt[k] > 0) ? -2 : inside ? (d[2] * 3 + d[1]) * 3 + d[0] : -1;
            if (lk[k] >= 0) used[lk[k]] = 1;
        }
        for (int w = 0; w < n; w++) {
            const double sum = sums[w];
            if (!(sum > 0)) continue;
            for (int k = 0; k < 8; k++) {
                if (lk[k] == -2) continue;
                const int64_t x = (int64_t)llrint(wt[k] * sum * MC_FIX);
                if (lk[k] >= 0)
                    loc[lk[k]][w] += x;
                else { /* not expected; the same sum either way */
#pragma omp atomic
                    acc[cell_of(F, ci[k]) * n + w] += x;
                }
            }
        }
    }
    for (int l = 0; l < 27; l++) {
        if (!used[l]) continue;
        const int ci[3] = {base[0] + l % 3, base[1] + l / 3 % 3, base[2] + l / 9};
        const size_t o = cell_of(F, ci) * n;
        for (int w = 0; w < n; w++) {
#pragma omp atomic
            acc[o + w] += loc[l][w];
        }
    }
}

/* Per cell and wavelength the integral of sigma_s' times the cell's trilinear weight (into ss,
 * in units of sig_max times a render voxel's volume), by the midpoint rule on SUB^3 points per
 * render voxel of the medium the photons see (the path tracer's: its density next to the
 * volume's faces is not the render grid's). Fixed point, so the same whatever the threads. */
static int cell_scattering(const atmos__nishita_plan *np, const atmos__nishita_mc *mc, double sig_max, double *ss,
                           int threads)
{
    const sgrid *g = &np->g;
    const atmos__lfield *F = &mc->field;
    const int sub = F->s >= 2 ? 2 : 4;
    const size_t vals = (size_t)F->c[0] * F->c[1] * F->c[2] * np->n;
    int64_t *acc = calloc(vals, sizeof(int64_t));
    if (!acc) return 0;
    const double unit = 1.0 / (sig_max * sub * sub * sub);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int k = 0; k < g->c[2]; k++)
        for (int j = 0; j < g->c[1]; j++)
            for (int i = 0; i < g->c[0]; i++) {
                const int v[3] = {i, j, k};
                voxel_scattering(np, &mc->med, F, v, sub, unit, acc);
            }
    for (size_t c = 0; c < vals; c++) ss[c] = acc[c] / MC_FIX;
    free(acc);
    return 1;
}

/* The kernel-weighted sigma_s' of the cells (m^3 / m): cell_scattering() scaled back from units of
 * sig_max (twice the grid's largest sigma_s') and render voxels. Made once per plan into mc->ss:
 * it depends on the plan's medium and cells only, not on the sun. 0: out of memory. */
static int cell_ss(const atmos__nishita_plan *np, atmos__nishita_mc *mc, int threads)
{
    if (mc->ss_done) return 1;
    const int n = np->n;
    const size_t vals = (size_t)mc->field.c[0] * mc->field.c[1] * mc->field.c[2] * n;
    const double h = 1.0 / np->g.sc;
    double sig_max = 0;
    for (size_t v = 0; v < (size_t)np->g.c[0] * np->g.c[1] * np->g.c[2]; v++)
        for (int f = 0; f < np->nf; f++)
            for (int w = 0; w < n; w++) sig_max = fmax(sig_max, 2.0 * np->g.v[v * np->nf + f] * np->mc_sca[f][w]);
    if (sig_max > 0) {
        if (!(mc->ss = calloc(vals, sizeof(double)))) return 0;
        if (!cell_scattering(np, mc, sig_max, mc->ss, threads)) {
            free(mc->ss), mc->ss = NULL;
            return 0;
        }
        for (size_t c = 0; c < vals; c++) mc->ss[c] *= sig_max * h * h * h;
    }
    mc->ss_done = 1;
    return 1;
}

/* The photons of one sun (and, for lmax -1, one direction toward the eye) into mc->coef. */
static atmos_status trace(atmos_plan *p, atmos__nishita_plan *np, const double sun_w[3], const double out_w[3],
                          const double *E, int threads)
{
    atmos__nishita_mc *mc = np->mc;
    const atmos__lfield *F = &mc->field;
    const int n = np->n, K = mc->K;
    const size_t cells = (size_t)F->c[0] * F->c[1] * F->c[2], vals = cells * n;
    int64_t *acc = calloc(vals * K, sizeof(int64_t));
    if (!acc || !cell_ss(np, mc, threads)) {
        free(acc);
        return atmos__error(p->ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the photons");
    }
    mc_job M;
    memset(&M, 0, sizeof M);
    M.np = np, M.mc = mc, M.J.med = &mc->med, M.J.ph = &mc->ph;
    for (int a = 0; a < 3; a++) M.lt[a] = -sun_w[a], M.out[a] = out_w[a];
    double ltg[3];
    atmos__vol_dir_to_frame(&mc->med.x, M.lt, ltg);
    M.A = mc->med.empty ? 0 : box_area(&mc->med, ltg, M.area3);
    const long long N = (long long)np->opt.mc_kphotons * 1000;
    const uint64_t seed = p->scene.path.seed;
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads)
    for (long long i = 0; i < N * n; i++) {
        atmos__stream r;
        atmos__stream_seed(&r, seed, (uint64_t)(i / n), (uint64_t)(i % n) + 0x6d63u);
        if (M.A > 0) photon(&M, (int)(i % n), &r, acc);
    }
    /* the kernel-weighted emission, acc E A / N, over the kernel-weighted sigma_s'; a cell whose
     * kernel holds almost no scattering (the cloud's fringe) divided by at least MC_SS_FLOOR of
     * the largest cell's: one collision there would otherwise make a radiance that the trilinear
     * read carries into the dense neighbours */
    const double *ss = mc->ss;
    if (!ss) { /* no scattering in the grid */
        free(acc);
        return ATMOS_OK;
    }
    double smax[ATMOS_MAX_WAVELENGTHS] = {0};
    for (size_t c = 0; c < vals; c++)
        if (ss[c] > smax[c % n]) smax[c % n] = ss[c];
    for (size_t c = 0; c < vals; c++) {
        const int w = (int)(c % n);
        const double d = fmax(ss[c], MC_SS_FLOOR * smax[w]), sc = N > 0 && d > 0 ? E[w] * M.A / ((double)N * d) : 0;
        for (int k = 0; k < K; k++) mc->coef[c * K + k] = (float)(acc[c * K + k] / MC_FIX * sc);
    }
    free(acc);
    return ATMOS_OK;
}

/* The same coefficients by discrete ordinates (nishita_do.c): chi_l per wavelength, the cut or
 * scaled phase's normalised moments mc->pl weighted by the fields' scattering in the grid. */
static atmos_status solve(atmos_plan *p, atmos__nishita_plan *np, const double sun_w[3], const double *E, int threads,
                          int warm)
{
    atmos__nishita_mc *mc = np->mc;
    const int n = np->n, nf = np->nf;
    double chi[ATMOS_MAX_WAVELENGTHS][4] = {{0}};
    double *dens = mc->do_dens; /* the medium's alone: summed at the plan's first solve */
    for (size_t v = 0; !mc->do_dens_done && v < (size_t)np->g.c[0] * np->g.c[1] * np->g.c[2]; v++)
        for (int f = 0; f < nf; f++) dens[f] += np->g.v[v * nf + f];
    mc->do_dens_done = 1;
    for (int w = 0; w < n; w++) {
        double S = 0;
        for (int f = 0; f < nf; f++) {
            const double sf = dens[f] * np->mc_sca[f][w], p0 = mc->delta_m ? 1 : mc->pl[f][w][0];
            S += sf;
            for (int l = 0; l <= mc->lmax; l++) chi[w][l] += sf * mc->pl[f][w][l] / p0;
        }
        for (int l = 0; l <= mc->lmax; l++) chi[w][l] = S > 0 ? chi[w][l] / S : l == 0;
    }
    if (mc->med.empty) {
        memset(mc->coef, 0, sizeof(float) * (size_t)mc->field.c[0] * mc->field.c[1] * mc->field.c[2] * n * mc->K);
        return ATMOS_OK;
    }
    const size_t cells = (size_t)mc->field.c[0] * mc->field.c[1] * mc->field.c[2];
    if (!mc->do_ws) mc->do_ws = atmos__do_ws_create(); /* NULL: each solve its own */
    if (!mc->do_phi && !(mc->do_phi = malloc(sizeof(double) * cells * n * mc->K)))
        return atmos__error(p->ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the field's moments");
    atmos__nishita_do_info info;
    const atmos_status st =
        atmos__nishita_do_fill(p->ctx, np, &mc->field, mc->lmax, (const double(*)[4])chi, sun_w, E,
                               np->opt.sky ? p->atm : NULL, threads, mc->coef, mc->do_phi,
                               warm && mc->do_phi_valid, mc->do_kappa, mc->do_ws, &mc->do_cells, &info);
    mc->do_phi_valid = st == ATMOS_OK;
    np->do_iters = info.iters, np->do_sweeps = info.sweeps, np->do_dirs = info.directions;
    np->do_resid = info.resid, np->do_cpu = info.cpu_s, np->do_source_its = info.source_its;
    return st;
}

/* The harmonics of degree lmax at the direction from cell (i, j, k)'s centre to the eye at eye_w
 * (world) into Y. */
static void cell_eye_harmonics(const atmos__nishita_plan *np, const double eye_w[3], int i, int j, int k, double *Y)
{
    const atmos__lfield *F = &np->mc->field;
    const sgrid *g = &np->g;
    const int ijk[3] = {i, j, k};
    double gc[3], pw[3], d[3];
    for (int a = 0; a < 3; a++) gc[a] = (ijk[a] * F->s + 0.5 * (F->s - 1) - g->off[a]) / g->sc;
    atmos__vol_frame_to_point(&np->x, gc, pw);
    for (int a = 0; a < 3; a++) d[a] = eye_w[a] - pw[a];
    atmos__normalize3(d);
    atmos__sh_eval(np->mc->lmax, d, Y);
}

/* The field toward the eye at eye_w (world): per cell its coefficients at the direction from
 * the cell's centre to the eye, not below 0. The directions' harmonics kept (mc->vy) for the
 * frames whose sun alone moved. */
static void view(atmos__nishita_plan *np, const double eye_w[3], int threads)
{
    atmos__nishita_mc *mc = np->mc;
    atmos__lfield *F = &mc->field;
    const int n = np->n, K = mc->K;
    const size_t cells = (size_t)F->c[0] * F->c[1] * F->c[2];
    if (mc->lmax >= 0 && !mc->vy) mc->vy = malloc(sizeof(double) * cells * K); /* NULL: not kept */
    const int kept = mc->vy && mc->vy_valid && !memcmp(mc->vy_eye, eye_w, sizeof mc->vy_eye);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int k = 0; k < F->c[2]; k++)
        for (int j = 0; j < F->c[1]; j++)
            for (int i = 0; i < F->c[0]; i++) {
                const size_t cell = ((size_t)k * F->c[1] + j) * F->c[0] + i;
                double own[MC_KMAX] = {1}, *Y = mc->vy ? mc->vy + cell * K : own;
                if (mc->lmax >= 0 && !kept) cell_eye_harmonics(np, eye_w, i, j, k, Y);
                for (int w = 0; w < n; w++) {
                    const float *c = mc->coef + (cell * n + w) * K;
                    double v = 0;
                    for (int q = 0; q < K; q++) v += c[q] * Y[q];
                    F->L[cell * n + w] = v > 0 ? (float)v : 0.0f;
                }
            }
    if (mc->vy) memcpy(mc->vy_eye, eye_w, sizeof mc->vy_eye), mc->vy_valid = 1;
}

atmos_status atmos__nishita_mc_update(atmos_plan *p, atmos__nishita_plan *np, const double sun_w[3],
                                      const double out_w[3], const double eye_w[3], const double *E, int threads,
                                      int warm)
{
    atmos__nishita_mc *mc = np->mc;
    const int same_out = mc->lmax >= 0 || !memcmp(mc->out, out_w, sizeof mc->out);
    if (!mc->valid || memcmp(mc->sun, sun_w, sizeof mc->sun) || !same_out || (mc->warm && !warm)) {
        const double t0 = atmos__now();
        const int warm_start = np->opt.do_field && warm && mc->do_phi_valid;
        atmos_status st = np->opt.do_field ? solve(p, np, sun_w, E, threads < 1 ? 1 : threads, warm)
                                           : trace(p, np, sun_w, out_w, E, threads < 1 ? 1 : threads);
        if (st != ATMOS_OK) return st;
        memcpy(mc->sun, sun_w, sizeof mc->sun), memcpy(mc->out, out_w, sizeof mc->out);
        mc->valid = 1, mc->view_valid = 0, mc->warm = warm_start;
        np->mc_s = atmos__now() - t0;
    }
    if (!mc->view_valid || memcmp(mc->eye, eye_w, sizeof mc->eye)) {
        view(np, eye_w, threads < 1 ? 1 : threads);
        memcpy(mc->eye, eye_w, sizeof mc->eye);
        mc->view_valid = 1;
    }
    return ATMOS_OK;
}
