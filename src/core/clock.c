/* Wall-clock time for the renderers' timings and budgets. */
#define _POSIX_C_SOURCE 200809L
#include "core/internal.h"

#include <time.h>

double atmos__now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
