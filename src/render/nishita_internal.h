/* The Nishita renderer ("renderer": "nishita"; Nishita, Dobashi & Nakamae 1996): eye rays
 * marched through the volume, the first order of the sunlight computed at every sample with
 * the fields' own phase functions and the sunlight's attenuation stored per render voxel, the
 * orders 2 and 3 and the sky's light interpolated from a light field (src/light/nishita.h).
 *
 *   nishita_plan.c    the render grid, the optics, the sunlight's attenuation per voxel (one
 *                     sweep across the grid per sun direction), the light field per sun and
 *                     eye direction, its sky elements
 *   nishita_render.c  the eye rays (four in the pixels at the volume's edges, edge_aa.c) and
 *                     the composite over the sky
 *   dfield.c          with "diffuse": the slice renderer's diffuse light field, shared
 *   nishita_mc.c      with "mc_kphotons": the Monte Carlo field of the orders >= 2
 *   nishita_do.c      with "do": the same field by discrete ordinates (light/lfield_do.c)
 *
 * Not part of the API. */
#ifndef ATMOS_RENDER_NISHITA_INTERNAL_H
#define ATMOS_RENDER_NISHITA_INTERNAL_H

#include "light/nishita.h"
#include "render/dfield.h"
#include "render/plan_internal.h"
#include "render/slice_grid.h"
#include "volume/volume_access.h"

typedef struct atmos__nishita_mc atmos__nishita_mc;

struct atmos__nishita_plan {
    atmos_scene_nishita opt; /* its settings: the scene's, or the slice renderer's field's (nishita_do_plan) */
    int nf, n;
    sgrid g;                 /* the volume box-filtered onto the render grid (slice_grid.c) */
    int g_borrowed;          /* g is the slice renderer's (nishita_do_plan): not freed here */
    atmos__vol_xform x;      /* the volume's placement */
    float sig[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* extinction cross-section, m^2 */
    float sca[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* scattering cross-section, m^2 */
    const atmos_phase_table *phase[ATMOS_VOLUME_MAX_FIELDS];
    float *col;              /* per render voxel and field: the column density toward the sun, m */
    double col_sun[3];       /* the sun (grid frame) col was made for */
    int col_valid;
    atmos__lmedium med;      /* the light field's medium: cells of s render voxels, forward peak truncated */
    double trunc[ATMOS_MAX_WAVELENGTHS]; /* the share of the scattering in the forward peak (above the
                                            phase's value at TRUNC_DEG), counted as not scattered by
                                            the orders 2-3 */
    float *fdens;            /* per cell and field: the mean density */
    int s;
    atmos__lfield field;
    double field_sun[3], field_ev[3];
    int field_valid;
    atmos__nishita_stats stats;
    double col_s;            /* the last sweep's time */
    /* "diffuse" (dfield.c, docs/lightfield.md): the slice renderer's diffuse field of all orders
     * and Riley's scattered beam, weighted by the field's fade (1 where the medium is thick), the
     * orders 2-3 and the sky elements by the rest */
    int diffuse;
    stables tab;             /* the field's tables: cross-sections, F_n, B_n, Ams_2 */
    atmos__dfield df;
    /* "mc_kphotons" (nishita_mc.c): the Monte Carlo field of the orders >= 2 toward the eye, the
     * first order and the eye rays in the medium truncated as its photons see it (sig'); the
     * field's part of the eye rays attenuated by mc_sig_ms and weighted by mc_sca, the medium its
     * photons see: sig' and sca' as well, or with "mc_delta_m" the delta-M scaled sig* and sca* */
    atmos__nishita_mc *mc;
    float mc_sig[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS];
    float mc_sig_ms[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS];
    float mc_sca[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS];
    double mc_s;             /* the last field's time */
    /* with "do" (nishita_do.c): the last solve's directions, GMRES iterations and sweeps (over the
     * wavelengths), largest relative residual, CPU time */
    int do_dirs, do_iters, do_sweeps, do_source_its; /* do_source_its > 0: do_resid is rho^k's bound */
    double do_resid, do_cpu;
    /* edge_aa (nishita_render.c, edge_aa.c): the edge pixels' transmittances and flags */
    unsigned char *edge;
    size_t edge_cap;
};

/* A plan of the discrete-ordinates field alone (nishita_plan.c), the field of the slice renderer's
 * "do" (slice_do.c): the optics, the render grid borrowed from the slice renderer (its own grid, not
 * a copy: it must outlive the plan), the sunlight's columns and the field
 * (atmos__nishita_mc_create: degree 3, delta-M, discrete ordinates), none of the orders 2-3. */
atmos_status atmos__nishita_do_plan_create(atmos_plan *p, const sgrid *grid, atmos__nishita_plan **out);

/* The Monte Carlo field (nishita_mc.c): made once per plan (the path tracer's medium and phase
 * tables, cut at 3 degrees), filled per sun (and, toward one direction, per out_w: the light's
 * direction toward the eye), turned toward the eye at eye_w per frame (E: the sunlight per
 * wavelength), read by the eye rays. warm: the discrete-ordinates field after a sun move starts
 * from the last sun's (the frame's warm_field). */
atmos_status atmos__nishita_mc_create(atmos_plan *p, atmos__nishita_plan *np);
void atmos__nishita_mc_free(atmos__nishita_mc *mc);
atmos_status atmos__nishita_mc_update(atmos_plan *p, atmos__nishita_plan *np, const double sun_w[3],
                                      const double out_w[3], const double eye_w[3], const double *E, int threads,
                                      int warm);
const atmos__lfield *atmos__nishita_mc_field(const atmos__nishita_plan *np);
/* With a delta-M scaled field (its photons saw sig*, not sig'): per field and wavelength the
 * moments chi*_0..3 of its scaled phase (0 above its degree) and sigma_s' - sigma_s*, the
 * scattering its peak turns (the eye rays' first order of two populations, dm_two_pop.c); returns
 * 1 then, 0 (nothing set) without delta-M. */
int atmos__nishita_mc_dm_phase(const atmos__nishita_plan *np, double chi[][ATMOS_MAX_WAVELENGTHS][4],
                               float turn[][ATMOS_MAX_WAVELENGTHS]);

/* Appends the discrete-ordinates field's last solve (directions, iterations, sweeps, residual,
 * cells, times) to buf as "; discrete-ordinates field, ..." (nishita_mc.c). */
void atmos__nishita_do_describe(const atmos__nishita_plan *np, char *buf, size_t cap);

/* The forward-peak truncation of the orders 2-3 (nishita_light.c): trunc[] from the fields'
 * mean phase function, the field's medium scaled (sig_s (1 - f), sig_t - f sig_s). */
void atmos__nishita_truncate(atmos__nishita_plan *np);

/* The sunlight's column densities for the sun sun_g (grid frame), unless already made. */
void atmos__nishita_columns(atmos__nishita_plan *np, const double sun_g[3], int threads);
/* The light field for the sun sun_w (world) and the eye at eye_w, unless made for the same
 * sun and eye direction. */
atmos_status atmos__nishita_field_update(atmos_plan *p, const double sun_w[3], const double eye_w[3]);

/* Trilinear value of m floats per voxel of a render-grid array at render-voxel coordinate
 * (u, v, w) (voxel centres at integers; clamped into the grid; nishita_grid.c). */
void atmos__nishita_grid_at(const sgrid *g, const float *arr, int m, double u, double v, double w, float *out);
/* What the volume's shadow takes from the air's single scattering along the eye ray cam + t d
 * (world; eye_g + t dg in the grid frame), t in [s0, s1], per wavelength into D; the sun sun_w
 * (world), sun_g (grid frame), the volume's transmittance toward it by the columns (made for
 * sun_g) times sig (nishita_air.c). */
void atmos__nishita_air_shadow(const atmos__nishita_plan *np, const atmos_atmosphere *atm, const double cam[3],
                               const double d[3], const double eye_g[3], const double dg[3], const double sun_w[3],
                               const double sun_g[3], const float sig[][ATMOS_MAX_WAVELENGTHS], double s0, double s1,
                               double *D);

#endif
