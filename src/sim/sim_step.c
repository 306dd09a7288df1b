/* One time step of the cloud simulation, a run of many with progress, and its statistics. */
#include "sim/sim_internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* The step: the largest that keeps the fastest wind within 1.5 cells (the semi-Lagrangian
 * trace stays accurate), at most the preset's dt_max. The fastest wind is the last
 * projection's (exact whatever the order, so it does not depend on the threads). */
static double time_step(const atmos_sim *s)
{
    const float m = s->vmax;
    if (m != m || m > 1e30f) return 0.0; /* NaN or overflow: unstable */
    const double dt = m > 0 ? 1.5 * s->dx / m : s->dt_max;
    return fmin(dt, s->dt_max);
}

/* The step's phases in one parallel region; the column-local ones (rain fall, surface fluxes,
 * cooling, buoyancy, sponge) share one pass over the rows. */
static void phases(atmos_sim *s, double dt)
{
    const float fix = (float)atmos__sim_advect(s, dt);
#pragma omp master
    atmos__sim_advected_velocity(s); /* the microphysics does not touch u, v, w; it ends at a barrier */
    atmos__sim_micro(s, dt, fix);
    const int ny = s->ny;
    double *rain = s->part, *surf = s->part + ny + 1;
    SIM_FOR
    for (int j = 0; j < ny; j++) {
        rain[j] = atmos__sim_fall_row(s, dt, j);
        surf[j] = atmos__sim_forces_row(s, dt, j);
    }
    atmos__sim_sync(s);
#pragma omp master
    for (int j = 0; j < ny; j++) s->rain_out += rain[j], s->surface_in += surf[j];
    atmos__sim_diffuse(s, dt);
    atmos__sim_confine(s, dt);
    atmos__sim_project(s);
}

static void advance(atmos_sim *s, double dt)
{
#pragma omp parallel num_threads(s->threads)
    phases(s, dt);
    s->t += dt;
    s->steps++;
}

atmos_status atmos_sim_step(atmos_context *ctx, atmos_sim *s)
{
    if (!s) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: no simulation");
    advance(s, time_step(s));
    return ATMOS_OK;
}

atmos_status atmos__sim_run_to(atmos_context *ctx, atmos_sim *s, double end, int whole_steps)
{
    const double t0 = s->t, span = end - t0;
    if (atmos__progress(ctx, "simulate", 0.0)) return atmos__error(ctx, ATMOS_E_CANCELLED, "simulate: cancelled");
    while (s->t < end - 1e-9) {
        double dt = time_step(s);
        /* winds over 300 m/s (or NaN) mean the model has blown up: stop rather than crawl */
        if (!(dt >= 1.5 * s->dx / 300.0) || !isfinite(s->th[0]))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: the model became unstable at t = %g s", s->t);
        if (s->t + dt > end) {
            if (whole_steps) break;
            dt = end - s->t;
        }
        advance(s, dt);
        if (atmos__progress(ctx, "simulate", span > 0 ? (s->t - t0) / span : 1.0))
            return atmos__error(ctx, ATMOS_E_CANCELLED, "simulate: cancelled at t = %g s", s->t);
    }
    return ATMOS_OK;
}

atmos_status atmos_sim_run(atmos_context *ctx, atmos_sim *s, double seconds)
{
    if (!s) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: no simulation");
    if (!(seconds >= 0 && seconds <= ATMOS_SIM_MAX_MINUTES * 60))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: %g s is out of range [0, %g]", seconds,
                            ATMOS_SIM_MAX_MINUTES * 60);
    return atmos__sim_run_to(ctx, s, s->t + seconds, 0);
}

void atmos_sim_get_stats(const atmos_sim *s, atmos_sim_stats *o)
{
    if (!o) return;
    memset(o, 0, sizeof *o);
    if (!s) return;
    o->dims[0] = s->nx, o->dims[1] = s->ny, o->dims[2] = s->nz;
    o->cell_m = s->dx;
    o->time_s = s->t;
    o->steps = s->steps;
    o->cloud_base_m = o->cloud_top_m = -1;
    const size_t lev = (size_t)s->nx * s->ny;
    double water = 0;
    for (int k = 0; k < s->nz; k++) { /* level by level, in order: the same sum for any thread count */
        double wl = 0;
        for (size_t n = k * lev; n < (k + 1) * lev; n++) {
            wl += (double)s->qv[n] + s->qc[n] + s->qr[n];
            o->max_qc = fmax(o->max_qc, s->qc[n]);
            o->max_qr = fmax(o->max_qr, s->qr[n]);
            o->max_w = fmax(o->max_w, s->w[n]);
            if (s->qc[n] > 1e-5) {
                if (o->cloud_base_m < 0) o->cloud_base_m = (k + 0.5) * s->dx;
                o->cloud_top_m = (k + 0.5) * s->dx;
            }
        }
        water += wl * s->rho_c[k];
    }
    /* (kg/kg) x cells (of the ground's density) -> kg per m^2 of ground */
    const double per = s->rho_ref * s->dx / (double)lev;
    o->water = water * per;
    o->rain_out = s->rain_out * per;
    o->surface_in = s->surface_in * per;
}
