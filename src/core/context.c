/* The context object, status strings, error and log plumbing, atomic file writes. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, getpid, isatty, PATH_MAX */
#include "core/internal.h"

#include <errno.h>
#include <stdatomic.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

struct atmos_context {
    atmos_context_desc desc;
    char cache_dir[PATH_MAX];
    char error[1024];
    atmos_status error_status;
};

const char *atmos_version(void) { return ATMOS_VERSION_STRING; }

const char *atmos_status_string(atmos_status status)
{
    switch (status) {
    case ATMOS_OK: return "ok";
    case ATMOS_E_INVALID_ARG: return "invalid argument";
    case ATMOS_E_NOMEM: return "out of memory";
    case ATMOS_E_IO: return "input/output error";
    case ATMOS_E_FORMAT: return "malformed data";
    case ATMOS_E_UNSUPPORTED: return "unsupported";
    case ATMOS_E_LIMIT: return "limit exceeded";
    case ATMOS_E_CANCELLED: return "cancelled";
    }
    return "unknown status";
}

static int default_threads(void)
{
#ifdef _OPENMP
    int n = omp_get_num_procs();
    return n > 0 ? n : 1;
#else
    return 1;
#endif
}

static void resolve_cache_dir(char *out, size_t cap, const char *requested)
{
    const char *xdg = getenv("XDG_CACHE_HOME");
    const char *home = getenv("HOME");
    if (requested && *requested)
        snprintf(out, cap, "%s", requested);
    else if (xdg && *xdg)
        snprintf(out, cap, "%s/atmos", xdg);
    else if (home && *home)
        snprintf(out, cap, "%s/.cache/atmos", home);
    else
        snprintf(out, cap, ".atmos-cache");
}

void atmos_context_defaults(atmos_context_desc *desc)
{
    if (!desc) return;
    memset(desc, 0, sizeof *desc);
    desc->threads = default_threads();
    desc->log_level = ATMOS_LOG_WARN;
}

atmos_status atmos_context_create(const atmos_context_desc *desc, atmos_context **out)
{
    if (!out) return ATMOS_E_INVALID_ARG;
    *out = NULL;
    atmos_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx) return ATMOS_E_NOMEM;
    if (desc) ctx->desc = *desc;
    if (ctx->desc.threads < 0) {
        free(ctx);
        return ATMOS_E_INVALID_ARG;
    }
    if (ctx->desc.threads == 0) ctx->desc.threads = default_threads();
    resolve_cache_dir(ctx->cache_dir, sizeof ctx->cache_dir, ctx->desc.cache_dir);
    ctx->desc.cache_dir = ctx->cache_dir;
    *out = ctx;
    return ATMOS_OK;
}

void atmos_context_destroy(atmos_context *ctx) { free(ctx); }

int atmos_context_threads(const atmos_context *ctx) { return atmos__threads(ctx); }

const char *atmos_context_cache_dir(const atmos_context *ctx) { return ctx ? ctx->cache_dir : ""; }

const char *atmos_context_error(const atmos_context *ctx) { return ctx ? ctx->error : ""; }

atmos_status atmos_context_error_status(const atmos_context *ctx) { return ctx ? ctx->error_status : ATMOS_OK; }

void atmos_context_clear_error(atmos_context *ctx)
{
    if (!ctx) return;
    ctx->error[0] = '\0';
    ctx->error_status = ATMOS_OK;
}

void atmos__context_redirect_log(atmos_context *ctx, atmos_log_fn fn, void *user)
{
    if (!ctx) return;
    ctx->desc.log = fn;
    ctx->desc.log_user = user;
}

void atmos__context_redirect_progress(atmos_context *ctx, atmos_progress_fn fn, void *user)
{
    if (!ctx) return;
    ctx->desc.progress = fn;
    ctx->desc.progress_user = user;
}

int atmos__threads(const atmos_context *ctx)
{
    if (ctx && ctx->desc.threads > 0) return ctx->desc.threads;
    return default_threads();
}

static void vlog(const atmos_context *ctx, atmos_log_level level, const char *fmt, va_list ap)
{
    if (!ctx || !ctx->desc.log || level > ctx->desc.log_level) return;
    char buf[1024];
    vsnprintf(buf, sizeof buf, fmt, ap);
    ctx->desc.log(ctx->desc.log_user, level, buf);
}

void atmos__log(const atmos_context *ctx, atmos_log_level level, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vlog(ctx, level, fmt, ap);
    va_end(ap);
}

atmos_status atmos__error(atmos_context *ctx, atmos_status status, const char *fmt, ...)
{
    if (!ctx) return status;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ctx->error, sizeof ctx->error, fmt, ap);
    va_end(ap);
    ctx->error_status = status;
    atmos__log(ctx, ATMOS_LOG_ERROR, "%s", ctx->error);
    return status;
}

int atmos__progress(const atmos_context *ctx, const char *stage, double fraction)
{
    if (!ctx || !ctx->desc.progress) return 0;
    if (fraction < 0) fraction = 0;
    if (fraction > 1) fraction = 1;
    return ctx->desc.progress(ctx->desc.progress_user, stage, fraction);
}

static atomic_uint write_counter;

static atmos_status write_atomic(atmos_context *ctx, const char *path, atmos__write_fn fn, void *user, int unique)
{
    if (!path || !*path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "output path is empty");
    /* rename() would replace a device, FIFO, directory entry or symlink with our file
     * (as root, even /dev/full): write only to new or regular files. */
    struct stat sb;
    if (lstat(path, &sb) == 0 && !S_ISREG(sb.st_mode))
        return atmos__error(ctx, ATMOS_E_IO, "%s: exists and is not a regular file (%s); refusing to replace it", path,
                            S_ISLNK(sb.st_mode) ? "a symbolic link" : S_ISDIR(sb.st_mode) ? "a directory" : "a device or FIFO");
    size_t n = strlen(path);
    char *tmp = malloc(n + 32);
    if (!tmp) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
    /* Same directory as the target so rename() is atomic; pid makes it unique per
     * process, and a fixed-width counter per write within it (threads of one process
     * may store the same cache entry at once). */
    if (unique)
        snprintf(tmp, n + 32, "%s.tmp%ld%06u", path, (long)getpid(), atomic_fetch_add(&write_counter, 1u) % 1000000u);
    else
        snprintf(tmp, n + 32, "%s.tmp%ld", path, (long)getpid());
    atmos_status st = fn(ctx, tmp, user);
    if (st == ATMOS_OK && rename(tmp, path) != 0) {
        st = atmos__error(ctx, ATMOS_E_IO, "%s: cannot rename temporary file into place: %s", path,
                          strerror(errno));
    }
    if (st != ATMOS_OK) remove(tmp);
    free(tmp);
    return st;
}

atmos_status atmos__write_atomic(atmos_context *ctx, const char *path, atmos__write_fn fn, void *user)
{
    return write_atomic(ctx, path, fn, user, 0);
}

atmos_status atmos__write_atomic_unique(atmos_context *ctx, const char *path, atmos__write_fn fn, void *user)
{
    return write_atomic(ctx, path, fn, user, 1);
}

atmos_status atmos__temp_create_error(atmos_context *ctx, const char *path, int err)
{
    return atmos__error(ctx, ATMOS_E_IO, "%s: cannot create a temporary file beside it: %s", path, strerror(err));
}

typedef struct {
    const char *src;
    const char *dst;
} copy_job;

static atmos_status copy_fn(atmos_context *ctx, const char *tmp, void *user)
{
    const copy_job *j = user;
    FILE *in = fopen(j->src, "rb");
    if (!in) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", j->src, strerror(errno));
    FILE *out = fopen(tmp, "wb");
    if (!out) {
        int e = errno;
        fclose(in);
        return atmos__temp_create_error(ctx, j->dst, e);
    }
    char buf[65536];
    size_t n;
    int ok = 1;
    while (ok && (n = fread(buf, 1, sizeof buf, in)) > 0) ok = fwrite(buf, 1, n, out) == n;
    ok = ok && !ferror(in);
    fclose(in);
    if (fclose(out) != 0) ok = 0;
    return ok ? ATMOS_OK : atmos__error(ctx, ATMOS_E_IO, "%s: write failed: %s", j->dst, strerror(errno));
}

atmos_status atmos_copy_file_atomic(atmos_context *ctx, const char *src, const char *dst)
{
    if (!src || !dst) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "copy: missing path");
    copy_job j = {src, dst};
    return atmos__write_atomic(ctx, dst, copy_fn, &j);
}
