/* Creating a simulation: the arrays, the base state, the initial fields with their seeded
 * perturbations (warm bubbles, noise), and the public create/destroy. */
#include "sim/sim_internal.h"
#include "core/rng.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Uniform in [0, 1) from the seed and two counters: the same wherever it is evaluated. */
static double hash01(uint64_t seed, uint64_t a, uint64_t b)
{
    return atmos__u01(atmos__mix64(atmos__mix64(seed ^ 0x5bd1e995ULL) + a * 0x9e3779b97f4a7c15ULL + b));
}

static void add_bubbles(atmos_sim *s)
{
    const sim_env *e = &s->env;
    const double L = s->nx * s->dx, W = s->ny * s->dx;
    for (int b = 0; b < e->bubbles; b++) {
        double cx = 0.5 * L, cy = 0.5 * W, scale = 1.0;
        if (e->bubbles > 1) {
            cx = hash01(s->seed, 1, (uint64_t)b) * L;
            cy = hash01(s->seed, 2, (uint64_t)b) * W;
            scale = 0.6 + 0.8 * hash01(s->seed, 3, (uint64_t)b); /* sizes and strengths vary */
        }
        const double rh = e->bubble_rh * scale, rv = e->bubble_rv * scale;
        for (int k = 0; k < s->nz; k++)
            for (int j = 0; j < s->ny; j++)
                for (int i = 0; i < s->nx; i++) {
                    double dxp = (i + 0.5) * s->dx - cx, dyp = (j + 0.5) * s->dx - cy;
                    dxp -= L * floor(dxp / L + 0.5); /* nearest periodic image */
                    dyp -= W * floor(dyp / W + 0.5);
                    const double dz = (k + 0.5) * s->dx - e->bubble_z;
                    const double r = sqrt(dxp * dxp / (rh * rh) + dyp * dyp / (rh * rh) + dz * dz / (rv * rv));
                    if (r >= 1) continue;
                    const double c = cos(0.5 * ATMOS_PI * r), f = c * c;
                    const size_t n = sim_idx(s, i, j, k);
                    s->th[n] += (float)(e->bubble_dth * scale * f);
                    s->qv[n] += (float)(e->bubble_dqv * f);
                }
    }
}

static void init_fields(atmos_sim *s)
{
    const sim_env *e = &s->env;
    for (int k = 0; k < s->nz; k++)
        for (int j = 0; j < s->ny; j++)
            for (int i = 0; i < s->nx; i++) {
                const size_t n = sim_idx(s, i, j, k);
                double th = s->th0[k];
                if ((k + 0.5) * s->dx < fmax(e->zi, 1000.0) && e->noise_th > 0)
                    th += e->noise_th * (2.0 * hash01(s->seed, 4, n) - 1.0);
                s->th[n] = (float)th;
                s->qv[n] = (float)s->qv0[k];
                s->u[n] = (float)s->ue[k];
            }
    add_bubbles(s);
    if (!e->micro) return;
    /* air that starts supersaturated (a stratocumulus deck) condenses at once */
    for (int k = 0; k < s->nz; k++)
        for (size_t n = (size_t)k * s->nx * s->ny; n < (size_t)(k + 1) * s->nx * s->ny; n++) {
            double th = s->th[n], qv = s->qv[n], qc = s->qc[n];
            atmos__sim_adjust(&th, &qv, &qc, s->p0[k], s->pi0[k]);
            s->th[n] = (float)th, s->qv[n] = (float)qv, s->qc[n] = (float)qc;
        }
}

/* A zeroed array of the grid's size: on 2 MB pages where the system gives them
 * (atmos__big_alloc), as the passes read levels and columns far apart (fewer TLB misses). */
static float *grid_array(size_t floats)
{
    float *p = atmos__sim_alloc(floats * sizeof(float));
    if (p) memset(p, 0, floats * sizeof(float));
    return p;
}

atmos_status atmos__sim_create_env(atmos_context *ctx, const sim_env *env, int nx, int ny, int nz, double dx,
                                   uint64_t seed, atmos_sim **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: missing output");
    *out = NULL;
    if (nx < 4 || ny < 4 || nz < 4 || nx > ATMOS_SIM_MAX_GRID || ny > ATMOS_SIM_MAX_GRID || nz > 2 * ATMOS_SIM_MAX_GRID ||
        !(dx > 0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: grid %d x %d x %d of %g m is out of range", nx, ny, nz, dx);
    atmos_sim *s = calloc(1, sizeof *s);
    if (!s) return atmos__error(ctx, ATMOS_E_NOMEM, "simulate: out of memory");
    s->nx = nx, s->ny = ny, s->nz = nz, s->dx = dx, s->env = *env, s->seed = seed;
    s->threads = atmos__threads(ctx);
    s->dt_max = env->dt_max > 0 ? env->dt_max : 5.0;
    s->n = (size_t)nx * ny * nz;
    s->nw = (size_t)nx * ny * (nz + 1);
    int ok = 1;
    float **f[] = {&s->u, &s->v, &s->w, &s->th, &s->qv, &s->qc, &s->qr};
    for (int a = 0; a < 7; a++) ok &= (*f[a] = grid_array(s->nw)) != NULL;
    for (int a = 0; a < 8; a++) ok &= (s->s[a] = grid_array(s->nw)) != NULL;
    ok &= (s->pack = atmos__big_alloc(12 * s->n * sizeof(float))) != NULL; /* written before it is read */
    double **b[] = {&s->th0, &s->qv0, &s->pi0, &s->p0, &s->rho0, &s->ue};
    for (int a = 0; a < 6; a++) ok &= (*b[a] = calloc((size_t)nz, sizeof(double))) != NULL;
    ok &= (s->rho_c = calloc((size_t)nz, sizeof(double))) != NULL;
    ok &= (s->rho_f = calloc((size_t)nz + 1, sizeof(double))) != NULL;
    ok &= (s->part = calloc(4 * ((size_t)(nz > ny ? nz : ny) + 1), sizeof(double))) != NULL;
    if (!ok) {
        atmos_sim_destroy(s);
        return atmos__error(ctx, ATMOS_E_NOMEM, "simulate: out of memory for %d x %d x %d cells", nx, ny, nz);
    }
    atmos_status st = atmos__sim_fft_init(ctx, s);
    if (st != ATMOS_OK) {
        atmos_sim_destroy(s);
        return st;
    }
    atmos__sim_sync_init(s);
    atmos__sim_sounding(s);
    init_fields(s);
#pragma omp parallel num_threads(s->threads)
    atmos__sim_project(s);
    *out = s;
    return ATMOS_OK;
}

atmos_status atmos_sim_create(atmos_context *ctx, const atmos_sim_desc *desc, atmos_sim **out)
{
    if (!desc || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: missing argument");
    *out = NULL;
    const sim_env *env = atmos__sim_preset(desc->preset);
    if (!env)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "simulate: unknown preset '%s' (known: cumulus_field, towering_cumulus, cumulonimbus, "
                            "stratocumulus)",
                            desc->preset ? desc->preset : "(none)");
    const int g = desc->grid ? desc->grid : 64;
    if (g < ATMOS_SIM_MIN_GRID || g > ATMOS_SIM_MAX_GRID)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: grid %d is out of range [%d, %d]", g,
                            ATMOS_SIM_MIN_GRID, ATMOS_SIM_MAX_GRID);
    if (!(desc->minutes >= 0 && desc->minutes <= ATMOS_SIM_MAX_MINUTES))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: minutes %g is out of range [0, %g]", desc->minutes,
                            ATMOS_SIM_MAX_MINUTES);
    if (desc->refine < 0 || desc->refine > ATMOS_SIM_MAX_REFINE || !(desc->detail >= 0 && desc->detail <= 1) ||
        desc->ice < 0 || desc->ice > 1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "simulate: refine %d (0..%d), detail %g ([0, 1]) or ice %d (0 or 1) is out of range",
                            desc->refine, ATMOS_SIM_MAX_REFINE, desc->detail, desc->ice);
    const double dx = env->domain_m / g;
    int nz = (int)lround(env->height_m / dx);
    if (nz < 8) nz = 8;
    const long r = desc->refine > 0 ? desc->refine : 1;
    if (r * r * r * g * g * nz > SIM_MAX_VOXELS) /* found now rather than after the run */
        return atmos__error(ctx, ATMOS_E_LIMIT,
                            "simulate: refine %ld makes %ld x %ld x %ld voxels, more than %ld M: a smaller refine or grid",
                            r, r * g, r * nz, r * g, SIM_MAX_VOXELS >> 20);
    atmos_status st = atmos__sim_create_env(ctx, env, g, g, nz, dx, desc->seed, out);
    if (st == ATMOS_OK) {
        (*out)->out_refine = desc->refine > 0 ? desc->refine : 1;
        (*out)->out_detail = desc->detail, (*out)->out_ice = desc->ice;
    }
    return st;
}

void atmos_sim_destroy(atmos_sim *s)
{
    if (!s) return;
    atmos__sim_fft_free(s);
    atmos__sim_sync_free(s);
    float *f[] = {s->u, s->v, s->w, s->th, s->qv, s->qc, s->qr};
    for (int a = 0; a < 7; a++) free(f[a]);
    for (int a = 0; a < 8; a++) free(s->s[a]);
    free(s->pack);
    double *b[] = {s->th0, s->qv0, s->pi0, s->p0, s->rho0, s->ue};
    for (int a = 0; a < 6; a++) free(b[a]);
    free(s->part);
    free(s->rho_c);
    free(s->rho_f);
    free(s);
}
