/* The volume as a participating medium for the path tracer (path_medium.c): free flights,
 * transmittance and forced points over the volume's per-brick bounds. The volume itself is
 * read through the accessor (volume/volume_access.h); the medium adds the optics. Not
 * part of the API. */
#ifndef ATMOS_RENDER_PATH_MEDIUM_H
#define ATMOS_RENDER_PATH_MEDIUM_H

#include "render/path_common.h"
#include "volume/volume_access.h"

typedef struct {
    const atmos_volume *v;
    int nf;
    /* World <-> index: the volume's transform moved by the render's offset. path.c reads
     * org, R and inv_vs by name (the sky light's reference height), hence the union. */
    union {
        atmos__vol_xform x;
        struct {
            double org[3], R[9], vs, inv_vs;
        };
    };
    float scale;            /* density scale */
    double box_lo[3], box_hi[3]; /* index-space box of the bricks with a nonzero bound (ray clipping) */
    int empty;              /* no such brick */
    float sig[PATH_F][ATMOS_MAX_WAVELENGTHS]; /* extinction cross-section, m^2 */
    float sca[PATH_F][ATMOS_MAX_WAVELENGTHS]; /* scattering cross-section, m^2 */
} path_medium;

atmos_status atmos__path_medium_build(atmos_context *ctx, const atmos_volume *v, double scale, const double offset[3],
                                      const atmos_volume_optics *optics, int nwl, path_medium *m);
void atmos__path_medium_free(path_medium *m);
/* Forward-peak truncation of the medium: per field and wavelength the fraction trunc of the
 * scattering counts as not scattered, sigma_s' = sigma_s (1 - trunc), sigma_t' = sigma_t -
 * trunc sigma_s (the absorption is unchanged). Majorants and transmittance follow. */
void atmos__path_medium_truncate(path_medium *m, int nwl, const float trunc[][ATMOS_MAX_WAVELENGTHS]);

/* World point / direction to index space (t stays in metres along a unit world direction). */
void atmos__path_to_index(const path_medium *m, const double p[3], const double d[3], double q[3], double qd[3]);
/* Interval [t0, t1] of a ray (index space) inside the occupied box, clipped to [0, tmax];
 * 0 if none. */
int atmos__path_clip(const path_medium *m, const double q[3], const double qd[3], double tmax, double *t0, double *t1);

/* Steps of one walk (free flight or shadow ray) between its Russian roulettes (a power of
 * two; path_medium.c). */
#define PATH_WALK_RR 4096
/* The walks the calling thread ended at that roulette since the last call. */
long long atmos__path_walks_ended(void);

/* Free flight by delta tracking with spectral tracking weights (Kutz et al. 2017,
 * "Spectral and decomposition tracking", the history-aware average probabilities) from
 * t0 to t1 (inside the box). Returns 1 at a real scattering event (*t, dens[] = the
 * scaled field densities there), 0 when the ray leaves at t1, -1 when every weight is 0,
 * -2 when the walk ended at its roulette (every PATH_WALK_RR tentative collisions).
 * w[] (per carried wavelength) is updated. *tentative counts tentative collisions. */
int atmos__path_free_flight(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                            const path_bundle *b, double *w, atmos__stream *r, double *t, float *dens, long long *tentative);

/* Transmittance from t0 to t1 by ratio tracking on the residual above each cell's
 * minorant (the minorant's part is exact: exp(-sigma_c * length)), with Russian roulette
 * when it gets small and every PATH_WALK_RR steps. Writes T[] per carried wavelength;
 * returns 1 when the walk ended at the latter (T = 0). */
int atmos__path_transmittance(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                               const path_bundle *b, atmos__stream *r, double *T);

/* A point of [t0, t1] for forced single scattering, by the majorant mu of the carried
 * wavelengths: with u0 < 0.5 the first tentative collision conditioned to lie in [t0, t1]
 * (density mu e^-tau_mu(t) / (1 - e^-tau_mu(t1)): good in dense media), else uniform in
 * majorant optical depth (mu / tau_mu(t1): good in thin ones); *pdf is the mixture's
 * density (per metre), u uniform in [0, 1). 0 if the majorant is 0 all along or its optical
 * depth over [t0, t1] exceeds tau_max. */
int atmos__path_majorant_point(const path_medium *m, const double q[3], const double qd[3], double t0, double t1,
                               const path_bundle *b, double tau_max, double u0, double u, double *t, double *pdf);

/* Scaled densities at an index-space point (0 outside the grid). */
void atmos__path_density(const path_medium *m, double x, double y, double z, float *dens);

#endif
