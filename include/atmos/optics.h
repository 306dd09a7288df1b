/* Particle optics: analytic phase functions, Lorenz-Mie theory, refractive indices,
 * size distributions, ice and snow crystals, and cached wavelength-dependent phase
 * tables (Riley et al. 2004 §3.1, Table 2; Nishita et al. 1996 §3.3; Harris 2002 §2.1).
 *
 * Conventions: scattering angle theta between the incident and scattered
 * propagation directions (theta = 0 forward); phase functions in sr^-1 with
 * integral over the sphere = 1; radii in metres; wavelengths in nm.
 * Refractive indices follow MIEV0's sign convention: m = n - i k, imaginary part <= 0
 * for absorbing media. Pure functions are thread-safe; a built phase table is
 * immutable and may be shared by any number of threads.
 */
#ifndef ATMOS_OPTICS_H
#define ATMOS_OPTICS_H

#include "atmos/base.h"
#include "atmos/spectrum.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct atmos_complex {
    double re, im;
} atmos_complex;

/* ---------------------------------------------------------------- analytic phase functions */

/* Riley et al. 2004 Eq. 1: the Rayleigh phase function of air molecules, 3/(16 pi)(1 + mu^2), sr^-1. */
ATMOS_API double atmos_phase_rayleigh(double cos_theta);
/* Henyey-Greenstein (Harris 2002 Eq. 4, here normalised over the sphere:
 * (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5)), g in (-1, 1). */
ATMOS_API double atmos_phase_hg(double cos_theta, double g);
/* Cornette-Shanks (Nishita et al. 1996 Eq. 5, divided by 4 pi so it integrates to 1):
 * 3 (1 - g^2)(1 + mu^2) / (8 pi (2 + g^2)(1 + g^2 - 2 g mu)^1.5). */
ATMOS_API double atmos_phase_cornette_shanks(double cos_theta, double g);

typedef enum {
    ATMOS_PHASE_ISOTROPIC = 0,
    ATMOS_PHASE_RAYLEIGH = 1,
    ATMOS_PHASE_HG = 2,
    ATMOS_PHASE_CORNETTE_SHANKS = 3
} atmos_phase_kind;

#define ATMOS_PHASE_MAX_LOBES 8

/* A weighted mixture of analytic lobes (Nishita et al. 1996 Eq. 4); weights are
 * normalised to sum to 1 when evaluated. A single lobe is a mixture of one. */
typedef struct atmos_phase_mixture {
    int count;
    atmos_phase_kind kind[ATMOS_PHASE_MAX_LOBES];
    double g[ATMOS_PHASE_MAX_LOBES];       /* asymmetry parameter of HG / CS lobes */
    double weight[ATMOS_PHASE_MAX_LOBES];  /* >= 0 */
} atmos_phase_mixture;

ATMOS_API double atmos_phase_mixture_eval(const atmos_phase_mixture *p, double cos_theta);
/* Importance sampling: returns cos(theta) distributed with pdf = eval (per steradian,
 * azimuth uniform) from two uniform numbers in [0, 1). */
ATMOS_API double atmos_phase_mixture_sample(const atmos_phase_mixture *p, double u1, double u2);
/* pdf in sr^-1 of the direction with this cos(theta): equal to eval. */
ATMOS_API double atmos_phase_mixture_pdf(const atmos_phase_mixture *p, double cos_theta);

/* ---------------------------------------------------------------- Mie theory */

typedef struct atmos_mie_result {
    double qext, qsca, qback; /* efficiencies: cross-section / (pi r^2) */
    double g;                 /* asymmetry parameter <cos theta> */
    int terms;                /* number of series terms used */
} atmos_mie_result;

/* Lorenz-Mie scattering by a homogeneous sphere of size parameter x = 2 pi r / lambda
 * (1e-6 <= x <= 1e5) and relative refractive index m (MIEV0 convention, m.im <= 0; m.re = 0
 * and m.im = 0 together mean a perfectly conducting sphere). For n_angles directions
 * with cosines mu[], writes the amplitudes S1, S2 (MIEV0 / Bohren-Huffman convention)
 * to s1, s2 (either may be NULL). Errors: ATMOS_E_INVALID_ARG naming the value. */
ATMOS_API atmos_status atmos_mie(atmos_context *ctx, atmos_complex m, double x, int n_angles,
                                 const double *mu, atmos_complex *s1, atmos_complex *s2,
                                 atmos_mie_result *out);

/* Complex refractive index of liquid water (n: Daimon & Masumura 2007, 20 °C; k: Hale &
 * Querry 1973) and ice (Warren & Brandt 2008, -7 °C) at a wavelength in nm (valid
 * 200-1000 nm; clamped outside), MIEV0 sign convention (im <= 0). */
ATMOS_API atmos_complex atmos_refractive_index_water(double nm);
ATMOS_API atmos_complex atmos_refractive_index_ice(double nm);

/* ---------------------------------------------------------------- particles */

typedef enum {
    ATMOS_SIZE_MONODISPERSE = 0, /* every particle has radius r_m */
    ATMOS_SIZE_LOGNORMAL = 1,    /* n(r) ~ exp(-(ln r - ln r_m)^2 / (2 s^2)) / r; r_m median, s = sigma */
    ATMOS_SIZE_GAMMA = 2         /* modified gamma (Deirmendjian): n(r) ~ r^alpha exp(-b r^gamma),
                                    mode radius r_m = (alpha / (b gamma))^(1/gamma) */
} atmos_size_kind;

typedef struct atmos_size_distribution {
    atmos_size_kind kind;
    double r_m;        /* median (lognormal) or mode (gamma) or the radius (mono), metres */
    double sigma;      /* lognormal: standard deviation of ln r (dimensionless) */
    double alpha;      /* gamma: shape alpha > 0 */
    double gamma;      /* gamma: shape gamma > 0 */
    double r_min, r_max; /* integration bounds, metres; 0 = chosen from the distribution */
} atmos_size_distribution;

typedef enum {
    ATMOS_PARTICLE_AIR = 0,      /* Rayleigh (Riley Eq. 1) */
    ATMOS_PARTICLE_WATER = 1,    /* water spheres by Mie theory over a size distribution */
    ATMOS_PARTICLE_ICE = 2,      /* randomly oriented hexagonal ice crystals, ray tracing + diffraction */
    ATMOS_PARTICLE_SNOW = 3,     /* irregular (distorted, roughened) crystals: smooth phase function */
    ATMOS_PARTICLE_ANALYTIC = 4  /* an analytic mixture (HG, Cornette-Shanks ...) */
} atmos_particle_kind;

typedef enum { ATMOS_CRYSTAL_COLUMN = 0, ATMOS_CRYSTAL_PLATE = 1 } atmos_crystal_habit;

typedef struct atmos_particle_desc {
    char name[32];
    atmos_particle_kind kind;
    atmos_size_distribution size;   /* water; ice and snow use size.r_m as the crystal's radius */
    atmos_crystal_habit habit;      /* ice, snow */
    double aspect_ratio;            /* ice, snow: length / diameter of the hexagonal prism; 0 = habit default */
    double distortion;              /* snow: facet tilt roughness (std. dev. of normal perturbations, radians); 0 = default */
    long rays;                      /* ice, snow: Monte Carlo rays per wavelength; 0 = default */
    atmos_phase_mixture analytic;   /* ANALYTIC */
    double sigma_ext_m2;            /* extinction cross-section used by renderers; 0 = computed
                                       (presets set Riley Table 2's values) */
    double albedo;                  /* single-scattering albedo used by renderers; 0 = computed */
    int albedo_set;                 /* nonzero: albedo is used as given, 0 included (a purely absorbing medium) */
    int fast;                       /* nonzero: coarser size integration and fewer rays, for tests
                                       and previews (documented accuracy in docs/optics.md) */
} atmos_particle_desc;

/* Presets: "air", "cloud", "rain", "ice", "snow" (Riley et al. 2004 Table 2 cross-sections;
 * distribution parameters and their sources in docs/optics.md). ATMOS_E_INVALID_ARG for an
 * unknown name, listing the known ones. */
ATMOS_API atmos_status atmos_particle_preset(atmos_context *ctx, const char *name, atmos_particle_desc *out);
/* Names of the presets, NULL-terminated. */
ATMOS_API const char *const *atmos_particle_preset_names(void);

/* ---------------------------------------------------------------- phase tables */

/* The angular grid every table uses: theta in degrees, increasing from 0 to 180,
 * at most 0.1° apart everywhere and much finer near 0° where diffraction peaks live
 * (see docs/optics.md). Same for every table; *theta_deg points to static storage. */
ATMOS_API int atmos_phase_grid(const double **theta_deg);

typedef struct atmos_phase_table atmos_phase_table;

typedef struct atmos_phase_table_desc {
    int no_cache;             /* nonzero: neither read nor write the disk cache */
} atmos_phase_table_desc;

/* Builds (or loads from the cache) the phase function of a particle type at every
 * wavelength of a set, on the grid of atmos_phase_grid(), normalised. Reports progress
 * through ctx ("phase PRESET") and honours cancellation. */
ATMOS_API atmos_status atmos_phase_table_build(atmos_context *ctx, const atmos_particle_desc *particle,
                                               const atmos_wavelengths *wl, const atmos_phase_table_desc *desc,
                                               atmos_phase_table **out);
ATMOS_API void atmos_phase_table_destroy(atmos_phase_table *t);

ATMOS_API int atmos_phase_table_wavelength_count(const atmos_phase_table *t);
ATMOS_API double atmos_phase_table_wavelength_nm(const atmos_phase_table *t, int k);
/* Tabulated P (sr^-1) at every grid angle for wavelength k (for plotting and export: the
 * values themselves, without interpolation). */
ATMOS_API const double *atmos_phase_table_values(const atmos_phase_table *t, int k);
/* The phase function at any angle, sr^-1, as the density atmos_phase_table_sample draws
 * from: f(theta) / sin(theta), with f the piecewise-linear interpolant in theta of
 * f_i = P_i sin(theta_i) / F and F = 2 pi int P sin(theta) dtheta by the trapezoid rule, so
 * that it integrates to 1 over the sphere exactly (to rounding) and pdf = eval. Between grid
 * angles it differs from P interpolated linearly in theta by O(h^2) relative (h the grid step;
 * docs/phase-tables.md); at theta = 0 and 180° it is the finite limit (in the first and last
 * interval f is linear from 0 at the pole). cos_theta is clamped to [-1, 1]; NaN or a bad k
 * give 0. */
ATMOS_API double atmos_phase_table_eval(const atmos_phase_table *t, int k, double cos_theta);
/* Importance sampling by the inverse CDF of that density: cos(theta) from a uniform u in
 * [0, 1) (clamped into it); azimuth is uniform, the caller's to draw. */
ATMOS_API double atmos_phase_table_sample(const atmos_phase_table *t, int k, double u);
/* pdf in sr^-1 of the direction with this cos(theta) as atmos_phase_table_sample draws it:
 * equal to atmos_phase_table_eval. */
ATMOS_API double atmos_phase_table_pdf(const atmos_phase_table *t, int k, double cos_theta);
/* Per wavelength: extinction cross-section (m^2), single-scattering albedo, asymmetry g. */
ATMOS_API double atmos_phase_table_sigma_ext(const atmos_phase_table *t, int k);
ATMOS_API double atmos_phase_table_albedo(const atmos_phase_table *t, int k);
/* The extinction and scattering cross-sections (m^2) at wavelength k as renderers use them:
 * sigma_ext made finite and >= 0, the albedo clamped to [0, 1], sigma_sca = albedo sigma_ext. */
ATMOS_API void atmos_phase_table_cross_sections(const atmos_phase_table *t, int k, double *sigma_ext,
                                                double *sigma_sca);
ATMOS_API double atmos_phase_table_g(const atmos_phase_table *t, int k);
/* 1 if the table was read from the disk cache. */
ATMOS_API int atmos_phase_table_from_cache(const atmos_phase_table *t);

/* ---------------------------------------------------------------- multiple-scattering phase functions */

/* Riley et al. 2004 §4.2.1-4.2.2: Ams_n, the distribution of light directions after n
 * scattering events of an initially collimated beam (the phase function convolved with
 * itself n times on the sphere, Eq. 20), and F_n, its forward-hemisphere fraction
 * (Eq. 23). Built from a phase table by multiplying Legendre coefficients
 * (convolution of azimuthally symmetric functions on the sphere is a product of their
 * Legendre coefficients, the Funk-Hecke theorem); see docs/msphase.md. */
typedef struct atmos_msphase atmos_msphase;

typedef struct atmos_msphase_desc {
    int max_order;        /* highest n; 0 = until Ams_n is isotropic to isotropy_tol (at most 1000) */
    double isotropy_tol;  /* max |4 pi Ams_n - 1|; 0 = 1e-6 */
    int no_cache;         /* nonzero: neither read nor write the disk cache */
} atmos_msphase_desc;

/* Builds (or loads from the disk cache) Ams_n and F_n of a phase table. On failure *out is
 * NULL and the status says why (with a message in ctx). A built object is immutable: any
 * number of threads may read it. The accessors below return 0 (or NULL) for a NULL object
 * or an index out of range. */
ATMOS_API atmos_status atmos_msphase_build(atmos_context *ctx, const atmos_phase_table *table,
                                           const atmos_msphase_desc *desc, atmos_msphase **out);
ATMOS_API void atmos_msphase_destroy(atmos_msphase *m);

/* Highest order n tabulated (orders 0..n; Ams_0 is the collimated beam, a delta). */
ATMOS_API int atmos_msphase_max_order(const atmos_msphase *m);
ATMOS_API int atmos_msphase_wavelength_count(const atmos_msphase *m);
/* The output angle grid (degrees, 0..180, finer near 0, never coarser than 0.1°; not the
 * phase tables' grid, see docs/msphase.md). *theta_deg points to static storage, the same
 * for every object. */
ATMOS_API int atmos_msphase_grid(const atmos_msphase *m, const double **theta_deg);
/* Ams_n (sr^-1) at every grid angle for wavelength k, 1 <= n <= max_order. */
ATMOS_API const double *atmos_msphase_values(const atmos_msphase *m, int k, int n);
/* Ams at fractional order n >= 1 (linear interpolation between integer orders, and
 * in angle); orders above max_order are isotropic, 1/(4 pi). */
ATMOS_API double atmos_msphase_eval(const atmos_msphase *m, int k, double n, double cos_theta);
/* F_n (Eq. 23) at fractional n >= 0: F_0 = 1, linear interpolation between orders,
 * 1/2 beyond max_order. */
ATMOS_API double atmos_msphase_forward(const atmos_msphase *m, int k, double n);
/* S(n) = sum_{i=1}^{n} ln F_i, linear between integer n (S(0) = 0), so that the exact
 * light-buffer update of Eq. 24 is prod_{i=a}^{b} F_i = exp(S(b) - S(a - 1)). */
ATMOS_API double atmos_msphase_log_forward_sum(const atmos_msphase *m, int k, double n);
/* Legendre coefficient chi_l of the phase function (P = sum (2l+1)/(4 pi) chi_l P_l),
 * 0 <= l < atmos_msphase_legendre_count(). */
ATMOS_API int atmos_msphase_legendre_count(const atmos_msphase *m, int k);
ATMOS_API double atmos_msphase_legendre(const atmos_msphase *m, int k, int l);
ATMOS_API int atmos_msphase_from_cache(const atmos_msphase *m);

/* Ams_n of a mixture of particle types (Riley Eq. 6: the phase functions weighted by
 * each field's share of the scattering coefficient, alpha_i beta_i), exactly: the
 * mixture's Legendre coefficients are the weighted sums of the components'. All parts
 * must have the same wavelength count; weights >= 0, not all zero (normalised here).
 * The cheap alternative of mixing the components' Ams_n linearly is exact only for n = 1;
 * its error is measured in docs/msphase.md. On failure *out is NULL and the status is the
 * error's (ATMOS_E_NOMEM when the tables cannot be allocated), with or without a context. */
ATMOS_API atmos_status atmos_msphase_mix(atmos_context *ctx, const atmos_msphase *const *parts, const double *weights,
                                         int count, const atmos_msphase_desc *desc, atmos_msphase **out);

#ifdef __cplusplus
}
#endif
#endif
