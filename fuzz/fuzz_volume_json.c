/* libFuzzer target for the raw-volume JSON sidecar reader (atmos__volume_load_raw_json).
 *
 * The reader takes a path (the sidecar names its .raw files relative to itself), so each
 * input is written to a private temporary directory as fuzz.json, next to a small valid
 * raw file "x.raw" (4x4x4 float32) that inputs may reference. Beyond "does not crash,
 * hang or leak", it aborts when the reader breaks a promise:
 *  - a failure has a status the reader may return (FORMAT, LIMIT, IO, NOMEM,
 *    INVALID_ARG) and a message naming the sidecar;
 *  - an accepted volume has finite, non-negative statistics.
 * Build with -DATMOS_FUZZ=ON (clang), or replay a corpus with fuzz/replay.c.
 */
#define _POSIX_C_SOURCE 200809L /* mkdtemp */
#include "atmos/atmos.h"
#include "fuzz_tmpdir.h"
#include "volume/volume_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *dir;

static void fail(const char *what, const char *msg)
{
    fprintf(stderr, "fuzz_volume_json: %s (message: %s)\n", what, msg ? msg : "");
    abort();
}

static void setup(void)
{
    dir = fuzz_tmpdir();
    if (!dir) fail("cannot create a temporary directory", fuzz_tmpdir_path);
    char p[320];
    snprintf(p, sizeof p, "%s/x.raw", dir);
    FILE *f = fopen(p, "wb");
    if (!f) fail("cannot write x.raw", p);
    for (int i = 0; i < 64; i++) {
        float v = (float)(i % 7) * 0.5f;
        fwrite(&v, sizeof v, 1, f);
    }
    fclose(f);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!dir) setup();
    char path[320];
    snprintf(path, sizeof path, "%s/fuzz.json", dir);
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) return 0;
    atmos_volume_load_desc desc = {.max_memory = 64u << 20};
    atmos_volume *vol = NULL;
    atmos_status st = atmos__volume_load_raw_json(ctx, path, &desc, &vol);
    const char *msg = atmos_context_error(ctx);
    if (st != ATMOS_OK) {
        if (st != ATMOS_E_FORMAT && st != ATMOS_E_LIMIT && st != ATMOS_E_IO && st != ATMOS_E_NOMEM &&
            st != ATMOS_E_INVALID_ARG)
            fail("unexpected status", msg);
        if (!strstr(msg, "fuzz.json")) fail("message does not name the sidecar", msg);
        if (vol) fail("volume returned on failure", msg);
    } else {
        if (!vol) fail("no volume on success", NULL);
        for (int i = 0; i < atmos_volume_field_count(vol); i++) {
            atmos_volume_field_stats s;
            if (atmos_volume_field_stats_get(ctx, vol, i, &s) != ATMOS_OK) fail("stats failed", NULL);
            if (!isfinite(s.min) || !isfinite(s.max) || s.min < 0 || s.max < s.min) fail("bad statistics", NULL);
        }
    }
    atmos_volume_destroy(vol);
    atmos_context_destroy(ctx);
    return 0;
}
