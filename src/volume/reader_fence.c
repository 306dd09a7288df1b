/* The parser fence (see reader_fence.h): fork, limit, load in the child, send back.
 *
 * Pipe records (native byte order: parent and child are the same program):
 *   'L' int32 level, uint32 n, n bytes     a log message of the child
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
    child_limits(l);
    atmos_volume *vol = NULL;
    atmos_status st = load(ctx, path, desc, &vol);
    int rc;
    if (st != ATMOS_OK) rc = send_text(fd, 'E', (int32_t)st, atmos_context_error(ctx));
    else rc = send_volume(fd, vol);
    _exit(rc ? 3 : 0);
}

/* ------------------------------------------------------------ parent */

typedef struct {
    int fd;
    double deadline; /* CLOCK_MONOTONIC seconds */
    int timed_out;
} in_pipe;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Reads n bytes; -1 on end of pipe, error or deadline. */
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
        int pr = poll(&pfd, 1, left > 1e6 ? 1000000000 : (int)(left * 1000) + 1);
        if (pr < 0 && errno == EINTR) continue;
        if (pr < 0) return -1;
        if (pr == 0) continue;
        ssize_t r = read(p->fd, q, n);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return -1;
        q += r;
        n -= (size_t)r;
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
        if (type == 'L' || type == 'E') {
            int32_t code;
            uint32_t n;
            if (read_all(p, &code, 4) || read_all(p, &n, 4) || n > (1u << 20)) return ATMOS_E_IO;
            char *msg = malloc((size_t)n + 1);
            if (!msg) return atmos__error(ctx, ATMOS_E_NOMEM, "volume reader: out of memory");
            int bad = read_all(p, msg, n);
            msg[bad ? 0 : n] = '\0';
            if (!bad && type == 'L') atmos__log(ctx, (atmos_log_level)code, "%s", msg);
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
        if (st != ATMOS_E_IO) *reported = st != ATMOS_OK;
        return st;
    }
}

/* The error for a child that ended without reporting (crash, limit, hang). */
static atmos_status child_failure(atmos_context *ctx, const char *path, const char *library, int wstatus,
                                  const in_pipe *p, const fence_limits *l)
{
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

atmos_status atmos__reader_fenced(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                  const char *library, atmos__reader_fn load, atmos_volume **out)
{
    *out = NULL;
    fence_limits l;
    limits_for(path, desc, &l);
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
        child_main(fds[1], ctx, path, desc, load, &l);
    }
    close(fds[1]);
    in_pipe p = {fds[0], now_s() + l.wall_s, 0};
    int reported = 0;
    atmos_status st = receive(ctx, &p, out, &reported);
    close(fds[0]);
    if (p.timed_out) kill(pid, SIGKILL);
    int ws = 0;
    while (waitpid(pid, &ws, 0) < 0 && errno == EINTR) {
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
