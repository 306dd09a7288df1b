/* A volume's memory limit (atmos_volume_desc.max_memory): checked before every allocation
 * that grows a volume, and the message when one would pass it. */
#include "volume/volume_grid.h"

int atmos__volume_can_alloc(const atmos_volume *v, uint64_t bytes)
{
    return bytes <= v->desc.max_memory && v->memory <= v->desc.max_memory - bytes;
}

atmos_status atmos__volume_limit_error(atmos_context *ctx, const atmos_volume *v, const char *what, uint64_t bytes)
{
    return atmos__error(ctx, ATMOS_E_LIMIT,
                        "volume: %s needs %llu bytes but the volume already holds %llu of its %llu-byte limit "
                        "(max_memory / --max-memory)",
                        what, (unsigned long long)bytes, (unsigned long long)v->memory,
                        (unsigned long long)v->desc.max_memory);
}
