/* Minimal test harness: CHECK-style macros that count and report failures.
 * Each test program ends with `return test_summary("name");`, which prints
 * "name: N passed, N failed" and returns nonzero on any failure. */
#ifndef ATMOS_TEST_H
#define ATMOS_TEST_H

#include "atmos/atmos.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int test_passed_, test_failed_;

#define CHECK(cond)                                                                   \
    do {                                                                              \
        if (cond) test_passed_++;                                                     \
        else { test_failed_++; fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); } \
    } while (0)

#define CHECK_MSG(cond, ...)                                                          \
    do {                                                                              \
        if (cond) test_passed_++;                                                     \
        else { test_failed_++; fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
               fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); }                   \
    } while (0)

/* |a-b| <= tol */
#define CHECK_NEAR(a, b, tol)                                                         \
    do {                                                                              \
        double a_ = (a), b_ = (b), t_ = (tol);                                        \
        if (fabs(a_ - b_) <= t_) test_passed_++;                                      \
        else { test_failed_++; fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.10g, %s = %.10g, tol %.3g\n", \
                                       __FILE__, __LINE__, #a, a_, #b, b_, t_); }     \
    } while (0)

/* relative error |a-b|/|b| <= rel (absolute when b == 0) */
#define CHECK_REL(a, b, rel)                                                          \
    do {                                                                              \
        double a_ = (a), b_ = (b), r_ = (rel);                                        \
        double e_ = b_ != 0 ? fabs(a_ - b_) / fabs(b_) : fabs(a_);                    \
        if (e_ <= r_) test_passed_++;                                                 \
        else { test_failed_++; fprintf(stderr, "%s:%d: CHECK_REL failed: %s = %.10g, %s = %.10g, rel err %.3g > %.3g\n", \
                                       __FILE__, __LINE__, #a, a_, #b, b_, e_, r_); } \
    } while (0)

#define CHECK_OK(expr)                                                                \
    do {                                                                              \
        atmos_status s_ = (expr);                                                     \
        if (s_ == ATMOS_OK) test_passed_++;                                           \
        else { test_failed_++; fprintf(stderr, "%s:%d: %s returned %s\n", __FILE__, __LINE__, #expr, \
                                       atmos_status_string(s_)); }                    \
    } while (0)

static inline int test_summary(const char *name)
{
    printf("%s: %d passed, %d failed\n", name, test_passed_, test_failed_);
    return test_failed_ ? 1 : 0;
}

/* A context for a test: `threads` threads, no log, its tables cached in `cache_dir` (the test's
 * scratch cache; NULL: the user's); exits on failure. */
static inline atmos_context *test_context(int threads, const char *cache_dir)
{
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = threads;
    d.cache_dir = cache_dir;
    d.log = NULL;
    atmos_context *ctx = NULL;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) exit(1);
    return ctx;
}

/* Scratch path for a test's output files: $ATMOS_TEST_TMP/name (or /tmp). */
static inline void test_tmp_path(char *buf, size_t cap, const char *name)
{
    const char *dir = getenv("ATMOS_TEST_TMP");
    snprintf(buf, cap, "%s/%s", dir && *dir ? dir : "/tmp", name);
}

/* The whole file at path in a malloc'ed buffer (*n bytes), or NULL. */
static inline unsigned char *test_slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    *n = 0;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long sz = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc(sz > 0 ? (size_t)sz : 1);
    *n = buf && sz > 0 ? fread(buf, 1, (size_t)sz, f) : 0;
    fclose(f);
    return buf;
}

#endif
