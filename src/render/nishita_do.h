/* The Nishita renderer's discrete-ordinates field (nishita_do.c). Not part of the API. */
#ifndef ATMOS_RENDER_NISHITA_DO_H
#define ATMOS_RENDER_NISHITA_DO_H

#include "light/lfield_do.h"
#include "render/nishita_internal.h"

typedef struct {
    int directions, iters, sweeps; /* GMRES iterations and sweeps, summed over the wavelengths */
    double resid;                  /* the largest relative residual left; with source iterations
                                      (source_its > 0) not computed: the bound rho^k on the error */
    int source_its;                /* > 0: the source iterations that replaced GMRES (thin media) */
    double cpu_s;                  /* the process's CPU time during the solve */
} atmos__nishita_do_info;

/* The cells' medium, the same for every sun (nishita_do.c): made at a plan's first solve, kept
 * for the next suns' (the render grid does not change within a plan). */
typedef struct atmos__do_cells atmos__do_cells;
void atmos__do_cells_free(atmos__do_cells *dc);

/* The field's coefficients coef[(cell * n + w) * K + k], K = (L + 1)^2, for the sun sun_w
 * (world; E the sunlight per wavelength) and, with atm (else NULL), the sky's and the ground's
 * light entering through the grid's faces, by discrete ordinates on F's cells, chi[w] the
 * scattering's normalised Legendre moments; the sunlight's columns (np->col) made for this sun.
 * phi[(w * cells + cell) * K + k]: the radiance moments solved, per wavelength; on entry with warm
 * the last sun's, each wavelength's start (a warm start after a sun move), else ignored. kappa (or
 * NULL): per wavelength the ratio that lets a warm start leave its source's sweep out
 * (atmos__do_problem's) and, at kappa + n, the sunlight it was measured at, kept with phi; set
 * by a solve that sweeps its source. ws: the
 * solver's buffers, kept between suns (NULL: its own). *dc: the cells' medium, made when NULL and
 * kept for the next call (the caller frees it with atmos__do_cells_free). */
atmos_status atmos__nishita_do_fill(atmos_context *ctx, const atmos__nishita_plan *np, const atmos__lfield *F, int L,
                                    const double chi[][4], const double sun_w[3], const double *E,
                                    const atmos_atmosphere *atm, int threads, float *coef, double *phi, int warm,
                                    double *kappa, atmos__do_ws *ws, atmos__do_cells **dc,
                                    atmos__nishita_do_info *info);

#endif
