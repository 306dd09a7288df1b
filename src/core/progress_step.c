/* Progress from inside a parallel loop (internal.h, atmos__progress_step): the items done
 * are counted by every thread, the callback is called by the calling thread only. */
#include "core/internal.h"

#ifdef _OPENMP
#include <omp.h>
#endif

int atmos__cancelled(const int *cancelled)
{
    int stop;
#pragma omp atomic read
    stop = *cancelled;
    return stop;
}

void atmos__progress_step(const atmos_context *ctx, const char *stage, int *done, int n, int *cancelled)
{
    int d;
#pragma omp atomic capture
    d = ++*done;
#ifdef _OPENMP
    if (omp_get_thread_num() != 0) return; /* thread 0 of the team is the calling thread */
#endif
    if (atmos__progress(ctx, stage, (double)d / n)) {
#pragma omp atomic write
        *cancelled = 1;
    }
}
