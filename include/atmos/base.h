/* atmos — the base every public header includes: the export macro, the version, the
 * status codes, the log and progress callbacks and the context object. <atmos/atmos.h>
 * includes it and every module header. */
#ifndef ATMOS_BASE_H
#define ATMOS_BASE_H

#include <stddef.h>

#if defined(ATMOS_STATIC)
#  define ATMOS_API
#elif defined(ATMOS_BUILDING_LIBRARY)
#  define ATMOS_API __attribute__((visibility("default")))
#else
#  define ATMOS_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define ATMOS_VERSION_MAJOR 0
#define ATMOS_VERSION_MINOR 2
#define ATMOS_VERSION_PATCH 0

/* The library's version as "MAJOR.MINOR.PATCH". */
ATMOS_API const char *atmos_version(void);

/* Status codes. The numeric values never change once released. */
typedef enum {
    ATMOS_OK = 0,
    ATMOS_E_INVALID_ARG = 1, /* an argument or scene value is out of range or malformed */
    ATMOS_E_NOMEM = 2,       /* an allocation failed */
    ATMOS_E_IO = 3,          /* a file could not be opened, read, written or renamed */
    ATMOS_E_FORMAT = 4,      /* a file's contents are malformed */
    ATMOS_E_UNSUPPORTED = 5, /* valid request this build cannot do */
    ATMOS_E_LIMIT = 6,       /* a size or memory limit would be exceeded */
    ATMOS_E_CANCELLED = 7    /* the progress callback asked to stop */
} atmos_status;

/* A short static description of a status code ("invalid argument", ...). */
ATMOS_API const char *atmos_status_string(atmos_status status);

typedef enum {
    ATMOS_LOG_ERROR = 0,
    ATMOS_LOG_WARN = 1,
    ATMOS_LOG_INFO = 2,
    ATMOS_LOG_DEBUG = 3
} atmos_log_level;

/* Log sink. Called from the thread that called into the library (never from worker
 * threads). msg has no trailing newline. */
typedef void (*atmos_log_fn)(void *user, atmos_log_level level, const char *msg);

/* Progress sink for long work. stage names the work ("render", "table ..."),
 * fraction is in [0, 1]. Called from the calling thread only. Return nonzero to
 * cancel: the running function then returns ATMOS_E_CANCELLED. Without one (NULL, the
 * default) the library is silent while it works, table builds included: a first render
 * that builds optics tables for many spectral samples (rain's at 16 samples: more than
 * 10 minutes on two cores) logs nothing until it is done. Set one to show or cancel it. */
typedef int (*atmos_progress_fn)(void *user, const char *stage, double fraction);

/* Settings for a context; zero means default. */
typedef struct atmos_context_desc {
    int threads;            /* worker threads; 0 = all cores (OpenMP's default) */
    const char *cache_dir;  /* on-disk table cache; NULL = $XDG_CACHE_HOME/atmos, else ~/.cache/atmos */
    atmos_log_fn log;       /* NULL = no logging */
    void *log_user;
    atmos_log_level log_level; /* messages above this level are dropped; 0 = ATMOS_LOG_ERROR.
                                  Use atmos_context_defaults() for WARN. */
    atmos_progress_fn progress; /* NULL = no progress reports */
    void *progress_user;
} atmos_context_desc;

/* The context: thread count, cache directory, log and progress callbacks, and the
 * message of the last error. Not thread-safe itself: use one context per calling
 * thread (the library's own worker threads do not touch it). */
typedef struct atmos_context atmos_context;

/* Fills *desc with the resolved defaults (threads = number of cores, log level WARN,
 * cache directory from the environment). */
ATMOS_API void atmos_context_defaults(atmos_context_desc *desc);
ATMOS_API atmos_status atmos_context_create(const atmos_context_desc *desc, atmos_context **out);
ATMOS_API void atmos_context_destroy(atmos_context *ctx);

ATMOS_API int atmos_context_threads(const atmos_context *ctx);
ATMOS_API const char *atmos_context_cache_dir(const atmos_context *ctx);
/* Message of the last failed call made with this context ("" if none). Valid until
 * the next call that fails. */
ATMOS_API const char *atmos_context_error(const atmos_context *ctx);
ATMOS_API atmos_status atmos_context_error_status(const atmos_context *ctx);
ATMOS_API void atmos_context_clear_error(atmos_context *ctx);

/* Copies the file at src to dst through a temporary file beside dst and a rename, so dst
 * is never half-written; dst must not exist as anything but a regular file. */
ATMOS_API atmos_status atmos_copy_file_atomic(atmos_context *ctx, const char *src, const char *dst);

#ifdef __cplusplus
}
#endif

#endif
