/* The body of the fuzz targets for volume files read through the parser fence
 * (fuzz_openvdb.c, fuzz_netcdf.c): the input is written to a private temporary directory under
 * the reader's file name and loaded by that reader. It aborts when a promise is broken: a
 * failure must have a status the reader may return (FORMAT, UNSUPPORTED, LIMIT, NOMEM, IO) and
 * a message naming the input, and an accepted volume must have finite, non-negative
 * statistics. Included by one target each; not a library header. */
#ifndef ATMOS_FUZZ_VOLUME_FILE_H
#define ATMOS_FUZZ_VOLUME_FILE_H
#define _POSIX_C_SOURCE 200809L /* mkdtemp */
#include "atmos/atmos.h"
#include "fuzz_tmpdir.h"
#include "volume/volume_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef atmos_status (*fuzz_volume_loader)(atmos_context *, const char *, const atmos_volume_load_desc *,
                                           atmos_volume **);

static char fuzz_path[512];
static const char *fuzz_target_name;

static void fuzz_fail(const char *what, const char *msg)
{
    fprintf(stderr, "%s: %s (message: %s)\n", fuzz_target_name, what, msg ? msg : "");
    abort();
}

static void fuzz_setup(const char *file_name)
{
    const char *dir = fuzz_tmpdir();
    if (!dir) fuzz_fail("cannot create a temporary directory", fuzz_tmpdir_path);
    snprintf(fuzz_path, sizeof fuzz_path, "%s/%s", dir, file_name);
}

/* One input through loader, written as file_name; name is the target's, for messages. */
static int fuzz_volume_file(const uint8_t *data, size_t size, const char *name, const char *file_name,
                            fuzz_volume_loader loader)
{
    fuzz_target_name = name;
    if (!fuzz_path[0]) fuzz_setup(file_name);
    FILE *f = fopen(fuzz_path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) fuzz_fail("cannot write the input", fuzz_path);
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) return 0;
    atmos_volume_load_desc desc = {.max_memory = 64u << 20};
    atmos_volume *vol = NULL;
    atmos_status st = loader(ctx, fuzz_path, &desc, &vol);
    const char *msg = atmos_context_error(ctx);
    if (st != ATMOS_OK) {
        if (st != ATMOS_E_FORMAT && st != ATMOS_E_UNSUPPORTED && st != ATMOS_E_LIMIT && st != ATMOS_E_NOMEM &&
            st != ATMOS_E_IO)
            fuzz_fail("unexpected status", msg);
        if (!strstr(msg, fuzz_path)) fuzz_fail("message does not name the input", msg);
        if (vol) fuzz_fail("volume returned on failure", msg);
    } else {
        if (!vol) fuzz_fail("no volume on success", NULL);
        for (int i = 0; i < atmos_volume_field_count(vol); i++) {
            atmos_volume_field_stats s;
            if (atmos_volume_field_stats_get(ctx, vol, i, &s) != ATMOS_OK) fuzz_fail("stats failed", NULL);
            if (!isfinite(s.min) || !isfinite(s.max) || s.min < 0 || s.max < s.min) fuzz_fail("bad statistics", NULL);
        }
    }
    atmos_volume_destroy(vol);
    atmos_context_destroy(ctx);
    return 0;
}

#endif
