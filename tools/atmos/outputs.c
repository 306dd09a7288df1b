/* Output files written all or none (outputs.h). */
#define _XOPEN_SOURCE 700 /* realpath */
#include "outputs.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

cli_file_kind cli_file_kind_of(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash)) return CLI_FILE_OTHER;
    if (!strcasecmp(dot, ".png")) return CLI_FILE_PNG;
    if (!strcasecmp(dot, ".exr")) return CLI_FILE_EXR;
    if (!strcasecmp(dot, ".pfm")) return CLI_FILE_PFM;
    return CLI_FILE_OTHER;
}

int cli_volume_output(const char *cmd, const char *option, const char *path)
{
    const char *base = strrchr(path, '/'), *dot = strrchr(path, '.');
    base = base ? base + 1 : path;
    const int ext = dot && dot > base;
    if (ext && !strcasecmp(dot, ".json")) return 0;
    char why[96] = "the name needs the .json extension";
    if (ext) snprintf(why, sizeof why, "'%.40s' is not a format it can write", dot);
    fprintf(stderr,
            "atmos %s: %s %s: %s writes only a raw volume, NAME.json (the sidecar) with a NAME.FIELD.raw per field; "
            "%s\nTry 'atmos %s --help'.\n",
            cmd, option, path, cmd, why, cmd);
    return 1;
}

int cli_png_output(const char *cmd, const char *option, const char *path)
{
    if (cli_file_kind_of(path) == CLI_FILE_PNG) return 0;
    fprintf(stderr, "atmos %s: %s %s: writes a PNG image: the name needs the .png extension\nTry 'atmos %s --help'.\n",
            cmd, option, path, cmd);
    return 1;
}

/* ------------------------------------------------ temporaries removed on signals ---- */

/* Every staging file and the writer's temporary next to it (STAGE.tmpPID, as the
 * library's atomic writes name them). A slot is filled before its flag is set, so the
 * handler reads only whole names; unlink is async-signal-safe. */
#define SLOTS (4 * CLI_OUTPUTS_MAX) /* per output: its staging file and a writer's own (cli_outputs_also_remove) */
static char slot_name[SLOTS][CLI_OUTPUT_PATH_MAX + 64];
static volatile sig_atomic_t slot_used[SLOTS];

/* The staging files of an animation's finished frames, held until every frame is written
 * (cli_outputs_hold): an entry is filled before held_n counts it. */
typedef struct {
    char *stage, *path;
    const char *option;
} held_file;
static held_file *held;
static volatile sig_atomic_t held_n;
static int held_cap;

/* The signals that end a process by default and can be caught: a terminal hung up, a file
 * size limit reached (the writers' files are removed with the others). */
static const int ENDING[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGXFSZ, SIGPIPE};

/* The folders cli_outputs_prepare created (mkdir -p), outermost first: removed again, when
 * empty, on a signal. A name is stored before made_n counts it. */
#define MADE_MAX 16
static char made_dir[MADE_MAX][CLI_OUTPUT_PATH_MAX];
static volatile sig_atomic_t made_n;

static volatile sig_atomic_t line_open;   /* a progress bar's line is not ended */
static volatile sig_atomic_t frames_held; /* an animation's finished frames (held files) */
static volatile sig_atomic_t animation;   /* cli_outputs_hold_reserve was called */
static const char *signal_cmd = "render"; /* the command, for the "interrupted" line */
static volatile sig_atomic_t committing;  /* held files being renamed: a signal waits for the end */
static volatile sig_atomic_t deferred;    /* the signal that came meanwhile (any thread's) */

void cli_outputs_line_open(int open) { line_open = open; }

/* s appended to the buffer b of n bytes at *len, cut at its end (async-signal-safe) */
static void put(char *b, size_t n, size_t *len, const char *s)
{
    while (*s && *len + 1 < n) b[(*len)++] = *s++;
}

/* "interrupted" on a line of its own, in one write (async-signal-safe: no stdio) */
static void say_interrupted(void)
{
    char b[512];
    size_t n = 0;
    if (line_open) put(b, sizeof b, &n, "\n");
    put(b, sizeof b, &n, "atmos ");
    put(b, sizeof b, &n, signal_cmd);
    put(b, sizeof b, &n, ": interrupted");
    if (animation) {
        char num[24], *q = num + sizeof num;
        unsigned v = (unsigned)frames_held;
        *--q = '\0';
        do *--q = (char)('0' + v % 10); while ((v /= 10) && q > num);
        put(b, sizeof b, &n, ": no frame written (");
        put(b, sizeof b, &n, q);
        put(b, sizeof b, &n, frames_held == 1 ? " finished frame discarded" : " finished frames discarded");
        put(b, sizeof b, &n, ": an animation's frames are moved into place together, after the last one)");
    }
    put(b, sizeof b, &n, "\n");
    (void)!write(2, b, n);
}

/* The folders this run made, removed where still empty (rmdir fails otherwise: kept); safe in
 * a signal handler. */
static void remove_made_dirs(void)
{
    for (int i = made_n - 1; i >= 0; i--) rmdir(made_dir[i]);
}

static void on_signal(int sig)
{
    if (committing) { /* a thread the commit's mask does not cover: all or none still holds */
        deferred = sig;
        return;
    }
    /* timeout(1) signals the process and then its group: the same signal may come twice, to
     * two threads at once; the first handler cleans up, says so and ends the process */
    static atomic_flag handling = ATOMIC_FLAG_INIT;
    if (atomic_flag_test_and_set(&handling)) return;
    for (int i = 0; i < SLOTS; i++)
        if (slot_used[i]) unlink(slot_name[i]);
    for (int i = 0; i < held_n; i++) unlink(held[i].stage);
    remove_made_dirs();
    if (sig == SIGINT || sig == SIGTERM || sig == SIGHUP || sig == SIGQUIT) say_interrupted();
    signal(sig, SIG_DFL);
    raise(sig);
}

/* The handler installed on the ending signals, once. */
static void install_handlers(void)
{
    static int installed;
    if (!installed) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        for (size_t k = 0; k < sizeof ENDING / sizeof ENDING[0]; k++) {
            struct sigaction old;
            /* besides SIGINT and SIGTERM (caught always: a shell's background job ignores
             * SIGINT, yet kill -INT from its script means stop), a signal ignored by the
             * caller stays ignored (nohup; a write past a file size limit then fails as a
             * write, and the outputs are discarded as on any failure) */
            if (k >= 2 && sigaction(ENDING[k], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue;
            sigaction(ENDING[k], &sa, NULL);
        }
        installed = 1;
    }
}

void cli_outputs_catch(const char *cmd)
{
    signal_cmd = cmd;
    install_handlers();
}

/* Slots k and k + 1: name and the writer's temporary next to it. */
static void register_pair(int k, const char *name)
{
    install_handlers();
    slot_used[k] = slot_used[k + 1] = 0;
    snprintf(slot_name[k], sizeof slot_name[0], "%s", name);
    snprintf(slot_name[k + 1], sizeof slot_name[0], "%s.tmp%ld", name, (long)getpid());
    slot_used[k] = slot_used[k + 1] = 1;
}

static void register_stage(int i, const char *stage) { register_pair(2 * i, stage); }

static void unregister_stage(int i)
{
    slot_used[2 * i] = slot_used[2 * i + 1] = 0;
    slot_used[2 * (CLI_OUTPUTS_MAX + i)] = slot_used[2 * (CLI_OUTPUTS_MAX + i) + 1] = 0;
}

void cli_outputs_also_remove(const cli_outputs *set, const char *suffix)
{
    char name[CLI_OUTPUT_PATH_MAX + 32];
    for (int i = 0; i < set->n; i++) {
        snprintf(name, sizeof name, "%s%s", set->f[i].path, suffix);
        register_pair(2 * (CLI_OUTPUTS_MAX + i), name);
    }
}

/* ------------------------------------------------------------------ the set ---- */

int cli_outputs_add(cli_outputs *set, const char *option, const char *path)
{
    if (!path || set->n >= CLI_OUTPUTS_MAX) return -1;
    cli_output *o = &set->f[set->n];
    o->option = option, o->path = path, o->stage[0] = '\0';
    return set->n++;
}

const char *cli_outputs_stage(const cli_outputs *set, int i) { return set->f[i].stage; }

/* The path made absolute with '.', '..' and repeated '/' removed; the folder part resolved
 * by realpath when it exists (symbolic links followed). 0 when it does not fit. */
static int normalise(const char *path, char *out, size_t cap)
{
    char abs[2 * CLI_OUTPUT_PATH_MAX + 2], joined[sizeof abs + CLI_OUTPUT_PATH_MAX], cwd[CLI_OUTPUT_PATH_MAX];
    if (path[0] == '/') {
        snprintf(abs, sizeof abs, "%s", path);
    } else {
        if (!getcwd(cwd, sizeof cwd)) return 0;
        snprintf(abs, sizeof abs, "%s/%s", cwd, path);
    }
    char *slash = strrchr(abs, '/');
    *slash = '\0';
    char *real = realpath(abs[0] ? abs : "/", NULL);
    *slash = '/';
    if (real) snprintf(joined, sizeof joined, "%s/%s", real, slash + 1);
    else snprintf(joined, sizeof joined, "%s", abs);
    free(real);
    path = joined;
    /* lexical clean-up, component by component */
    size_t len = 0;
    for (const char *p = path; *p;) {
        while (*p == '/') p++;
        const char *e = strchr(p, '/');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        if (n == 0) break;
        if (n == 2 && p[0] == '.' && p[1] == '.') {
            while (len > 0 && out[len - 1] != '/') len--;
            if (len > 0) len--;
        } else if (!(n == 1 && p[0] == '.')) {
            if (len + 1 + n + 1 > cap) return 0;
            out[len++] = '/';
            memcpy(out + len, p, n);
            len += n;
        }
        p += n;
    }
    if (len == 0) out[len++] = '/';
    out[len] = '\0';
    return 1;
}

/* Whether a and b name the same file: equal normalised paths, or both existing with the
 * same device and inode (hard links, symbolic links). */
static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino) return 1;
    char na[CLI_OUTPUT_PATH_MAX + 2], nb[CLI_OUTPUT_PATH_MAX + 2];
    return normalise(a, na, sizeof na) && normalise(b, nb, sizeof nb) && !strcmp(na, nb);
}

int cli_outputs_check(const char *cmd, const cli_outputs *set, const char *const *inputs, int ninputs)
{
    for (int i = 0; i < set->n; i++) {
        const cli_output *o = &set->f[i];
        if (!o->path[0]) return fprintf(stderr, "atmos %s: %s: empty file name\n", cmd, o->option), 2;
        if (strlen(o->path) >= CLI_OUTPUT_PATH_MAX)
            return fprintf(stderr, "atmos %s: %s: the path is too long\n", cmd, o->option), 2;
        for (int k = 0; k < i; k++)
            if (same_file(o->path, set->f[k].path)) {
                fprintf(stderr, "atmos %s: %s %s and %s %s name the same file: one would overwrite the other\n", cmd,
                        set->f[k].option, set->f[k].path, o->option, o->path);
                return 2;
            }
        for (int k = 0; k < ninputs; k++)
            if (inputs[k] && same_file(o->path, inputs[k])) {
                fprintf(stderr, "atmos %s: %s %s is the input file %s: refusing to overwrite an input\n", cmd,
                        o->option, o->path, inputs[k]);
                return 2;
            }
    }
    return 0;
}

/* mkdir -p of the folder part of path. 0 or errno, with the failing folder in bad. */
static int make_parents(const char *path, char *bad, size_t cap)
{
    char dir[CLI_OUTPUT_PATH_MAX];
    const char *slash = strrchr(path, '/');
    if (!slash || slash == path) return 0;
    snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    for (char *p = dir + 1;; p++) {
        if (*p != '/' && *p) continue;
        const char c = *p;
        *p = '\0';
        struct stat sb;
        if (stat(dir, &sb) != 0) {
            if (mkdir(dir, 0777) == 0) {
                if (made_n < MADE_MAX) {
                    snprintf(made_dir[made_n], sizeof made_dir[0], "%s", dir);
                    atomic_signal_fence(memory_order_seq_cst); /* the name stored before the count */
                    made_n++;
                }
            } else if (errno != EEXIST) {
                snprintf(bad, cap, "%s", dir);
                return errno;
            }
        }
        if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
            snprintf(bad, cap, "%s", dir);
            return ENOTDIR;
        }
        if (!c) return 0;
        *p = c;
    }
}

int cli_output_folder(const char *cmd, const char *option, const char *path)
{
    char bad[CLI_OUTPUT_PATH_MAX];
    const int e = make_parents(path, bad, sizeof bad);
    if (e) {
        fprintf(stderr, "atmos %s: %s %s: cannot create the folder %s: %s\n", cmd, option, path, bad, strerror(e));
        return 1;
    }
    const char *slash = strrchr(path, '/');
    char dir[CLI_OUTPUT_PATH_MAX];
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path + (slash == path)) : 1, slash ? path : ".");
    if (access(dir, W_OK) != 0) {
        fprintf(stderr, "atmos %s: %s %s: cannot write in %s: %s\n", cmd, option, path, dir, strerror(errno));
        return 1;
    }
    return 0;
}

/* Whether path exists in a folder with the sticky bit (such as /tmp) and belongs neither to
 * this user nor to the folder's owner: the final rename onto it would fail (EPERM) only after
 * all the work, and after the set's other outputs were renamed. Root may (CAP_FOWNER). */
static int sticky_foreign(const char *path)
{
    struct stat f, d;
    if (lstat(path, &f) != 0 || geteuid() == 0) return 0;
    char dir[CLI_OUTPUT_PATH_MAX];
    const char *slash = strrchr(path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + 1 : 1, slash ? path : ".");
    return stat(dir, &d) == 0 && (d.st_mode & S_ISVTX) && f.st_uid != geteuid() && d.st_uid != geteuid();
}

int cli_outputs_prepare(const char *cmd, cli_outputs *set)
{
    signal_cmd = cmd;
    for (int i = 0; i < set->n; i++) {
        cli_output *o = &set->f[i];
        char bad[CLI_OUTPUT_PATH_MAX];
        int e = make_parents(o->path, bad, sizeof bad);
        struct stat sb;
        const char *why = NULL;
        if (e) {
            fprintf(stderr, "atmos %s: %s %s: cannot create the folder %s: %s\n", cmd, o->option, o->path, bad, strerror(e));
        } else if (lstat(o->path, &sb) == 0 && !S_ISREG(sb.st_mode)) {
            why = S_ISLNK(sb.st_mode) ? "a symbolic link" : S_ISDIR(sb.st_mode) ? "a folder" : "a device or FIFO";
            fprintf(stderr, "atmos %s: %s %s: exists and is %s; refusing to replace it\n", cmd, o->option, o->path, why);
            e = 1;
        } else if (sticky_foreign(o->path)) {
            fprintf(stderr, "atmos %s: %s %s: exists, belongs to another user, and its folder has the sticky bit (as "
                            "/tmp has): it cannot be replaced; choose another name\n", cmd, o->option, o->path);
            e = 1;
        } else {
            snprintf(o->stage, sizeof o->stage, "%s.tmp%ld", o->path, (long)getpid());
            register_stage(i, o->stage);
            errno = 0;
            FILE *f = fopen(o->stage, "wb");
            if (!f || fclose(f) != 0) {
                e = errno ? errno : EIO;
                fprintf(stderr, "atmos %s: %s %s: cannot write there: %s\n", cmd, o->option, o->path, strerror(e));
            }
        }
        if (e) {
            cli_outputs_discard(set);
            return 1;
        }
    }
    return 0;
}

int cli_raw_outputs(const char *cmd, const char *out, const char *const *fields, int n,
                    char (*raw)[CLI_OUTPUT_PATH_MAX], cli_outputs *set)
{
    const int stem = (int)strlen(out) - 5; /* without .json */
    cli_outputs_add(set, "-o", out);
    for (int f = 0; f < n && f + 1 < CLI_OUTPUTS_MAX; f++) {
        const int k = snprintf(raw[f], CLI_OUTPUT_PATH_MAX, "%.*s.%s.raw", stem, out, fields[f]);
        if (k < 0 || k >= CLI_OUTPUT_PATH_MAX) return fprintf(stderr, "atmos %s: -o %s: the path is too long\n", cmd, out), 2;
        cli_outputs_add(set, "-o", raw[f]);
    }
    int rc = cli_outputs_check(cmd, set, NULL, 0);
    if (rc == 0 && (rc = cli_outputs_prepare(cmd, set)) == 0)
        cli_outputs_also_remove(set, ".staged"); /* atmos_volume_write_raw's names until all are written */
    return rc;
}

int cli_outputs_probe(const char *cmd, cli_outputs *set)
{
    const int made0 = made_n;
    const int rc = cli_outputs_prepare(cmd, set);
    cli_outputs_discard(set);
    made_n = made0; /* the folders it made are gone again (they were left empty) */
    return rc;
}

/* 0 when every staging file of set is written (not empty); else 1, the message printed and
 * the staging files removed. */
static int all_written(const char *cmd, cli_outputs *set)
{
    for (int i = 0; i < set->n; i++) {
        struct stat sb;
        if (stat(set->f[i].stage, &sb) != 0 || sb.st_size == 0) {
            fprintf(stderr, "atmos %s: %s %s was not written\n", cmd, set->f[i].option, set->f[i].path);
            cli_outputs_discard(set);
            return 1;
        }
    }
    return 0;
}

int cli_outputs_hold_reserve(int frames, int per_frame)
{
    const int n = frames * per_frame;
    cli_outputs_held_discard();
    held = n > 0 ? calloc((size_t)n, sizeof *held) : NULL;
    held_cap = held ? n : 0;
    frames_held = 0;
    animation = frames > 1;
    return n > 0 && !held;
}

int cli_outputs_hold(const char *cmd, cli_outputs *set)
{
    if (all_written(cmd, set)) return 1;
    for (int i = 0; i < set->n; i++) {
        cli_output *o = &set->f[i];
        held_file h = {strdup(o->stage), strdup(o->path), o->option};
        if (held_n >= held_cap || !h.stage || !h.path) {
            fprintf(stderr, "atmos %s: %s %s: out of memory to hold the frame's files\n", cmd, o->option, o->path);
            free(h.stage), free(h.path);
            cli_outputs_discard(set);
            return 1;
        }
        held[held_n] = h;
        atomic_signal_fence(memory_order_seq_cst); /* the names stored before the count */
        held_n++; /* counted once its names are in place (the signal handler reads them) */
        unregister_stage(i);
        o->stage[0] = '\0';
    }
    frames_held++;
    return 0;
}

/* The end of a commit: signals act again, one that came during it (to another thread) now. */
static void commit_end(const sigset_t *old)
{
    atomic_signal_fence(memory_order_seq_cst);
    committing = 0;
    atomic_signal_fence(memory_order_seq_cst);
    pthread_sigmask(SIG_SETMASK, old, NULL); /* this thread's mask (the process has others) */
    if (deferred) raise(deferred);
}

/* The start of a commit: the ending signals blocked in this thread, other threads' handlers
 * defer theirs to commit_end. */
static void commit_begin(sigset_t *old)
{
    sigset_t block;
    sigemptyset(&block);
    for (size_t k = 0; k < sizeof ENDING / sizeof ENDING[0]; k++) sigaddset(&block, ENDING[k]);
    pthread_sigmask(SIG_BLOCK, &block, old);
    committing = 1;
    atomic_signal_fence(memory_order_seq_cst);
}

void cli_outputs_defer_signals(int on)
{
    static sigset_t old;
    static int depth; /* nested calls: the outermost pair blocks and unblocks */
    if (on && depth++ == 0) commit_begin(&old);
    else if (!on && depth > 0 && --depth == 0) commit_end(&old);
}

/* The held files renamed into place with the ending signals blocked, so that a signal cannot
 * remove the frames not yet renamed once the first is (it is taken after the loop, when every
 * frame is in place). A rename that fails part way leaves the frames before it new: said. */
int cli_outputs_held_commit(const char *cmd)
{
    sigset_t old;
    commit_begin(&old);
    for (int i = 0; i < held_n; i++)
        if (rename(held[i].stage, held[i].path) != 0) {
            fprintf(stderr, "atmos %s: %s: cannot rename %s into place: %s (%d of %d files renamed before it)\n",
                    cmd, held[i].path, held[i].stage, strerror(errno), i, held_n);
            cli_outputs_held_discard();
            commit_end(&old);
            return 1;
        }
    const int n = held_n;
    held_n = 0;
    animation = 0; /* the frames are in place: a signal now interrupts nothing of theirs */
    commit_end(&old);
    for (int i = 0; i < n; i++) free(held[i].stage), free(held[i].path);
    free(held), held = NULL, held_cap = 0;
    return 0;
}

void cli_outputs_held_discard(void)
{
    const int n = held_n;
    for (int i = 0; i < n; i++) unlink(held[i].stage); /* those renamed already are gone */
    held_n = 0;
    atomic_signal_fence(memory_order_seq_cst); /* the handler reads none of them once freed */
    for (int i = 0; i < n; i++) free(held[i].stage), free(held[i].path);
    free(held), held = NULL, held_cap = 0;
    remove_made_dirs();
}

int cli_outputs_commit(const char *cmd, cli_outputs *set)
{
    if (all_written(cmd, set)) return 1;
    for (int i = 0; i < set->n; i++) {
        cli_output *o = &set->f[i];
        if (rename(o->stage, o->path) != 0) {
            fprintf(stderr, "atmos %s: %s: cannot rename %s into place: %s\n", cmd, o->path, o->stage, strerror(errno));
            cli_outputs_discard(set);
            return 1;
        }
        unregister_stage(i);
        o->stage[0] = '\0';
    }
    return 0;
}

void cli_outputs_discard(cli_outputs *set)
{
    for (int i = 0; i < set->n; i++) {
        cli_output *o = &set->f[i];
        if (!o->stage[0]) continue;
        unlink(o->stage);
        unlink(slot_name[2 * i + 1]);
        unregister_stage(i);
        o->stage[0] = '\0';
    }
    remove_made_dirs();
}

void cli_outputs_final_names(const char *msg, char *out, size_t cap)
{
    char suffix[32];
    const int n = snprintf(suffix, sizeof suffix, ".tmp%ld", (long)getpid());
    size_t len = 0;
    if (!cap) return;
    for (const char *p = msg; *p && len + 1 < cap;) {
        const char *q = strstr(p, suffix);
        const size_t k = q ? (size_t)(q - p) : strlen(p);
        const size_t take = k < cap - 1 - len ? k : cap - 1 - len;
        memcpy(out + len, p, take);
        len += take;
        if (!q) break;
        p = q + n;
    }
    out[len] = '\0';
}
