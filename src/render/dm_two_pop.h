/* The first order of two populations in a delta-M scaled medium (dm_two_pop.c), shared by the
 * slice renderer's do field (slice_do.c) and the Nishita renderer's eye rays (nishita_render.c).
 * Not part of the API. */
#ifndef ATMOS_RENDER_DM_TWO_POP_H
#define ATMOS_RENDER_DM_TWO_POP_H

#include "render/slice_tables.h"

/* The angle of the forward peak's cut (the path tracer's --truncate 3, the field's cut), degrees. */
#define ATMOS_DM_CUT_DEG 3.0

/* The share of field f's phase table (Ams_1, row 0 of t, n wavelengths) above its value at
 * ATMOS_DM_CUT_DEG within that angle, at wavelength w: the part the cut counts as not scattered. */
double atmos__dm_cut_share(const stables *t, int f, int w, int n);

/* The moments chi_0..chi_3 of field f's phase table at wavelength w (n wavelengths), chi_0 = 1. */
void atmos__dm_moments3(const stables *t, int f, int w, int n, double chi[4]);

/* sigma_s* / sigma_s times delta-M's scaled phase of degree 3 at cosine mu, from the moments chi and
 * delta-M's share sh (1 - sigma_s* / sigma_s): sum (2l + 1) / (4 pi) (chi_l - sh) P_l(mu), not below 0. */
double atmos__dm_phase3(const double chi[4], double sh, double mu);

#endif
