/* Internal interfaces between the optics sources.
 *
 * The table builder (phase_table.c) asks a per-kind "single wavelength" function
 * for the phase function at one wavelength on the grid of atmos_phase_grid(); each
 * returns the phase function normalised over the sphere, the extinction
 * cross-section, the albedo and the asymmetry parameter.
 */
#ifndef ATMOS_OPTICS_INTERNAL_H
#define ATMOS_OPTICS_INTERNAL_H

#include "atmos/atmos.h"

typedef struct atmos__phase_result {
    double sigma_ext_m2;  /* extinction cross-section per particle (size-averaged), m^2 */
    double albedo;        /* single-scattering albedo */
    double g;             /* asymmetry parameter */
} atmos__phase_result;

/* Progress for one wavelength's work, fraction in [0, 1]; returns nonzero to cancel. */
typedef int (*atmos__phase_progress)(void *user, double fraction);

/* Water spheres: Mie theory integrated over the particle's size distribution
 * (mie.c / polydisperse.c). phase[] gets n_angles values at theta_deg[]. */
atmos_status atmos__water_phase(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                                const double *theta_deg, double *phase, atmos__phase_result *res,
                                atmos__phase_progress progress, void *progress_user);

/* Ice and snow crystals: Monte Carlo geometric optics + diffraction (crystal.c).
 * Deterministic for given inputs (fixed seeds), independent of thread count. */
atmos_status atmos__crystal_phase(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                                  const double *theta_deg, double *phase, atmos__phase_result *res,
                                  atmos__phase_progress progress, void *progress_user);

/* Integral of f over the sphere for f tabulated on a theta grid (degrees), by the
 * trapezoid rule in theta with the sin(theta) weight: 2 pi int f sin(theta) dtheta. */
double atmos__sphere_integral(int n, const double *theta_deg, const double *f);

/* atmos_msphase_eval(m, k, n, cos_theta) for k = 0..nw-1 into out[k], the angle looked up once:
 * the same numbers, bit for bit (a light pass's or a splat's wavelengths at one angle). */
void atmos__msphase_eval_all(const atmos_msphase *m, int nw, double n, double cos_theta, double *out);
/* Ams_n from phase functions tabulated on the grid of atmos_phase_grid() (n and theta_deg
 * as it returns them; another grid is ATMOS_E_INVALID_ARG), one array per wavelength: the
 * core of atmos_msphase_build, also used by tests with analytic phase functions. */
atmos_status atmos__msphase_build_arrays(atmos_context *ctx, int nwl, int n, const double *theta_deg,
                                         const double *const *P, const atmos_msphase_desc *desc,
                                         atmos_msphase **out);

#endif
