/* libFuzzer target for the NanoVDB reader (atmos__volume_load_nanovdb_mem).
 *
 * Beyond "does not crash, hang or leak", it checks the reader's promises and
 * aborts when one is broken:
 *  - a failure has a status the reader may return (FORMAT, UNSUPPORTED, LIMIT,
 *    NOMEM) and a message naming the input;
 *  - an accepted volume has finite, non-negative statistics.
 * The memory limit is small so inputs claiming huge extents are refused quickly.
 * Build with -DATMOS_FUZZ=ON (clang), or replay a corpus with fuzz/replay.c.
 */
#include "atmos/atmos.h"
#include "volume/reader_common.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fail(const char *what, const char *msg)
{
    fprintf(stderr, "fuzz_nanovdb: %s (message: %s)\n", what, msg ? msg : "");
    abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) return 0;
    atmos_volume_load_desc desc = {.max_memory = 64u << 20};
    atmos_volume *vol = NULL;
    atmos_status st = atmos__volume_load_nanovdb_mem(ctx, "fuzz.nvdb", data, size, &desc, &vol);
    const char *msg = atmos_context_error(ctx);
    if (st != ATMOS_OK) {
        if (st != ATMOS_E_FORMAT && st != ATMOS_E_UNSUPPORTED && st != ATMOS_E_LIMIT && st != ATMOS_E_NOMEM)
            fail("unexpected status", msg);
        if (strncmp(msg, "fuzz.nvdb", 9) != 0) fail("message does not name the source", msg);
        if (vol) fail("volume returned on failure", msg);
    } else {
        if (!vol) fail("no volume on success", NULL);
        for (int f = 0; f < atmos_volume_field_count(vol); f++) {
            atmos_volume_field_stats s;
            if (atmos_volume_field_stats_get(ctx, vol, f, &s) != ATMOS_OK) fail("stats failed", NULL);
            if (!isfinite(s.min) || !isfinite(s.max) || s.min < 0 || s.max < s.min) fail("bad statistics", NULL);
        }
    }
    atmos_volume_destroy(vol);
    atmos_context_destroy(ctx);
    return 0;
}
