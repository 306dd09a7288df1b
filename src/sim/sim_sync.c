/* The simulation's barrier between the phases of a step (sim_internal.h): a POSIX barrier,
 * whose waiting threads sleep, rather than OpenMP's, which spins while the other core is
 * held by another process; OpenMP's when the team is not the one the barrier was made for. */
#define _POSIX_C_SOURCE 200809L /* pthread barriers */
#include "sim/sim_internal.h"

#include <omp.h>
#include <pthread.h>
#include <stdlib.h>

void atmos__sim_sync_init(atmos_sim *s)
{
    s->bar = NULL;
    if (s->threads < 2) return;
    pthread_barrier_t *b = malloc(sizeof *b);
    if (b && pthread_barrier_init(b, NULL, (unsigned)s->threads) == 0) s->bar = b;
    else free(b); /* OpenMP's barriers then */
}

void atmos__sim_sync_free(atmos_sim *s)
{
    if (!s->bar) return;
    pthread_barrier_destroy(s->bar);
    free(s->bar);
    s->bar = NULL;
}

void atmos__sim_sync(atmos_sim *s)
{
    const int team = omp_get_num_threads();
    if (team == 1) return;
    if (s->bar && team == s->threads) {
        pthread_barrier_wait(s->bar);
    } else { /* a smaller team than asked for (nested or limited): OpenMP's own barrier */
#pragma omp barrier
    }
}
