/* The parser fence (src/volume/reader_fence.c): a load that crashes, runs away with memory
 * or fails in the child process becomes an error naming the file in the parent; a load that
 * succeeds comes back voxel for voxel, with the child's log messages. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, kill */
#include "atmos/atmos.h"
#include "test.h"
#include "core/internal.h"
#include "volume/reader_fence.h"

#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static atmos_context *ctx;

static atmos_status load_abort(atmos_context *c, const char *path, const atmos_volume_load_desc *d, atmos_volume **out)
{
    (void)c, (void)path, (void)d, (void)out;
    raise(SIGSEGV);
    abort();
}

/* Grows the address space without bound, as a damaged length field can make a parser do. */
static atmos_status load_runaway(atmos_context *c, const char *path, const atmos_volume_load_desc *d,
                                 atmos_volume **out)
{
    (void)d, (void)out;
    for (;;) {
        volatile char *p = malloc((size_t)64 << 20);
        if (!p) return atmos__error(c, ATMOS_E_NOMEM, "%s: out of memory", path);
        p[0] = 1;
    }
}

static atmos_status load_error(atmos_context *c, const char *path, const atmos_volume_load_desc *d, atmos_volume **out)
{
    (void)d;
    return atmos_volume_load(c, path, NULL, out); /* a missing file: the reader's own error */
}

/* A 20 x 9 x 17 volume with two fields (odd sizes: edge bricks are partial), a warning logged. */
static atmos_status load_ok(atmos_context *c, const char *path, const atmos_volume_load_desc *d, atmos_volume **out)
{
    (void)path, (void)d;
    atmos_volume_desc vd = {.dims = {20, 9, 17}, .voxel_size_m = 2.5, .origin_m = {1, 2, 3}};
    atmos_status st = atmos_volume_create(c, &vd, out);
    int f0, f1;
    if (st == ATMOS_OK) st = atmos_volume_add_field(c, *out, "cloud", "cloud", &f0);
    if (st == ATMOS_OK) st = atmos_volume_add_field(c, *out, "rain", "rain", &f1);
    for (int k = 0; k < 17 && st == ATMOS_OK; k++)
        for (int j = 0; j < 9 && st == ATMOS_OK; j++)
            for (int i = 0; i < 20 && st == ATMOS_OK; i++) {
                if ((i + j + k) % 3 == 0) st = atmos_volume_set(c, *out, f0, i, j, k, 0.5f + i + 100.0f * j + k / 7.0f);
                if (st == ATMOS_OK && i == 19 && k == 16) st = atmos_volume_set(c, *out, f1, i, j, k, 3.0f + j);
            }
    if (st == ATMOS_OK) st = atmos_volume_finalize(c, *out);
    return st;
}

static int warned, restarted;
static void on_log(void *user, atmos_log_level level, const char *msg)
{
    (void)user;
    if (level == ATMOS_LOG_WARN && strstr(msg, "from the child")) warned++;
    if (level == ATMOS_LOG_WARN && strstr(msg, "stopped making progress")) restarted++;
}

static atmos_status load_ok_warn(atmos_context *c, const char *path, const atmos_volume_load_desc *d,
                                 atmos_volume **out)
{
    atmos__log(c, ATMOS_LOG_WARN, "a warning from the child");
    return load_ok(c, path, d, out);
}

/* Sleeps forever in the child (as a child stuck on a lock held at the fork does) unless the
 * marker file `path` exists; creates it first, so a second child loads normally. */
static atmos_status load_stuck_once(atmos_context *c, const char *path, const atmos_volume_load_desc *d,
                                    atmos_volume **out)
{
    FILE *f = fopen(path, "r");
    if (f) {
        fclose(f);
        return load_ok(c, path, d, out);
    }
    f = fopen(path, "w");
    if (f) fclose(f);
    for (;;) pause();
    return ATMOS_E_IO; /* not reached */
}

static atmos_status load_stuck(atmos_context *c, const char *path, const atmos_volume_load_desc *d, atmos_volume **out)
{
    (void)c, (void)path, (void)d, (void)out;
    for (;;) pause();
    return ATMOS_E_IO; /* not reached */
}

/* Works for 4.5 s of CPU time without a word: busy, not stuck. */
static atmos_status load_busy(atmos_context *c, const char *path, const atmos_volume_load_desc *d, atmos_volume **out)
{
    clock_t t0 = clock();
    volatile double x = 0;
    while ((double)(clock() - t0) / CLOCKS_PER_SEC < 4.5) x += 1e-9;
    return load_ok(c, path, d, out);
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(void)
{
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.log = on_log;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    atmos_volume *v = NULL;

    /* A crash in the child: an error naming the file and the library. */
    atmos_status st = atmos__reader_fenced(ctx, "crash.vdb", NULL, "TestLib", load_abort, &v);
    CHECK(st == ATMOS_E_FORMAT && v == NULL);
    CHECK_MSG(strstr(atmos_context_error(ctx), "crash.vdb") && strstr(atmos_context_error(ctx), "TestLib library crashed"),
              "%s", atmos_context_error(ctx));

    /* A memory runaway stops at the address-space limit (2 x max_memory + some). */
    atmos_volume_load_desc small = {.max_memory = 16u << 20};
    double t0 = now_s();
    st = atmos__reader_fenced(ctx, "runaway.vdb", &small, "TestLib", load_runaway, &v);
    CHECK_MSG(st == ATMOS_E_LIMIT || st == ATMOS_E_FORMAT, "status %s", atmos_status_string(st));
    CHECK_MSG(strstr(atmos_context_error(ctx), "runaway.vdb"), "%s", atmos_context_error(ctx));
    CHECK_MSG(now_s() - t0 < 30, "runaway took %.1f s", now_s() - t0);
    printf("runaway: %s (%.2f s)\n", atmos_context_error(ctx), now_s() - t0);

    /* The child's own error comes back unchanged. */
    st = atmos__reader_fenced(ctx, "/nonexistent/x.vdb", NULL, "TestLib", load_error, &v);
    CHECK(st == ATMOS_E_IO && v == NULL);
    CHECK_MSG(strstr(atmos_context_error(ctx), "/nonexistent/x.vdb: cannot open"), "%s", atmos_context_error(ctx));

    /* A volume comes back voxel for voxel, with the child's warning. */
    atmos_volume *ref = NULL;
    CHECK_OK(load_ok(ctx, "direct", NULL, &ref));
    CHECK_OK(atmos__reader_fenced(ctx, "ok.vdb", NULL, "TestLib", load_ok_warn, &v));
    CHECK(warned == 1);
    if (v && ref) {
        CHECK(memcmp(atmos_volume_get_desc(v)->dims, atmos_volume_get_desc(ref)->dims, sizeof(int[3])) == 0);
        CHECK(atmos_volume_field_count(v) == 2);
        CHECK(strcmp(atmos_volume_field_name(v, 1), "rain") == 0);
        long diff = 0;
        for (int f = 0; f < 2; f++)
            for (int k = 0; k < 17; k++)
                for (int j = 0; j < 9; j++)
                    for (int i = 0; i < 20; i++) {
                        double w[3] = {1 + 2.5 * (i + 0.5), 2 + 2.5 * (j + 0.5), 3 + 2.5 * (k + 0.5)};
                        diff += atmos_volume_sample(v, f, w) != atmos_volume_sample(ref, f, w);
                    }
        CHECK_MSG(diff == 0, "%ld voxels differ", diff);
        atmos_volume_field_stats a, b;
        CHECK_OK(atmos_volume_field_stats_get(ctx, v, 0, &a));
        CHECK_OK(atmos_volume_field_stats_get(ctx, ref, 0, &b));
        CHECK(a.active_voxels == b.active_voxels && a.max == b.max);
    }
    atmos_volume_destroy(v);
    v = NULL;

    /* A child stuck asleep (a lock held at the fork) is started again; a busy one is not. */
    char marker[1024];
    const char *tmp = getenv("ATMOS_TEST_TMP");
    snprintf(marker, sizeof marker, "%s/stuck-once.marker", tmp && *tmp ? tmp : ".");
    remove(marker);
    t0 = now_s();
    st = atmos__reader_fenced(ctx, marker, NULL, "TestLib", load_stuck_once, &v);
    CHECK_MSG(st == ATMOS_OK && v, "%s", atmos_context_error(ctx));
    CHECK_MSG(restarted == 1, "%d restarts", restarted);
    CHECK_MSG(now_s() - t0 < 30, "stuck once took %.1f s", now_s() - t0);
    if (v) CHECK(atmos_volume_field_count(v) == 2);
    atmos_volume_destroy(v);
    v = NULL;
    remove(marker);
    restarted = 0;
    st = atmos__reader_fenced(ctx, "busy.vdb", NULL, "TestLib", load_busy, &v);
    CHECK_MSG(st == ATMOS_OK && v && restarted == 0, "%s, %d restarts", atmos_context_error(ctx), restarted);
    atmos_volume_destroy(v);
    v = NULL;
    t0 = now_s();
    st = atmos__reader_fenced(ctx, "stuck.vdb", NULL, "TestLib", load_stuck, &v);
    CHECK_MSG(st == ATMOS_E_LIMIT && !v && strstr(atmos_context_error(ctx), "stuck.vdb") &&
                  strstr(atmos_context_error(ctx), "stopped making progress"),
              "%s", atmos_context_error(ctx));
    CHECK_MSG(restarted == 2 && now_s() - t0 < 40, "%d restarts, %.1f s", restarted, now_s() - t0);
    printf("stuck: %s (%.1f s)\n", atmos_context_error(ctx), now_s() - t0);
    atmos_volume_destroy(ref);
    atmos_context_destroy(ctx);
    return test_summary("test_reader_fence");
}
