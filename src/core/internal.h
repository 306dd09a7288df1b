/* Internal helpers shared across the library's source files (symbols atmos__*). */
#ifndef ATMOS_INTERNAL_H
#define ATMOS_INTERNAL_H

#include "atmos/atmos.h"
#include <stdarg.h>

#if defined(__GNUC__)
#  define ATMOS_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#  define ATMOS_PRINTF(a, b)
#endif

/* Records an error in ctx (may be NULL), logs it, and returns status so callers can
 * write `return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));` */
atmos_status atmos__error(atmos_context *ctx, atmos_status status, const char *fmt, ...) ATMOS_PRINTF(3, 4);
void atmos__log(const atmos_context *ctx, atmos_log_level level, const char *fmt, ...) ATMOS_PRINTF(3, 4);
/* Reports progress; returns nonzero if the caller asked to cancel. */
int atmos__progress(const atmos_context *ctx, const char *stage, double fraction);
/* Thread count to use for ctx (>= 1); 1 when ctx is NULL? No: all cores. */
int atmos__threads(const atmos_context *ctx);

/* Writes through a temporary file in the same directory and renames on success,
 * so no half-written file ever appears under path. write_fn gets the open temporary
 * path and returns a status; on failure the temporary is removed. */
typedef atmos_status (*atmos__write_fn)(atmos_context *ctx, const char *tmp_path, void *user);
atmos_status atmos__write_atomic(atmos_context *ctx, const char *path, atmos__write_fn fn, void *user);
/* The same with a temporary name unique to this write within the process
 * (PATH.tmpPID + 6-digit counter): for files that several threads may write. */
atmos_status atmos__write_atomic_unique(atmos_context *ctx, const char *path, atmos__write_fn fn, void *user);

#define ATMOS_PI 3.14159265358979323846
#define ATMOS_DEG2RAD (ATMOS_PI / 180.0)
#define ATMOS_RAD2DEG (180.0 / ATMOS_PI)

/* The phase tables (and, with with_msphase, the Ams_n tables) of every field of a volume
 * for a scene's wavelength set (src/render/slice.c); used by the slice renderer and the
 * path tracer. */
atmos_status atmos__optics_build(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                 int with_msphase, atmos_slice_optics *out);

#endif
