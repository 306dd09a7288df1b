/* Shared helpers for the atmos subcommands. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, isatty */
#include "cli.h"
#include "outputs.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

int cli_strtod(const char *text, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = text ? strtod(text, &end) : 0.0;
    if (!text || end == text || *end != '\0' || errno == ERANGE || !isfinite(v)) return 0;
    if (strpbrk(text, "xX")) return 0; /* decimal only, as the integer options are (strtod reads 0x10 as 16) */
    *out = v;
    return 1;
}

int cli_parse_double(const char *cmd, const char *opt, const char *text, double *out)
{
    double v = 0.0;
    if (!cli_strtod(text, &v)) {
        fprintf(stderr, "atmos %s: %s: expected a finite number, got '%s'\nTry 'atmos %s --help'.\n", cmd, opt,
                text ? text : "", cmd);
        return 0;
    }
    *out = v;
    return 1;
}

int cli_parse_azimuth(const char *cmd, const char *opt, const char *text, double *out)
{
    if (!cli_parse_double(cmd, opt, text, out)) return 0;
    if (*out >= 0.0 && *out < 360.0) return 1;
    cli_usage_error(cmd, "%s: expected degrees in [0, 360) (clockwise from north), got %s", opt, text);
    return 0;
}

int cli_parse_int(const char *cmd, const char *opt, const char *text, long lo, long hi, int *out)
{
    char *end = NULL;
    errno = 0;
    long v = text ? strtol(text, &end, 10) : 0;
    if (!text || end == text || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
        fprintf(stderr, "atmos %s: %s: expected an integer in [%ld, %ld], got '%s'\nTry 'atmos %s --help'.\n", cmd, opt,
                lo, hi, text ? text : "", cmd);
        return 0;
    }
    *out = (int)v;
    return 1;
}

int cli_parse_seed(const char *cmd, const char *text, unsigned long long *out)
{
    char *end = NULL;
    errno = 0;
    const unsigned long long v = text ? strtoull(text, &end, 10) : 0;
    if (!text || !*text || *end || text[0] == '-' || errno == ERANGE) {
        cli_usage_error(cmd, "--seed: expected an integer in [0, 18446744073709551615], got '%s'", text ? text : "");
        return 0;
    }
    *out = v;
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

int cli_lit_without_sun(const atmos_scene *s, atmos_renderer_kind r)
{
    return (r == ATMOS_RENDERER_BEAMS && !s->beams.sun) ||
           (r == ATMOS_RENDERER_PATH && (s->light_count > 0 || s->fog.enabled || s->object_count > 0));
}

int cli_runtime_error(const char *cmd, atmos_context *ctx, atmos_status st)
{
    const char *msg = ctx ? atmos_context_error(ctx) : "";
    char buf[2048];
    cli_outputs_final_names(msg && *msg ? msg : atmos_status_string(st), buf, sizeof buf);
    /* the library's messages may start with the command's own name ("simulate: ..."): once */
    const size_t n = strlen(cmd);
    const char *text = !strncmp(buf, cmd, n) && buf[n] == ':' && buf[n + 1] == ' ' ? buf + n + 2 : buf;
    fprintf(stderr, "atmos %s: %s\n", cmd, text);
    return CLI_EXIT_RUNTIME;
}

static void log_stderr(void *user, atmos_log_level level, const char *msg)
{
    (void)user;
    /* Errors are printed by the subcommand with its own prefix; log the rest. */
    if (level == ATMOS_LOG_ERROR) return;
    char buf[2048];
    cli_outputs_final_names(msg, buf, sizeof buf);
    fprintf(stderr, "atmos: %s: %s\n", level == ATMOS_LOG_WARN ? "warning" : "info", buf);
}

static cli_progress shared_progress; /* shown on a terminal whatever the log level */

cli_progress *cli_shared_progress(void) { return &shared_progress; }

void cli_desc_progress(atmos_context_desc *d)
{
    cli_progress_init(&shared_progress, 0);
    d->progress = cli_progress_bar;
    d->progress_user = &shared_progress;
}

atmos_context *cli_context(int threads, int quiet)
{
    atmos_context_desc d;
    cli_desc_progress(&d);
    return cli_context_with_progress(threads, quiet, d.progress, d.progress_user);
}

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

char *cli_read_stream(FILE *f, size_t max)
{
    char *buf = NULL;
    size_t n = 0, cap = 0;
    int bad = 0;
    for (;;) {
        if (n + 4096 + 1 > cap) {
            cap = 2 * cap + 8192;
            char *nb = realloc(buf, cap);
            if (!nb) { bad = 1; break; }
            buf = nb;
        }
        const size_t r = fread(buf + n, 1, 4096, f);
        n += r;
        if (n > max) { bad = 1; break; }
        if (r < 4096) break;
    }
    bad = bad || ferror(f) || !buf || memchr(buf, 0, n);
    if (bad) return free(buf), NULL;
    buf[n] = '\0';
    return buf;
}

char *cli_read_text(const char *path, size_t max)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *buf = cli_read_stream(f, max);
    fclose(f);
    return buf;
}

double cli_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

void cli_progress_init(cli_progress *p, int quiet)
{
    memset(p, 0, sizeof *p);
    p->enabled = !quiet && isatty(2);
    const char *iv = getenv("ATMOS_PROGRESS_INTERVAL");
    char *end = NULL;
    /* off a terminal (a batch job's log): a line every few seconds, whichever stage is running,
     * so that a long first build of the tables (many stages of seconds each) is not silent;
     * ATMOS_PROGRESS_INTERVAL=S sets the interval */
    p->interval = iv && *iv ? strtod(iv, &end) : CLI_PROGRESS_LOG_INTERVAL;
    if (!(p->interval >= 0) || (end && *end)) p->interval = CLI_PROGRESS_LOG_INTERVAL;
    p->log = !quiet && !p->enabled;
    const char *dl = getenv("ATMOS_PROGRESS_DELAY");
    end = NULL;
    p->delay = dl && *dl ? strtod(dl, &end) : 1.0;
    if (!(p->delay >= 0) || (end && *end)) p->delay = 1.0;
    p->start = p->log_at = cli_now_s();
}

/* A new stage (another name, or the fraction starting again) restarts the clock; a bar
 * left unfinished on the terminal ends its line first. */
static void progress_stage(cli_progress *p, const char *stage, double f)
{
    if (!strncmp(p->stage, stage, sizeof p->stage - 1) && f >= p->last_fraction) {
        p->last_fraction = f;
        return;
    }
    if (p->shown && p->enabled) fputc('\n', stderr), cli_outputs_line_open(0);
    snprintf(p->stage, sizeof p->stage, "%s", stage);
    p->start = cli_now_s();
    p->shown = 0;
    p->last_draw = 0.0;
    p->last_fraction = f;
}

/* Off a terminal: a line every interval seconds of the run, the first after one interval,
 * whatever stage is running then (its own elapsed time). */
static void progress_log(cli_progress *p, const char *stage, double f)
{
    const double now = cli_now_s();
    if (now - p->log_at < p->interval) return;
    p->log_at = now;
    fprintf(stderr, "atmos: %s: %.0f %%, %.1f s elapsed\n", stage, 100.0 * f, now - p->start);
    fflush(stderr);
}

int cli_progress_bar(void *user, const char *stage, double f)
{
    cli_progress *p = user;
    if (!p->enabled && !p->log) return 0;
    if (!stage) stage = "working";
    progress_stage(p, stage, f);
    if (p->log) progress_log(p, stage, f);
    if (!p->enabled) return 0;
    double t = cli_now_s() - p->start;
    if (t < p->delay && !p->shown) return 0;
    if (f < 1.0 && t - p->last_draw < 0.1) return 0; /* redraw at most ten times a second */
    p->last_draw = t;
    int width = 30, fill = (int)(f * width + 0.5);
    char bar[64];
    for (int i = 0; i < width; i++) bar[i] = i < fill ? '#' : '.';
    bar[width] = '\0';
    double eta = f > 0 ? t * (1.0 - f) / f : 0;
    fprintf(stderr, "\r%s [%s] %3.0f%%  %.1fs elapsed, ETA %.1fs ", stage, bar, 100.0 * f, t, eta);
    p->shown = 1;
    cli_outputs_line_open(f < 1.0);
    if (f >= 1.0) {
        fputc('\n', stderr);
        p->stage[0] = '\0'; /* the line is ended: the next report starts a new bar */
        p->shown = 0;
    }
    fflush(stderr);
    return 0;
}

int cli_take_value(int argc, char **argv, int *i, const char *name, const char **value)
{
    const char *a = argv[*i];
    size_t n = strlen(name);
    if (strncmp(a, name, n) != 0) return 0;
    if (a[n] == '=') {
        *value = a + n + 1;
        return 1;
    }
    if (a[n] != '\0') return 0;
    *value = *i + 1 < argc ? argv[++*i] : NULL;
    return 1;
}

int cli_list_has(const char *list, const char *name)
{
    const size_t n = strlen(name);
    for (const char *t = list; *t; t += *t == ',') {
        const size_t len = strcspn(t, ",");
        if (len == n && !strncmp(t, name, n)) return 1;
        t += len;
    }
    return 0;
}
