/* Shared helpers for the atmos command-line tool. No physics here: subcommands
 * turn arguments into library calls. */
#ifndef ATMOS_CLI_H
#define ATMOS_CLI_H

#include "atmos/atmos.h"

#include <stdio.h>

/* Exit statuses of every subcommand; every --help ends with CLI_HELP_EXIT. */
#define CLI_HELP_EXIT "\nExit status: 0 success, 1 runtime error, 2 usage error.\n"
enum { CLI_EXIT_OK = 0, CLI_EXIT_RUNTIME = 1, CLI_EXIT_USAGE = 2 };

/* text as a finite decimal number (all of it, in range; no hexadecimal) into *out: 1; else 0, *out
 * untouched, nothing said. */
int cli_strtod(const char *text, double *out);
/* Parses a finite number; on failure prints "atmos CMD: OPT: expected a finite number, got
 * 'TEXT'" to stderr and returns 0. */
int cli_parse_double(const char *cmd, const char *opt, const char *text, double *out);
/* Parses an azimuth in degrees, [0, 360) as the scene file's azimuth keys: another value is a
 * usage error naming OPT and the range (the same rule for every azimuth option). */
int cli_parse_azimuth(const char *cmd, const char *opt, const char *text, double *out);
/* Parses an integer in [lo, hi]; prints a message naming OPT and the range on failure. */
int cli_parse_int(const char *cmd, const char *opt, const char *text, long lo, long hi, int *out);
/* Parses a seed: a decimal integer in [0, 2^64 - 1] (a larger one refused, not clamped); on
 * failure prints a usage message naming --seed and returns 0. */
int cli_parse_seed(const char *cmd, const char *text, unsigned long long *out);
/* Prints "atmos CMD: message" and "Try 'atmos CMD --help'." to stderr; returns CLI_EXIT_USAGE. */
int cli_usage_error(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Prints "atmos CMD: <ctx error or status string>" to stderr; returns CLI_EXIT_RUNTIME. */
int cli_runtime_error(const char *cmd, atmos_context *ctx, atmos_status st);
/* 1 when renderer r lights scene s by its lamps only, without the sun: the beam renderer without
 * beams.sun, the path tracer of a scene with lights, fog or objects (docs/beams.md, docs/path.md). */
int cli_lit_without_sun(const atmos_scene *s, atmos_renderer_kind r);
/* A context for a subcommand: logs warnings and errors to stderr (errors only when quiet: for
 * commands whose own output replaces the warnings, not for a user's -q), threads as given (0 = all). */
atmos_context *cli_context(int threads, int quiet);
/* Commands' contexts draw the library's progress (a process-wide cli_progress: a bar on a
 * terminal whatever quiet says of the log); cli_context_with_progress names its own. */
atmos_context *cli_context_with_progress(int threads, int quiet, atmos_progress_fn fn, void *user);
/* A progress bar with ETA on stderr for work that takes over a second (ATMOS_PROGRESS_DELAY), redrawn at most
 * ten times a second, when stderr is a terminal and not quiet; each stage (a new name, or
 * a fraction that starts again) has its own bar and ETA. When stderr is not a terminal (a
 * log, a batch job) the bar is not drawn: a line "atmos: STAGE: N %, T s elapsed" is written
 * every CLI_PROGRESS_LOG_INTERVAL seconds of the run (ATMOS_PROGRESS_INTERVAL=S: every S; 0:
 * every report), whichever stage runs then, T that stage's time. Pass cli_progress_bar with a
 * cli_progress as the context's progress callback; p.shown: a bar is on the terminal and its
 * line is not ended. */
#define CLI_PROGRESS_LOG_INTERVAL 5.0
typedef struct {
    int enabled;
    double start;
    int shown;
    double last_draw;
    int log;                /* not a terminal (and not quiet): log lines */
    double interval;        /* seconds between log lines */
    double log_at;          /* when the last log line was written (or the start) */
    char stage[48];         /* the stage being shown */
    double last_fraction;
    double delay;           /* seconds before a bar appears (ATMOS_PROGRESS_DELAY, default 1) */
} cli_progress;
void cli_progress_init(cli_progress *p, int quiet);
int cli_progress_bar(void *user, const char *stage, double fraction);
/* The commands' shared progress bar as d's progress callback (contexts made by hand). */
void cli_desc_progress(atmos_context_desc *d);
/* That bar, for a command's own stages (one thread at a time). */
cli_progress *cli_shared_progress(void);
/* atmos sky's models (sky_tables.c): the kind of --model NAME (0 when unknown) and a kind's name. */
int cli_sky_model(const char *name, atmos_atmosphere_kind *kind);
const char *cli_sky_model_name(atmos_atmosphere_kind kind);
/* atmos sky --table NAME [-o FILE] before any atmosphere is made: "list" prints the model's
 * tables (or, for a model without any, every model's), a table another model keeps or an
 * unknown one is a usage error. Returns -1 when NAME is to be written, else the exit code. */
int cli_sky_table_check(const char *C, atmos_atmosphere_kind kind, const char *name, const char *out);
/* Writes the table NAME of atm to out (.exr, .pfm or .png). */
int cli_sky_table(const char *C, atmos_context *ctx, const atmos_atmosphere *atm, const char *name, const char *out);
/* Monotonic clock, seconds. */
double cli_now_s(void);
/* The whole of a text file as a new string; NULL when it cannot be read, is longer than max
 * bytes or holds a NUL byte. */
char *cli_read_text(const char *path, size_t max);
/* The same from an open stream (standard input), read to its end. */
char *cli_read_stream(FILE *f, size_t max);
#define CLI_TEXT_MAX ((size_t)16 << 20)
/* Option with a value, as "--name VALUE" or "--name=VALUE": returns 1 if argv[*i] is
 * that option (advancing *i past a separate value) with *value set (NULL when the value
 * is missing), else 0. */
int cli_take_value(int argc, char **argv, int *i, const char *name, const char **value);
/* 1 when name is one of the comma-separated names of list. */
int cli_list_has(const char *list, const char *name);
/* Prints a JSON array of n doubles (%.9g) to stdout. */
void cli_print_json_array(const double *v, int n);

/* Subcommands: each gets argv with argv[0] = subcommand name. */
int cli_cmd_render(int argc, char **argv);
int cli_cmd_sky(int argc, char **argv);
int cli_cmd_sun(int argc, char **argv);
int cli_cmd_bench(int argc, char **argv);
int cli_cmd_phase(int argc, char **argv);
int cli_cmd_cache(int argc, char **argv);
int cli_cmd_mie(int argc, char **argv);
int cli_cmd_volume(int argc, char **argv);
/* atmos volume's help, and its stats subcommand (cmd_volume_stats.c) with its parts of the help */
void cli_volume_help(void);
int cli_cmd_volume_stats(int argc, char **argv);
void cli_volume_stats_usage(void);
void cli_volume_stats_help(void);
/* atmos volume's options of how a file is read (--grids, --time, ...; volume_read_opts.c): 1 if
 * argv[*i] was one (its value consumed), 0 if not, -1 after a usage error was printed. */
int cli_volume_load_option(int argc, char **argv, int *i, atmos_volume_load_desc *d);
int cli_cmd_simulate(int argc, char **argv);
int cli_cmd_compare(int argc, char **argv);
int cli_cmd_view(int argc, char **argv); /* tools/view/ */

#endif
