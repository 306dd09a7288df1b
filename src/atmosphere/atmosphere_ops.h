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

/* The air's single scattering of sunlight toward p over [s0, s1] of the segment p + t d
 * (s1 finite), by the midpoint rule over n equal cells: out[c * m + i] (wavelength k[i] of
 * the subset) = the scattering coefficient times the phase function at theta (cos theta =
 * d . sun; a planet's Rayleigh and aerosol parts each with its own, per wavelength) times
 * the sunlight (atmos__atm_sunlight_sub) at cell c's centre, times the air's transmittance
 * from p to the centre, times the cell's length. Over a planet the transmittance is the
 * model's to s0 and from there the planet's extinction at the cells' centres (atmosphere_single.c). */
void atmos__atm_single_cells_sub(const atmos_atmosphere *a, const double p[3], const double d[3], double s0,
                                 double s1, int n, const double sun[3], int m, const int *k, double *out);
/* [*s0, *s1] along p + t d narrowed to the air (a planet's: below its top, above its ground;
 * the flat kinds' is left as it is); 0 when no air is left in it. */
int atmos__atm_air_span(const atmos_atmosphere *a, const double p[3], const double d[3], double *s0, double *s1);

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

/* The ground at distance K along dir from p (K infinite: none) lit by the attenuated sun,
 * seen through the air between: the part of atmos_atmosphere_radiance's ground that a shadow
 * between the ground and the sun takes (albedo / pi cos E T, without the sky's light or a
 * planet's night lights and cloud spheres). */
void atmos__atm_ground_sunlit(const atmos_atmosphere *atm, const double p[3], const double dir[3], double K,
                              const double sun_dir[3], double *out);

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
    int threads;           /* the threads that make those tables (the caller's context's) */
} atmos__atm_batch;
#define ATMOS__ATM_BATCH_SCRATCH ATMOS__SKY_BATCH_SCRATCH
/* threads: how many threads make the per-eye tables (the caller's atmos__threads(ctx); 0: the
 * default count, atmos__threads(NULL)); the tables are the same for any count. */
void atmos__atm_batch_init(atmos__atm_batch *b, const atmos_atmosphere *a, const double eye[3], const double sun[3],
                           int threads);
/* Frees what atmos__atm_batch_init allocated (a spherical kind's per-eye tables). */
void atmos__atm_batch_release(atmos__atm_batch *b);
/* b (zeroed, or initialised before) made to answer for atmosphere a, eye and sun: its per-eye
 * tables kept when they answer for them as they are (returns 1), else built again (0). The
 * rays' values are those of atmos__atm_batch_init's either way, but for cloud spheres seen
 * from above the air: from the second frame with the same sun on, their attenuation comes
 * from textures (planet_clouds.h), within the textures' error of the first frame's. */
int atmos__atm_batch_update(atmos__atm_batch *b, const atmos_atmosphere *a, const double eye[3], const double sun[3],
                            int threads);
void atmos__atm_batch_eval(const atmos__atm_batch *b, int count, const float *dx, const float *dy, const float *dz,
                           const float *weight, float *out, float *scratch);

/* The aerial-perspective volume (atmosphere_aerial.c; Hillaire 2020 §5.5): for one eye and
 * sun, the in-scattered radiance and the transmittance of the air from the eye to distance t
 * along direction d, on a grid over the directions d = fwd + u right + v up of a pinhole
 * frustum (u in [u0, u1], v in [v0, v1], nu x nv nodes; fwd, right, up orthonormal) times nd
 * distances t_j = tmin + (tmax - tmin) f(j / (nd - 1)), f(x) = x^2 (crowded near the eye, or
 * near tmin: the near side of what the renderer draws; 0 for all distances) or, crowd_far,
 * 1 - (1 - x)^2 (crowded at tmax: views down into the air from above), each node direction built by
 * one pass along its ray, interpolated per query (what is exact and what interpolated:
 * docs/sky.md, "Aerial perspective"). The answers approximate atmos_atmosphere_inscatter
 * and atmos_atmosphere_transmittance of the segment eye -> eye + t d. */
#define ATMOS__AERIAL_MAX_SLICES 128
#define ATMOS__AERIAL_SLICES 64 /* what the renderers ask for (test_aerial's accuracy) */
typedef struct atmos__aerial_grid {
    double eye[3], sun[3];
    double fwd[3], right[3], up[3];
    double u0, u1, v0, v1;
    int nu, nv, nd;        /* >= 2 each; nd at most ATMOS__AERIAL_MAX_SLICES */
    double tmin, tmax;     /* m, 0 <= tmin < tmax */
    int crowd_far;
} atmos__aerial_grid;
typedef struct atmos__aerial {
    atmos__aerial_grid g;
    const atmos_atmosphere *atm;
    int n, split;          /* split: Rayleigh and aerosol single scattering kept apart, their
                              phase functions applied per query (a planet kind's fast path) */
    float *tab;            /* [v][u][slice][wavelength][4]: Rayleigh, aerosols (no phase),
                              the rest of the in-scatter, optical depth */
    size_t cap;
    float *ground;         /* [v][u]: each node ray's distance to the ground (INFINITY: none) */
    size_t gcap;
    float *mie;            /* split: the aerosols' phase function over sin(theta / 2) */
    const atmos_atmosphere *mie_atm; /* the atmosphere it was made for */
} atmos__aerial;
/* Sets g->nu and g->nv from g's frustum and tmax: the air's density changes with height, so
 * neighbouring node rays are at most ATMOS__AERIAL_NODE_SPACING_M apart vertically (the local
 * vertical where the frustum's axis reaches tmax) at tmax, and at most ATMOS__AERIAL_NODE_SPACING_ACROSS_M apart at all
 * (what changes across the view at one height: the sun's angle over the curved ground, the
 * ground's distance); between ATMOS__AERIAL_MIN_NODES and _MAX_NODES per axis, and fewer
 * (both axes scaled alike) where the table would pass ATMOS__AERIAL_MAX_BYTES (many
 * wavelengths); with the sun below ATMOS__AERIAL_LOW_SUN at the far end's vertical the spacing
 * across halves (the higher orders' light changes fastest across a twilight view). test_aerial
 * measures the error this leaves (< 1 % at rgb). */
#define ATMOS__AERIAL_MAX_BYTES (48.0 * 1024 * 1024)
#define ATMOS__AERIAL_NODE_SPACING_M 300.0
#define ATMOS__AERIAL_NODE_SPACING_ACROSS_M 3000.0
/* the sine of the sun's elevation below which the nodes across are twice as dense (5 degrees) */
#define ATMOS__AERIAL_LOW_SUN 0.0872
#define ATMOS__AERIAL_MIN_NODES 4
#define ATMOS__AERIAL_MAX_NODES 64
void atmos__aerial_nodes(const atmos_atmosphere *a, atmos__aerial_grid *g);
/* 1 when the kind's direct answers are costly enough for a renderer to ask the volume instead
 * (the planet kinds); Riley's, the homogeneous layer's and a vacuum's are closed forms. */
int atmos__aerial_wanted(const atmos_atmosphere *a);
/* (Re)builds ap (its storage kept from the last build, grown when needed) for the grid g on
 * `threads` threads; the result does not depend on the thread count. 0: out of memory or a
 * degenerate grid. */
int atmos__aerial_build(atmos__aerial *ap, const atmos_atmosphere *a, const atmos__aerial_grid *g, int threads);
/* The in-scatter and the transmittance (all wavelengths) for unit direction d and distance t;
 * 0 (outputs untouched) when (d, t) lies outside the grid: ask the atmosphere then. */
int atmos__aerial_eval(const atmos__aerial *ap, const double d[3], double t, double *inscatter,
                       double *transmittance);
/* The single-scattered in-scatter from the eye to the slice distances along unit direction d
 * (bilinear between the node rays around d) that cover [t0, t1]: the distances in t[0..m-1]
 * (t[0] <= t0 unless t0 lies before the first slice, t[m-1] >= t1 unless t1 lies past the
 * last) and S[j * n + k] (the planet kinds' Rayleigh and aerosol terms with their phase
 * functions at d's angle, without the higher orders; another kind's whole in-scatter, which
 * is single scattering). Returns m >= 2, or 0 when d lies outside the grid or the range is
 * empty (t and S untouched). For the renderers' shadows on the air: the difference between
 * two distances is what the air between them scatters toward the eye. */
int atmos__aerial_single_profile(const atmos__aerial *ap, const double d[3], double t0, double t1, double *t,
                                 float *S);
void atmos__aerial_free(atmos__aerial *ap);

#endif
