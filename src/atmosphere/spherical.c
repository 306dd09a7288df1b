/* The production sky over a spherical earth with all orders of scattering (Hillaire 2020):
 * the solver table of the SPHERICAL kind over the tables and the march of spherical.h,
 * the tables cached on disk (src/core/cache.h) under a key naming the air's description
 * (the planet's members before its geographic frame). docs/sky.md, "The production sky". */
#include "atmosphere/spherical.h"

#include "core/cache.h"
#include "core/vec.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Bumped whenever the tables' content or layout changes. */
#define SPH_TABLE_VERSION 6

static void sph_destroy(void *model)
{
    atmos__sph_model *m = model;
    if (!m) return;
    free(m->block);
    free(m);
}

/* The key sums the air's description: the planet's members before its geographic frame. The
 * frame, the ground's maps and the cloud spheres (pointers: other addresses every run) do not
 * enter the tables, and summing them made every run of an Earth scene build them again. */
/* The key sums the bytes before geo_east, so it relies on the members' order: the tail after
 * the air (frame, maps, clouds) is pinned here, and a member added to it, or between the air and
 * it, stops the build instead of silently dropping out of the key. A new member of the air goes
 * before geo_east. */
_Static_assert(offsetof(atmos__planet, geo_east) == offsetof(atmos__planet, mie_g) + sizeof(((atmos__planet *)0)->mie_g),
               "atmos__planet: the air's description must end with mie_g, just before geo_east");
_Static_assert(offsetof(atmos__planet, surface) == offsetof(atmos__planet, geo_east) + 9 * sizeof(double) &&
                   offsetof(atmos__planet, clouds) == offsetof(atmos__planet, surface) + sizeof(void *) &&
                   sizeof(atmos__planet) == offsetof(atmos__planet, clouds) + sizeof(void *),
               "atmos__planet: a member after geo_east does not enter the cache key; put the air's before it");

static void cache_key(const atmos__planet *pl, const atmos__sph_model *m, char *key, size_t cap)
{
    snprintf(key, cap,
             "spherical-sky v%d tau %dx%d psi %dx%d esky %d j %dx%dx%dx%d it %d steps %d floats %zu planet %016llx",
             SPH_TABLE_VERSION, ATMOS__SPH_T_R, ATMOS__SPH_T_MU, ATMOS__SPH_M_R, ATMOS__SPH_M_MU, ATMOS__SPH_E_MU,
             ATMOS__SPH_J_R, ATMOS__SPH_J_MUS, ATMOS__SPH_J_G, ATMOS__SPH_J_P, ATMOS__SPH_J_ITER,
             ATMOS__SPH_STEPS_TABLE, m->block_floats, (unsigned long long)atmos__cache_checksum(pl, offsetof(atmos__planet, geo_east)));
}

static atmos_status sph_create(atmos_context *ctx, atmos_atmosphere *a)
{
    const atmos__planet *pl = a->planet;
    atmos__sph_model *m = calloc(1, sizeof *m);
    if (!m) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory");
    m->n = pl->n;
    m->R = pl->r_ground, m->Rt = pl->r_top, m->H = sqrt(m->Rt * m->Rt - m->R * m->R);
    const size_t nt = (size_t)ATMOS__SPH_T_R * ATMOS__SPH_T_MU, nm = (size_t)ATMOS__SPH_M_R * ATMOS__SPH_M_MU;
    const size_t ne = 2 * (size_t)ATMOS__SPH_E_MU;
    const size_t nj = 2 * (size_t)ATMOS__SPH_J_R * ATMOS__SPH_J_MUS * ATMOS__SPH_J_G * ATMOS__SPH_J_P;
    m->block_floats = (size_t)m->n * (nt + 2 * nm + ne + nj);
    m->block = calloc(m->block_floats, sizeof(float));
    if (!m->block) {
        free(m);
        return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory");
    }
    m->tau = m->block;
    m->psi = m->tau + (size_t)m->n * nt;
    m->fms = m->psi + (size_t)m->n * nm;
    m->esky = m->fms + (size_t)m->n * nm;
    m->jms = m->esky + (size_t)m->n * ne;
    a->model = m;
    char key[320];
    cache_key(pl, m, key, sizeof key);
    void *data = NULL;
    size_t size = 0;
    if (ctx && atmos__cache_load(ctx, key, &data, &size)) {
        if (size == m->block_floats * sizeof(float)) {
            memcpy(m->block, data, size);
            free(data);
            m->use_j = 1;
            return ATMOS_OK;
        }
        free(data);
    }
    atmos_status st = atmos__sph_build(ctx, pl, m);
    if (st == ATMOS_OK && ctx) atmos__cache_store(ctx, key, m->block, m->block_floats * sizeof(float));
    return st;
}

/* Optical depth of q + t d, t in [t0, t1], by composite Gauss-Legendre over each monotone
 * piece in s, t = t_low +- L s^2 (as the march). */
static void segment_depth(const atmos__planet *pl, const double q[3], const double d[3], double t0, double t1, int m,
                          const int *k, double *out)
{
    static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
    static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
    enum { P = 16 };
    for (int i = 0; i < m; i++) out[i] = 0.0;
    double tc = -atmos__dot3(q, d);
    tc = tc < t0 ? t0 : (tc > t1 ? t1 : tc);
    const double len[2] = {tc - t0, t1 - tc};
    for (int side = 0; side < 2; side++) {
        const double L = len[side], sg = side ? 1.0 : -1.0;
        if (!(L > 0)) continue;
        for (int p = 0; p < P; p++)
            for (int g = 0; g < 4; g++) {
                const double s = (p + 0.5 + 0.5 * gx[g]) / P, w = gw[g] / P * L * s, t = tc + sg * L * s * s;
                const double x[3] = {q[0] + t * d[0], q[1] + t * d[1], q[2] + t * d[2]};
                const double h = sqrt(atmos__dot3(x, x)) - pl->r_ground;
                for (int i = 0; i < m; i++) out[i] += w * atmos__planet_extinction(pl, h, ATMOS__WL(k, i));
            }
    }
}

static void sph_transmittance(const atmos_atmosphere *a, const double p[3], const double d[3], double dist, int m,
                              const int *k, double *out)
{
    const atmos__planet *pl = a->planet;
    double t0, t1;
    if (!atmos__planet_clip(pl, p, d, dist, &t0, &t1)) {
        for (int i = 0; i < m; i++) out[i] = 1.0;
        return;
    }
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    segment_depth(pl, q, d, t0, t1, m, k, out);
    for (int i = 0; i < m; i++) out[i] = exp(-out[i]);
}

static void sph_sunlight(const atmos_atmosphere *a, const double p[3], const double sun[3], int m, const int *k,
                         double *out)
{
    const atmos__planet *pl = a->planet;
    const atmos__sph_model *md = a->model;
    double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    double r = sqrt(atmos__dot3(q, q));
    if (r > pl->r_top) { /* from space: where the sunward ray enters the air, if it does */
        const double t = atmos__planet_sphere_hit(pl, p, sun, pl->r_top);
        if (t < INFINITY && atmos__dot3(q, sun) < 0)
            for (int i = 0; i < 3; i++) q[i] += t * sun[i];
        r = sqrt(atmos__dot3(q, q));
    }
    atmos__sph_sun_t(md, r, r > 0 ? atmos__dot3(q, sun) / r : 1.0, m, k, out);
    for (int i = 0; i < m; i++) out[i] *= a->sun_e[ATMOS__WL(k, i)];
}

static int sph_inscatter(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                         const double sun[3], int m, const int *k, double *out)
{
    const atmos__planet *pl = a->planet;
    double t0, t1;
    for (int i = 0; i < m; i++) out[i] = 0.0;
    if (!atmos__planet_clip(pl, p, d, dist, &t0, &t1)) return 0;
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    atmos__sph_sums s;
    atmos__sph_march(pl, a->model, q, d, t0, t1, sun, ATMOS__SPH_STEPS, 1, m, k, &s);
    const double nu = atmos__dot3(d, sun);
    int any = 0;
    for (int i = 0; i < m; i++) {
        const int kk = ATMOS__WL(k, i);
        out[i] = (atmos__planet_rayleigh_phase(pl, kk, nu) * s.sr[i] + atmos__planet_mie_phase(pl, kk, nu) * s.sm[i] + s.ms[i]) * a->sun_e[kk];
        any |= out[i] > 0;
    }
    return any;
}

static void sph_radiance(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                         double *out, atmos_atmosphere_hit *info)
{
    atmos__sph_radiance(a, p, d, sun, ATMOS__SPH_STEPS, out, info);
}

/* The tables as images (atmos_atmosphere_table): rows and columns as spherical_lookup.c
 * maps them. */
static const char *const sph_table_names[] = {"transmittance", "multiple_scattering", "f_ms", "sky_irradiance",
                                              "higher_orders_air", "higher_orders_aerosols", NULL};

/* An image of J_ms's part (0 air molecules, 1 aerosols): x over (gamma, psi) with psi
 * fastest, y over (altitude row, sun column) with the sun column fastest; the table's
 * logarithms turned back into values. */
static atmos_status j_table(atmos_context *ctx, const atmos__sph_model *m, int part, const char *name,
                            atmos_image **out)
{
    const int n = m->n, w = ATMOS__SPH_J_G * ATMOS__SPH_J_P, h = ATMOS__SPH_J_R * ATMOS__SPH_J_MUS;
    if (!m->use_j) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere table '%s': not built", name);
    float *v = malloc(sizeof(float) * (size_t)w * h * n);
    if (!v) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere table '%s': out of memory", name);
    for (size_t e = 0; e < (size_t)w * h; e++)
        for (int k = 0; k < n; k++)
            v[(size_t)k * w * h + e] = (float)(exp(m->jms[(e * n + k) * 2 + part]) - ATMOS__SPH_J_FLOOR);
    const atmos_status st = atmos__planet_table_image(
        ctx, v, w, h, n, 1, (size_t)w, (size_t)w * h, 0, name,
        "x: gamma node * J_P + psi node (gamma, the angle from the sun, = pi (0.3 u + 2.1 u^2 - 1.4 u^3), u = node / "
        "(J_G - 1); psi, the azimuth about the sun, (1 - cos psi) / 2 = node / (J_P - 1)); y: altitude row * "
        "J_MUS + sun column (rows sqrt(altitude / top); columns uniform in u, the sun's elevation (pi / 2) u |u|, from asin(-0.3) to the zenith); "
        "sr^-1 per unit irradiance and scattering coefficient",
        "J_ms: sr^-1 per unit irradiance of the sun and scattering coefficient", out);
    free(v);
    return st;
}

static atmos_status sph_table(atmos_context *ctx, const atmos_atmosphere *a, int i, atmos_image **out)
{
    const atmos__sph_model *m = a->model;
    const int n = m->n;
    switch (i) {
    case 0:
        return atmos__planet_table_image(ctx, m->tau, ATMOS__SPH_T_MU, ATMOS__SPH_T_R, n, 1, ATMOS__SPH_T_MU,
                                         (size_t)ATMOS__SPH_T_R * ATMOS__SPH_T_MU, 1, sph_table_names[i],
                                         "x: (d - d_min) / (d_max - d_min) of the distance d to the top; "
                                         "y: rho / H (Bruneton 2017); exp(-depth to the top)",
                                         "1: the transmittance to the top of the air", out);
    case 1:
    case 2:
        return atmos__planet_table_image(ctx, i == 1 ? m->psi : m->fms, ATMOS__SPH_M_MU, ATMOS__SPH_M_R, n, 1,
                                         ATMOS__SPH_M_MU, (size_t)ATMOS__SPH_M_R * ATMOS__SPH_M_MU, 0,
                                         sph_table_names[i],
                                         "x: mu_s = x'|x'|, x' in [-1, 1]; y: sqrt(altitude / top)",
                                         i == 1 ? "Psi_ms: sr^-1 per unit irradiance of the sun and scattering coefficient"
                                                : "1: f_ms, the share of isotropic light scattered again",
                                         out);
    case 4:
    case 5:
        return j_table(ctx, m, i - 4, sph_table_names[i], out);
    default:
        return atmos__planet_table_image(ctx, m->esky, ATMOS__SPH_E_MU, 1, n, 1, 0, ATMOS__SPH_E_MU, 0,
                                         sph_table_names[i], "x: mu_s = x'|x'|, x' in [-1, 1] (the ground)",
                                         "1: the sky's irradiance of the ground per unit irradiance of the sun", out);
    }
}

const atmos__planet_solver atmos__spherical_solver = {
    .table_names = sph_table_names,
    .table = sph_table,
    .name = "spherical",
    .create = sph_create,
    .destroy = sph_destroy,
    .transmittance = sph_transmittance,
    .sunlight = sph_sunlight,
    .inscatter = sph_inscatter,
    .radiance = sph_radiance,
    .batch_init = atmos__sph_batch_init,
    .batch_eval = atmos__sph_batch_eval,
    .batch_release = atmos__sph_batch_release,
    .batch_keep = atmos__sph_batch_keep,
    .batch_clouds = 1,
    .aerial = atmos__sph_aerial,
};
