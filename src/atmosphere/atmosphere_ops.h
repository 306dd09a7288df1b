/* What the renderers ask an atmosphere beyond the public interface (atmos/atmosphere.h):
 * the same questions for a subset of the wavelength set (a path carries a few), the
 * sampling of a scattering point of the air, and the radiance of many view rays from one
 * eye at once. Not part of the API; the atmosphere's fields stay in atmosphere_internal.h,
 * which no renderer includes. */
#ifndef ATMOS_ATMOSPHERE_OPS_H
#define ATMOS_ATMOSPHERE_OPS_H

#include "atmosphere/riley_batch.h"
#include "core/internal.h"
#include "core/rng.h"

/* The subset forms: wavelengths k[0..m-1] of the set (k NULL: 0..m-1); out has m values. */
void atmos__atm_transmittance_sub(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                                  int m, const int *k, double *out);
void atmos__atm_sunlight_sub(const atmos_atmosphere *a, const double p[3], const double sun[3], int m, const int *k,
                             double *out);
/* Returns 0 (out all 0) when no sunlight reaches the air at all (a vacuum, the sun below a
 * flat earth's horizon): then nothing about the segment needs estimating. */
int atmos__atm_inscatter_sub(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                             const double sun[3], int m, const int *k, double *out);

/* A point of the segment p + t d, t in [0, dist], drawn with density proportional to the
 * air's scattering times its transmittance from p at one wavelength h of the subset (the one
 * with w[i] != 0 that scatters least, so that the others' ratios stay bounded), for
 * estimating what shadows take from the in-scatter. ratio[i] = f_i(t) / pdf(t) with
 * f_i = sigma_s,i(t) T_i(p, t): the in-scatter of wavelength i is the integral of f_i times
 * the phase function and the sunlight. Draws one number from rng only when it returns 1;
 * returns 0 (no point) when the air does not scatter there or no w is nonzero. */
int atmos__atm_scatter_point(const atmos_atmosphere *a, const double p[3], const double d[3], double dist, int m,
                             const int *k, const double *w, atmos__stream *rng, double *t, double *ratio);

/* A point that has reached the ground moved onto it exactly (a flat earth: y = 0), and the
 * ground's outward normal there. */
void atmos__atm_ground_hit(const atmos_atmosphere *a, double p[3], double n[3]);

/* The extraterrestrial solar irradiance per wavelength of the set (W m^-2 nm^-1) and the
 * cosine of the sun's angular radius. */
const double *atmos__atm_sun_irradiance(const atmos_atmosphere *a);
double atmos__atm_cos_sun_radius(const atmos_atmosphere *a);
/* Radiance arriving from beyond the atmosphere (a vacuum's background; 0 for the sky of a
 * planet, whose sun's disk is counted apart), per wavelength (the same at every one). */
double atmos__atm_background(const atmos_atmosphere *a);

/* One random walk of the Monte Carlo reference of the spherical kinds
 * (atmos_atmosphere_reference_radiance, planet_reference.c): an unbiased estimate of the
 * radiance at wavelength k of the set seen from eye along dir, without the sun's disk, with
 * at most max_order scatterings (0: all), drawing from r. 0 for the other kinds. */
double atmos__atm_reference_walk(const atmos_atmosphere *a, const double eye[3], const double dir[3],
                                 const double sun[3], int k, int max_order, atmos__stream *r);

/* Radiance (without the sun's disk) of many view rays from one eye, in single precision: the
 * renderers' inner loop. atmos__atm_batch_eval adds weight[i] * L_k(ray i) to
 * out[k * count + i]; scratch holds count * ATMOS__ATM_BATCH_SCRATCH floats. */
typedef struct atmos__atm_batch {
    const atmos_atmosphere *atm;
    int kind;
    double eye[3], sun[3];
    float background;
    atmos__sky_batch riley;
    void *state;           /* a spherical kind's per-eye tables (its solver's batch_init) */
} atmos__atm_batch;
#define ATMOS__ATM_BATCH_SCRATCH ATMOS__SKY_BATCH_SCRATCH
void atmos__atm_batch_init(atmos__atm_batch *b, const atmos_atmosphere *a, const double eye[3], const double sun[3]);
/* Frees what atmos__atm_batch_init allocated (a spherical kind's per-eye tables). */
void atmos__atm_batch_release(atmos__atm_batch *b);
void atmos__atm_batch_eval(const atmos__atm_batch *b, int count, const float *dx, const float *dy, const float *dz,
                           const float *weight, float *out, float *scratch);

#endif
