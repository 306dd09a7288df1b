/* A discrete-ordinates solve of the diffuse light on a coarse grid of cubic cells (lfield_do.c,
 * docs/lightfield.md "A discrete-ordinates field"): the radiance of the orders >= 1 that a given
 * first-order emission starts, in a medium of per-cell extinction and scattering whose phase
 * function is given by its normalised Legendre moments up to degree L <= 3; the answer is the
 * radiance's real spherical harmonics of degree <= L per cell (the orthonormal ones of
 * atmos__sh_eval). Upwind sweeps (the step scheme, positive, or the weighted diamond: theta,
 * not positive), the scattering source re-projected on degree
 * <= L after every sweep, and restarted GMRES on the moments (the source iteration's fixed point).
 * The same numbers whatever the threads. Not part of the API. */
#ifndef ATMOS_LIGHT_LFIELD_DO_H
#define ATMOS_LIGHT_LFIELD_DO_H

#include <stddef.h>

#define ATMOS__DO_KMAX 16  /* coefficients per cell at most: degree 3 */
#define ATMOS__DO_NMAX 512 /* directions at most */

/* The renderers' sweeps' weighted diamond (atmos__do_problem's theta, theta_tau): 1/2, diamond
 * difference, in optically thick cells, toward the step scheme (1) in thin ones, over an optical
 * depth ATMOS__DO_THETA_TAU a cell. The step scheme alone diffuses too much across thick cells:
 * the rain's cumulus (cells of 4 voxels) too dark with the sun behind and too bright toward it;
 * the diamond leaves a slightly negative mean radiance deep inside thick clouds
 * (docs/lightfield.md, "The step scheme in thick cells"). */
#define ATMOS__DO_THETA 0.5
#define ATMOS__DO_THETA_TAU 1.0

/* The degree l of coefficient k of the real spherical harmonics (k = l^2 ... (l + 1)^2 - 1), k < 16. */
static inline int atmos__sh_degree(int k)
{
    return k >= 9 ? 3 : k >= 4 ? 2 : k >= 1 ? 1 : 0;
}

/* Real spherical harmonics (orthonormal over the sphere) of degree <= lmax (<= 3) at unit d. */
void atmos__sh_eval(int lmax, const double d[3], double *Y);

/* An angular quadrature: n directions (unit) and weights summing to 4 pi. */
typedef struct {
    int n;
    double dir[ATMOS__DO_NMAX][3], w[ATMOS__DO_NMAX];
} atmos__do_quad;

/* The product set of nmu Gauss-Legendre cosines about the z axis and nphi equally spaced
 * azimuths (half a step off the x axis): exact for the products of spherical harmonics of
 * degree <= min(2 nmu - 1, nphi - 1) / 2 in each. Returns 0 when nmu * nphi > ATMOS__DO_NMAX. */
int atmos__do_quadrature(int nmu, int nphi, atmos__do_quad *q);

/* Buffers kept between solves (the pages of a large one touched once, not per solve). */
typedef struct atmos__do_ws atmos__do_ws;
atmos__do_ws *atmos__do_ws_create(void);
/* The buffers of the i-th of concurrent solves (i = 0: ws itself), made when first asked for, freed
 * with ws; NULL when ws is or when out of memory (the solve then uses its own). Not thread-safe. */
atmos__do_ws *atmos__do_ws_at(atmos__do_ws *ws, int i);
void atmos__do_ws_free(atmos__do_ws *ws);
/* A second buffer of ws of at least bytes, for its owner's own arrays of each solve (kept, grown as
 * needed); NULL when out of memory. Not thread-safe. */
void *atmos__do_ws_aux(atmos__do_ws *ws, size_t bytes);

typedef struct {
    int c[3];                   /* cells, the first axis fastest */
    double h;                   /* cell edge, m */
    int L;                      /* degree, 0-3 */
    double chi[4];              /* the phase function's normalised Legendre moments, chi[0] = 1 */
    const float *sig_t, *sig_s; /* per cell, 1/m */
    const double *q1;           /* per cell and coefficient: the first-order emission's moments per m^3 */
    const double *inflow;       /* per direction of quad: the radiance entering through the grid's faces
                                   travelling along it (the same over the faces); NULL: none */
    const atmos__do_quad *quad; /* directions in the frame of the spherical harmonics */
    double R[3][3];             /* a direction's components along the cells' axes: R d */
    double tol;                 /* GMRES: relative residual */
    int max_iter, restart, threads;
    int leak;                   /* 1: the last source iteration by a sweep, which gives the leaving
                                   power; 0: from GMRES's residual, no sweep (stats' leak 0) */
    atmos__do_ws *ws;           /* the buffers to use (grown as needed); NULL: the solve's own */
    double theta;               /* the sweep's weighted diamond: 1 (or 0, unset) the step scheme,
                                   1/2 diamond difference (lfield_do.c, cell_faces()) */
    double theta_tau;           /* > 0: theta in optically thick cells only, a cell of optical depth
                                   tau 1 - (1 - theta) (1 - exp(-tau / theta_tau)); 0: in every cell */
    int dsa;                    /* ATMOS__DO_DSA_ON: GMRES right-preconditioned by a diffusion solve of
                                   the low moments (flexible GMRES; lfield_dsa.h); ATMOS__DO_DSA_AUTO:
                                   plain until its rate predicts more than ATMOS__DO_DSA_AFTER
                                   iterations, then preconditioned; 0: plain */
    int richardson;             /* > 0: that many source iterations from phi instead of GMRES (no
                                   residual: the caller knows them converged, the scattering
                                   operator's norm small; nishita_do.c's thin media); 0: GMRES */
    double *kappa;              /* in/out, or NULL: ||b|| / ||T (S x + q1)|| at the end of a solve that
                                   swept its source b (x its solution; the inflow's in both). A start
                                   from phi not 0 with *kappa > 0 takes ||b|| (GMRES's scale) as
                                   *kappa ||T (S x0 + q1)||, whose sweep is its first residual's, and
                                   leaves b's own sweep out: a warm start after a small change of
                                   the source (a sun move), one sweep fewer */
} atmos__do_problem;

typedef struct {
    int iters, sweeps;    /* GMRES iterations; sweeps of all the directions */
    double resid;         /* the last relative residual */
    double leak;          /* power leaving the grid (with the problem's leak, else 0) */
    double emitted;       /* power of the first-order emission (per 1 of q1 units m^3) */
    double entering;      /* power entering through the grid's faces (the inflow's) */
    int dsa_iters;        /* the diffusion preconditioner's conjugate-gradient iterations, all */
    int dsa_at;           /* the GMRES iterations before the preconditioner came on (0: from the
                             first); -1: it did not */
} atmos__do_stats;

#define ATMOS__DO_DSA_ON 1
#define ATMOS__DO_DSA_AUTO 2
#define ATMOS__DO_DSA_AFTER 12

/* A bound on the norm of P's scattering operator T S (a sweep of the scattering source, the
 * maximum norm), so that a source iteration multiplies a start's error by at most it: C tau, tau
 * the largest optical depth of scattering a ray can cross (the cells' largest sigma_s times a
 * cell's longest chord sqrt(3) h times the c[0] + c[1] + c[2] cells a ray crosses at most), C =
 * sum (2l + 1) |chi_l| (l <= L), the largest integral over the sphere of |the phase function|. */
double atmos__do_rho(const atmos__do_problem *P);

/* The radiance moments phi[cell * K + k], K = (L + 1)^2, of the orders >= 1 and of the inflow
 * (its uncollided part too; phi on entry: the start, 0 if nothing better). Returns 0 when out of
 * memory. */
int atmos__do_solve(const atmos__do_problem *P, double *phi, atmos__do_stats *st);

#endif
