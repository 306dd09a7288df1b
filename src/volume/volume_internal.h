/* Internals shared by the volume sources (core, readers, generators). */
#ifndef ATMOS_VOLUME_INTERNAL_H
#define ATMOS_VOLUME_INTERNAL_H

#include "atmos/atmos.h"

/* Readers (one per format), dispatched by atmos_volume_load() in volume_io.c.
 * Each returns a finalized volume or an error naming the file. */
atmos_status atmos__volume_load_raw_json(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                         atmos_volume **out);
atmos_status atmos__volume_load_nanovdb(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                        atmos_volume **out);
atmos_status atmos__volume_load_netcdf(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                       atmos_volume **out);
/* OpenVDB through the C++ shim (src/volume/openvdb_shim.cpp), when built with it. */
atmos_status atmos__volume_load_openvdb(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                        atmos_volume **out);

/* Records a reader's own count of active voxels for a field (see
 * atmos_volume_field_stats.file_active_voxels); call before or after finalize. */
void atmos__volume_set_file_active(atmos_volume *vol, int field, uint64_t count);

/* Multiplies every length of a finalized volume (voxel size, origin, the fields' boxes) by
 * factor > 0: a unit conversion of the file's lengths. */
void atmos__volume_rescale(atmos_volume *vol, double factor);
/* Records the kind of file the volume came from (atmos_volume_source_format). */
void atmos__volume_set_source_format(atmos_volume *vol, const char *format);

#endif
