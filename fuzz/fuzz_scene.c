/* libFuzzer target for the scene parser (atmos_scene_parse).
 *
 * Beyond "does not crash", it checks the parser's promises, aborting (which
 * libFuzzer reports as a finding) when one is broken:
 *  - failures carry a status the header allows and a message starting with the
 *    source name;
 *  - a scene the parser accepts passes atmos_scene_validate (the parser never
 *    builds something the validator would refuse);
 *  - an accepted scene's sun direction is a finite unit vector.
 * Build with -DATMOS_FUZZ=ON (clang), or replay a corpus with fuzz/replay.c.
 */
#include "atmos/atmos.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fail(const char *what, const char *msg)
{
    fprintf(stderr, "fuzz_scene: %s (message: %s)\n", what, msg ? msg : "");
    abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    atmos_context *ctx = NULL;
    if (atmos_context_create(NULL, &ctx) != ATMOS_OK) return 0;
    atmos_scene scene;
    atmos_status st = atmos_scene_parse(ctx, (const char *)data, size, "fuzz.json", &scene);
    const char *msg = atmos_context_error(ctx);
    if (st != ATMOS_OK) {
        if (st != ATMOS_E_INVALID_ARG && st != ATMOS_E_FORMAT && st != ATMOS_E_LIMIT && st != ATMOS_E_NOMEM)
            fail("unexpected status", msg);
        if (strncmp(msg, "fuzz.json", 9) != 0) fail("message does not name the source", msg);
    } else {
        if (atmos_scene_validate(ctx, &scene, "fuzz.json") != ATMOS_OK)
            fail("parsed scene fails validation", atmos_context_error(ctx));
        if (memchr(scene.name, '\0', sizeof scene.name) == NULL) fail("name not terminated", NULL);
        double dir[3], e, a;
        /* Time-based suns need the solar position code; angles are checked
         * always, times only if that code accepts the instant. */
        if (atmos_scene_sun_direction(ctx, &scene, dir, &e, &a) == ATMOS_OK) {
            double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
            if (!isfinite(e) || !isfinite(a) || !(fabs(n - 1.0) < 1e-9)) fail("bad sun direction", NULL);
        } else if (!scene.sun.from_time) {
            fail("sun direction failed for angles", atmos_context_error(ctx));
        }
    }
    atmos_context_destroy(ctx);
    return 0;
}
