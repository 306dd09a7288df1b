/* The simulation's state as an atmos volume: "cloud" and "rain" number densities
 * eta = q rho / m (rho the base-state air density of the level, m the particle type's mean
 * mass, atmos_particle_mean_mass: the WRF reader's conversion), y up. */
#include "sim/sim_internal.h"

#include <stdlib.h>
#include <string.h>

atmos_status atmos_sim_to_volume(atmos_context *ctx, const atmos_sim *s, atmos_volume **out)
{
    if (!s || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: missing argument");
    *out = NULL;
    atmos_volume_desc d;
    memset(&d, 0, sizeof d);
    d.dims[0] = s->nx, d.dims[1] = s->nz, d.dims[2] = s->ny;
    d.voxel_size_m = s->dx;
    d.origin_m[0] = -0.5 * s->nx * s->dx;
    d.origin_m[2] = -0.5 * s->ny * s->dx;
    d.periodic = 1; /* the model's sides are periodic (sim_pressure.c) */
    atmos_volume *v = NULL;
    atmos_status st = atmos_volume_create(ctx, &d, &v);
    if (st != ATMOS_OK) return st;
    float *buf = malloc(s->n * sizeof *buf);
    if (!buf) {
        atmos_volume_destroy(v);
        return atmos__error(ctx, ATMOS_E_NOMEM, "simulate: out of memory");
    }
    const char *names[2] = {"cloud", "rain"};
    const float *q[2] = {s->qc, s->qr};
    for (int f = 0; f < 2 && st == ATMOS_OK; f++) {
        int index = 0;
        st = atmos_volume_add_field(ctx, v, names[f], names[f], &index);
        if (st != ATMOS_OK) break;
        const double m = atmos_particle_mean_mass(names[f]);
        /* volume voxel (i, k, j): x fastest, then up, then y of the model */
        for (int j = 0; j < s->ny; j++)
            for (int k = 0; k < s->nz; k++) {
                const float c = (float)(s->rho0[k] / m);
                float *row = buf + ((size_t)j * s->nz + k) * s->nx;
                const float *src = q[f] + sim_idx(s, 0, j, k);
                for (int i = 0; i < s->nx; i++) row[i] = src[i] > 1e-7f ? src[i] * c : 0.0f;
            }
        const int off[3] = {0, 0, 0}, size[3] = {s->nx, s->nz, s->ny};
        st = atmos_volume_set_dense(ctx, v, index, off, size, buf, 1.0f);
    }
    free(buf);
    if (st == ATMOS_OK) st = atmos_volume_finalize(ctx, v);
    if (st != ATMOS_OK) {
        atmos_volume_destroy(v);
        return st;
    }
    *out = v;
    return ATMOS_OK;
}

atmos_status atmos_simulate(atmos_context *ctx, const atmos_sim_desc *desc, atmos_volume **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "simulate: missing output");
    *out = NULL;
    atmos_sim *s = NULL;
    atmos_status st = atmos_sim_create(ctx, desc, &s);
    if (st != ATMOS_OK) return st;
    const double minutes = desc->minutes > 0 ? desc->minutes : atmos_sim_preset_minutes(desc->preset);
    st = atmos_sim_run(ctx, s, minutes * 60.0);
    if (st == ATMOS_OK) {
        atmos_sim_stats ss;
        atmos_sim_get_stats(s, &ss);
        if (ss.max_qc < 1e-5 && ss.max_qr < 1e-5) /* nothing a renderer would see */
            atmos__log(ctx, ATMOS_LOG_WARN,
                       "simulate: %s after %g minutes has no cloud or rain yet: the volume is empty (the first cloud "
                       "forms after about %g minutes at grid 64)",
                       desc->preset, minutes, atmos_sim_preset_first_cloud_minutes(desc->preset));
        st = atmos_sim_to_volume(ctx, s, out);
    }
    atmos_sim_destroy(s);
    return st;
}
