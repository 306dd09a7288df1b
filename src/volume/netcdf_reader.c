#include "core/internal.h"
#include "volume/volume_internal.h"
atmos_status atmos__volume_load_netcdf(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                       atmos_volume **out)
{
    (void)desc; *out = NULL;
    return atmos__error(ctx, ATMOS_E_UNSUPPORTED, "%s: todo", path);
}
