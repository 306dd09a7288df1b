/* The cloud simulation's state and its steps (docs/clouds.md). Fields live on a staggered
 * (MAC) grid of nx * ny * nz cubic cells of edge dx, z up, x and y periodic: scalars at cell
 * centres, u and v on the x and y faces (u[i] between cells i-1 and i), w on the nz + 1
 * horizontal faces (w = 0 at the ground and the lid). Index (k ny + j) nx + i. */
#ifndef ATMOS_SIM_INTERNAL_H
#define ATMOS_SIM_INTERNAL_H

#include "atmos/sim.h"
#include "core/internal.h"

#include <stddef.h>
#include <stdint.h>

/* Physical constants (SI). */
#define SIM_G 9.81
#define SIM_CP 1004.0
#define SIM_RD 287.0
#define SIM_LV 2.5e6
#define SIM_LF 3.34e5 /* latent heat of fusion */
#define SIM_MAX_VOXELS (64L << 20) /* the most voxels a state is written as (sim_volume.c) */
#define SIM_P00 1e5
#define SIM_EPS 0.622

/* The environment and the triggers of a run (a preset is one of these). */
typedef enum { SIM_SOUNDING_LAYERED = 0, SIM_SOUNDING_WK82 = 1 } sim_sounding_kind;
typedef struct sim_env {
    sim_sounding_kind kind;
    double domain_m, height_m;    /* horizontal side and depth of the domain */
    double minutes;               /* default simulated time */
    double first_cloud;           /* minutes to the first cloud (q_c > 1e-5) at grid 64, seed 1, measured */
    double dt_max;                /* longest step, s */
    /* layered sounding: theta_s up to zi (mixed layer), a jump dtheta_inv over inv_depth, then
     * gamma_ft (K/m) up to z_tp, gamma_strat above; vapour qv_bl in the mixed layer, above
     * qv_ft exp(-(z - zi - inv_depth) / hq) */
    double theta_s, zi, dtheta_inv, inv_depth, gamma_ft, z_tp, gamma_strat;
    double qv_bl, qv_ft, hq;
    /* Weisman & Klemp (1982): theta = theta_s + (theta_tr - theta_s) (z / z_tp)^1.25 below z_tp,
     * RH = 1 - 0.75 (z / z_tp)^1.25, vapour at most qv_bl */
    double theta_tr, t_tr;
    /* wind: u = u_s tanh(z / z_shear) - u_move, v = 0 */
    double u_s, z_shear, u_move;
    /* warm bubbles: count, horizontal and vertical radii, centre height, theta excess (K),
     * vapour excess (kg/kg); placed at random (seeded) when count > 1, else at the centre */
    int bubbles;
    double bubble_rh, bubble_rv, bubble_z, bubble_dth, bubble_dqv;
    /* surface fluxes: kinematic heat (K m/s) and moisture (kg/kg m/s), each cell's times
     * 1 + flux_noise (2 r - 1), r uniform (seeded, new every step) */
    double shf, lhf, flux_noise;
    double noise_th;              /* initial theta noise amplitude below zi, at least 1 km (K) */
    double top_cooling;           /* cloud-top radiative cooling, W m^-2 (0 = none) */
    double confinement;           /* vorticity confinement epsilon (Fedkiw et al. 2001) */
    double k_eddy;                /* sub-grid eddy diffusivity, m^2/s (0 = none; sim_diffuse.c) */
    int micro;                    /* 0: dry (no phase changes) */
} sim_env;

struct atmos_sim {
    int nx, ny, nz, threads;
    double dx, dt_max;
    size_t n, nw;                 /* cells; w faces (nx ny (nz + 1)) */
    float *u, *v, *w, *th, *qv, *qc, *qr;
    float *s[8];                  /* scratch arrays of nw floats */
    float *pack;                  /* 12 n floats: the advection's packed fields (sim_advect.c) */
    double *part;                 /* per-level or per-row partial sums, 4 (max(nz, ny) + 1) doubles:
                                   * each filled by one thread, added in index order afterwards */
    /* base state at the cell-centre levels z_k = (k + 0.5) dx */
    double *th0, *qv0, *pi0, *p0, *rho0, *ue;
    double rho_ref;               /* the ground's density (the budget's reference) */
    double *rho_c, *rho_f;        /* rho0 / rho_ref at the centres (nz) and on the w faces (nz + 1;
                                   * 0 at the ground and the lid): the anelastic projection's */
    sim_env env;
    uint64_t seed;
    int out_refine, out_ice;      /* the volume's form (atmos_sim_desc; sim_volume.c) */
    double out_detail;
    double t;
    long steps;
    double rain_out, surface_in;  /* in (kg/kg) x cells */
    float vmax;                   /* largest |u|, |v|, |w| after the last projection */
    void *bar;                    /* a pthread barrier of `threads` threads (NULL: one thread) */
    void *fft_fwd, *fft_inv;      /* fftwf plans of one level, for levels aligned as the arrays are */
    void *fft_fwd_u, *fft_inv_u;  /* the same for any level (FFTW_UNALIGNED) */
    void *spec;                   /* complex spectrum, nz ny (nx / 2 + 1) */
    double *colbuf;               /* the projection's column solves: SIM_COLUMN_SCRATCH(nz) a thread */
};

/* Threads. A step is one OpenMP parallel region (sim_step.c); its phases hand out whole
 * levels or rows (SIM_FOR: dynamic, so a thread that the machine's other work keeps off its
 * core holds the others up by one level at most) and end at atmos__sim_sync, a barrier whose
 * waiting threads sleep instead of spinning (OpenMP's own barriers spin, which on a busy
 * machine takes the core from the thread being waited for). A cell's arithmetic is the same
 * whichever thread does it and sums are made per level or row and added in order, so the
 * results do not depend on the thread count. Called outside a parallel region, the phases
 * run on the calling thread. */
#define SIM_FOR _Pragma("omp for schedule(dynamic, 1) nowait")
void atmos__sim_sync(atmos_sim *s); /* sim_sync.c */
void atmos__sim_sync_init(atmos_sim *s);
void atmos__sim_sync_free(atmos_sim *s);

static inline size_t sim_idx(const atmos_sim *s, int i, int j, int k)
{
    return ((size_t)k * s->ny + j) * s->nx + i;
}

/* i wrapped into [0, n) (the periodic sides); floor() without the library call (the baseline
 * x86-64 target has no rounding instruction), for positions far inside int's range. */
static inline int sim_wrap(int i, int n)
{
    if ((unsigned)i >= (unsigned)n) {
        i %= n;
        if (i < 0) i += n;
    }
    return i;
}

static inline int sim_ifloor(float x)
{
    const int i = (int)x;
    return i - (x < i);
}

/* Runs to the time `end` (s), the last step shortened to end there, or with whole_steps only
 * the steps that end at or before it (a time-lapse's run: sim_timelapse.c); progress as
 * atmos_sim_run's (sim_step.c). */
atmos_status atmos__sim_run_to(atmos_context *ctx, atmos_sim *s, double end, int whole_steps);

/* The simulation's arrays (sim_alloc.c): 64-byte aligned, on 2 MB pages where large
 * (atmos__big_alloc), so that a level's FFT plan does not depend on where malloc put it. */
void *atmos__sim_alloc(size_t bytes);

/* Presets (sim_presets.c). NULL if unknown. */
const sim_env *atmos__sim_preset(const char *name);

/* Builds a simulation of an environment on nx * ny * nz cells of dx metres (sim_create.c). */
atmos_status atmos__sim_create_env(atmos_context *ctx, const sim_env *env, int nx, int ny, int nz, double dx,
                                   uint64_t seed, atmos_sim **out);

/* Thermodynamics (sim_thermo.c). Saturation vapour pressure over water (Bolton 1980, Eq. 10), Pa;
 * saturation mixing ratio; dew point (its inverse), K. */
double atmos__sim_esat(double t_k);
double atmos__sim_qsat(double t_k, double p_pa);
double atmos__sim_dewpoint(double qv, double p_pa);
/* Saturation over ice (Alduchov & Eskridge 1996), Pa; the fraction of the condensate that is
 * ice at temperature t, K (the IFS's mixed phase: all water at 0 C, all ice at -23 C); the
 * condensate's saturation mixing ratio (over water and ice by that fraction) and its latent
 * heat, L_v + L_f times the fraction. */
double atmos__sim_esat_ice(double t_k);
double atmos__sim_ice_fraction(double t);
double atmos__sim_qsat_cond(double t_k, double p_pa);
double atmos__sim_latent(double t_k);
/* Saturation adjustment of one cell at pressure p and Exner function pi: condenses vapour
 * above the condensate's saturation or evaporates cloud into subsaturated air, with the
 * latent heat of the cell's starting temperature, so that afterwards q_c = 0 and
 * q_v <= q_s,cond, or q_c > 0 and q_v = q_s,cond (Newton iteration). */
void atmos__sim_adjust(double *th, double *qv, double *qc, double p_pa, double pi);
/* Fills the base state (th0, qv0, pi0, p0, rho0, ue) from sim->env. */
void atmos__sim_sounding(atmos_sim *sim);

/* The step's parts. */
/* sim_advect.c; returns the water fixer's factor for the vapour (applied by atmos__sim_micro) */
double atmos__sim_advect(atmos_sim *sim, double dt);
void atmos__sim_advected_velocity(atmos_sim *sim);
/* sim_maccormack.c: the scalars' correction after the semi-Lagrangian step, which left its
 * result packed in pack[8 n ..], the old values in pack[4 n ..] and the departure points in
 * s[0..2] (cell units); the corrected fields into th, q_v, q_c, q_r, the level's water after it
 * into part[2 (nz + 1) + k] and part[3 (nz + 1) + k]. Ends at a barrier. */
void atmos__sim_maccormack(atmos_sim *sim);
/* sim_trace.c: trilinear samples of a field of nz_f levels (x, y wrapped, z clamped) at n points
 * of its index space (single precision), into out[m]; of four fields packed per cell (f4[4 cell + field]) into
 * out4[4 m + field] */
void atmos__sim_sample_row(const atmos_sim *sim, const float *f, int nz_f, const float *x, const float *y,
                           const float *z, float *out, int n);
void atmos__sim_sample4_row(const atmos_sim *sim, const float *f4, int nz_f, const float *x, const float *y,
                            const float *z, float *out4, int n);
/* The same by the scalar code only (what the vectorised path must match bit for bit; tests) */
void atmos__sim_sample_row_scalar(const atmos_sim *sim, const float *f, int nz_f, const float *x, const float *y,
                                  const float *z, float *out, int n);
void atmos__sim_sample4_row_scalar(const atmos_sim *sim, const float *f4, int nz_f, const float *x, const float *y,
                                   const float *z, float *out4, int n);
/* sim_forces.c: surface fluxes, cloud-top cooling, buoyancy and the sponge of row j (y = j);
 * returns the water the surface added to the row */
double atmos__sim_forces_row(atmos_sim *sim, double dt, int j);
void atmos__sim_diffuse(atmos_sim *sim, double dt);       /* sim_diffuse.c: sub-grid mixing */
void atmos__sim_confine(atmos_sim *sim, double dt);       /* sim_confine.c: vorticity confinement */
void atmos__sim_project(atmos_sim *sim);                  /* sim_pressure.c */
#define SIM_CW 8 /* columns of modes solved side by side (sim_pressure.c) */
#define SIM_COLUMN_SCRATCH(nz) (4 * (size_t)SIM_CW * (size_t)(nz))
atmos_status atmos__sim_fft_init(atmos_context *ctx, atmos_sim *sim);
void atmos__sim_fft_free(atmos_sim *sim);
/* sim_micro.c: the vapour times fix, Kessler + adjustment; rain sedimentation in the columns of
 * row j, returning the rain that left through the ground */
void atmos__sim_micro(atmos_sim *sim, double dt, float fix);
double atmos__sim_fall_row(atmos_sim *sim, double dt, int j);
/* Largest |divergence| x dx (m/s) over the cells, to check the projection. */
double atmos__sim_max_divergence(const atmos_sim *sim);

#endif
