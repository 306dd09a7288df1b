/* The output files of a command, written all or none.
 *
 * Before any work: each name's extension says its format, no two outputs are the same
 * file and no output is one of the command's input files (cli_outputs_check). Then, still
 * before the work, the missing parent folders are created and an empty staging file is
 * made next to each output (cli_outputs_prepare): a folder or file that cannot be
 * written fails the command before anything is rendered. The writers write the staging
 * files; cli_outputs_commit renames them all onto the final names at the end, and any
 * failure removes them (cli_outputs_discard) so that no output is replaced; an animation
 * holds each frame's staging files until all its frames are written (cli_outputs_hold).
 * SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGXFSZ and SIGPIPE remove the staging files, the held
 * ones and the writers' temporaries before the process ends by the signal (the last four
 * stay ignored when the caller ignores them), and the folders cli_outputs_prepare created
 * when they are left empty; SIGINT, SIGTERM, SIGHUP and SIGQUIT print "atmos CMD:
 * interrupted" on a line of its own (an animation's line adds how many finished frames are
 * discarded). The exit status is the signal's (130 for SIGINT, 143 for SIGTERM). */
#ifndef ATMOS_CLI_OUTPUTS_H
#define ATMOS_CLI_OUTPUTS_H

#include <stddef.h>

typedef enum { CLI_FILE_OTHER = 0, CLI_FILE_PNG, CLI_FILE_EXR, CLI_FILE_PFM } cli_file_kind;

/* The format a file name's extension names (case-insensitive .png, .exr, .pfm). */
cli_file_kind cli_file_kind_of(const char *path);

/* 0 when path names a raw volume's JSON sidecar (NAME.json, any case); else prints which
 * extension cannot be written and returns 1 (a usage error, found before any work). */
int cli_volume_output(const char *cmd, const char *option, const char *path);
/* 0 when path names a PNG file (NAME.png, any case); else prints that the option writes a PNG
 * and returns 1 (a usage error, found before any work). */
int cli_png_output(const char *cmd, const char *option, const char *path);

#define CLI_OUTPUTS_MAX 8
#define CLI_OUTPUT_PATH_MAX 4096

typedef struct {
    const char *option; /* the option that named it, for messages ("-o", "--exr") */
    const char *path;   /* the final name */
    char stage[CLI_OUTPUT_PATH_MAX + 32]; /* written here, renamed to path by commit */
} cli_output;

typedef struct {
    int n;
    cli_output f[CLI_OUTPUTS_MAX];
} cli_outputs;

/* Adds an output (path NULL: nothing); returns its index or -1 when path is NULL. */
int cli_outputs_add(cli_outputs *set, const char *option, const char *path);
/* The name a writer should write output i to (its staging file). */
const char *cli_outputs_stage(const cli_outputs *set, int i);

/* No output twice (the same file after normalising the path, or the same existing file
 * by device and inode) and no output that is one of inputs[0..ninputs) (NULL entries
 * skipped). Returns 0 (CLI_EXIT_OK) or 2 (CLI_EXIT_USAGE) with a message on stderr. */
int cli_outputs_check(const char *cmd, const cli_outputs *set, const char *const *inputs, int ninputs);
/* Creates missing parent folders, refuses outputs that exist and are not regular files,
 * and creates the staging files. Returns 0 or 1 (CLI_EXIT_RUNTIME) with a message on
 * stderr; on failure no staging file is left. */
int cli_outputs_prepare(const char *cmd, cli_outputs *set);
/* cli_outputs_prepare, then its staging files and the folders it made removed again: an
 * output that cannot be written is told before a long read of the inputs (whose names the
 * outputs may still depend on), and no trace is left. 0 or 1 (message printed). */
int cli_outputs_probe(const char *cmd, cli_outputs *set);
/* Before work whose output the library writes itself (a raw volume and its sidecar): the
 * folder of path made (mkdir -p) and writable. 0, or 1 with the reason printed. */
int cli_output_folder(const char *cmd, const char *option, const char *path);
/* After cli_outputs_prepare, for outputs the library writes itself under names of its own
 * (a raw volume's PATH.staged until the whole set is written): PATH + suffix, and its writer's
 * temporary, removed too on the ending signals, until the set is discarded. */
void cli_outputs_also_remove(const cli_outputs *set, const char *suffix);
/* The files atmos_volume_write_raw writes for out = NAME.json: the sidecar and NAME.FIELD.raw for
 * each of the n fields (at most CLI_OUTPUTS_MAX - 1; their names kept in raw), added to the empty
 * set, checked and prepared before any is written (none in the way, each creatable), their
 * PATH.staged names removed too on the ending signals. The set stays prepared through the write,
 * so the folders it made are there for the library; the caller discards it afterwards. 0, or
 * the exit status with the message printed (the set then holds nothing to discard). */
int cli_raw_outputs(const char *cmd, const char *out, const char *const *fields, int n,
                    char (*raw)[CLI_OUTPUT_PATH_MAX], cli_outputs *set);
/* Renames every staging file onto its final name. Returns 0 or 1 (message printed). */
int cli_outputs_commit(const char *cmd, cli_outputs *set);
/* An animation's frames, all or none: room for frames * per_frame held files (0 or 1: out
 * of memory); with frames > 1 a signal's "interrupted" line counts the finished frames. */
int cli_outputs_hold_reserve(int frames, int per_frame);
/* Instead of cli_outputs_commit: the staging files of set, all written, are held (kept
 * under their staging names, removed on signals) until cli_outputs_held_commit renames
 * every held file onto its final name; set is emptied of them. Returns 0 or 1 (message
 * printed, set's staging files removed). */
int cli_outputs_hold(const char *cmd, cli_outputs *set);
int cli_outputs_held_commit(const char *cmd);
/* Removes the held files (after a failure). */
void cli_outputs_held_discard(void);
/* Removes the staging files (and the writers' temporaries next to them). */
void cli_outputs_discard(cli_outputs *set);
/* Whether a progress bar's line on the terminal is open (not ended): a signal's
 * "interrupted" line starts on a new line then. */
void cli_outputs_line_open(int open);
/* A command that writes its files as it goes (atmos view --record, its saves): the ending
 * signals caught as for the staging files, a signal saying "atmos CMD: interrupted" and ending
 * the process by the signal. */
void cli_outputs_catch(const char *cmd);
/* on = 1 .. on = 0 around writing a set of files that must not be cut (a recorded frame's PNG
 * and its csv line): an ending signal that comes meanwhile acts at on = 0, so that no file is
 * left half written and no writer's temporary is left. Nested pairs: the outermost acts. */
void cli_outputs_defer_signals(int on);
/* A message with the staging suffix (".tmpPID") taken out of the names it holds, so
 * that the library's messages about a staging file name the output. */
void cli_outputs_final_names(const char *msg, char *out, size_t cap);

#endif
