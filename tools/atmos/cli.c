/* Shared helpers for the atmos subcommands. */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

int cli_parse_double(const char *cmd, const char *opt, const char *text, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = text ? strtod(text, &end) : 0.0;
    if (!text || end == text || *end != '\0' || errno == ERANGE || !isfinite(v)) {
        fprintf(stderr, "atmos %s: %s: expected a finite number, got '%s'\n", cmd, opt, text ? text : "");
        return 0;
    }
    *out = v;
    return 1;
}

int cli_parse_int(const char *cmd, const char *opt, const char *text, long lo, long hi, int *out)
{
    char *end = NULL;
    errno = 0;
    long v = text ? strtol(text, &end, 10) : 0;
    if (!text || end == text || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
        fprintf(stderr, "atmos %s: %s: expected an integer in [%ld, %ld], got '%s'\n", cmd, opt, lo, hi,
                text ? text : "");
        return 0;
    }
    *out = (int)v;
    return 1;
}

int cli_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "atmos %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\nTry 'atmos %s --help'.\n", cmd);
    va_end(ap);
    return CLI_EXIT_USAGE;
}

int cli_runtime_error(const char *cmd, atmos_context *ctx, atmos_status st)
{
    const char *msg = ctx ? atmos_context_error(ctx) : "";
    fprintf(stderr, "atmos %s: %s\n", cmd, msg && *msg ? msg : atmos_status_string(st));
    return CLI_EXIT_RUNTIME;
}

static void log_stderr(void *user, atmos_log_level level, const char *msg)
{
    (void)user;
    /* Errors are printed by the subcommand with its own prefix; log the rest. */
    if (level == ATMOS_LOG_ERROR) return;
    fprintf(stderr, "atmos: %s: %s\n", level == ATMOS_LOG_WARN ? "warning" : "info", msg);
}

atmos_context *cli_context(int threads, int quiet) { return cli_context_with_progress(threads, quiet, NULL, NULL); }

atmos_context *cli_context_with_progress(int threads, int quiet, atmos_progress_fn fn, void *user)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    if (threads > 0) d.threads = threads;
    d.log = log_stderr;
    d.log_level = quiet ? ATMOS_LOG_ERROR : ATMOS_LOG_WARN;
    d.progress = fn;
    d.progress_user = user;
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) {
        fprintf(stderr, "atmos: cannot create a context\n");
        return NULL;
    }
    return ctx;
}

void cli_print_json_array(const double *v, int n)
{
    putchar('[');
    for (int i = 0; i < n; i++) printf("%s%.9g", i ? ", " : "", v[i]);
    putchar(']');
}
