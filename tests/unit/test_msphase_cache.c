/* The multiple-scattering entries of the table cache are value-checked on load: an
 * entry whose bytes are intact (its checksum recomputed) but whose numbers are not a
 * multiple-scattering table is warned about and rebuilt, never used. A FIFO in place of
 * an entry is a miss, not a render that blocks forever. Caches live under
 * $ATMOS_TEST_TMP. */
#define _POSIX_C_SOURCE 200809L /* mkfifo, alarm */
#include "atmos/atmos.h"
#include "atmos/cache.h"
#include "core/cache.h"
#include "test.h"
#include "test_optics.h"

#include <dirent.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int warnings;
static char last_warning[1024];

static void log_fn(void *user, atmos_log_level level, const char *msg)
{
    (void)user;
    if (level == ATMOS_LOG_WARN) {
        warnings++;
        snprintf(last_warning, sizeof last_warning, "%s", msg);
    }
}

static void on_alarm(int sig)
{
    (void)sig;
    static const char msg[] = "FAIL: a cache load blocked (FIFO in place of an entry)\n";
    if (write(2, msg, sizeof msg - 1) < 0) _exit(1);
    _exit(1);
}

/* The msphase entry: the cache file whose payload starts with nwl = 1 and is not the
 * phase table's (the only other entry). Identified by its key's first word. */
static int find_entry(const char *dir, char *path, size_t cap)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    int found = 0;
    struct dirent *e;
    while (!found && (e = readdir(d)) != NULL) {
        size_t l = strlen(e->d_name);
        if (l < 11 || strcmp(e->d_name + l - 11, ".atmoscache") != 0) continue;
        snprintf(path, cap, "%s/%s", dir, e->d_name);
        FILE *f = fopen(path, "rb");
        char head[64] = {0};
        if (f) {
            size_t n = fread(head, 1, sizeof head - 1, f);
            (void)n;
            fclose(f);
        }
        found = memcmp(head + 32, "msphase ", 8) == 0;
    }
    closedir(d);
    return found;
}

static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = size > 0 ? malloc((size_t)size) : NULL;
    if (b && fread(b, 1, (size_t)size, f) != (size_t)size) free(b), b = NULL;
    fclose(f);
    *n = (size_t)size;
    return b;
}

typedef enum { VALUES_TIMES_10, VALUE_NAN, VALUES_NEGATIVE, FORWARD_CHANGED, CHI_TOO_BIG } damage;
static const char *const damage_name[] = {"values x 10", "one value NaN", "negative values", "F_1 changed",
                                          "chi_1 = 2"};

/* Damages the numbers of the entry at path and recomputes its checksum, so that only a
 * check of the values can tell. Payload: int32 nwl, max_order, ngrid, nchi[nwl]; doubles
 * grid, forward, logsum, chi; floats values (docs/phase-tables.md). */
static int damage_entry(const char *path, damage how)
{
    size_t n = 0;
    unsigned char *b = slurp(path, &n);
    if (!b || n < 32) return free(b), 0;
    uint32_t key_len = 0;
    for (int i = 0; i < 4; i++) key_len |= (uint32_t)b[12 + i] << (8 * i);
    unsigned char *p = b + 32 + key_len;
    size_t size = n - 32 - key_len;
    int32_t hdr[4];
    memcpy(hdr, p, sizeof hdr); /* nwl = 1: nwl, max_order, ngrid, nchi[0] */
    size_t nv = (size_t)hdr[1] * (size_t)hdr[2];
    unsigned char *v = p + size - 4 * nv; /* the floats (the file's bytes: unaligned) */
    unsigned char *fwd = p + 16 + 8 * (size_t)hdr[2];
    unsigned char *chi = fwd + 8 * 2 * (size_t)(hdr[1] + 1);
    double x;
    float fv;
    switch (how) {
    case VALUES_TIMES_10:
    case VALUES_NEGATIVE:
        for (size_t i = 0; i < nv; i++) {
            memcpy(&fv, v + 4 * i, 4);
            fv = how == VALUES_NEGATIVE ? -fv : 10 * fv;
            memcpy(v + 4 * i, &fv, 4);
        }
        break;
    case VALUE_NAN:
        fv = (float)NAN;
        memcpy(v + 4 * (nv / 2), &fv, 4);
        break;
    case FORWARD_CHANGED:
        memcpy(&x, fwd + 8, 8);
        x *= 0.9;
        memcpy(fwd + 8, &x, 8);
        break;
    case CHI_TOO_BIG:
        x = 2;
        memcpy(chi + 8, &x, 8);
        break;
    }
    uint64_t sum = atmos__cache_checksum(p, size);
    for (int i = 0; i < 8; i++) b[24 + i] = (unsigned char)(sum >> (8 * i));
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(b, 1, n, f) == n;
    if (f && fclose(f) != 0) ok = 0;
    free(b);
    return ok;
}

/* Builds the msphase of t; 1 if it came from the cache, and its values must equal ref's. */
static int build_same(atmos_context *ctx, const atmos_phase_table *t, const atmos_msphase *ref)
{
    atmos_msphase *m = NULL;
    atmos_msphase_desc md = {0};
    CHECK_OK(atmos_msphase_build(ctx, t, &md, &m));
    if (!m) return -1;
    int fc = atmos_msphase_from_cache(m);
    int n = atmos_msphase_max_order(m), same = n == atmos_msphase_max_order(ref);
    const double *grid;
    int ng = atmos_msphase_grid(m, &grid);
    for (int o = 1; same && o <= n; o++) {
        const double *a = atmos_msphase_values(m, 0, o), *b = atmos_msphase_values(ref, 0, o);
        for (int j = 0; j < ng; j++) same = same && fabs(a[j] - b[j]) <= 1e-6 * fabs(b[j]) + 1e-30;
        same = same && atmos_msphase_forward(m, 0, o) == atmos_msphase_forward(ref, 0, o);
    }
    CHECK_MSG(same, "a loaded multiple-scattering table differs from the one built");
    atmos_msphase_destroy(m);
    return fc;
}

int main(void)
{
    char dir[1024];
    test_tmp_path(dir, sizeof dir, "mscache");
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.cache_dir = dir;
    cd.log = log_fn;
    cd.log_level = ATMOS_LOG_WARN;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    if (!ctx) return test_summary("test_msphase_cache");
    CHECK_OK(atmos_cache_clear(ctx, NULL));

    atmos_particle_desc p;
    test_hg_particle(&p, "test-hg", 0.7, 0.0);
    atmos_wavelengths wl;
    atmos_wavelengths_spectral(1, &wl);
    atmos_phase_table *t = NULL;
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, NULL, &t));
    atmos_msphase *ref = NULL;
    atmos_msphase_desc md = {0};
    if (t) CHECK_OK(atmos_msphase_build(ctx, t, &md, &ref));
    char entry[1200];
    CHECK(ref && !atmos_msphase_from_cache(ref) && find_entry(dir, entry, sizeof entry));
    if (!ref || !find_entry(dir, entry, sizeof entry)) goto done;
    CHECK(build_same(ctx, t, ref) == 1);

    for (int h = VALUES_TIMES_10; h <= CHI_TOO_BIG; h++) {
        CHECK(damage_entry(entry, (damage)h));
        int w0 = warnings;
        CHECK_MSG(build_same(ctx, t, ref) == 0, "%s: a damaged entry was used", damage_name[h]);
        CHECK_MSG(warnings > w0 && strstr(last_warning, entry), "%s: no warning naming the entry (last: %s)",
                  damage_name[h], last_warning);
        CHECK_MSG(build_same(ctx, t, ref) == 1, "%s: not rebuilt into the cache", damage_name[h]);
    }

    /* A FIFO in place of the entry: a warned miss within the alarm, then rebuilt. */
    signal(SIGALRM, on_alarm);
    alarm(20);
    remove(entry);
    CHECK(mkfifo(entry, 0644) == 0);
    int w0 = warnings;
    CHECK(build_same(ctx, t, ref) == 0);
    CHECK_MSG(warnings > w0 && strstr(last_warning, "not a regular file"), "FIFO: no warning (last: %s)", last_warning);
    alarm(0);
    struct stat st;
    CHECK(stat(entry, &st) == 0 && S_ISREG(st.st_mode)); /* the rebuilt entry replaced it */
    CHECK(build_same(ctx, t, ref) == 1);

done:
    atmos_msphase_destroy(ref);
    atmos_phase_table_destroy(t);
    atmos_cache_clear(ctx, NULL);
    atmos_context_destroy(ctx);
    return test_summary("test_msphase_cache");
}
