/* The float exponential of a whole array (fastmath.h's atmos__expf_fast), in one loop that
 * the compiler vectorises; built for AVX2 as well as the baseline, the loader picking the best
 * at run time (without FMA both give the same bits). */
#include "core/clones.h"
#include "core/fastmath.h"

ATMOS_CLONES
void atmos__expf_fast_array(float *v, int count)
{
    for (int j = 0; j < count; j++) v[j] = atmos__expf_fast(v[j]);
}
