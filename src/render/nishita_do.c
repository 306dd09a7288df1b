/* The Nishita renderer's field of the orders >= 2 by discrete ordinates ("nishita": {"do":
 * true}; docs/lightfield.md, "A discrete-ordinates field"): the same per-cell spherical
 * harmonics as the Monte Carlo field's (nishita_mc.c), solved on its cells (lfield_do.c). Per
 * wavelength: the cells' mean sigma_t and sigma_s of the medium the field's photons would see
 * (sig' cut at 3 degrees, or delta-M scaled sig*), the first order's emission per cell from the
 * sunlight's columns per render voxel (nishita_plan.c's sweep, its voxel's mean transmittance
 * along the sun), the quadrature's directions about the world's axes (the harmonics' frame),
 * swept along the cells' axes, each wavelength after the first started from the last one's
 * solution; the moments times chi_l are the field's coefficients (the
 * emission of orders >= 2 per unit sigma_s).
 *
 * The sky's and the ground's light (with atm) enter as the sweeps' inflow through the grid's
 * faces: per direction the mean over its patch of the sphere of what a view ray from the box's
 * centre sees the other way (sky_inflow.c, the P1 field's source; the sun's disk left out), the
 * same over the faces. The moments then hold that light too, its uncollided part included, so the
 * coefficients are also the sky's and the ground's light of the orders >= 1 per unit sigma_s (the
 * eye pass adds no other sky light in the volume; the sky seen straight through the volume is
 * the eye pass's background, attenuated). */
#include "core/vec.h"
#include "light/lfield_do.h"
#include "render/nishita_do.h"
#include "render/sky_inflow.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define DO_NMU 4    /* Gauss-Legendre cosines */
#define DO_NPHI 8   /* azimuths: 32 directions, exact for the products of the harmonics of degree <= 3 */
#define DO_TOL 1e-3 /* GMRES's relative residual */
#define DO_RESTART 20
#define DO_MAX_ITER 200
#define SKY_NS 4 /* the sky's samples per direction's patch: SKY_NS x SKY_NS */
/* The sweeps' weighted diamond (lfield_do.h): 1/2, diamond difference, in optically thick cells,
 * toward the step scheme (1) in thin ones, over an optical depth DO_THETA_TAU a cell. The step
 * scheme alone diffuses too much across thick cells: the rain's cumulus (cells of 4 voxels) too
 * dark with the sun behind and too bright toward it (docs/lightfield.md, "The step scheme in
 * thick cells"). */
#define DO_THETA 0.5
#define DO_THETA_TAU 1.0

/* The sky's and the ground's radiance entering the grid along each direction of q (DO_NMU x
 * DO_NPHI, atmos__do_quadrature's order: the cosines descending), the mean over the direction's
 * patch (its Gauss-Legendre weight's band of cosines, its azimuth's sector), per wavelength:
 * in[dir * n + w]. Returns 1 when any is not 0. */
static int sky_inflow(const atmos_atmosphere *atm, const atmos__nishita_plan *np, const atmos__do_quad *q,
                      const double sun_w[3], double *in)
{
    double cen[3], cw[3], top = 1;
    for (int a = 0; a < 3; a++) cen[a] = 0.5 * (np->g.box_lo[a] + np->g.box_hi[a]);
    atmos__sky_inflow_point(atm, &np->x, cen, cw);
    int any = 0;
    for (int i = 0; i < DO_NMU; i++) {
        const double wmu = q->w[i * DO_NPHI] * DO_NPHI / (2 * ATMOS_PI), bot = i == DO_NMU - 1 ? -1 : top - wmu;
        for (int j = 0; j < DO_NPHI; j++) {
            double *L = in + (size_t)(i * DO_NPHI + j) * np->n;
            atmos__sky_patch_inflow(atm, cw, sun_w, np->n, bot, top, 2 * ATMOS_PI * j / DO_NPHI,
                                    2 * ATMOS_PI * (j + 1) / DO_NPHI, SKY_NS, L);
            for (int w = 0; w < np->n; w++) any |= L[w] != 0;
        }
        top = bot;
    }
    return any;
}

/* Per cell the mean sigma_t, sigma_s (1/m) and the mean of sigma_s E T_sun over its render voxels,
 * wavelength w. */
static void cell_medium(const atmos__nishita_plan *np, const atmos__lfield *F, int w, const double sun_g[3],
                        float *st, float *ss, double *src, int threads)
{
    const sgrid *g = &np->g;
    const int s = F->s, nf = np->nf;
    double amax = 0;
    for (int a = 0; a < 3; a++) amax = fmax(amax, fabs(sun_g[a]));
    const double len = 1.0 / amax / g->sc, inv = 1.0 / ((double)s * s * s);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int k = 0; k < F->c[2]; k++)
        for (int j = 0; j < F->c[1]; j++)
            for (int i = 0; i < F->c[0]; i++) {
                const size_t c = ((size_t)k * F->c[1] + j) * F->c[0] + i;
                double at = 0, as = 0, aq = 0;
                for (int z = k * s; z < (k + 1) * s && z < g->c[2]; z++)
                    for (int y = j * s; y < (j + 1) * s && y < g->c[1]; y++)
                        for (int x = i * s; x < (i + 1) * s && x < g->c[0]; x++) {
                            const size_t v = (((size_t)z * g->c[1] + y) * g->c[0] + x) * nf;
                            double t = 0, sc = 0, tau = 0;
                            for (int f = 0; f < nf; f++) {
                                t += g->v[v + f] * np->mc_sig_ms[f][w], sc += g->v[v + f] * np->mc_sca[f][w];
                                tau += np->col[v + f] * np->mc_sig_ms[f][w];
                            }
                            at += t, as += sc;
                            if (!(sc != 0)) continue; /* an empty voxel: no exponentials */
                            /* the voxel's mean of e^-tau along the sun about its centre, sinh(d/2)/(d/2) */
                            const double d = fmin(t * len, 2 * tau), m = d > 1e-6 ? sinh(0.5 * d) / (0.5 * d) : 1;
                            aq += sc * exp(-tau) * m;
                        }
                st[c] = (float)(at * inv), ss[c] = (float)(as * inv), src[c] = aq * inv;
            }
}

atmos_status atmos__nishita_do_fill(atmos_context *ctx, const atmos__nishita_plan *np, const atmos__lfield *F, int L,
                                    const double chi[][4], const double sun_w[3], const double *E,
                                    const atmos_atmosphere *atm, int threads, float *coef, double *phi_all, int warm,
                                    atmos__do_ws *ws, atmos__nishita_do_info *info)
{
    const int n = np->n, K = (L + 1) * (L + 1);
    const size_t cells = (size_t)F->c[0] * F->c[1] * F->c[2];
    const clock_t c0 = clock();
    memset(info, 0, sizeof *info);
    atmos__do_quad quad;
    atmos__do_problem P;
    memset(&P, 0, sizeof P);
    if (!atmos__do_quadrature(DO_NMU, DO_NPHI, &quad))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render nishita: no quadrature");
    for (int j = 0; j < 3; j++) {
        double e[3] = {0, 0, 0}, r[3];
        e[j] = 1;
        atmos__vol_dir_to_frame(&np->x, e, r);
        for (int a = 0; a < 3; a++) P.R[a][j] = r[a];
    }
    double lt[3], ltg[3], Ys[ATMOS__DO_KMAX];
    for (int a = 0; a < 3; a++) lt[a] = -sun_w[a];
    atmos__vol_dir_to_frame(&np->x, lt, ltg);
    atmos__sh_eval(L, lt, Ys);
    double inw[ATMOS__DO_NMAX], skymean[ATMOS_MAX_WAVELENGTHS] = {0};
    double *sky = atm ? malloc(sizeof(double) * quad.n * n) : NULL;
    if (atm && !sky) return atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the field's solve");
    const int sky_on = sky && sky_inflow(atm, np, &quad, sun_w, sky);
    for (int d = 0; sky_on && d < quad.n; d++)
        for (int w = 0; w < n; w++) skymean[w] += sky[d * n + w] * quad.w[d];
    float *st = malloc(sizeof(float) * cells * 4); /* this wavelength's sigma_t, sigma_s; the last one's */
    double *src = malloc(sizeof(double) * cells * 2), *q1 = malloc(sizeof(double) * cells * K);
    int ok = st && src && q1;
    P.c[0] = F->c[0], P.c[1] = F->c[1], P.c[2] = F->c[2], P.h = F->s / (double)np->g.sc, P.L = L;
    P.sig_t = st, P.sig_s = st + cells, P.q1 = q1, P.quad = &quad;
    P.theta = DO_THETA, P.theta_tau = DO_THETA_TAU;
    P.tol = DO_TOL, P.max_iter = DO_MAX_ITER, P.restart = DO_RESTART, P.threads = threads, P.ws = ws;
    int w_last = -1; /* the wavelength whose solution phi holds */
    for (int w = 0; w < n && ok; w++) {
        double *phi = phi_all + (size_t)w * cells * K;
        cell_medium(np, F, w, ltg, st, st + cells, src, threads);
        /* a wavelength whose medium and phase are the last one's (a grey cloud): its field is the
         * last one's times the ratio of the sunlight */
        if (w > 0 && E[w - 1] > 0 && !sky_on && !memcmp(chi[w], chi[w - 1], sizeof chi[w]) &&
            !memcmp(st, st + 2 * cells, sizeof(float) * cells * 2) && !memcmp(src, src + cells, sizeof(double) * cells)) {
            for (size_t c = 0; c < cells; c++)
                for (int k = 0; k < K; k++)
                    coef[(c * n + w) * K + k] = (float)(coef[(c * n + w - 1) * K + k] * (E[w] / E[w - 1]));
            for (size_t i = 0; i < cells * (size_t)K; i++) phi[i] = phi[i - cells * K] * (E[w] / E[w - 1]);
            continue;
        }
        memcpy(st + 2 * cells, st, sizeof(float) * cells * 2), memcpy(src + cells, src, sizeof(double) * cells);
        for (int l = 0; l <= L; l++) P.chi[l] = chi[w][l];
        for (size_t c = 0; c < cells; c++)
            for (int k = 0; k < K; k++) {
                const int l = atmos__sh_degree(k);
                q1[c * K + k] = E[w] * src[c] * chi[w][l] * Ys[k];
            }
        for (int d = 0; sky_on && d < quad.n; d++) inw[d] = sky[d * n + w];
        P.inflow = sky_on ? inw : NULL;
        /* the start: the last wavelength's solution times the ratio of the sunlight (the clouds are
         * nearly grey; 2 GMRES iterations on the Disney cloud where the last sun's takes 3; with the
         * sun off, of the sky's light), else with warm this wavelength's solution for the last sun
         * (phi as it is), else 0. Only a start: the solve reaches its tolerance from any. */
        const double ratio = w_last < 0          ? 0
                             : E[w_last] > 0     ? E[w] / E[w_last]
                             : skymean[w_last] > 0 ? skymean[w] / skymean[w_last]
                                                   : 0;
        if (ratio > 0) {
            const double *last = phi_all + (size_t)w_last * cells * K;
            for (size_t i = 0; i < cells * (size_t)K; i++) phi[i] = last[i] * ratio;
        } else if (!warm)
            memset(phi, 0, sizeof(double) * cells * K);
        atmos__do_stats S;
        ok = atmos__do_solve(&P, phi, &S);
        for (size_t c = 0; c < cells && ok; c++)
            for (int k = 0; k < K; k++) {
                const int l = atmos__sh_degree(k);
                coef[(c * n + w) * K + k] = (float)(chi[w][l] * phi[c * K + k]);
            }
        w_last = ok ? w : -1;
        info->iters += S.iters, info->sweeps += S.sweeps;
        info->resid = fmax(info->resid, S.resid);
    }
    free(st), free(src), free(q1), free(sky);
    info->cpu_s = (double)(clock() - c0) / CLOCKS_PER_SEC;
    info->directions = quad.n;
    return ok ? ATMOS_OK : atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the field's solve");
}
