/* The Nishita renderer's field of the orders >= 2 by discrete ordinates ("nishita": {"do":
 * true}; docs/lightfield.md, "A discrete-ordinates field"): the same per-cell spherical
 * harmonics as the Monte Carlo field's (nishita_mc.c), solved on its cells (lfield_do.c). Per
 * wavelength: the cells' mean sigma_t and sigma_s of the medium the field's photons would see
 * (sig' cut at 3 degrees, or delta-M scaled sig*), the first order's emission per cell from the
 * sunlight's columns per render voxel (nishita_plan.c's sweep, its voxel's mean transmittance
 * along the sun), the quadrature's directions about the world's axes (the harmonics' frame),
 * swept along the cells' axes (GMRES, or in an optically thin medium one or two source
 * iterations: thin_sweeps); the first wavelength solved on all the threads, the others in
 * parallel, one a thread, each started from the first one's solution (solve_all); the moments
 * times chi_l are the field's coefficients (the emission of orders >= 2 per unit sigma_s), plus
 * per cell the sub-cell term that gives the eye the voxels' sigma_s-weighted radiance
 * (cell_source).
 *
 * The sky's and the ground's light (with atm) enter as the sweeps' inflow through the grid's
 * faces: per direction the mean over its patch of the sphere of what a view ray from the box's
 * centre sees the other way (sky_inflow.c, the P1 field's source; the sun's disk left out), the
 * same over the faces. The moments then hold that light too, its uncollided part included, so the
 * coefficients are also the sky's and the ground's light of the orders >= 1 per unit sigma_s (the
 * eye pass adds no other sky light in the volume; the sky seen straight through the volume is
 * the eye pass's background, attenuated). */
#include "core/clones.h"
#include "core/fastmath.h"
#include "core/vec.h"
#include "light/lfield_do.h"
#include "render/nishita_do.h"
#include "render/sky_inflow.h"

#include <math.h>
#include <omp.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define DO_NMU 4    /* Gauss-Legendre cosines */
#define DO_NPHI 8   /* azimuths: 32 directions, exact for the products of the harmonics of degree <= 3 */
#define DO_TOL 1e-3 /* GMRES's relative residual */
#define DO_RESTART 20
#define DO_MAX_ITER 200
#define KAPPA_E 0.2 /* a warm start estimates its source's norm within this change of the sunlight (do_fill) */
#define SKY_NS 4 /* the sky's samples per direction's patch: SKY_NS x SKY_NS */
#define WS_MAX 64 /* the wavelengths solved in parallel at most (their buffers) */
/* the face neighbours' first scattering in a voxel's local radiance, per neighbour, in voxel
 * sizes: fitted on a textured crop against its field on cells of 1 voxel (docs/lightfield.md,
 * "The cells' averaging: a sub-cell term") */
#define SUB_NB 0.4
/* a neighbour's optical size (sigma_t h) beyond which its share stops growing: fitted too (16: the
 * simulated cumulus -3.2 -> -6.9 %, a dense tower's brightest cell 1.6 times dimmer; 1 as the
 * voxel's own share: -17 %) */
#define SUB_NB_TAU 16.0
/* the share of its cell's densest sigma_s below which a voxel counts in the sub-cell term's plain
 * mean in proportion to its sigma_s: dust, nearly empty (counted in full, voxels of less than
 * 10^-6 of it gave a deck's cells a term by how many of them each held, a checkerboard of cells;
 * docs/slice.md, "The deck's checkerboard"). 10^-5: the simulated cumulus moves 0.05 points,
 * 10^-3 moved it 0.8 (within the path tracer's noise either way) */
#define SUB_DUST 1e-5

/* The volume's shadow on the air of the sky's inflow (sky_inflow.h), by the sun's columns (made
 * for sun_g before the solve) in the medium the first order and the photons see (mc_sig: the
 * forward peak cut), as the path tracer's shadow rays, out to reach metres along a sample's ray. */
typedef struct {
    const atmos__nishita_plan *np;
    const atmos_atmosphere *atm;
    double sun_g[3], sun_w[3], reach;
} inflow_shade;

static void world_to_frame(const atmos__nishita_plan *np, const double p[3], double q[3])
{
    atmos__vol_point_to_index(&np->x, p, q);
    for (int a = 0; a < 3; a++) q[a] *= np->x.vs;
}

/* what the volume's shadow takes from the air's light along cw + t d, t in [0, min(K, reach)] */
static void shade_air(const void *u, const double cw[3], const double d[3], double K, double *D)
{
    const inflow_shade *sh = u;
    double q[3], dg[3];
    world_to_frame(sh->np, cw, q);
    atmos__vol_dir_to_frame(&sh->np->x, d, dg);
    atmos__nishita_air_shadow(sh->np, sh->atm, cw, d, q, dg, sh->sun_w, sh->sun_g,
                              (const float(*)[ATMOS_MAX_WAVELENGTHS])sh->np->mc_sig, 0, fmin(K, sh->reach), D);
}

/* The sky's and the ground's radiance entering the grid along each direction of q (DO_NMU x
 * DO_NPHI, atmos__do_quadrature's order: the cosines descending), the mean over the direction's
 * patch (its Gauss-Legendre weight's band of cosines, its azimuth's sector), per wavelength:
 * in[dir * n + w]; the air in the volume's shadow lit by the sky alone (the ground's shadow is
 * not in it: docs/accuracy.md). Returns 1 when any is not 0. */
static int sky_inflow(const atmos_atmosphere *atm, const atmos__nishita_plan *np, const atmos__do_quad *q,
                      const double sun_w[3], double *in, int threads)
{
    double cen[3], cw[3], top[DO_NMU + 1] = {1};
    for (int a = 0; a < 3; a++) cen[a] = 0.5 * (np->g.box_lo[a] + np->g.box_hi[a]);
    atmos__sky_inflow_point(atm, &np->x, cen, cw);
    inflow_shade sh = {np, atm, {0, 0, 0}, {sun_w[0], sun_w[1], sun_w[2]}, 0};
    for (int a = 0; a < 3; a++) sh.reach += (np->g.box_hi[a] - np->g.box_lo[a]) * (np->g.box_hi[a] - np->g.box_lo[a]);
    sh.reach = 4 * sqrt(sh.reach); /* 4 box diagonals */
    atmos__vol_dir_to_frame(&np->x, sun_w, sh.sun_g);
    const atmos__sky_air_shade air = {shade_air, &sh};
    /* the bands of cosines: band i from top[i] down to top[i + 1] */
    for (int i = 0; i < DO_NMU; i++)
        top[i + 1] = i == DO_NMU - 1 ? -1 : top[i] - q->w[i * DO_NPHI] * DO_NPHI / (2 * ATMOS_PI);
    int any = 0;
    /* the patches, each its own sums, on the threads (the same numbers) */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(| : any)
    for (int d = 0; d < DO_NMU * DO_NPHI; d++) {
        const int i = d / DO_NPHI, j = d % DO_NPHI;
        double *L = in + (size_t)d * np->n;
        atmos__sky_patch_inflow(atm, cw, sun_w, np->n, top[i + 1], top[i], 2 * ATMOS_PI * j / DO_NPHI,
                                2 * ATMOS_PI * (j + 1) / DO_NPHI, SKY_NS, np->col_valid ? &air : NULL, L);
        for (int w = 0; w < np->n; w++) any |= L[w] != 0;
    }
    return any;
}

/* The voxel's mean of e^-tau along the sun about its centre, e^-tau sinh(h) / h (h: half the
 * optical depth across it along the sun, h <= tau), in single precision's polynomial exponential
 * (relative error < 1e-6; the library's exp and sinh took half the cells' set-up): below h 0.5 by
 * the series of sinh(h) / h, else as (e^(h - tau) - e^(-h - tau)) / 2h, no exponent above 0. */
ATMOS_CLONE_HELPER double mean_transmittance_series(double tau, double h)
{
    const double h2 = h * h;
    return atmos__expf_fast((float)-tau) * (1 + h2 * (1.0 / 6 + h2 * (1.0 / 120 + h2 * (1.0 / 5040))));
}

ATMOS_CLONE_HELPER double mean_transmittance(double tau, double h)
{
    if (h < 0.5) return mean_transmittance_series(tau, h);
    return (atmos__expf_fast((float)(h - tau)) - atmos__expf_fast((float)(-h - tau))) / (2 * h);
}

/* (1 - e^-x) / x: the mean of e^-tau over [0, x], the share of a voxel's own emission that its
 * optical size x lets reach a point of it (as a length: the voxel's size times this). */
static inline double escape(double x)
{
    return x < 1e-3 ? 1 - 0.5 * x : (1 - atmos__expf_fast((float)-x)) / x;
}

/* What a voxel sends its face neighbours as their first scattering (sub_terms), per wavelength
 * w < n (o, 1/m): its sigma_s escape(sigma_t h / SUB_NB_TAU), 0 where its sigma_s is 0 (u: its grid
 * index times nf); its sigma_s bounded where its optical size passes SUB_NB_TAU (its sigma_s alone
 * grew without bound and drew a cell of a dense tower 1.5 times as bright as the cloud about it,
 * the path tracer 0.9 times). */
static inline void nb_value(const atmos__nishita_plan *np, int n, size_t u, double hv, double *o)
{
    const sgrid *g = &np->g;
    const int nf = np->nf;
    for (int w = 0; w < n; w++) {
        double t = 0, sc = 0;
        for (int f = 0; f < nf; f++) t += g->v[u + f] * np->mc_sig_ms[f][w], sc += g->v[u + f] * np->mc_sca[f][w];
        o[w] = sc != 0 ? sc * escape(t * hv / SUB_NB_TAU) : 0;
    }
}

/* nb_value of the voxels of planes z0 .. z0 + nz - 1 (those inside the grid) into nb, plane
 * z - z0's voxel (x, y) at ((z - z0) c[1] + y) c[0] + x, n each. */
static void nb_planes(const atmos__nishita_plan *np, int n, int z0, int nz, double hv, double *nb)
{
    const sgrid *g = &np->g;
    const size_t plane = (size_t)g->c[0] * g->c[1];
    for (int z = z0 < 0 ? 0 : z0; z < z0 + nz && z < g->c[2]; z++)
        for (size_t p = 0; p < plane; p++)
            nb_value(np, n, ((size_t)z * plane + p) * np->nf, hv, nb + ((size_t)(z - z0) * plane + p) * n);
}

/* The first scattering the voxel (x, y, z)'s six face neighbours send it, per wavelength w < n
 * (out, 1/m, added in the order -x, +x, -y, +y, -z, +z): their nb_value, from nb (nb_planes from
 * plane z0, which holds z - 1 .. z + 1 where they are inside the grid). */
static void neighbours(const atmos__nishita_plan *np, int n, int x, int y, int z, const double *nb, int z0,
                       double *out)
{
    const sgrid *g = &np->g;
    const int xyz[3] = {x, y, z};
    for (int a = 0; a < 3; a++)
        for (int d = -1; d <= 1; d += 2) {
            int q[3] = {xyz[0], xyz[1], xyz[2]};
            q[a] += d;
            if (q[a] < 0 || q[a] >= g->c[a]) continue;
            const double *v = nb + (((size_t)(q[2] - z0) * g->c[1] + q[1]) * g->c[0] + q[0]) * n;
            for (int w = 0; w < n; w++) out[w] += v[w];
        }
}

/* The cells' medium, the same for every sun: per wavelength the cells' mean sigma_t and sigma_s
 * (1/m; st + 2 cells w, the cells' sigma_t then their sigma_s), and the render voxels holding a
 * field's density, cell by cell in the order z, y, x (vox[first[c] .. first[c + 1]): each one's
 * place in its cell, x | y << 4 | z << 8, the cells' edge at most 16 voxels). An empty voxel adds
 * 0 to every sum: a sun's source (cell_source) visits the others alone. With cells of more than
 * one voxel, per listed voxel e and wavelength w the sun-free parts of its local radiance
 * (cell_source's sub-cell term): sub[2 (e n + w)] = h sigma_s escape(sigma_t h), and
 * sub[2 (e n + w) + 1] = SUB_NB h times its six face neighbours' sigma_s; and per cell c and
 * wavelength w dust[c n + w], SUB_DUST times the largest sigma_s of its voxels. */
#define DO_CELL_MAX 16 /* the packing's bound on a cell's edge (nishita.mc_cell's cap) */
struct atmos__do_cells {
    float *st, *sub, *dust;
    uint16_t *vox;
    size_t *first;
};

void atmos__do_cells_free(atmos__do_cells *dc)
{
    if (dc) free(dc->st), free(dc->sub), free(dc->dust), free(dc->vox), free(dc->first), free(dc);
}

/* Cell (i, j, k)'s voxels holding a field's density: their count, with vox (else NULL) their
 * places into vox, with at, as (else NULL) their sums of sigma_t and sigma_s per wavelength. */
static size_t cell_voxels(const atmos__nishita_plan *np, int s, int n, int i, int j, int k, uint16_t *vox, double *at,
                          double *as)
{
    const sgrid *g = &np->g;
    const int nf = np->nf;
    size_t m = 0;
    for (int z = k * s; z < (k + 1) * s && z < g->c[2]; z++)
        for (int y = j * s; y < (j + 1) * s && y < g->c[1]; y++)
            for (int x = i * s; x < (i + 1) * s && x < g->c[0]; x++) {
                const size_t v = (((size_t)z * g->c[1] + y) * g->c[0] + x) * nf;
                int any = 0;
                for (int f = 0; f < nf; f++) any |= g->v[v + f] != 0;
                if (!any) continue;
                if (vox) vox[m] = (uint16_t)((x - i * s) | (y - j * s) << 4 | (z - k * s) << 8);
                m++;
                for (int w = 0; at && w < n; w++) {
                    double t = 0, sc = 0;
                    for (int f = 0; f < nf; f++)
                        t += g->v[v + f] * np->mc_sig_ms[f][w], sc += g->v[v + f] * np->mc_sca[f][w];
                    at[w] += t, as[w] += sc;
                }
            }
    return m;
}

/* One pass of cells_make over the cells: list 0, their voxels counted into first[c + 1] and their
 * mean sigma_t and sigma_s into st; list 1, their voxels' places into vox from first[c]. */
static void cells_pass(const atmos__nishita_plan *np, const atmos__lfield *F, atmos__do_cells *dc, int n, int threads,
                       int list)
{
    const int s = F->s;
    const size_t cells = (size_t)F->c[0] * F->c[1] * F->c[2];
    const double inv = 1.0 / ((double)s * s * s);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int k = 0; k < F->c[2]; k++)
        for (int j = 0; j < F->c[1]; j++)
            for (int i = 0; i < F->c[0]; i++) {
                const size_t c = ((size_t)k * F->c[1] + j) * F->c[0] + i;
                if (list) {
                    cell_voxels(np, s, n, i, j, k, dc->vox + dc->first[c], NULL, NULL);
                    continue;
                }
                double at[ATMOS_MAX_WAVELENGTHS], as[ATMOS_MAX_WAVELENGTHS]; /* n of them set */
                for (int w = 0; w < n; w++) at[w] = as[w] = 0;
                dc->first[c + 1] = cell_voxels(np, s, n, i, j, k, NULL, at, as);
                for (int w = 0; w < n; w++)
                    dc->st[2 * cells * w + c] = (float)(at[w] * inv),
                                           dc->st[2 * cells * w + cells + c] = (float)(as[w] * inv);
            }
}

/* The grid index (times nf) of the kept voxel packed as p in cell (i, j, k) of edge s. */
static inline size_t kept_voxel(const sgrid *g, int nf, int s, int i, int j, int k, int p, int *x, int *y, int *z)
{
    *x = i * s + (p & 15), *y = j * s + (p >> 4 & 15), *z = k * s + (p >> 8);
    return (((size_t)*z * g->c[1] + *y) * g->c[0] + *x) * nf;
}

/* dc->sub and dc->dust (struct atmos__do_cells) for the voxels listed in dc. Each plane of cells
 * with the neighbours' values of its voxels' planes and the one either side made once (nb_planes,
 * a buffer a thread: each voxel's value was made again for each of its six neighbours). 0: out of
 * memory. */
static int sub_terms(const atmos__nishita_plan *np, const atmos__lfield *F, atmos__do_cells *dc, int n, int threads)
{
    const sgrid *g = &np->g;
    const int s = F->s, nf = np->nf;
    const double hv = 1.0 / g->sc;
    const size_t span = (size_t)(s + 2) * g->c[0] * g->c[1] * n; /* a thread's planes */
    int nt = threads > F->c[2] ? F->c[2] : threads; /* no more than planes */
    nt = nt < 1 ? 1 : nt;
    double *buf = malloc(sizeof(double) * span * nt);
    if (!buf) return 0;
#pragma omp parallel for schedule(static) num_threads(nt)
    for (int k = 0; k < F->c[2]; k++) {
        double *nb = buf + span * omp_get_thread_num();
        const int z0 = k * s - 1;
        nb_planes(np, n, z0, s + 2, hv, nb);
        for (int j = 0; j < F->c[1]; j++)
            for (int i = 0; i < F->c[0]; i++) {
                const size_t c = ((size_t)k * F->c[1] + j) * F->c[0] + i;
                double scmax[ATMOS_MAX_WAVELENGTHS];
                for (int w = 0; w < n; w++) scmax[w] = 0;
                for (size_t e = dc->first[c]; e < dc->first[c + 1]; e++) {
                    int x, y, z;
                    const size_t v = kept_voxel(g, nf, s, i, j, k, dc->vox[e], &x, &y, &z);
                    double scn[ATMOS_MAX_WAVELENGTHS]; /* n of them: not all 128 set each voxel */
                    for (int w = 0; w < n; w++) scn[w] = 0;
                    neighbours(np, n, x, y, z, nb, z0, scn);
                    for (int w = 0; w < n; w++) {
                        double t = 0, sc = 0;
                        for (int f = 0; f < nf; f++)
                            t += g->v[v + f] * np->mc_sig_ms[f][w], sc += g->v[v + f] * np->mc_sca[f][w];
                        dc->sub[2 * (e * n + w)] = (float)(hv * sc * escape(t * hv));
                        dc->sub[2 * (e * n + w) + 1] = (float)(hv * SUB_NB * scn[w]);
                        scmax[w] = sc > scmax[w] ? sc : scmax[w];
                    }
                }
                for (int w = 0; w < n; w++) dc->dust[c * n + w] = (float)(SUB_DUST * scmax[w]);
            }
    }
    free(buf);
    return 1;
}

/* The cells' medium of np on F's cells (struct atmos__do_cells); NULL when out of memory or
 * when a cell's edge is outside [1, DO_CELL_MAX]. */
static atmos__do_cells *cells_make(const atmos__nishita_plan *np, const atmos__lfield *F, int n, int threads)
{
    const int s = F->s;
    const size_t cells = (size_t)F->c[0] * F->c[1] * F->c[2];
    if (s < 1 || s > DO_CELL_MAX) return NULL;
    atmos__do_cells *dc = calloc(1, sizeof *dc);
    if (!dc || !(dc->st = malloc(sizeof(float) * cells * 2 * n)) ||
        !(dc->first = malloc(sizeof(size_t) * (cells + 1)))) {
        atmos__do_cells_free(dc);
        return NULL;
    }
    cells_pass(np, F, dc, n, threads, 0);
    dc->first[0] = 0;
    for (size_t c = 0; c < cells; c++) dc->first[c + 1] += dc->first[c];
    if (!(dc->vox = malloc(sizeof(uint16_t) * (dc->first[cells] + 1)))) {
        atmos__do_cells_free(dc);
        return NULL;
    }
    cells_pass(np, F, dc, n, threads, 1);
    if (s > 1 && (!(dc->sub = malloc(sizeof(float) * 2 * n * (dc->first[cells] + 1))) ||
                  !(dc->dust = malloc(sizeof(float) * n * cells)))) {
        atmos__do_cells_free(dc);
        return NULL;
    }
    if (s > 1 && !sub_terms(np, F, dc, n, threads)) {
        atmos__do_cells_free(dc);
        return NULL;
    }
    return dc;
}

#define CS_BLOCK 64 /* cell_source's voxels a block: its arrays stay in L1 */

/* The sun seen from the render grid, for cell_source: len the chord per unit sigma_t along the
 * dominant axis (m), hv a voxel's size (m), lbar its mean chord along the light (m), lt the
 * light's travel (a unit vector in the grid's frame). */
typedef struct {
    double len, hv, lbar, lt[3];
} sun_geom;

/* The sunlight at the sunward faces of voxels id[0 .. k) of a block (per unit sunlight; their
 * grid indices times nf vi, their coordinates xyz; sig: a wavelength's sigma_t per field) into
 * tff[0 .. k): per axis a whose face the light enters (lt, the light's travel in sg), that face's
 * share of the light entering, |lt_a| / M (M = sum |lt_a|), times e^-tau at the face. tau at a
 * face: the column at the sunward neighbour's centre plus that neighbour's sigma_t over the
 * light's part of the half voxel between them, |lt_a| h / 2 (0 outside the grid). Times
 * escape(sigma_t h / M) (h / M: the voxel's mean chord along the light) it is the voxel's mean
 * sunlight through its faces (source_block): in a voxel of many optical depths the light
 * entering its faces over sigma_t h, sum |lt_a| T_a / (sigma_t h). The columns gathered, then
 * each face's exponentials in a vector loop (the same operations in the same order as one voxel
 * at a time). */
ATMOS_CLONE_HELPER void sun_faces(const atmos__nishita_plan *np, const size_t *vi, const int (*xyz)[3], const int *id, int k,
                                  const sun_geom *sg, const float *sig, double *tff)
{
    const sgrid *g = &np->g;
    const int nf = np->nf;
    const double *lt = sg->lt, M = fabs(lt[0]) + fabs(lt[1]) + fabs(lt[2]);
    const ptrdiff_t stride[3] = {nf, (ptrdiff_t)g->c[0] * nf, (ptrdiff_t)g->c[0] * g->c[1] * nf};
    double tau[CS_BLOCK];
    for (int q = 0; q < k; q++) tff[q] = 0;
    for (int a = 0; a < 3; a++) {
        if (lt[a] == 0) continue;
        const int d = lt[a] > 0 ? -1 : 1;
        const double half = 0.5 * sg->hv * fabs(lt[a]), la = fabs(lt[a]);
        for (int q = 0; q < k; q++) {
            const int e = id[q], qa = xyz[e][a] + d;
            double ta = 0;
            if (qa >= 0 && qa < g->c[a]) {
                const size_t u = (size_t)((ptrdiff_t)vi[e] + d * stride[a]);
                for (int f = 0; f < nf; f++) ta += (np->col[u + f] + g->v[u + f] * half) * sig[f];
            }
            tau[q] = ta;
        }
        for (int q = 0; q < k; q++) tff[q] += la * atmos__expf_fast((float)-tau[q]);
    }
    for (int q = 0; q < k; q++) tff[q] /= M;
}

/* cell_source's sums over a block of m listed voxels (their grid indices times nf vi, their first
 * list entry e0) for wavelength w: acc[0 .. 3] += the voxels' sigma_s T_sun, sigma_s, local
 * radiance and sigma_s times it, *nv += the scattering voxels, one of dust (sigma_s below dust) as
 * its sigma_s / dust (sub: the sub-cell term's, cells of more than one voxel; sg: the sun's
 * geometry). The same operations in the same order per
 * wavelength as one voxel at a time, in four loops: the medium gathered, the exponentials of
 * every voxel in one vector loop (both sides of mean_transmittance's branch, the one kept chosen
 * per voxel: the same values; a block whose voxels all take the series side, the optically thin
 * ones, that side alone), the faces' estimate where it is the larger (sun_faces, vectorised
 * over the voxels it may win),
 * the sums in the voxels' order (the same bits as the voxel-at-a-time loop; built for AVX2 as
 * well as the baseline, chosen at run time). */
ATMOS_CLONES static void source_block(const atmos__nishita_plan *np, const atmos__do_cells *dc, int n, int w,
                                      const size_t *vi, const int (*xyz)[3], size_t e0, int m, const float *sig,
                                      const float *sca, const sun_geom *sg, int sub, double dust, double acc[4],
                                      double *nv)
{
    const double len = sg->len;
    const float *gv = np->g.v, *col = np->col;
    const int nf = np->nf;
    double t[CS_BLOCK], sc[CS_BLOCK], tau[CS_BLOCK], tr[CS_BLOCK], tf[CS_BLOCK];
    float a0[CS_BLOCK], a1[CS_BLOCK];
    for (int e = 0; e < m; e++) {
        double tt = 0, ss = 0, ta = 0;
        for (int f = 0; f < nf; f++)
            tt += gv[vi[e] + f] * sig[f], ss += gv[vi[e] + f] * sca[f], ta += col[vi[e] + f] * sig[f];
        t[e] = tt, sc[e] = ss, tau[e] = ta;
    }
    for (int e = 0; sub && e < m; e++) a0[e] = dc->sub[2 * ((e0 + e) * n + w)], a1[e] = dc->sub[2 * ((e0 + e) * n + w) + 1];
    double hs[CS_BLOCK], hmax = 0;
    for (int e = 0; e < m; e++) {
        const double tl = t[e] * len, ta = tau[e]; /* fmin's value, no call: neither is NaN */
        hs[e] = 0.5 * (tl < 2 * ta ? tl : 2 * ta), hmax = hs[e] > hmax ? hs[e] : hmax;
    }
    if (hmax < 0.5) /* a block thin along the chord: mean_transmittance's series side alone */
        for (int e = 0; e < m; e++)
            tr[e] = mean_transmittance_series(tau[e], hs[e]), tf[e] = atmos__expf_fast((float)(hs[e] - tau[e]));
    else
        for (int e = 0; e < m; e++)
            tr[e] = mean_transmittance(tau[e], hs[e]), tf[e] = atmos__expf_fast((float)(hs[e] - tau[e]));
    /* the faces' estimate where it is the larger: a voxel thick along the chord. It is at most
     * escape(sigma_t lbar) (its faces' share at most 1): the voxels below that alone listed */
    double esc[CS_BLOCK], tff[CS_BLOCK];
    int id[CS_BLOCK], k = 0;
    double xmax = 0; /* a block of optically thin voxels: escape's series alone, no exponential */
    for (int e = 0; e < m; e++) xmax = t[e] * sg->lbar > xmax ? t[e] * sg->lbar : xmax;
    if (xmax < 1e-3)
        for (int e = 0; e < m; e++) esc[e] = 1 - 0.5 * (t[e] * sg->lbar); /* escape's own, below 1e-3 */
    else
        for (int e = 0; e < m; e++) esc[e] = escape(t[e] * sg->lbar);
    for (int e = 0; e < m; e++) id[k] = e, k += sc[e] != 0 && tr[e] < esc[e];
    if (k) sun_faces(np, vi, xyz, id, k, sg, sig, tff);
    for (int q = 0; q < k; q++) {
        const int e = id[q];
        const double trf = tff[q] * esc[e];
        if (trf > tr[e]) tr[e] = trf, tf[e] = tff[q];
    }
    for (int e = 0; e < m; e++) {
        acc[1] += sc[e];
        if (!(sc[e] != 0)) continue;
        acc[0] += sc[e] * tr[e];
        if (!sub) continue; /* a voxel's cell: no spread */
        const double l1 = tr[e] * a0[e] + a1[e] * tf[e];
        const double u = sc[e] < dust ? sc[e] / dust : 1; /* a voxel of dust: in proportion */
        acc[2] += u * l1, acc[3] += sc[e] * l1, *nv += u;
    }
}

/* Per cell and wavelength w < n the mean of sigma_s E T_sun over its render voxels (src + cells w)
 * for the sun along sun_g (grid frame), over the voxels holding a field's density (dc).
 * And the cell's sub-cell term (dsrc + cells w, per unit E; 0 for cells of 1 voxel): the eye pass
 * multiplies the cell's one radiance by each voxel's sigma_s, where it should read the voxels'
 * radiance weighted by their sigma_s, and a dense sunlit voxel sees its own first scattering
 * (docs/lightfield.md, "The cells' averaging"). A voxel's local radiance is taken as its first
 * order's emission sigma_s T_sun over the voxel's size, at most its mean free path
 * (h escape(sigma_t h)), plus SUB_NB h times its six face neighbours' sigma_s seen with the
 * sunlight at its sunward face (their first scattering, in a texture whose dense voxels sit
 * together; with the voxel's own mean T_sun a dense voxel's neighbours looked dark); the term is the
 * mean of that weighted by sigma_s less its plain mean over the scattering voxels (an empty
 * voxel's radiance is its neighbours', not 0: counted as 0 a uniform slab's edge cells got a
 * term; a voxel of dust, below SUB_DUST of the cell's densest, is nearly empty and counts in
 * proportion), the covariance of sigma_s and the local radiance over sigma_s's mean: 0 where the
 * scattering voxels are uniform. The voxels in blocks (source_block).
 * A voxel's mean sunlight is the larger of two estimates: along the chord through its centre
 * along the sun's dominant axis (the column at the centre, mean_transmittance), and through its
 * sunward faces (sun_faces). The chord's is the right one in a voxel of a few optical depths at
 * most; in a thick one it takes the light through the neighbours along that axis only: a
 * horizontal deck one voxel (tens of optical depths) thick at a low sun is lit through the deck
 * (about 130 optical depths to its voxel's centre), not through its top face, and the sunlit
 * skin the voxel holds, the light entering its faces, was lost (docs/slice.md, "Why the deck is
 * dark"). The faces' estimate alone was darker in thin clouds (its face columns are cruder). */
static void cell_source(const atmos__nishita_plan *np, const atmos__lfield *F, const atmos__do_cells *dc, int n,
                        const double sun_g[3], double *src, double *dsrc, int threads)
{
    const sgrid *g = &np->g;
    const int s = F->s, nf = np->nf;
    const size_t cells = (size_t)F->c[0] * F->c[1] * F->c[2];
    double amax = 0;
    for (int a = 0; a < 3; a++) amax = fmax(amax, fabs(sun_g[a]));
    const double len = 1.0 / amax / g->sc, inv = 1.0 / ((double)s * s * s), hv = 1.0 / g->sc;
    const double lbar = hv / (fabs(sun_g[0]) + fabs(sun_g[1]) + fabs(sun_g[2])); /* the mean chord */
    const sun_geom sg = {len, hv, lbar, {sun_g[0], sun_g[1], sun_g[2]}};
    float sig[ATMOS_MAX_WAVELENGTHS][ATMOS_VOLUME_MAX_FIELDS], sca[ATMOS_MAX_WAVELENGTHS][ATMOS_VOLUME_MAX_FIELDS];
    for (int f = 0; f < nf; f++)
        for (int w = 0; w < n; w++) sig[w][f] = np->mc_sig_ms[f][w], sca[w][f] = np->mc_sca[f][w];
    /* planes of cells handed out one at a time: the Disney cloud's voxels are 46 % in the lower
       half of its planes and 54 % in the upper (each cell's sums alone: the same bits) */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int k = 0; k < F->c[2]; k++)
        for (int j = 0; j < F->c[1]; j++)
            for (int i = 0; i < F->c[0]; i++) {
                const size_t c = ((size_t)k * F->c[1] + j) * F->c[0] + i;
                double acc[ATMOS_MAX_WAVELENGTHS][4];
                double nv[ATMOS_MAX_WAVELENGTHS];
                for (int w = 0; w < n; w++) acc[w][0] = acc[w][1] = acc[w][2] = acc[w][3] = 0, nv[w] = 0;
                for (size_t e0 = dc->first[c]; e0 < dc->first[c + 1]; e0 += CS_BLOCK) {
                    const int m = dc->first[c + 1] - e0 < CS_BLOCK ? (int)(dc->first[c + 1] - e0) : CS_BLOCK;
                    size_t vi[CS_BLOCK];
                    int xyz[CS_BLOCK][3];
                    for (int e = 0; e < m; e++)
                        vi[e] = kept_voxel(g, nf, s, i, j, k, dc->vox[e0 + e], &xyz[e][0], &xyz[e][1], &xyz[e][2]);
                    for (int w = 0; w < n; w++)
                        source_block(np, dc, n, w, vi, (const int(*)[3])xyz, e0, m, sig[w], sca[w], &sg, s > 1,
                                     s > 1 ? dc->dust[c * n + w] : 0, acc[w], &nv[w]);
                }
                for (int w = 0; w < n; w++)
                    src[cells * w + c] = acc[w][0] * inv,
                               dsrc[cells * w + c] = nv[w] > 0 ? acc[w][3] / acc[w][1] - acc[w][2] / nv[w] : 0;
            }
}

/* The source iterations that replace GMRES in an optically thin medium (atmos__do_rho's bound
 * rho on the scattering operator of every wavelength's problem; P's medium and phase set per
 * wavelength), always from 0, so that the error is at most rho^k times the field itself whatever
 * came before (from a warm start it would be rho^k times the field's change since the last sun,
 * which need not be small against a field that fell, e.g. at sunset): one where rho <= DO_TOL (GMRES from 0 took
 * two sweeps: the source's and one iteration's), two where rho^2 <= DO_TOL; else 0 (GMRES). */
static int thin_sweeps(const atmos__do_problem *P0, const float *st, size_t cells, int n, const double chi[][4],
                       double *bound)
{
    atmos__do_problem P = *P0;
    double rho = 0;
    for (int w = 0; w < n; w++) {
        P.sig_s = st + 2 * cells * w + cells;
        for (int l = 0; l <= P.L; l++) P.chi[l] = chi[w][l];
        rho = fmax(rho, atmos__do_rho(&P));
    }
    const int k = rho <= DO_TOL ? 1 : rho * rho <= DO_TOL ? 2 : 0;
    *bound = k == 1 ? rho : rho * rho;
    return k;
}

/* What the wavelengths' solves share: the problem but for the wavelength's medium, emission and
 * inflow; per wavelength the cells' sigma_t and sigma_s (st, 2 cells each) and the mean of
 * sigma_s E T_sun (src, cells each). */
typedef struct {
    atmos__do_problem P;
    int n, K;
    size_t cells;
    const float *st;
    const double *src, *dsrc, *Ys, *E, *sky; /* sky: per direction and wavelength, NULL: none */
    const double (*chi)[4];
    float *coef;
    double *kappa; /* per wavelength (atmos__do_problem's), or NULL */
} do_fill;

/* Wavelength w's solve from phi as it is (its start) on threads threads with ws's buffers and q1
 * (cells * K) for the emission: its moments into phi, its coefficients into D->coef. */
static int solve_w(const do_fill *D, int w, double *q1, int threads, int dsa, atmos__do_ws *ws, double *phi,
                   atmos__do_stats *S)
{
    const size_t cells = D->cells;
    const int n = D->n, K = D->K;
    atmos__do_problem P = D->P;
    double inw[ATMOS__DO_NMAX];
    P.sig_t = D->st + 2 * cells * w, P.sig_s = P.sig_t + cells, P.q1 = q1, P.threads = threads, P.ws = ws;
    P.dsa = dsa, P.kappa = D->kappa ? D->kappa + w : NULL;
    double chik[ATMOS__DO_KMAX]; /* chi_l of each coefficient */
    for (int l = 0; l <= P.L; l++) P.chi[l] = D->chi[w][l];
    for (int k = 0; k < K; k++) chik[k] = D->chi[w][atmos__sh_degree(k)];
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
    for (size_t c = 0; c < cells; c++) {
        const double e = D->E[w] * D->src[cells * w + c];
        for (int k = 0; k < K; k++) q1[c * K + k] = e * chik[k] * D->Ys[k];
    }
    for (int d = 0; D->sky && d < P.quad->n; d++) inw[d] = D->sky[d * n + w];
    P.inflow = D->sky ? inw : NULL;
    const int ok = atmos__do_solve(&P, phi, S);
    if (!ok) return 0;
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
    for (size_t c = 0; c < cells; c++) {
        /* the sub-cell term as radiance moments of the first order's emission over a length:
           q1's harmonics times the term, into the coefficients only (phi stays the solve's) */
        const double e = D->E[w] * D->dsrc[cells * w + c];
        for (int k = 0; k < K; k++)
            D->coef[(c * n + w) * K + k] = (float)(chik[k] * (phi[c * K + k] + e * chik[k] * D->Ys[k]));
    }
    return 1;
}

/* The wavelengths to solve, wl[0 .. ns - 1] (the first on all the threads, from phi_all's start
 * with warm, else 0; the others each on one thread, in parallel, from the first one's solution
 * times the ratio of the sunlight, or of the sky's mean radiance with the sun off: the clouds are
 * nearly grey, 2 GMRES iterations on the Disney cloud where the last sun's start takes 3; with
 * warm, from their own last solution plus the ratio times the first one's change since its last:
 * the nearly grey start's error is then only its change, and the Disney cloud's second and third
 * wavelengths, the sun turned 3 degrees, take one GMRES iteration each instead of 4 and 5). When
 * the first one's solve switched the diffusion preconditioner on (ATMOS__DO_DSA_AUTO), the others
 * have it from their first iteration: their media are nearly the first one's, and their rates
 * would switch it on later anyway (the generated storm: the third wavelength 12 GMRES iterations
 * instead of 16, the fill -1.1 % instructions; the second's 10 either way). But
 * when the first, started from 0, took one GMRES iteration or none (an optically thin medium:
 * its first order, the sweep of the source, is nearly the whole), the others start from 0 too:
 * one iteration each, where the ratio's start pays a sweep for its residual and then mostly
 * still that iteration (the Disney cloud in `atmos bench slice`, at its file's densities: 2
 * sweeps a wavelength instead of 3). Which thread solves which wavelength changes no number.
 * Returns 0 when out of memory. */
static int solve_all(const do_fill *D, const int *wl, int ns, const double *skymean, double *phi_all, int warm,
                     int threads, atmos__do_ws *ws, atmos__nishita_do_info *info)
{
    const size_t NK = D->cells * D->K;
    /* the other wavelengths' threads: no more than there are wavelengths or buffers */
    int nt = threads < ns - 1 ? threads : ns - 1;
    nt = nt > WS_MAX ? WS_MAX : nt < 1 ? 1 : nt;
    const int w0 = wl[0];
    /* q1 per thread and the first wavelength's last solution, kept with ws (a sun move's solve
       then touches no fresh pages: 1 450 page faults a frame on the Disney cloud) */
    const int keep_last = warm && ns > 1;
    const size_t bytes = sizeof(double) * NK * (size_t)(nt + keep_last);
    double *own = ws ? NULL : malloc(bytes), *q1 = ws ? atmos__do_ws_aux(ws, bytes) : own;
    double *phi0 = phi_all + (size_t)w0 * NK;
    atmos__do_ws *wss[WS_MAX];
    int oks[ATMOS_MAX_WAVELENGTHS];
    atmos__do_stats S[ATMOS_MAX_WAVELENGTHS];
    if (!q1) return 0;
    for (int t = 0; t < nt; t++) wss[t] = atmos__do_ws_at(ws, t);
    if (!warm) memset(phi0, 0, sizeof(double) * NK);
    double *last0 = keep_last ? q1 + NK * nt : NULL;
    if (last0) memcpy(last0, phi0, sizeof(double) * NK);
    oks[0] = solve_w(D, w0, q1, threads, D->P.dsa, ws, phi0, &S[0]);
    const int thin = !warm && S[0].iters <= 1;
    const int dsa = S[0].dsa_at >= 0 ? ATMOS__DO_DSA_ON : D->P.dsa;
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
    for (int i = 1; i < ns; i++) {
        const int w = wl[i], t = omp_get_thread_num();
        const double ratio = !oks[0] || thin    ? 0
                             : D->E[w0] > 0     ? D->E[w] / D->E[w0]
                             : skymean[w0] > 0 ? skymean[w] / skymean[w0]
                                                : 0;
        double *phi = phi_all + (size_t)w * NK;
        if (last0 && ratio > 0)
            for (size_t j = 0; j < NK; j++) phi[j] += ratio * (phi0[j] - last0[j]);
        else
            for (size_t j = 0; j < NK; j++) phi[j] = ratio > 0 ? phi0[j] * ratio : warm ? phi[j] : 0;
        oks[i] = solve_w(D, w, q1 + NK * t, 1, dsa, wss[t], phi, &S[i]);
    }
    int ok = 1;
    for (int i = 0; i < ns; i++) {
        ok &= oks[i];
        info->iters += S[i].iters, info->sweeps += S[i].sweeps;
        info->resid = fmax(info->resid, S[i].resid);
    }
    free(own);
    return ok;
}

atmos_status atmos__nishita_do_fill(atmos_context *ctx, const atmos__nishita_plan *np, const atmos__lfield *F, int L,
                                    const double chi[][4], const double sun_w[3], const double *E,
                                    const atmos_atmosphere *atm, int threads, float *coef, double *phi_all, int warm,
                                    double *kappa, atmos__do_ws *ws, atmos__do_cells **dc,
                                    atmos__nishita_do_info *info)
{
    const int n = np->n, K = (L + 1) * (L + 1);
    const size_t cells = (size_t)F->c[0] * F->c[1] * F->c[2], NK = cells * K;
    const clock_t c0 = clock();
    memset(info, 0, sizeof *info);
    atmos__do_quad quad;
    do_fill D;
    memset(&D, 0, sizeof D);
    atmos__do_problem *P = &D.P;
    if (!atmos__do_quadrature(DO_NMU, DO_NPHI, &quad))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render nishita: no quadrature");
    for (int j = 0; j < 3; j++) {
        double e[3] = {0, 0, 0}, r[3];
        e[j] = 1;
        atmos__vol_dir_to_frame(&np->x, e, r);
        for (int a = 0; a < 3; a++) P->R[a][j] = r[a];
    }
    double lt[3], ltg[3], Ys[ATMOS__DO_KMAX];
    for (int a = 0; a < 3; a++) lt[a] = -sun_w[a];
    atmos__vol_dir_to_frame(&np->x, lt, ltg);
    atmos__sh_eval(L, lt, Ys);
    double skymean[ATMOS_MAX_WAVELENGTHS] = {0};
    double *sky = atm ? malloc(sizeof(double) * quad.n * n) : NULL;
    if (atm && !sky) return atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the field's solve");
    const int sky_on = sky && sky_inflow(atm, np, &quad, sun_w, sky, threads);
    for (int d = 0; sky_on && d < quad.n; d++)
        for (int w = 0; w < n; w++) skymean[w] += sky[d * n + w] * quad.w[d];
    if (!*dc) *dc = cells_make(np, F, n, threads);
    const float *st = *dc ? (*dc)->st : NULL; /* per wavelength sigma_t, sigma_s */
    double *src = malloc(sizeof(double) * cells * n * 2), *dsrc = src ? src + cells * n : NULL;
    int ok = st && src;
    P->c[0] = F->c[0], P->c[1] = F->c[1], P->c[2] = F->c[2], P->h = F->s / (double)np->g.sc, P->L = L, P->quad = &quad;
    P->theta = ATMOS__DO_THETA, P->theta_tau = ATMOS__DO_THETA_TAU; /* the weighted diamond (lfield_do.h) */
    P->tol = DO_TOL, P->max_iter = DO_MAX_ITER, P->restart = DO_RESTART;
    P->dsa = ATMOS__DO_DSA_AUTO; /* GMRES preconditioned by the P1 solve of the low moments where it pays
                                   (lfield_dsa.h, lfield_do.h) */
    D.n = n, D.K = K, D.cells = cells, D.st = st, D.src = src, D.dsrc = dsrc, D.Ys = Ys, D.E = E;
    D.sky = sky_on ? sky : NULL, D.chi = chi, D.coef = coef, D.kappa = kappa;
    /* a wavelength whose medium and phase are the last one's (a grey cloud, no sky): its field is
     * the last one's times the ratio of the sunlight; the others solved */
    int copy[ATMOS_MAX_WAVELENGTHS] = {0}, wl[ATMOS_MAX_WAVELENGTHS], ns = 0;
    if (ok) cell_source(np, F, *dc, n, ltg, src, dsrc, threads);
    /* an optically thin medium: source iterations alone */
    double bound = 0;
    P->richardson = ok ? thin_sweeps(P, st, cells, n, chi, &bound) : 0;
    if (P->richardson) warm = 0; /* thin_sweeps: from 0 */
    /* kappa's ratio kept only for a sunlight within KAPPA_E of its own (kappa[n + w]): after a
       larger change (the sun setting, the sky alone) the source's shape is not the last one's */
    for (int w = 0; kappa && w < n; w++)
        if (!warm || !(E[w] > 0) || !(kappa[n + w] > 0) || fabs(E[w] / kappa[n + w] - 1) > KAPPA_E) kappa[w] = 0;
    double kappa0[ATMOS_MAX_WAVELENGTHS];
    for (int w = 0; kappa && w < n; w++) kappa0[w] = kappa[w];
    for (int w = 0; w < n && ok; w++) {
        const float *sw = st + 2 * cells * w;
        copy[w] = w > 0 && E[w - 1] > 0 && !sky_on && !memcmp(chi[w], chi[w - 1], sizeof chi[w]) &&
                  !memcmp(sw, sw - 2 * cells, sizeof(float) * cells * 2) &&
                  !memcmp(src + cells * w, src + cells * (w - 1), sizeof(double) * cells) &&
                  !memcmp(dsrc + cells * w, dsrc + cells * (w - 1), sizeof(double) * cells);
        if (!copy[w]) wl[ns++] = w;
    }
    ok = ok && solve_all(&D, wl, ns, skymean, phi_all, warm, threads, ws, info);
    for (int w = 0; kappa && w < n; w++)
        if (kappa0[w] == 0) kappa[n + w] = E[w]; /* measured by this solve (0 where not solved) */
    if (P->richardson) info->source_its = P->richardson, info->resid = bound; /* no residual computed */
    for (int w = 1; w < n && ok; w++) {
        if (!copy[w]) continue;
        /* the last wavelength's moments, just before this one's in phi_all (w >= 1); indexed from
           their own start, as phi[i - NK] wrapped round as an unsigned index for every i < NK */
        double *phi = phi_all + (size_t)w * NK;
        const double *prev = phi_all + (size_t)(w - 1) * NK;
        for (size_t c = 0; c < cells; c++)
            for (int k = 0; k < K; k++)
                coef[(c * n + w) * K + k] = (float)(coef[(c * n + w - 1) * K + k] * (E[w] / E[w - 1]));
        for (size_t i = 0; i < NK; i++) phi[i] = prev[i] * (E[w] / E[w - 1]);
    }
    free(src), free(sky);
    info->cpu_s = (double)(clock() - c0) / CLOCKS_PER_SEC;
    info->directions = quad.n;
    return ok ? ATMOS_OK : atmos__error(ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the field's solve");
}
