/* The on-disk cache of precomputed tables (DESIGN.md §7), internal API.
 *
 * An entry is one file <cache_dir>/<16 hex digits>.atmoscache whose name is a 64-bit
 * hash of a key string; the key describes everything the payload depends on (resolved
 * parameters, algorithm version, payload layout). File layout, all integers
 * little-endian:
 *
 *   offset  size  field
 *        0     8  magic "ATMOSCA\x1a"
 *        8     4  container format version (ATMOS__CACHE_FORMAT_VERSION)
 *       12     4  key length K in bytes (1..65536), no terminator
 *       16     8  payload size N in bytes (<= 1 GiB)
 *       24     8  payload checksum (64-bit, see cache.c)
 *       32     K  the key string, compared in full on load (a hash collision can
 *                 therefore never return another entry's data)
 *     32+K     N  payload: the caller's bytes
 *
 * Nothing else may follow. A file that breaks any of this is reported with a warning
 * naming it, removed, and treated as a miss: the caller rebuilds. Cache failures are
 * never fatal; the functions log at WARN and do not set the context's error.
 * Thread safety: as the context (one context per calling thread).
 */
#ifndef ATMOS_CACHE_INTERNAL_H
#define ATMOS_CACHE_INTERNAL_H

#include "atmos/atmos.h"
#include <stddef.h>
#include <stdint.h>

#define ATMOS__CACHE_FORMAT_VERSION 1u
#define ATMOS__CACHE_MAX_PAYLOAD ((uint64_t)1 << 30)
#define ATMOS__CACHE_MAX_KEY 65536u
#define ATMOS__CACHE_SUFFIX ".atmoscache"

/* 64-bit FNV-1a of a string: names the entry. */
uint64_t atmos__cache_hash_key(const char *key);
/* 64-bit checksum of a byte range (word-wise multiply-rotate mixing, cache.c). */
uint64_t atmos__cache_checksum(const void *data, size_t size);
/* Writes the entry's full path into buf (cap bytes); 0 if it does not fit. */
int atmos__cache_entry_path(const atmos_context *ctx, const char *key, char *buf, size_t cap);

/* Looks the key up. Returns 1 and a malloc'ed payload (*data, *size; free() it) on a
 * hit; 0 on a miss (no entry: silent; a stale or corrupt entry: warned and removed). */
int atmos__cache_load(atmos_context *ctx, const char *key, void **data, size_t *size);
/* Stores an entry atomically (temporary file + rename), creating the cache directory
 * with its parents (mode 0755) if needed. Returns ATMOS_OK, or an error status after
 * logging a warning; the context's error is left alone. */
atmos_status atmos__cache_store(atmos_context *ctx, const char *key, const void *data, size_t size);

#endif
