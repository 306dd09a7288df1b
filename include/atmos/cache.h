/* The on-disk cache of precomputed tables (phase tables, ...).
 *
 * Location: atmos_context_cache_dir() — the context's cache_dir, else
 * $XDG_CACHE_HOME/atmos, else ~/.cache/atmos. Entries are files named
 * <16 hex digits>.atmoscache (format in docs/phase-tables.md). Building functions read
 * and write the cache themselves; this header only manages it.
 */
#ifndef ATMOS_CACHE_H
#define ATMOS_CACHE_H

#include "atmos/base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Removes every atmos cache entry (and leftover temporary files of interrupted writes)
 * from the context's cache directory; other files are left alone. A missing directory
 * is not an error. *removed (may be NULL) gets the number of files removed.
 * ATMOS_E_IO if the directory cannot be read or a file cannot be removed. */
ATMOS_API atmos_status atmos_cache_clear(atmos_context *ctx, int *removed);

#ifdef __cplusplus
}
#endif
#endif
