/* Dobashi et al. 2002 §5: the solver table of ATMOS_ATMOSPHERE_DOBASHI (planet_solver.h)
 * over the look-up tables of dobashi.h. Every answer is Eq. 12 or a part of it: the view
 * transmittance is the product of the dg_v, the sunlight I_sun g_l, the in-scatter the sum
 * over the sub-segments (single scattering) plus the ambient term. */
#include "atmosphere/dobashi.h"

#include <stdlib.h>

static atmos_status dob_create(atmos_context *ctx, atmos_atmosphere *a)
{
    atmos__dobashi *m = atmos__dobashi_build(a->planet, 0.0, 0);
    if (!m) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory for Dobashi's tables");
    m->ambient = a->desc.dobashi_ambient;
    a->model = m;
    return ATMOS_OK;
}

static void dob_transmittance(const atmos_atmosphere *a, const double p[3], const double d[3], double dist, int cnt,
                              const int *k, double *out)
{
    double sr[ATMOS_MAX_WAVELENGTHS], sm[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    atmos__dobashi_march(a->model, a->planet, p, d, dist, d, sr, sm, T);
    for (int i = 0; i < cnt; i++) out[i] = T[ATMOS__WL(k, i)];
}

static void dob_sunlight(const atmos_atmosphere *a, const double p[3], const double sun[3], int cnt, const int *k,
                         double *out)
{
    atmos__dobashi_gl(a->model, a->planet, p, sun, cnt, k, out);
    for (int i = 0; i < cnt; i++) out[i] *= a->sun_e[ATMOS__WL(k, i)];
}

static int dob_inscatter(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                         const double sun[3], int cnt, const int *k, double *out)
{
    const atmos__dobashi *m = a->model;
    double sr[ATMOS_MAX_WAVELENGTHS], sm[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    atmos__dobashi_march(m, a->planet, p, d, dist, sun, sr, sm, T);
    const double nu = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
    int any = 0;
    for (int i = 0; i < cnt; i++) {
        const int kk = ATMOS__WL(k, i);
        out[i] = a->sun_e[kk] * (atmos__planet_rayleigh_phase(a->planet, kk, nu) * sr[kk] + atmos__planet_mie_phase(a->planet, kk, nu) * sm[kk] +
                                 m->ambient * (1.0 - T[kk]));
        any |= out[i] > 0;
    }
    return any;
}

/* The tables as images (atmos_atmosphere_table); grids as dobashi_tables.c lays them out. */
static const char *const dob_table_names[] = {"sun_attenuation", "plane_rayleigh", "plane_mie",
                                              "plane_attenuation", NULL};

static atmos_status dob_table(atmos_context *ctx, const atmos_atmosphere *a, int i, atmos_image **out)
{
    const atmos__dobashi *m = a->model;
    const int n = m->n;
    if (i == 0)
        return atmos__planet_table_image(ctx, m->gl, ATMOS__DOB_NS, ATMOS__DOB_NH, n, (size_t)n,
                                         (size_t)ATMOS__DOB_NS * n, 1, 1, dob_table_names[0],
                                         "x: the sun's cosine at the point; y: height (dobashi_tables.c); g_l",
                                         "1: g_l, the sunlight's transmittance to the top of the air", out);
    return atmos__planet_table_image(ctx, m->plane + (i - 1), ATMOS__DOB_NV, ATMOS__DOB_NH, n, (size_t)n * 3,
                                     (size_t)ATMOS__DOB_NV * n * 3, 3, 0, dob_table_names[i],
                                     "x: the view's cosine; y: height (dobashi_tables.c); one sub-segment",
                                     i == 3 ? "1: dg_v, the sub-segment's transmittance"
                                            : "1: the scattering coefficient times the transmittance from the start, "
                                              "integrated over the sub-segment",
                                     out);
}

const atmos__planet_solver atmos__dobashi_solver = {
    .table_names = dob_table_names,
    .table = dob_table,
    .name = "dobashi",
    .create = dob_create,
    .destroy = atmos__dobashi_free,
    .transmittance = dob_transmittance,
    .sunlight = dob_sunlight,
    .inscatter = dob_inscatter,
    .radiance = atmos__dobashi_radiance,
    .batch_init = atmos__dobashi_batch_init,
    .batch_eval = atmos__dobashi_batch_eval,
    .batch_release = atmos__dobashi_batch_release,
};
