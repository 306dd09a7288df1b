/* A time-lapse of one simulation (atmos/sim.h: atmos_sim_volume_at): the run goes on by whole
 * steps, and each time asked for is reached on a copy, whose last step is shortened to end
 * there as a run of its own would end: a frame is the same whether or not other frames came
 * before it. */
#include "sim/sim_internal.h"

#include <math.h>
#include <string.h>

/* A new simulation holding s's state (its fields, scratch, time and sums). */
static atmos_status copy_of(atmos_context *ctx, const atmos_sim *s, atmos_sim **out)
{
    atmos_status st = atmos__sim_create_env(ctx, &s->env, s->nx, s->ny, s->nz, s->dx, s->seed, out);
    if (st != ATMOS_OK) return st;
    atmos_sim *c = *out;
    float *const from[] = {s->u, s->v, s->w, s->th, s->qv, s->qc, s->qr};
    float *const to[] = {c->u, c->v, c->w, c->th, c->qv, c->qc, c->qr};
    for (int a = 0; a < 7; a++) memcpy(to[a], from[a], s->nw * sizeof(float));
    for (int a = 0; a < 8; a++) memcpy(c->s[a], s->s[a], s->nw * sizeof(float));
    memcpy(c->pack, s->pack, 12 * s->n * sizeof(float));
    c->t = s->t, c->steps = s->steps, c->rain_out = s->rain_out, c->surface_in = s->surface_in, c->vmax = s->vmax;
    c->out_refine = s->out_refine, c->out_detail = s->out_detail, c->out_ice = s->out_ice;
    return ATMOS_OK;
}

atmos_status atmos_sim_volume_at(atmos_context *ctx, atmos_sim *s, double minutes, atmos_volume **out)
{
    if (!s || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: missing argument");
    *out = NULL;
    if (!(minutes >= 0 && minutes <= ATMOS_SIM_MAX_MINUTES))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: minutes %g is out of range [0, %g]", minutes,
                            ATMOS_SIM_MAX_MINUTES);
    const double end = minutes * 60.0;
    if (end < s->t - 1e-9)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "simulate: a time-lapse goes forward: %g minutes asked after %g minutes", minutes, s->t / 60.0);
    atmos_status st = atmos__sim_run_to(ctx, s, end, 1);
    atmos_sim *c = NULL;
    if (st == ATMOS_OK) st = copy_of(ctx, s, &c);
    if (st == ATMOS_OK) st = atmos__sim_run_to(ctx, c, end, 0);
    if (st == ATMOS_OK) st = atmos_sim_to_volume(ctx, c, out);
    atmos_sim_destroy(c);
    return st;
}
