/* Dobashi, Yamamoto and Nishita 2002 §5 and Appendix A: the Earth's atmosphere from
 * look-up tables over the spherical planet (planet.h), single scattering plus a constant
 * ambient term. Internal to src/atmosphere/ (dobashi_tables.c builds the tables,
 * dobashi_eval.c evaluates Eq. 12, dobashi_batch.c the renderers' many rays from one eye).
 *
 * Tables (per wavelength k, single precision, docs/sky.md "Dobashi's tables"):
 *  - g_l(h, theta_sun): transmittance of the sunlight from height h to the top (0 where the
 *    planet hides the sun), rows h_i = top (i / (NH - 1))^2, columns x_j = j / (NS - 1) with
 *    mu_sun = mu_hor(h) + (1 - mu_hor(h)) x^2 (mu_hor: the cosine of the horizon's zenith
 *    angle at h, so that the shadow's edge falls on the first column);
 *  - the sampling planes' dI_r, dI_m, dg_v (h, theta_v): one sub-segment of length dt from
 *    height h in the direction of zenith cosine mu_v, rows as g_l, columns
 *    mu_v = sign(y) y^2, y uniform in [-1, 1] (fine near the horizon);
 *  - the sample spheres' dI_r, dI_m, dg_v (theta_v) per sphere s at height h_s = h_{4s}:
 *    the segment from sphere s to the next sphere the ray crosses, in three ranges of mu_v
 *    (up to sphere s + 1; down missing sphere s - 1, back to sphere s; down to sphere s - 1). */
#ifndef ATMOS_DOBASHI_H
#define ATMOS_DOBASHI_H

#include "atmosphere/planet_solver.h"

#define ATMOS__DOB_NH 129        /* heights of g_l and the planes' tables */
#define ATMOS__DOB_NS 256        /* sun cosines of g_l */
#define ATMOS__DOB_NV 129        /* view cosines of the planes' tables */
#define ATMOS__DOB_SPHERES 33    /* sample spheres: every 4th row of the height grid */
#define ATMOS__DOB_NSV 64        /* view cosines per range of a sphere's tables */
#define ATMOS__DOB_PLANES 100    /* planes over the longest sight line from the ground */
#define ATMOS__DOB_PHASE_N 1024  /* the aerosols' phase per sin(alpha / 2) for the batch */

typedef struct atmos__dobashi {
    int n;                      /* wavelengths */
    double top;                 /* r_top - r_ground */
    double dt;                  /* the planes' spacing, the sub-segments' length */
    double ambient;             /* I_a per unit extraterrestrial irradiance, sr^-1 */
    int spheres;                /* sample spheres in use (h_sphere[0] = 0, the last at the top) */
    double h_sphere[ATMOS__DOB_SPHERES];
    double mu_split[ATMOS__DOB_SPHERES]; /* cosine below which the ray reaches sphere s - 1 */
    int sphere_row[ATMOS__DOB_SPHERES];  /* the sphere's row of the height grid */
    double sphere_mh[ATMOS__DOB_SPHERES]; /* the horizon's cosine there */
    float *gl;     /* [NH][NS][n]: -ln g_l */
    float *plane;  /* [NH][NV][n][3]: dI_r, dI_m, dg_v */
    float *sphere; /* [SPHERES][3 ranges][NSV][n][3] */
    float *mie;    /* [n][PHASE_N]: the aerosols' phase at sin(alpha / 2) = j / (PHASE_N - 1) */
    double build_seconds;
} atmos__dobashi;

/* Builds the tables for the planes' spacing dt (<= 0: the default, ATMOS__DOB_PLANES over the
 * ground's longest sight line) and nspheres sample spheres (<= 0 or larger than
 * ATMOS__DOB_SPHERES: all of them; else every (32 / (nspheres - 1))-th row of them, e.g.
 * 2, 3, 5, 9, 17 spheres). NULL: no memory. */
atmos__dobashi *atmos__dobashi_build(const atmos__planet *pl, double dt, int nspheres);
void atmos__dobashi_free(void *model);

/* g_l(h, mu_sun) per wavelength (subset k): 0 below the horizon; above the top the sun's
 * ray may still cross the air (sunlight seen from orbit near the terminator). */
void atmos__dobashi_gl(const atmos__dobashi *m, const atmos__planet *pl, const double p[3], const double sun[3],
                       int cnt, const int *k, double *out);

/* Eq. 12 along p + t d, t in [0, dist] clipped to the air: the sums without the phase
 * functions, per unit solar irradiance, S_r = sum g_l dI_r prod dg_v and S_m, and the view
 * transmittance T = prod dg_v, for every wavelength. Sampling planes when p is in the air
 * (§5.2), sample spheres from space (§5.3, p above the top). Returns the number of
 * sub-segments. */
int atmos__dobashi_march(const atmos__dobashi *m, const atmos__planet *pl, const double p[3], const double d[3],
                         double dist, const double sun[3], double *sr, double *sm, double *T);

/* The radiance of a view ray without the disk (solver's radiance). */
void atmos__dobashi_radiance(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                             double *out, atmos_atmosphere_hit *info);

/* The batch (dobashi_batch.c). */
void atmos__dobashi_batch_init(atmos__atm_batch *b);
void atmos__dobashi_batch_eval(const atmos__atm_batch *b, int count, const float *dx, const float *dy,
                               const float *dz, const float *weight, float *out, float *scratch);
void atmos__dobashi_batch_release(atmos__atm_batch *b);

/* The aerosols' phase function from the table m->mie (wavelength k). */
double atmos__dobashi_mie_phase(const atmos__dobashi *m, int k, double cos_alpha);

#endif
