/* The slice renderer's optics tables (slice_tables.c). Not part of the API. */
#ifndef ATMOS_RENDER_SLICE_TABLES_H
#define ATMOS_RENDER_SLICE_TABLES_H

#include "core/internal.h"

#define SLICE_F_ORDERS 256     /* F_n and S(n) tabulated at integer n = 0..SLICE_F_ORDERS */

typedef struct {
    int n;                     /* wavelengths */
    int nf;                    /* fields */
    float sig[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* sigma_ext, m^2 */
    float sca[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* albedo * sigma_ext */
    int no;                    /* Ams orders tabulated: 1..no */
    int ng[ATMOS_VOLUME_MAX_FIELDS];
    const double *grid[ATMOS_VOLUME_MAX_FIELDS];  /* theta, degrees */
    float *ams[ATMOS_VOLUME_MAX_FIELDS];          /* [(a * no + (order - 1)) * n + k]: the wavelengths of
                                                     an angle and order side by side, so that the
                                                     bilinear taps of all wavelengths of a sample
                                                     fall in two cache lines */
    float *F[ATMOS_VOLUME_MAX_FIELDS];            /* [k * (SLICE_F_ORDERS+1) + n]: F_n (Eq. 23) */
    float *S[ATMOS_VOLUME_MAX_FIELDS];            /* same layout: S(n) = sum_{i<=n} ln F_i */
    float *B[ATMOS_VOLUME_MAX_FIELDS];            /* same layout: the mean cosine of Ams_n over the
                                                     backward hemisphere, the part 1 - F_n that the
                                                     forward model drops (-1/2 where isotropic) */
} stables;

/* The tables of the volume's optics for n wavelengths, Ams orders 1..max_order. */
atmos_status atmos__stables_build(atmos_context *ctx, const atmos_volume_optics *o, int n, int max_order, stables *t);
void atmos__stables_free(stables *t);

/* Index a and weight w (of grid point a+1) of angle theta on an increasing grid. *a
 * holds a guess on entry (the neighbouring pixel's index), tried with its neighbours
 * before the angle-table reader (optics/angle_table.h); the result does not depend on it. */
void atmos__angle_locate(const double *grid, int ng, double theta_deg, int *a, float *w);

/* Linear interpolation in a per-order table at fractional n >= 0; past the last order,
 * F is held (F_n -> 1/2) and S grows by ln F of the last order per order. */
static inline float order_lerp(const float *tab, float n, int extend)
{
    if (!(n > 0.0f)) return tab[0];
    if (n >= (float)SLICE_F_ORDERS) {
        if (!extend) return tab[SLICE_F_ORDERS];
        float slope = tab[SLICE_F_ORDERS] - tab[SLICE_F_ORDERS - 1];
        return tab[SLICE_F_ORDERS] + slope * (n - (float)SLICE_F_ORDERS);
    }
    int i = (int)n;
    float f = n - (float)i;
    return tab[i] + f * (tab[i + 1] - tab[i]);
}

#endif
