/* Internal interfaces of the ice / snow crystal ray tracer (crystal_geometry.c) and its
 * driver (crystal.c): the hexagonal prism, the seeding of its random streams, and the
 * tracing of one ray through one randomly oriented crystal.
 *
 * Frame: the crystal is fixed (c-axis along z, centred at the origin) and the incident
 * direction is random, which for uniformly random crystal orientations is the same
 * thing (the phase function only depends on the angle between the incident and the
 * outgoing directions).
 */
#ifndef ATMOS_CRYSTAL_INTERNAL_H
#define ATMOS_CRYSTAL_INTERNAL_H

#include "atmos/atmos.h"
#include "core/rng.h"
#include "optics/optics_internal.h"

#include <stdint.h>

/* ---------------------------------------------------------------- random numbers */

/* One atmos__rng stream (core/rng.h) per (wavelength, chunk): the seed is a hash of both, so
 * results do not depend on which thread runs which chunk. */

/* ---------------------------------------------------------------- the crystal */

#define ATMOS_CRYSTAL_FACES 8       /* six prism faces, two basal faces */
#define ATMOS_CRYSTAL_MAX_HITS 64   /* upper limit of internal interactions per ray */

/* A hexagonal prism: hexagon of circumradius `radius` (half the diameter across
 * corners) in the xy plane, vertices at angles 0°, 60°, ...; length `length` along z.
 * Face i is the plane normal[i] . x = dist[i] with outward unit normal; area[i]. */
typedef struct atmos__crystal {
    double radius, length;
    double normal[ATMOS_CRYSTAL_FACES][3];
    double dist[ATMOS_CRYSTAL_FACES];
    double area[ATMOS_CRYSTAL_FACES];
    double surface_area;   /* sum of area[] */
} atmos__crystal;

void atmos__crystal_init(atmos__crystal *c, double radius, double length);
/* Area of the crystal's shadow on a plane normal to the unit direction d. */
double atmos__crystal_projected_area(const atmos__crystal *c, const double d[3]);

/* ---------------------------------------------------------------- tracing one ray */

typedef struct atmos__crystal_optics {
    double n;          /* real refractive index of ice relative to air */
    double alpha;      /* absorption coefficient inside the crystal, 4 pi k / lambda, m^-1 */
    double tilt;       /* facet tilt (radians, Rayleigh scale of the tilt angle); 0 = perfect facets */
    int max_hits;      /* internal interactions followed, 1..ATMOS_CRYSTAL_MAX_HITS */
    double cutoff;     /* stop following a ray whose remaining energy is below this (counted as lost) */
} atmos__crystal_optics;

/* Everything that leaves one ray: the outgoing rays (scattering angle in radians and
 * energy) and the energy balance. reflected + transmitted + absorbed + lost = 1 up to
 * rounding, where reflected is the external reflection at the entry face, transmitted
 * the sum of the refracted rays leaving the crystal, absorbed what k removed along the
 * internal paths, lost what was still inside after max_hits internal interactions.
 * The external reflection is exit[0]. */
typedef struct atmos__crystal_ray {
    int n_exit;
    double theta[ATMOS_CRYSTAL_MAX_HITS + 1];
    double weight[ATMOS_CRYSTAL_MAX_HITS + 1];
    double reflected, transmitted, absorbed, lost;
} atmos__crystal_ray;

/* Samples a crystal orientation (incident direction) with probability proportional to
 * the projected area, i.e. the orientation distribution of the rays that hit a
 * randomly oriented crystal, a uniform entry point on the lit silhouette, and traces
 * the ray: Fresnel reflection and refraction at every interaction (both branches kept:
 * the leaving one is recorded, the staying one followed), total internal reflection,
 * absorption along internal paths. */
void atmos__crystal_trace(const atmos__crystal *c, const atmos__crystal_optics *o, atmos__rng *rng,
                          atmos__crystal_ray *out);

/* Unpolarised Fresnel reflectance (mean of s and p) for light going from index n1 into
 * n2 with incidence cosine cos_i in [0, 1]; 1 for total internal reflection. If cos_t
 * is not NULL it receives the cosine of the refraction angle (0 for TIR). */
double atmos__fresnel(double n1, double n2, double cos_i, double *cos_t);

/* ---------------------------------------------------------------- the driver (crystal.c) */

/* What atmos__crystal_phase resolved and measured, for tests and logs. Energies are
 * fractions of the energy that hit the crystal (the geometric-optics half of the
 * extinction), summed over all rays: reflected + transmitted + absorbed + lost = 1. */
typedef struct atmos__crystal_stats {
    double radius_m, length_m;       /* the resolved crystal */
    double mean_projected_area_m2;   /* surface area / 4 (Cauchy) */
    double n_real, k_imag;           /* refractive index used (k >= 0) */
    double tilt_rad;                 /* facet tilt used (0 for ICE) */
    long rays;                       /* rays traced */
    double reflected, transmitted, absorbed, lost;
    double delta_transmitted;        /* part of transmitted leaving exactly forward */
    double kernel_deg;               /* smoothing kernel standard deviation away from the poles */
} atmos__crystal_stats;

/* atmos__crystal_phase that also reports the statistics (stats may be NULL). */
atmos_status atmos__crystal_phase_ex(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                                     const double *theta_deg, double *phase, atmos__phase_result *res,
                                     atmos__phase_progress progress, void *progress_user,
                                     atmos__crystal_stats *stats);

#endif
