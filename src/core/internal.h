/* Internal helpers shared across the library's source files (symbols atmos__*). */
#ifndef ATMOS_INTERNAL_H
#define ATMOS_INTERNAL_H

#include "atmos/atmos.h"
#include "core/clones.h"
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
/* Sends ctx's log messages to fn instead of the user's callback (a reader's child process
 * forwards them to its parent, volume/reader_fence.c); the level filter stays. */
void atmos__context_redirect_log(atmos_context *ctx, atmos_log_fn fn, void *user);
/* Sends ctx's progress reports to fn instead (the volume readers' child process). */
void atmos__context_redirect_progress(atmos_context *ctx, atmos_progress_fn fn, void *user);
/* Reports progress; returns nonzero if the caller asked to cancel. */
int atmos__progress(const atmos_context *ctx, const char *stage, double fraction);
/* Inside a parallel loop over n items: one more item done (*done, shared); the calling
 * thread reports the fraction and sets *cancelled (shared) when asked to stop
 * (progress_step.c). atmos__cancelled reads that flag. */
void atmos__progress_step(const atmos_context *ctx, const char *stage, int *done, int n, int *cancelled);
int atmos__cancelled(const int *cancelled);
/* Thread count to use for ctx (>= 1): the context's setting, all cores when ctx is NULL. */
int atmos__threads(const atmos_context *ctx);
/* A large buffer that is read at random (render grids, light buffers, per-pixel planes):
 * 2 MB aligned and, on Linux, backed by transparent huge pages where the system allows
 * it, so that samples do not pay a page walk per access. Freed with free(); NULL when
 * out of memory. */
void *atmos__big_alloc(size_t bytes);
/* The bytes atmos__big_alloc(bytes) holds (whole 2 MB pages where large): a buffer that grows
 * may use them all before it is made again. */
size_t atmos__big_size(size_t bytes);
/* Monotonic wall-clock time in seconds (for timings and time budgets only). */
double atmos__now(void);
/* The k-th smallest (0: the least) of n floats, none NaN (select.c); reorders v. k < n. */
float atmos__select_float(float *v, size_t n, size_t k);
/* The same, the rest of the range sorted after depth partitions (the tests reach the sort). */
float atmos__select_float_depth(float *v, size_t n, size_t k, int depth);
/* Indices sorted by a key (keysort.c): ascending, or descending with desc; ties by ascending
 * index, a total order, so the result does not depend on the sort's algorithm. */
typedef struct atmos__keyed {
    double key;
    int index;
} atmos__keyed;
void atmos__keyed_sort(atmos__keyed *a, size_t n, int desc);

/* Writes through a temporary file in the same directory and renames on success,
 * so no half-written file ever appears under path. write_fn gets the open temporary
 * path and returns a status; on failure the temporary is removed. */
typedef atmos_status (*atmos__write_fn)(atmos_context *ctx, const char *tmp_path, void *user);
atmos_status atmos__write_atomic(atmos_context *ctx, const char *path, atmos__write_fn fn, void *user);
/* The same with a temporary name unique to this write within the process
 * (PATH.tmpPID + 6-digit counter): for files that several threads may write. */
atmos_status atmos__write_atomic_unique(atmos_context *ctx, const char *path, atmos__write_fn fn, void *user);
/* A write_fn's error when its temporary cannot be created (err: errno): named by path only,
 * the temporary's name being the final one with a suffix that messages do not show. */
atmos_status atmos__temp_create_error(atmos_context *ctx, const char *path, int err);

#define ATMOS_PI 3.14159265358979323846
#define ATMOS_DEG2RAD (ATMOS_PI / 180.0)
#define ATMOS_RAD2DEG (180.0 / ATMOS_PI)

#endif
