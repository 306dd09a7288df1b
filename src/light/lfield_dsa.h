/* Diffusion synthetic acceleration of the discrete-ordinates solve (lfield_dsa.c; docs/lightfield.md
 * "A diffusion preconditioner for the discrete-ordinates field"): the P1 equations' diffusion
 * operator -div(D grad) + sig_a on the solve's cells, D = 1 / (3 (sig_t - chi_1 sig_s)), sig_a =
 * sig_t - sig_s, a vacuum (Marshak) face toward the grid's edge and toward a cell without medium.
 * M^-1 = I + C S (C: its solve of the scattering of the moments of degree <= 1) is the right
 * preconditioner of GMRES on (I - T S) (lfield_do.c): the slow modes of the source iteration in
 * optically thick cells of high albedo, the near-isotropic ones and (forward scattering) the
 * degree-1 ones, are the ones the P1 solve carries (Alcouffe 1977; as a Krylov preconditioner,
 * Warsa, Wareing & Morel 2004). Not part of the API. */
#ifndef ATMOS_LIGHT_LFIELD_DSA_H
#define ATMOS_LIGHT_LFIELD_DSA_H

#include "light/lfield_do.h"

#include <stddef.h>

typedef struct atmos__dsa atmos__dsa;

/* The operator on the n cells idx[0 .. n - 1] (of P's grid, in increasing order) of P's medium.
 * NULL when out of memory. */
atmos__dsa *atmos__dsa_create(const atmos__do_problem *P, const size_t *idx, size_t n);
void atmos__dsa_free(atmos__dsa *d);

/* The moments corrected per cell: 4 (degree <= 1) when the phase function's chi_1 is not 0, else 1. */
int atmos__dsa_moments(const atmos__dsa *d);

/* The correction of the low moments for v (n cells of K moments, idx's order): out (n cells of
 * atmos__dsa_moments() values, the moments 0 .. 3) = the P1 solve of the scattering of v's
 * moments of degree <= 1, sig_s phi_0 and sig_s chi_1 J (-div(D grad phi) + sig_a phi = sig_s
 * phi_0 - div(3 D sig_s chi_1 J), its flux -D grad phi + 3 D sig_s chi_1 J), by conjugate gradients
 * (Jacobi-preconditioned, from 0, to a relative residual ATMOS__DSA_TOL or ATMOS__DSA_MAX_ITER
 * iterations; one thread: the same numbers whatever the threads). Returns the iterations. */
int atmos__dsa_apply(atmos__dsa *d, const double *v, int K, double *out);

#define ATMOS__DSA_TOL 1e-1
#define ATMOS__DSA_MAX_ITER 30

#endif
