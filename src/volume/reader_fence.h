/* A fence around third-party file parsers (OpenVDB, libnetcdf/libhdf5).
 *
 * Those libraries trust the files they read: a damaged file can crash them (heap overflow,
 * invalid free) or make them allocate without bound. atmos__reader_fenced runs a whole load
 * in a child process (fork) with limits on its address space and CPU time; the child sends
 * the loaded volume, or its error, back through a pipe, and the parent rebuilds the volume
 * brick for brick (the same values, so loads stay deterministic). A crash, a limit hit or a
 * hang in the child becomes an error here that names the file. Internal (atmos__ prefix).
 */
#ifndef ATMOS_VOLUME_READER_FENCE_H
#define ATMOS_VOLUME_READER_FENCE_H

#include "atmos/atmos.h"

#include <stdint.h>

typedef atmos_status (*atmos__reader_fn)(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                         atmos_volume **out);

/* Runs load(ctx, path, desc, out) in a child process. `library` names the parser in
 * messages ("OpenVDB"). Limits: address space 2 x max_memory + 256 MiB + 16 MiB per CPU
 * beyond what the process already maps; CPU time 60 s + 1 s per 20 MB of file; wall time
 * 4 x the CPU limit. A child asleep with no CPU time spent and nothing sent for 3 s (stuck on
 * a lock another thread held at the fork) is killed and started again, 3 attempts in all.
 * Log messages of the child reach ctx's log callback. */
atmos_status atmos__reader_fenced(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                  const char *library, atmos__reader_fn load, atmos_volume **out);

#endif
