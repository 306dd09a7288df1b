/* The parser fence (see reader_fence.h): fork, limit, load in the child, send back.
 *
 * Pipe records (native byte order: parent and child are the same program):
 *   'L' int32 level, uint32 n, n bytes     a log message of the child
 *   'P' int32 fraction x 1e6, uint32 n, n bytes   a progress report of the child (its stage)
 *   'E' int32 status, uint32 n, n bytes    the load failed with this error
 *   'V' atmos_volume_desc, int32 nfields   the volume, followed by nfields x
 *   'F' name[64], particle[64], uint64 file_active, uint32 bricks, bricks x (uint64 position, 512 floats)
 *   'D'                                    the end: the volume is complete
 * The child leaves with _exit (no atexit handlers, no stdio buffers flushed twice).
 */
#define _POSIX_C_SOURCE 200809L /* fork, pipe, poll, kill, strsignal, sysconf */
#include "volume/reader_fence.h"

#include "core/internal.h"
#include "volume/volume_grid.h"
#include "volume/volume_internal.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

typedef struct {
    uint64_t mem;     /* address space the child may add, bytes */
    unsigned cpu_s;   /* CPU seconds */
    unsigned wall_s;  /* wall seconds before the parent gives up */
} fence_limits;

static void limits_for(const char *path, const atmos_volume_load_desc *desc, fence_limits *l)
{
    const uint64_t mm = desc && desc->max_memory ? desc->max_memory : ATMOS_VOLUME_DEFAULT_MAX_MEMORY;
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    if (ncpu < 1) ncpu = 1;
    l->mem = 2 * mm + ((uint64_t)256 << 20) + (uint64_t)ncpu * ((uint64_t)16 << 20);
    struct stat sb;
    uint64_t size = stat(path, &sb) == 0 && sb.st_size > 0 ? (uint64_t)sb.st_size : 0;
    l->cpu_s = 60u + (unsigned)(size / 20000000u);
    l->wall_s = 4 * l->cpu_s;
}

/* ------------------------------------------------------------ child */

static int write_all(int fd, const void *buf, size_t n)
{
    const char *p = buf;
    while (n) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return -1;
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

static int send_text(int fd, char type, int32_t code, const char *msg)
{
    uint32_t n = (uint32_t)strlen(msg);
    return write_all(fd, &type, 1) || write_all(fd, &code, 4) || write_all(fd, &n, 4) || write_all(fd, msg, n);
}

static void forward_log(void *user, atmos_log_level level, const char *msg)
{
    /* errors travel in the 'E' record; the parent logs them when it reports them */
    if (level != ATMOS_LOG_ERROR) send_text(*(const int *)user, 'L', (int32_t)level, msg);
}

/* The child's progress goes to the parent, which reports it as the first 90 % of the load. */
static int forward_progress(void *user, const char *stage, double fraction)
{
    double f = fraction < 0 ? 0 : fraction > 1 ? 1 : fraction;
    send_text(*(const int *)user, 'P', (int32_t)(f * 1e6), stage ? stage : "volume load");
    return 0;
}

static int send_volume(int fd, const atmos_volume *v)
{
    const char type_v = 'V', type_f = 'F', type_d = 'D';
    int32_t nf = v->nfields;
    if (write_all(fd, &type_v, 1) || write_all(fd, &v->desc, sizeof v->desc) || write_all(fd, &nf, 4)) return -1;
    for (int f = 0; f < v->nfields; f++) {
        const vol_field *fl = &v->field[f];
        if (write_all(fd, &type_f, 1) || write_all(fd, fl->name, VOL_NAME_MAX) ||
            write_all(fd, fl->particle, VOL_NAME_MAX) || write_all(fd, &fl->file_active, 8) ||
            write_all(fd, &fl->count, 4))
            return -1;
        for (uint64_t b = 0; b < v->nbricks; b++) {
            if (!fl->table[b]) continue;
            if (write_all(fd, &b, 8) || write_all(fd, vol_brick_data(v, fl->table[b]), VOL_BRICK_BYTES)) return -1;
        }
    }
    return write_all(fd, &type_d, 1);
}

/* The address space mapped now (VmSize), from /proc; 0 if unknown. */
static uint64_t mapped_now(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f) return 0;
    unsigned long long pages = 0;
    if (fscanf(f, "%llu", &pages) != 1) pages = 0;
    fclose(f);
    long ps = sysconf(_SC_PAGESIZE);
    return pages * (uint64_t)(ps > 0 ? ps : 4096);
}

static void child_limits(const fence_limits *l)
{
#if defined(__GLIBC__) && defined(M_ARENA_MAX)
    mallopt(M_ARENA_MAX, 2); /* each thread arena would reserve 64 MiB of address space */
#endif
    uint64_t now = mapped_now();
    if (now) {
        struct rlimit r = {(rlim_t)(now + l->mem), (rlim_t)(now + l->mem)};
        setrlimit(RLIMIT_AS, &r);
    }
    struct rlimit c = {(rlim_t)l->cpu_s, (rlim_t)l->cpu_s + 5};
    setrlimit(RLIMIT_CPU, &c);
}

static void child_main(int fd, atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                       atmos__reader_fn load, const fence_limits *l)
{
    signal(SIGPIPE, SIG_IGN);
    static int out_fd;
    out_fd = fd;
    atmos__context_redirect_log(ctx, forward_log, &out_fd);
    atmos__context_redirect_progress(ctx, forward_progress, &out_fd);
    child_limits(l);
    atmos_volume *vol = NULL;
    atmos_status st = load(ctx, path, desc, &vol);
    int rc;
    if (st != ATMOS_OK) rc = send_text(fd, 'E', (int32_t)st, atmos_context_error(ctx));
    else rc = send_volume(fd, vol);
    _exit(rc ? 3 : 0);
}

/* ------------------------------------------------------------ parent */

/* A child asleep with no CPU time spent and nothing sent for this long is stuck: a lock that
 * another thread of the parent held at the fork (an allocator's, a library's) stays locked in
 * the child forever. It is killed and started again, up to FENCE_ATTEMPTS times in all. */
#define FENCE_STALL_S 3.0
#define FENCE_ATTEMPTS 3

typedef struct {
    int fd;
    pid_t pid;
    double deadline;      /* CLOCK_MONOTONIC seconds */
    double progress_at;   /* when the child last sent bytes or spent CPU time */
    long long cpu_ticks;  /* its CPU time then, clock ticks; -1 unknown */
    int timed_out, stalled;
} in_pipe;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The child's CPU time (user + system, clock ticks) if it is asleep ('S'), -1 if it is
 * running, in the kernel's disk wait, gone, or /proc cannot tell. */
static long long asleep_cpu_ticks(pid_t pid)
{
    char name[64], line[1024];
    snprintf(name, sizeof name, "/proc/%ld/stat", (long)pid);
    FILE *f = fopen(name, "r");
    if (!f) return -1;
    size_t n = fread(line, 1, sizeof line - 1, f);
    fclose(f);
    line[n] = '\0';
    const char *c = strrchr(line, ')'); /* the command name may hold spaces and parentheses */
    char state;
    unsigned long long utime, stime;
    if (!c || sscanf(c + 1, " %c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &state, &utime, &stime) != 3)
        return -1;
    return state == 'S' ? (long long)(utime + stime) : -1;
}

/* Called while no bytes arrive: has the child been asleep, spending no CPU time, for
 * FENCE_STALL_S seconds? */
static int child_stalled(in_pipe *p)
{
    const long long ticks = asleep_cpu_ticks(p->pid);
    const double t = now_s();
    if (ticks < 0 || ticks != p->cpu_ticks) {
        p->cpu_ticks = ticks;
        p->progress_at = t;
        return 0;
    }
    return t - p->progress_at >= FENCE_STALL_S;
}

/* Reads n bytes; -1 on end of pipe, error, deadline or a stalled child. */
static int read_all(in_pipe *p, void *buf, size_t n)
{
    char *q = buf;
    while (n) {
        double left = p->deadline - now_s();
        if (left <= 0) {
            p->timed_out = 1;
            return -1;
        }
        struct pollfd pfd = {p->fd, POLLIN, 0};
        int pr = poll(&pfd, 1, left > 0.5 ? 500 : (int)(left * 1000) + 1);
        if (pr < 0 && errno == EINTR) continue;
        if (pr < 0) return -1;
        if (pr == 0) {
            if (child_stalled(p)) {
                p->stalled = 1;
                return -1;
            }
            continue;
        }
        ssize_t r = read(p->fd, q, n);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return -1;
        q += r;
        n -= (size_t)r;
        p->progress_at = now_s();
    }
    return 0;
}

/* One brick of the child's volume into ours: the part of brick position b inside the grid. */
static atmos_status put_brick(atmos_context *ctx, atmos_volume *vol, int field, uint64_t b, const float *data)
{
    const int *d = vol->desc.dims;
    const uint64_t bi = b % (uint64_t)vol->nb[0], bj = b / (uint64_t)vol->nb[0] % (uint64_t)vol->nb[1],
                   bk = b / ((uint64_t)vol->nb[0] * (uint64_t)vol->nb[1]);
    int off[3] = {(int)bi * VOL_BRICK, (int)bj * VOL_BRICK, (int)bk * VOL_BRICK}, n[3];
    for (int a = 0; a < 3; a++) n[a] = d[a] - off[a] < VOL_BRICK ? d[a] - off[a] : VOL_BRICK;
    float buf[VOL_BRICK_VOXELS];
    for (int k = 0; k < n[2]; k++)
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++) buf[(k * n[1] + j) * n[0] + i] = data[(k * VOL_BRICK + j) * VOL_BRICK + i];
    return atmos_volume_set_dense(ctx, vol, field, off, n, buf, 1.0f);
}

static atmos_status receive_field(atmos_context *ctx, in_pipe *p, atmos_volume *vol)
{
    char type, name[VOL_NAME_MAX], particle[VOL_NAME_MAX];
    uint64_t file_active;
    uint32_t count;
    if (read_all(p, &type, 1) || type != 'F' || read_all(p, name, sizeof name) ||
        read_all(p, particle, sizeof particle) || read_all(p, &file_active, 8) || read_all(p, &count, 4))
        return ATMOS_E_IO;
    name[VOL_NAME_MAX - 1] = particle[VOL_NAME_MAX - 1] = '\0';
    int field;
    atmos_status st = atmos_volume_add_field(ctx, vol, name, particle, &field);
    if (st != ATMOS_OK) return st;
    atmos__volume_set_file_active(vol, field, file_active);
    static _Thread_local float data[VOL_BRICK_VOXELS];
    for (uint32_t i = 0; i < count; i++) {
        uint64_t b;
        if (read_all(p, &b, 8) || read_all(p, data, VOL_BRICK_BYTES)) return ATMOS_E_IO;
        if (b >= vol->nbricks) return ATMOS_E_IO;
        if ((st = put_brick(ctx, vol, field, b, data)) != ATMOS_OK) return st;
    }
    return ATMOS_OK;
}

/* Reads the child's records until its error or its volume. ATMOS_E_IO without a message:
 * the pipe ended early (the child died or hung; the caller finds out which). */
static atmos_status receive(atmos_context *ctx, in_pipe *p, atmos_volume **out, int *reported)
{
    for (;;) {
        char type;
        if (read_all(p, &type, 1)) return ATMOS_E_IO;
        if (type == 'L' || type == 'E' || type == 'P') {
            int32_t code;
            uint32_t n;
            if (read_all(p, &code, 4) || read_all(p, &n, 4) || n > (1u << 20)) return ATMOS_E_IO;
            char *msg = malloc((size_t)n + 1);
            if (!msg) return atmos__error(ctx, ATMOS_E_NOMEM, "volume reader: out of memory");
            int bad = read_all(p, msg, n);
            msg[bad ? 0 : n] = '\0';
            if (!bad && type == 'L') atmos__log(ctx, (atmos_log_level)code, "%s", msg);
            if (!bad && type == 'P') atmos__progress(ctx, msg, 0.9e-6 * code);
            if (!bad && type == 'E') {
                *reported = 1;
                atmos__error(ctx, (atmos_status)code, "%s", msg);
            }
            free(msg);
            if (bad) return ATMOS_E_IO;
            if (type == 'E') return (atmos_status)code;
            continue;
        }
        if (type != 'V') return ATMOS_E_IO;
        atmos_volume_desc vd;
        int32_t nf;
        if (read_all(p, &vd, sizeof vd) || read_all(p, &nf, 4) || nf < 0 || nf > ATMOS_VOLUME_MAX_FIELDS)
            return ATMOS_E_IO;
        atmos_status st = atmos_volume_create(ctx, &vd, out);
        for (int f = 0; f < nf && st == ATMOS_OK; f++) st = receive_field(ctx, p, *out);
        if (st == ATMOS_OK && (read_all(p, &type, 1) || type != 'D')) st = ATMOS_E_IO;
        if (st == ATMOS_OK) st = atmos_volume_finalize(ctx, *out);
        if (st == ATMOS_OK) atmos__progress(ctx, "volume load", 1.0);
        if (st != ATMOS_E_IO) *reported = st != ATMOS_OK;
        return st;
    }
}

/* The error for a child that ended without reporting (crash, limit, hang). */
static atmos_status child_failure(atmos_context *ctx, const char *path, const char *library, int wstatus,
                                  const in_pipe *p, const fence_limits *l)
{
    if (p->stalled)
        return atmos__error(ctx, ATMOS_E_LIMIT, "%s: the %s library stopped making progress reading the file (asleep, "
                            "no CPU time for %.0f s) in %d attempts; stopped", path, library, FENCE_STALL_S,
                            FENCE_ATTEMPTS);
    if (p->timed_out)
        return atmos__error(ctx, ATMOS_E_LIMIT, "%s: the %s library did not finish reading the file in %u s; stopped",
                            path, library, l->wall_s);
    if (WIFSIGNALED(wstatus)) {
        int sig = WTERMSIG(wstatus);
        if (sig == SIGXCPU)
            return atmos__error(ctx, ATMOS_E_LIMIT, "%s: the %s library used more than %u s of CPU time reading the "
                                "file; stopped (a damaged file?)", path, library, l->cpu_s);
        return atmos__error(ctx, ATMOS_E_FORMAT,
                            "%s: the %s library crashed reading the file (signal %d, %s): the file is damaged or "
                            "not what it claims to be",
                            path, library, sig, strsignal(sig));
    }
    return atmos__error(ctx, ATMOS_E_FORMAT, "%s: the %s library stopped reading the file without a result (exit "
                        "status %d): the file is damaged", path, library, WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1);
}

/* One child: fork, load there, receive here. *p tells how it ended. */
static atmos_status fence_attempt(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                  atmos__reader_fn load, const fence_limits *l, in_pipe *p, int *ws, int *reported,
                                  atmos_volume **out)
{
    *p = (in_pipe){-1, -1, 0, 0, -1, 0, 0};
    int fds[2];
    if (pipe(fds) != 0)
        return atmos__error(ctx, ATMOS_E_IO, "%s: cannot create a pipe for the reader: %s", path, strerror(errno));
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: cannot start the reader process: %s", path, strerror(errno));
    }
    if (pid == 0) {
        close(fds[0]);
        child_main(fds[1], ctx, path, desc, load, l);
    }
    close(fds[1]);
    const double t = now_s();
    *p = (in_pipe){fds[0], pid, t + l->wall_s, t, -1, 0, 0};
    atmos_status st = receive(ctx, p, out, reported);
    close(fds[0]);
    if (p->timed_out || p->stalled) kill(pid, SIGKILL);
    while (waitpid(pid, ws, 0) < 0 && errno == EINTR) {
    }
    return st;
}

atmos_status atmos__reader_fenced(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                  const char *library, atmos__reader_fn load, atmos_volume **out)
{
    *out = NULL;
    fence_limits l;
    limits_for(path, desc, &l);
    in_pipe p;
    int ws = 0, reported = 0;
    atmos_status st = ATMOS_E_IO;
    for (int attempt = 1; attempt <= FENCE_ATTEMPTS; attempt++) {
        atmos_volume_destroy(*out);
        *out = NULL;
        ws = reported = 0;
        st = fence_attempt(ctx, path, desc, load, &l, &p, &ws, &reported, out);
        if (!p.stalled || attempt == FENCE_ATTEMPTS) break;
        atmos__log(ctx, ATMOS_LOG_WARN, "%s: the %s reader process stopped making progress (asleep, no CPU time "
                   "for %.0f s); starting it again (attempt %d of %d)", path, library, FENCE_STALL_S, attempt + 1,
                   FENCE_ATTEMPTS);
    }
    if (st != ATMOS_OK) {
        atmos_volume_destroy(*out);
        *out = NULL;
        if (!reported) return child_failure(ctx, path, library, ws, &p, &l);
        if (st == ATMOS_E_NOMEM) {
            char msg[768];
            snprintf(msg, sizeof msg, "%s", atmos_context_error(ctx));
            return atmos__error(ctx, ATMOS_E_LIMIT,
                                "%s (reading a file may use %.0f MB of address space: twice max_memory and some; "
                                "raise max_memory / --max-memory for a larger file)",
                                msg, (double)l.mem / 1e6);
        }
    }
    return st;
}
