/* The production sky's tables (after Hillaire 2020, "A Scalable and Production Ready Sky and
 * Atmosphere Rendering Technique", EGSR): the optical depth to the top of the atmosphere
 * tau(r, mu), the multiple-scattering term Psi_ms(r, mu_s) (all orders >= 2 under his
 * isotropic approximation with the series 1 / (1 - f_ms)), the sky's irradiance of the
 * ground E_sky(mu_s), and the ray march that answers the solver's questions with them
 * (docs/sky.md, "The production sky"). Internal to src/atmosphere/.
 *
 * Frame of the functions here: positions relative to the planet's centre (q = p + (0, R, 0)),
 * all quantities per unit extraterrestrial irradiance unless stated. */
#ifndef ATMOS_SPHERICAL_H
#define ATMOS_SPHERICAL_H

#include "atmosphere/planet_solver.h"

/* Table sizes: tau over (r, mu) with Bruneton's 2017 mapping, Psi_ms over (sqrt altitude,
 * mu_s), E_sky over mu_s. */
#define ATMOS__SPH_T_R 64
#define ATMOS__SPH_T_MU 256
#define ATMOS__SPH_M_R 24
#define ATMOS__SPH_M_MU 32
#define ATMOS__SPH_E_MU 64
/* The higher orders' scattering density J_ms (spherical_ms.c): rows in sqrt(altitude / top),
 * sun cosines, angles from the sun, azimuths about it; the fixed-point iterations that
 * build it from Psi_ms. */
#define ATMOS__SPH_J_R 16
#define ATMOS__SPH_J_MUS 40
#define ATMOS__SPH_J_G 24
#define ATMOS__SPH_J_P 10
#define ATMOS__SPH_J_ITER 2
/* gamma's mapping gamma = pi (a x + b x^2 + c x^3): the slope of gamma / pi is GA at the sun
 * (a = GA) and GE at the anti-sun, b and c from gamma(1) = pi; the gather's own nodes
 * (spherical_ms.c) map s as gamma = pi (a s + (1 - a) s^2) */
#define ATMOS__SPH_J_GA 0.3
#define ATMOS__SPH_J_GE 0.3
/* The table holds log(j + ATMOS__SPH_J_FLOOR) and is interpolated in it: in twilight j falls by ~3.6
 * times per degree of the sun's depression (the sky's irradiance of the ground between
 * 5.2 and 6.4 degrees below), which linear interpolation over a node spacing of a degree
 * overestimates by a quarter. */
#define ATMOS__SPH_J_FLOOR 1e-20
/* Steps of the march per monotone piece of a ray (the piece going down to the ray's lowest
 * point and the piece rising from it): the one-ray answers and the tables. */
#define ATMOS__SPH_STEPS 40
/* The sky-view table (spherical_batch.c): rows per side of the horizon, azimuths over
 * [0, pi]; row j of a side at x = (j / (ROWS - 1))^2 (1e-7 at j = 0), azimuth i at
 * pi i / (AZ - 1). */
#define ATMOS__SPH_SV_ROWS 48
#define ATMOS__SPH_SV_AZ 16
#define ATMOS__SPH_STEPS_TABLE 12
/* Steps of the march per piece for the per-eye tables' nodes: the sky-view table's and the
 * table of an eye above the air (spherical_space.c). */
#define ATMOS__SPH_STEPS_SKYVIEW 20
#define ATMOS__SPH_STEPS_SPACE 20
/* The table of an eye above the air (spherical_space.c): rows over the disk and over the
 * limb, azimuths over [0, pi]. */
#define ATMOS__SPH_SP_DISK 48
#define ATMOS__SPH_SP_LIMB 32
#define ATMOS__SPH_SP_AZ 64

typedef struct atmos__sph_model {
    int n;                  /* wavelengths */
    double R, Rt, H;        /* ground and top radii, H = sqrt(Rt^2 - R^2) */
    float *tau;             /* [n][T_R][T_MU] optical depth to the top (rays above the horizon) */
    float *psi;             /* [n][M_R][M_MU] Psi_ms, sr^-1 per unit irradiance and scattering */
    float *fms;             /* [n][M_R][M_MU] f_ms: the share of isotropic light scattered again */
    float *esky;            /* [n][E_MU] the sky's irradiance of the ground, per unit irradiance */
    float *jms;             /* [J_R][J_MUS][J_G][J_P][n][2] J_ms per unit scattering coefficient of
                               the air molecules and of the aerosols, sr^-1 per unit irradiance */
    int use_j;              /* the march takes the higher orders from jms (else from Psi_ms) */
    float *block;           /* one allocation holding the four (the cache's payload) */
    size_t block_floats;
    double build_seconds;   /* 0 when loaded from the cache */
} atmos__sph_model;

/* What a march along a segment gathers, per wavelength of the subset (phase functions left
 * out: along one ray the scattering angle is constant):
 *   sr = int sigma_R T T_sun dt, sm = int sigma_M,sca T T_sun dt,
 *   ms = int (sigma_R j_R + sigma_M j_M) T dt (the higher orders, phase included; from
 *   Psi_ms, ms = int sigma_s T Psi_ms dt, while the J table is being built),
 *   f = int sigma_s T dt, t = T over the whole segment. */
typedef struct atmos__sph_sums {
    double sr[ATMOS_MAX_WAVELENGTHS], sm[ATMOS_MAX_WAVELENGTHS], ms[ATMOS_MAX_WAVELENGTHS];
    double f[ATMOS_MAX_WAVELENGTHS], t[ATMOS_MAX_WAVELENGTHS];
} atmos__sph_sums;

/* ------------------------------------------------------------------ tables (spherical_tables.c) */
/* Builds the tables of the planet (threads over rows). */
atmos_status atmos__sph_build(atmos_context *ctx, const atmos__planet *pl, atmos__sph_model *m);
/* ---- look-ups (spherical_lookup.c) */
/* Optical depth to the top from radius r along cosine mu (rays that miss the ground), per
 * wavelength of the subset. */
void atmos__sph_tau_top(const atmos__sph_model *m, double r, double mu, int cnt, const int *k, double *out);
/* Transmittance of the sunlight at radius r with the sun at cosine mu_s (0 in the planet's
 * shadow, the sun's centre behind the ground). */
void atmos__sph_sun_t(const atmos__sph_model *m, double r, double mu_s, int cnt, const int *k, double *out);
void atmos__sph_psi(const atmos__sph_model *m, double r, double mu_s, int cnt, const int *k, double *out);
void atmos__sph_esky(const atmos__sph_model *m, double mu_s, int cnt, const int *k, double *out);
/* J_ms at radius r for a view of zenith cosine mu, the sun at cosine mu_s, the view at the
 * angle g (atmos__sph_j_gamma of the cosine nu between view and sun, once per ray) from it:
 * jr, jm per unit scattering coefficient of the air molecules and the aerosols
 * (spherical_ms.c). */
typedef struct atmos__sph_jg {
    int i;
    double a, cg, sg;
} atmos__sph_jg;
void atmos__sph_j_gamma(double nu, atmos__sph_jg *g);
/* J_ms's coordinate mappings (spherical_jlookup.c): gamma of a column coordinate in [0, 1],
 * mu_s of a sun-column coordinate in [0, 1]. */
double atmos__sph_j_x_to_gamma(double x);
double atmos__sph_j_x_mus(double x);
void atmos__sph_j(const atmos__sph_model *m, double r, double mu, double mus, const atmos__sph_jg *g, int cnt,
                  const int *k, double *jr, double *jm);
/* Builds jms by one fixed-point iteration over the field marched with the current higher
 * orders (Psi_ms, or jms of the iteration before) and sets use_j; albedo: the uniform
 * ground's. */
atmos_status atmos__sph_build_j(const atmos__planet *pl, atmos__sph_model *m, const double *albedo);
/* J_ms gathered directly at radius r with the sun at cosine mus (the build's gather over
 * the field marched with the current tables, off the table's columns): out[(v * n + k) * 2
 * + part] = log(j + ATMOS__SPH_J_FLOOR) at view node v = ig * J_P + ip (gamma of ig /
 * (J_G - 1), psi's cosine 1 - 2 ip / (J_P - 1)), part 0 the air molecules, 1 the aerosols
 * (a check of the table's interpolation between its sun columns). */
atmos_status atmos__sph_j_direct(const atmos__planet *pl, const atmos__sph_model *m, double r, double mus,
                                 const double *albedo, float *out);
/* f_ms at (r, mu_s) of wavelength k (a diagnostic of the multiple-scattering table). */
double atmos__sph_fms(const atmos__sph_model *m, double r, double mu_s, int k);
/* The mappings' inverses the build needs (spherical_lookup.c): the (r, mu) of a depth-table
 * node, the mu_s of a column coordinate (the clamp is atmos__clampd, core/vec.h). */
void atmos__sph_tau_node(const atmos__sph_model *m, double xr, double xm, double *r, double *mu);
double atmos__sph_x_to_mus(double x);

/* ------------------------------------------------------------------ the march (spherical_march.c) */
/* Marches q + t d, t in [t0, t1] (inside the air), sun direction sun; use_ms: add the
 * higher orders (J_ms, or Psi_ms before J is built; the tables must hold it). steps per
 * monotone piece. */
void atmos__sph_march(const atmos__planet *pl, const atmos__sph_model *m, const double q[3], const double d[3],
                      double t0, double t1, const double sun[3], int steps, int use_ms, int cnt, const int *k,
                      atmos__sph_sums *s);
/* The march's running sums from t0 to each distance tj[0] < tj[1] < ... < tj[nd-1] along
 * q + t d ([t0, t1] inside the air; the sums stop at t1): out[(j * cnt + i) * 4 + 0..3] = sr,
 * sm, ms, t of atmos__sph_sums for wavelength i from t0 to tj[j]. One pass: each slice
 * [tj[j-1], tj[j]] (from t0 for j = 0) in at least `steps` equal steps, more where the ray
 * climbs or descends (at most 150 m of height a step), sampled at their midpoints (the
 * aerial-perspective volume, spherical_aerial.c). */
void atmos__sph_march_cumulative(const atmos__planet *pl, const atmos__sph_model *m, const double q[3],
                                 const double d[3], double t0, double t1, int nd, const double *tj,
                                 const double sun[3], int steps, int use_ms, int cnt, const int *k, double *out);
/* The ground's irradiance per unit solar irradiance with the sun at cosine cs there:
 * cs T_sun (lit side only) + E_sky. */
void atmos__sph_ground_irradiance(const atmos__planet *pl, const atmos__sph_model *m, double cs, int cnt,
                                  const int *k, double *out);
/* Radiance per unit irradiance reflected by the ground point g (centre frame, on the
 * sphere) lit by the sun and the sky, plus its emission divided by the irradiance. */
void atmos__sph_ground(const atmos__planet *pl, const atmos__sph_model *m, const double g[3], const double sun[3],
                       const double *sun_e, int cnt, const int *k, double *out);
/* The radiance of the view ray from p (world frame) without the sun's disk, all
 * wavelengths, in W m^-2 sr^-1 nm^-1; steps per piece. */
void atmos__sph_radiance(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                         int steps, double *out, atmos_atmosphere_hit *info);

/* The aerial-perspective volume's node (planet_solver.h's `aerial`; spherical_aerial.c). */
void atmos__sph_aerial(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3], int nd,
                       const double *t, float *out);

/* ------------------------------------------------------------------ per eye (spherical_batch.c) */
void atmos__sph_batch_init(atmos__atm_batch *b);
void atmos__sph_batch_eval(const atmos__atm_batch *b, int count, const float *dx, const float *dy, const float *dz,
                           const float *weight, float *out, float *scratch);
void atmos__sph_batch_release(atmos__atm_batch *b);
/* Whether b's table answers for a new eye and sun (the same quanta; spherical_batch.c), and
 * if so turns it to them; an eye above the air with cloud spheres and the sun of the frame
 * before: the sun's attenuation textures made or kept, the per-eye table kept or built
 * again (returns 1; the clouds' G then from the textures, within their error of the first
 * frame's). */
int atmos__sph_batch_keep(atmos__atm_batch *b, const double eye[3], const double sun[3]);
/* An eye above the top of the air (spherical_space.c): its table (NULL when out of memory),
 * the radiance of many view rays added to out as batch_eval does, and the release. gs: the
 * cloud spheres' attenuation textures for this sun (planet_clouds.h; not owned), or NULL. */
typedef struct atmos__sph_space atmos__sph_space;
struct atmos__clouds_sun;
atmos__sph_space *atmos__sph_space_create(const atmos_atmosphere *a, const double eye[3], const double sun[3],
                                          struct atmos__clouds_sun *gs);
/* Whether s's table answers for a new eye and sun (built for the same quantised distance
 * from the centre and sun's cosine), and if so turns it to them, with the clouds' textures
 * gs (NULL: none). */
int atmos__sph_space_keep(atmos__sph_space *s, const atmos__planet *pl, const double eye[3], const double sun[3],
                          struct atmos__clouds_sun *gs);
void atmos__sph_space_eval(const atmos__sph_space *s, const atmos_atmosphere *a, const double sun[3], int count,
                           const float *dx, const float *dy, const float *dz, const float *weight, float *out);
void atmos__sph_space_destroy(atmos__sph_space *s);

#endif
