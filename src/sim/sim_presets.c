/* The simulation's presets: a sounding, a wind profile and the triggers of convection
 * (docs/clouds.md lists them with their sources). */
#include "sim/sim_internal.h"

#include <string.h>

typedef struct {
    const char *name;
    sim_env env;
} preset;

static const preset presets[] = {
    /* Fair-weather cumulus: a moist mixed layer 700 m deep (LCL ~ 800 m) under a weak
     * inversion and a trade-wind inversion at 2 km; surface heating and moistening plus
     * a dozen small seeded warm, moist bubbles; light wind. */
    {"cumulus_field",
     {.kind = SIM_SOUNDING_LAYERED, .domain_m = 6400, .height_m = 3200, .minutes = 20, .first_cloud = 4, .dt_max = 6,
      .theta_s = 298, .zi = 700, .dtheta_inv = 0.5, .inv_depth = 100, .gamma_ft = 3.5e-3, .z_tp = 2000,
      .gamma_strat = 15e-3, .qv_bl = 13.5e-3, .qv_ft = 11e-3, .hq = 1500, .u_s = 3, .z_shear = 1000,
      .u_move = 0, .bubbles = 12, .bubble_rh = 350, .bubble_rv = 250, .bubble_z = 300, .bubble_dth = 0.8,
      .bubble_dqv = 1.0e-3, .shf = 0.08, .lhf = 8e-5, .flux_noise = 0.5, .noise_th = 0.1,
      .confinement = 0.15, .micro = 1}},
    /* A towering cumulus: the Weisman-Klemp sounding with less vapour and no tropopause
     * in reach, one warm bubble, weak shear. */
    {"towering_cumulus",
     {.kind = SIM_SOUNDING_WK82, .domain_m = 8000, .height_m = 8000, .minutes = 20, .first_cloud = 3, .dt_max = 8,
      .theta_s = 300, .theta_tr = 343, .t_tr = 213, .z_tp = 12000, .qv_bl = 13e-3, .u_s = 5, .z_shear = 3000,
      .u_move = 2.5, .bubbles = 1, .bubble_rh = 1500, .bubble_rv = 800, .bubble_z = 800, .bubble_dth = 2.0,
      .bubble_dqv = 1e-3, .shf = 0, .lhf = 0, .flux_noise = 0, .noise_th = 0.2, .confinement = 0.2, .micro = 1}},
    /* A sheared cumulonimbus: Weisman & Klemp (1982)'s sounding (14 g/kg mixed layer,
     * tropopause at 12 km, 213 K) and wind (U_s tanh(z / 3 km), U_s = 15 m/s), their warm bubble
     * (2 K; 10 km x 1.4 km radii, here 5 km across the smaller domain). */
    {"cumulonimbus",
     {.kind = SIM_SOUNDING_WK82, .domain_m = 25600, .height_m = 16000, .minutes = 45, .first_cloud = 4, .dt_max = 10,
      .theta_s = 300, .theta_tr = 343, .t_tr = 213, .z_tp = 12000, .qv_bl = 14e-3, .u_s = 15, .z_shear = 3000,
      .u_move = 8, .bubbles = 1, .bubble_rh = 5000, .bubble_rv = 1400, .bubble_z = 1400, .bubble_dth = 2.0,
      .bubble_dqv = 0, .shf = 0, .lhf = 0, .flux_noise = 0, .noise_th = 0.2, .confinement = 0.2, .micro = 1}},
    /* A stratocumulus deck after DYCOMS-II RF01 (Stevens et al. 2005): a well-mixed layer
     * (theta 289 K, 9 g/kg) to 840 m under an 8.5 K inversion with dry air above, cloud-top
     * radiative cooling (60 W m^-2) stirring it. No wind: the mixed layer's momentum is well
     * mixed, so the domain moves with it (a tanh shear through the layer drew the deck out
     * into streaks along the wind). Horizontal sub-grid mixing (k_eddy, sim_diffuse.c) keeps
     * the cells several grid cells across (without it they were noise one cell wide). */
    {"stratocumulus",
     {.kind = SIM_SOUNDING_LAYERED, .domain_m = 6400, .height_m = 1600, .minutes = 20, .dt_max = 5,
      .theta_s = 289, .zi = 840, .dtheta_inv = 8.5, .inv_depth = 50, .gamma_ft = 3e-3, .z_tp = 5000,
      .gamma_strat = 3e-3, .qv_bl = 9e-3, .qv_ft = 1.5e-3, .hq = 1e6, .u_s = 0, .z_shear = 1000, .u_move = 0, .k_eddy = 30,
      .bubbles = 0, .shf = 0.01, .lhf = 1e-5, .flux_noise = 0.5, .noise_th = 0.2, .top_cooling = 60,
      .confinement = 0.1, .micro = 1}},
};
#define NPRESETS ((int)(sizeof presets / sizeof presets[0]))

const sim_env *atmos__sim_preset(const char *name)
{
    for (int i = 0; name && i < NPRESETS; i++)
        if (!strcmp(presets[i].name, name)) return &presets[i].env;
    return NULL;
}

const char *const *atmos_sim_preset_names(void)
{
    static const char *const names[NPRESETS + 1] = {"cumulus_field", "towering_cumulus", "cumulonimbus",
                                                    "stratocumulus", NULL};
    return names;
}

double atmos_sim_preset_minutes(const char *name)
{
    const sim_env *e = atmos__sim_preset(name);
    return e ? e->minutes : 0.0;
}

double atmos_sim_preset_first_cloud_minutes(const char *name)
{
    const sim_env *e = atmos__sim_preset(name);
    return e ? e->first_cloud : 0.0;
}
