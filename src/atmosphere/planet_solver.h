/* The solvers of the spherical kinds (DOBASHI, SPHERICAL): each answers the atmosphere's
 * questions over the same planet description (planet.h) with its own tables. The shared
 * answers (geometry, coefficients, phase, the sun's disk, the dispatch) are planet_ask.c's.
 * Every function gets the atmosphere (a->planet, a->model, a->sun_e, a->wl) and the subset
 * convention of atmosphere_ops.h (k NULL: wavelengths 0..m-1). */
#ifndef ATMOS_PLANET_SOLVER_H
#define ATMOS_PLANET_SOLVER_H

#include "atmosphere/atmosphere_internal.h"
#include "atmosphere/planet.h"

typedef struct atmos__planet_solver {
    const char *name;
    /* builds a->model (its tables) from a->planet; NULL: no tables */
    atmos_status (*create)(atmos_context *ctx, atmos_atmosphere *a);
    void (*destroy)(void *model);
    void (*transmittance)(const atmos_atmosphere *a, const double p[3], const double d[3], double dist, int m,
                          const int *k, double *out);
    /* extraterrestrial irradiance times the sun's transmittance to p (0 in the planet's shadow) */
    void (*sunlight)(const atmos_atmosphere *a, const double p[3], const double sun[3], int m, const int *k,
                     double *out);
    /* radiance scattered by the air of the segment toward p (every order the solver has);
     * returns 0 when it is 0 at every wavelength */
    int (*inscatter)(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                     const double sun[3], int m, const int *k, double *out);
    /* what the view ray sees without the sun's disk: the air to the ground or to space and
     * the lit ground (all wavelengths); NULL: planet_ask.c's from the three above */
    void (*radiance)(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                     double *out, atmos_atmosphere_hit *info);
    /* many rays from one eye (atmosphere_ops.h); NULL: one by one through radiance */
    void (*batch_init)(atmos__atm_batch *b);
    void (*batch_eval)(const atmos__atm_batch *b, int count, const float *dx, const float *dy, const float *dz,
                       const float *weight, float *out, float *scratch);
    void (*batch_release)(atmos__atm_batch *b);
    /* nonzero: batch_eval answers rays through cloud spheres too (else they go one by one) */
    int batch_clouds;
    /* whether b's per-eye tables answer for a new eye and sun as they are (turned toward
     * them); NULL: never */
    int (*batch_keep)(atmos__atm_batch *b, const double eye[3], const double sun[3]);
    /* the aerial-perspective volume's node (atmosphere_aerial.c): along d from p, at each
     * distance t[0] < ... < t[nd-1], per wavelength of the set: the Rayleigh and the aerosol
     * single scattering without their phase functions, the rest of the in-scatter (phase
     * included) in W m^-2 sr^-1 nm^-1, and the optical depth (at most 80), in
     * out[(j * n + k) * 4 + 0..3]; NULL: the volume asks inscatter and transmittance */
    void (*aerial)(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3], int nd,
                   const double *t, float *out);
    /* the solver's look-up tables by name (atmos_atmosphere_table; NULL-terminated names, a
     * function making table i as an image with one channel per wavelength) */
    const char *const *table_names;
    atmos_status (*table)(atmos_context *ctx, const atmos_atmosphere *a, int i, atmos_image **out);
} atmos__planet_solver;

/* An image of w x h pixels and n channels whose pixel (x, y), channel k is
 * src[k * ks + y * ys + x * xs] (times scale; exp(-value) when neg_exp), with the metadata
 * atmos:table = name, atmos:axes = axes and atmos:units = units (what a value is, in what
 * units; planet_ask.c). */
atmos_status atmos__planet_table_image(atmos_context *ctx, const float *src, int w, int h, int n, size_t xs,
                                       size_t ys, size_t ks, int neg_exp, const char *name, const char *axes,
                                       const char *units, atmos_image **out);

/* The solvers: dobashi.c, spherical.c; planet_numeric.c's brute-force quadrature (single
 * scattering, a test reference). */
extern const atmos__planet_solver atmos__dobashi_solver;
extern const atmos__planet_solver atmos__spherical_solver;
extern const atmos__planet_solver atmos__numeric_solver;

/* The numeric solver's functions, for other solvers to fall back on. */
void atmos__numeric_transmittance(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                                  int m, const int *k, double *out);
void atmos__numeric_sunlight(const atmos_atmosphere *a, const double p[3], const double sun[3], int m, const int *k,
                             double *out);
int atmos__numeric_inscatter(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                             const double sun[3], int m, const int *k, double *out);

/* planet_ask.c: the radiance of a view ray from the solver's three answers (in-scatter to
 * the ground or space, plus the ground lit by the attenuated sun), without the disk. */
void atmos__planet_radiance_generic(const atmos_atmosphere *a, const double p[3], const double d[3],
                                    const double sun[3], double *out, atmos_atmosphere_hit *info);
/* The ground at distance K along d from p, lit by the attenuated sun (and, with lights, the
 * night side's lights), seen through the air between: albedo / pi cos E T per wavelength. */
void atmos__planet_ground_sunlit(const atmos_atmosphere *a, const double p[3], const double d[3], double K,
                                 const double sun[3], int lights, double *out);

#endif
