/* Whether two simulations hold the same state, byte for byte: the thread-count checks of the
 * simulation's tests; and their context of a given thread count, without a log. */
#ifndef ATMOS_TEST_SIM_STATE_H
#define ATMOS_TEST_SIM_STATE_H

#include "sim/sim_internal.h"

#include <string.h>

static inline atmos_context *test_sim_ctx(int threads)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = threads;
    d.log = NULL;
    atmos_context *c = NULL;
    atmos_context_create(&d, &c);
    return c;
}

static inline int test_sim_same_state(const atmos_sim *a, const atmos_sim *b)
{
    const float *fa[] = {a->u, a->v, a->w, a->th, a->qv, a->qc, a->qr}, *fb[] = {b->u, b->v, b->w, b->th, b->qv, b->qc, b->qr};
    for (int f = 0; f < 7; f++)
        if (memcmp(fa[f], fb[f], (f == 2 ? a->nw : a->n) * sizeof(float))) return 0;
    return a->rain_out == b->rain_out && a->surface_in == b->surface_in && a->t == b->t;
}

#endif
