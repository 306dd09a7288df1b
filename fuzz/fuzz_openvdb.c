/* libFuzzer target for the OpenVDB reader (atmos__volume_load_openvdb), through the parser fence:
 * the OpenVDB library reads each input in a child process (src/volume/reader_fence.c), so a crash
 * there is reported as an error, not found by the fuzzer; what is fuzzed is atmos's own part
 * (the header checks, the fence, the volume rebuilt from the child's bricks).
 *
 * It aborts when a promise is broken: a failure must have a status the reader may return
 * (FORMAT, UNSUPPORTED, LIMIT, NOMEM, IO) and a message naming the input, and an accepted
 * volume must have finite, non-negative statistics. The input is written as fuzz.vdb to a
 * private temporary directory. Build with -DATMOS_FUZZ=ON (clang), or replay with replay.c.
 */
#define _POSIX_C_SOURCE 200809L /* mkdtemp */
#include "atmos/atmos.h"
#include "volume/volume_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char path[512];

static void fail(const char *what, const char *msg)
{
    fprintf(stderr, "fuzz_openvdb: %s (message: %s)\n", what, msg ? msg : "");
    abort();
}

static void setup(void)
{
    const char *t = getenv("TMPDIR");
    char dir[256];
    snprintf(dir, sizeof dir, "%s/atmos-fuzz-XXXXXX", t && *t ? t : "/tmp");
    if (!mkdtemp(dir)) fail("cannot create a temporary directory", dir);
    snprintf(path, sizeof path, "%s/fuzz.vdb", dir);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!path[0]) setup();
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) fail("cannot write the input", path);
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) return 0;
    atmos_volume_load_desc desc = {.max_memory = 64u << 20};
    atmos_volume *vol = NULL;
    atmos_status st = atmos__volume_load_openvdb(ctx, path, &desc, &vol);
    const char *msg = atmos_context_error(ctx);
    if (st != ATMOS_OK) {
        if (st != ATMOS_E_FORMAT && st != ATMOS_E_UNSUPPORTED && st != ATMOS_E_LIMIT && st != ATMOS_E_NOMEM &&
            st != ATMOS_E_IO)
            fail("unexpected status", msg);
        if (!strstr(msg, path)) fail("message does not name the input", msg);
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
