/* Helpers shared by the file readers (vdb_reader.c, nanovdb_reader.c,
 * netcdf_reader.c): naming fields, placing a sparse grid's index box in the
 * world, writing blocks clipped to the volume, and the memory check that runs
 * before anything is allocated. Internal (atmos__ prefix). */
#ifndef ATMOS_VOLUME_READER_COMMON_H
#define ATMOS_VOLUME_READER_COMMON_H

#include "atmos/atmos.h"

#include <stddef.h>
#include <stdint.h>

/* Field and particle names for a grid called `grid` (VDB, NanoVDB):
 * "density" (the usual fog-volume name) becomes desc->field or "cloud"; a grid
 * named like a particle preset keeps its name; anything else keeps its name and
 * gets the particle desc->field or "cloud". `field` and `particle` hold 64 bytes. */
void atmos__reader_field_names(const char *grid, const atmos_volume_load_desc *desc, char field[64],
                               char particle[64]);

/* Fills the placement of *vd (origin_m, voxel_size_m, rotation) from an affine
 * index-to-world map world = A idx + t (A row-major, column vectors) and the
 * inclusive index-box minimum imin. The atmos voxel (0,0,0) is the cell centred on
 * index imin, so its corner is A (imin - 0.5) + t. Returns 0, or -1 with a reason
 * in why when A is not a uniform scale times a rotation (non-uniform or sheared
 * voxels, reflections), which atmos's cubic voxels cannot represent. */
int atmos__reader_placement(const double A[9], const double t[3], const int imin[3], atmos_volume_desc *vd,
                            char *why, size_t cap);

/* ATMOS_E_LIMIT naming path if storing `voxels` float values (times a factor for
 * bookkeeping) would exceed max_memory (0 = default). Call before allocating. */
atmos_status atmos__reader_check_memory(atmos_context *ctx, const char *path, uint64_t voxels, uint64_t max_memory);

/* Writes a block of values (x fastest, size[] voxels) whose corner is at voxel
 * `origin` of the volume (may lie partly outside: the outside part is dropped).
 * values == NULL writes `constant` everywhere in the block. */
atmos_status atmos__reader_write_block(atmos_context *ctx, atmos_volume *vol, int field, const int64_t origin[3],
                                       const int64_t size[3], const float *values, float constant, float scale);

/* Returns st after making sure the context's message names path (errors from the
 * volume core, e.g. a memory limit hit while writing, do not know the file). */
atmos_status atmos__reader_name_error(atmos_context *ctx, const char *path, atmos_status st);

/* The NanoVDB reader over a memory buffer (the fuzzing entry point); `name`
 * stands for the file in messages. Same behaviour as atmos__volume_load_nanovdb. */
atmos_status atmos__volume_load_nanovdb_mem(atmos_context *ctx, const char *name, const void *data, size_t size,
                                            const atmos_volume_load_desc *desc, atmos_volume **out);

#endif
