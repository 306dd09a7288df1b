/* A cloud-physics simulation as a volume source (docs/clouds.md): a 3-D anelastic fluid on
 * a staggered (MAC) grid with potential temperature, water vapour, cloud (water or ice by
 * temperature) and rain (or snow), semi-Lagrangian advection, vorticity confinement, buoyancy
 * from temperature and water loading, an exact FFT pressure projection (periodic sides, rigid
 * ground and lid), Kessler rain with Lin et al.'s ice and snow, and saturation adjustment over
 * water and ice with latent heat. Its state is handed to the renderers
 * as an atmos volume ("cloud" and "rain" number densities through the particle types' mean
 * masses, like the WRF reader).
 *
 * Deterministic: the same preset, grid and seed give the same bytes for any thread count.
 */
#ifndef ATMOS_SIM_H
#define ATMOS_SIM_H

#include "atmos/base.h"
#include "atmos/volume.h"
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_SIM_MIN_GRID 16
#define ATMOS_SIM_MAX_GRID 512
#define ATMOS_SIM_MAX_MINUTES 600.0
#define ATMOS_SIM_MAX_REFINE 4

/* What to simulate; zero means default where stated. */
typedef struct atmos_sim_desc {
    const char *preset;  /* "cumulus_field", "towering_cumulus", "cumulonimbus", "stratocumulus" */
    double minutes;      /* simulated time for atmos_simulate; 0 = the preset's default */
    int grid;            /* cells along each horizontal side, in [ATMOS_SIM_MIN_GRID,
                            ATMOS_SIM_MAX_GRID]; 0 = 64. The domain's size is the preset's: a finer
                            grid has smaller (cubic) cells */
    uint64_t seed;       /* the random perturbations (bubble places, surface-flux noise) */
    /* How atmos_sim_to_volume writes the state (zeros: one voxel a cell, liquid only, no
       texture: the model's fields as they are). */
    int refine;          /* voxels per cell along each axis, 1..ATMOS_SIM_MAX_REFINE (0 = 1): the
                            fields interpolated between cell centres in their logarithm, so that
                            a cloud's edge lies where its smeared-out values cross, not on the
                            faces of the cells */
    double detail;       /* [0, 1], for artists: the fields sampled at places moved by a fractal
                            noise of up to `detail` cells, whose features run from a cell down to
                            a voxel: ragged edges the model does not hold (0 = off) */
    int ice;             /* 1: condensate (cloud water) reported as "ice" in the fraction that the
                            temperature gives (ECMWF IFS's mixed phase: all liquid at 0 C, all
                            ice at -23 C, quadratic between): the fraction the model's
                            saturation and latent heat use too, written as a field of its own */
} atmos_sim_desc;

typedef struct atmos_sim atmos_sim;

/* The presets, NULL-terminated. */
ATMOS_API const char *const *atmos_sim_preset_names(void);
/* A preset's default simulated time, minutes (0 for an unknown name). */
ATMOS_API double atmos_sim_preset_minutes(const char *preset);

/* Roughly when a preset's first cloud (q_c > 1e-5 kg/kg) forms, simulated minutes, as measured at
 * the default grid with seed 1 (docs/clouds.md); a shorter run gives an empty volume. 0 for a
 * preset that starts cloudy and for an unknown name. */
ATMOS_API double atmos_sim_preset_first_cloud_minutes(const char *preset);

/* Builds the initial state (the preset's sounding and triggers). Unknown presets and
 * out-of-range values: ATMOS_E_INVALID_ARG naming the known presets / the range; a refine
 * whose volume would exceed 64 M voxels (refine^3 x the cells): ATMOS_E_LIMIT, before any run. */
ATMOS_API atmos_status atmos_sim_create(atmos_context *ctx, const atmos_sim_desc *desc, atmos_sim **out);
ATMOS_API void atmos_sim_destroy(atmos_sim *sim);
/* Advances by one time step (chosen from the flow's speed, at most the preset's maximum). */
ATMOS_API atmos_status atmos_sim_step(atmos_context *ctx, atmos_sim *sim);
/* Advances by `seconds`, reporting progress (stage "simulate") through ctx; the progress
 * callback may cancel (ATMOS_E_CANCELLED). */
ATMOS_API atmos_status atmos_sim_run(atmos_context *ctx, atmos_sim *sim, double seconds);

typedef struct atmos_sim_stats {
    int dims[3];            /* cells along x, y (horizontal) and z (up) */
    double cell_m;          /* cell edge, metres */
    double time_s;          /* simulated time */
    long steps;
    double water;           /* vapour + cloud + rain in the domain, kg per m^2 of ground (each
                               level's base-state density) */
    double rain_out;        /* rain that fell through the ground, kg m^-2 */
    double surface_in;      /* water the surface moisture flux added, kg m^-2 */
    double max_w;           /* largest updraught, m/s */
    double max_qc, max_qr;  /* largest cloud and rain mixing ratios, kg/kg */
    double cloud_base_m, cloud_top_m; /* lowest and highest cell centre with q_c > 1e-5 (-1: no cloud) */
} atmos_sim_stats;
ATMOS_API void atmos_sim_get_stats(const atmos_sim *sim, atmos_sim_stats *out);

/* The state as a volume: fields "cloud" and "rain", and "ice" with desc->ice (number densities,
 * m^-3: q rho / m, m from atmos_particle_mean_mass), voxels the model's cells (refined by
 * desc->refine), y up with the ground at y = 0 and the domain centred on x = z = 0. */
ATMOS_API atmos_status atmos_sim_to_volume(atmos_context *ctx, const atmos_sim *sim, atmos_volume **out);
/* A time-lapse: the volume at `minutes` of simulated time, the same bytes as atmos_simulate
 * with those minutes gives, from a simulation that goes on from where the last call left it:
 * sim is advanced by whole steps up to that time (never past it) and the last, shortened step
 * is taken on a copy. minutes must not be less than sim's time (ATMOS_E_INVALID_ARG). */
ATMOS_API atmos_status atmos_sim_volume_at(atmos_context *ctx, atmos_sim *sim, double minutes, atmos_volume **out);
/* create + run(desc->minutes, or the preset's default) + to_volume. */
ATMOS_API atmos_status atmos_simulate(atmos_context *ctx, const atmos_sim_desc *desc, atmos_volume **out);

#ifdef __cplusplus
}
#endif
#endif
