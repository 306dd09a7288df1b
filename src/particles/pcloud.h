/* Particle clouds (Harris 2002 §1.1.1, §2.3): a cloud as a set of soft particles, each a
 * Gaussian blob of number density n(x) = n0 exp(-|x - c|^2 / (2 s^2)) of one particle type
 * (a field of the volume it came from, whose optics give its cross sections and phase
 * function), cut at CUT s. The blob's optical depth along a line at distance b from its
 * centre is tau(b) = sigma_ext n0 s sqrt(2 pi) exp(-b^2 / (2 s^2)) erf(sqrt((CUT^2 s^2 -
 * b^2) / (2 s^2))): a (nearly) Gaussian splat on screen, which is what Harris draws, and a
 * sum of such blobs is a density field the path tracer can render as it is (pconvert.c),
 * so the two renderers see the very same cloud.
 *
 * Internal to the library (src/particles/, above core and volume). Structure of arrays. */
#ifndef ATMOS_PCLOUD_H
#define ATMOS_PCLOUD_H

#include "atmos/atmos.h"
#include "core/fastmath.h"

#include <math.h>

#include <stdint.h>

/* Splats and grids stop at this many s from a centre (the density is exp(-4.5) = 1.1 % of
 * the peak there). */
#define ATMOS__PCLOUD_CUT 3.0

/* The column of a particle cut at CUT = 3 widths, at distance b from its centre, relative to
 * tc = sigma_ext n0 s sqrt(2 pi): exp(-u / 2) erf(sqrt((9 - u) / 2)), u = b^2 / s^2 (0 beyond
 * the cut). With Abramowitz & Stegun 7.1.26 for erf (|error| <= 1.5e-7), erf(z) = 1 - P(t)
 * exp(-z^2), t = 1 / (1 + 0.3275911 z), and exp(-u / 2) exp(-z^2) = exp(-4.5): one exponential,
 * no branch (the loops over texels and pixels vectorise). */
static inline float atmos__pcloud_column(float u)
{
    u = u < 9.0f ? u : 9.0f;
    const float z = sqrtf(0.5f * (9.0f - u)), t = 1.0f / (1.0f + 0.3275911f * z);
    const float P = t * (0.254829592f + t * (-0.284496736f + t * (1.421413741f + t * (-1.453152027f + t * 1.061405429f))));
    const float c = atmos__expf_poly(-0.5f * u) - 0.011108996538242306f * P; /* exp(-4.5) */
    return c > 0.0f ? c : 0.0f;
}

typedef struct atmos__pcloud {
    int n, cap;
    float *x, *y, *z;     /* centres, m (world) */
    float *s;             /* Gaussian widths, m */
    float *n0;            /* peak number densities, m^-3 */
    uint8_t *field;       /* particle type: the field of the source volume */
    int nfields;
    char field_name[ATMOS_VOLUME_MAX_FIELDS][32];
    char particle[ATMOS_VOLUME_MAX_FIELDS][64];
} atmos__pcloud;

/* Appends a particle; returns ATMOS_E_NOMEM when it cannot grow. */
atmos_status atmos__pcloud_add(atmos__pcloud *pc, double x, double y, double z, double s, double n0, int field);
void atmos__pcloud_free(atmos__pcloud *pc);
/* The box holding every particle's splat (centres +- CUT s); empty cloud: lo > hi. */
void atmos__pcloud_bounds(const atmos__pcloud *pc, double lo[3], double hi[3]);

/* ---- pconvert.c */
/* Particles from a volume: one per cell of spacing h (m; 0: the volume's voxel, at least so
 * many that at most max_particles are made, 0 = 2 million) whose mean density over the cell
 * is above 1e-4 of the field's largest, at the cell's density-weighted centre, with
 * s = 0.6 h and n0 = mean h^3 / (0.9707 (2 pi)^(3/2) s^3) (0.9707: the Gaussian's mass within
 * the cut), so that each particle holds its cell's particles and the sum over a lattice
 * reproduces a uniform field within 0.2 %. offset: added
 * to the volume's positions. */
atmos_status atmos__pcloud_from_volume(atmos_context *ctx, const atmos_volume *vol, const double offset[3], double h,
                                       int max_particles, atmos__pcloud *out);
/* The density grid of particles (voxels of edge voxel_m over their bounds, one field per
 * particle type): the same cloud for the path tracer and the slice renderer. */
atmos_status atmos__pcloud_to_volume(atmos_context *ctx, const atmos__pcloud *pc, double voxel_m, atmos_volume **out);

/* ---- pshade.c: Harris's multiple forward scattering (§2.2.1, Eq. 8) */
/* What the light pass and the eye pass need of each particle type, per wavelength. */
typedef struct atmos__poptics {
    int nw;                                               /* wavelengths */
    double sigma_ext[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* m^2 */
    double albedo[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS];
    const atmos_msphase *ms[ATMOS_VOLUME_MAX_FIELDS];    /* Ams_n and F_n of each type */
} atmos__poptics;

/* The light reaching each particle from the sun (direction sun, toward it): light[p * nw + k]
 * is the share of the sunlight outside the cloud that arrives at particle p's centre, and
 * order[p] the expected count of scatterings behind it (Riley's n: the scattering optical
 * depth on the way, Eq. 21; mean over the wavelengths). Harris's recurrence
 * I_k = g_{k-1} + T_{k-1} I_{k-1} on a light buffer seen from the sun, the particles
 * splatted nearest-first, with Riley's forward share: a particle of optical depth tau along
 * a texel leaves T + (1 - T) a F_{n+1} of the light, T = exp(-tau) (Eq. 25 for a thin slab),
 * F_{n+1} the forward fraction at the particle's scattering count. One thread per
 * wavelength (the result does not depend on the thread count). res: the buffer's texels per
 * side (0: texels of texel_scale x 0.7 of the smallest particle's width, at most 1024). */
atmos_status atmos__pcloud_shade(atmos_context *ctx, const atmos__pcloud *pc, const atmos__poptics *o,
                                 const double sun[3], int res, double texel_scale, float *light, float *order);

/* ---- psplat.c: the eye pass (§2.2.2, Eq. 9) */
/* Composites the particles over img (width x height, nw + 1 channels: radiance per
 * wavelength, then coverage) back to front, within rect [x0, y0, x1, y1): a particle adds
 * a sum_j Ams_{n_j+1}(theta_j) E_j I_pj (1 - T) and leaves T = exp(-tau(b)) of what is behind
 * it, b the pixel ray's distance from its centre (Harris's splat, exactly), over the lights
 * j (toward dir[j], irradiance e[j] outside the cloud; light[j], order[j] their
 * atmos__pcloud_shade), theta_j the scattering angle from light j toward the eye. air_t,
 * air_l (NULL: no air): the transmittance and the in-scattered radiance of the air from the
 * eye to each particle [p * nw + k]; the particle's colour is seen as air_l + air_t colour
 * (exact for an opaque particle; the air behind a translucent one is in what it covers). Pinhole
 * cameras; particles whose splat holds the eye are left out. Threads over tiles of 32 x 32
 * pixels (the image does not depend on the thread count). *drawn: the particles drawn (may
 * be NULL). */
atmos_status atmos__pcloud_splat_lights(atmos_context *ctx, const atmos__pcloud *pc, const atmos__poptics *o, int nlights,
                                        const float *const *light, const float *const *order, const double (*dir)[3],
                                        const double (*e)[ATMOS_MAX_WAVELENGTHS], const float *air_t,
                                        const float *air_l, const atmos_camera *cam, const int rect[4],
                                        atmos_image *img, int *drawn);

#endif
