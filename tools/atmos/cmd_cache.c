/* atmos cache: where the table cache lives, and clearing it. */
#include "cli.h"
#include "atmos/cache.h"

#include <stdio.h>
#include <string.h>

static void help(void)
{
    printf("Usage: atmos cache path | clear\n\n"
           "Precomputed tables (particle phase tables, multiple-scattering phase functions, the\n"
           "spherical sky's tables, aerosol optics) are cached on disk so that they are built once.\n"
           "  path    print the cache directory: $XDG_CACHE_HOME/atmos, else ~/.cache/atmos\n"
           "  clear   remove every atmos cache entry (*.atmoscache) from it; other files are left alone\n\n"
           "A stale or corrupt entry is detected on load, reported, removed and rebuilt, so clearing is\n"
           "only needed to reclaim space; 'atmos phase --no-cache' builds a table without the cache.\n");
    fputs(CLI_HELP_EXIT, stdout);
}

int cli_cmd_cache(int argc, char **argv)
{
    const char *C = "cache";
    const char *what = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            help();
            return CLI_EXIT_OK;
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "unknown option '%s'", argv[i]);
        } else if (!what) {
            what = argv[i];
        } else {
            return cli_usage_error(C, "unexpected argument '%s'", argv[i]);
        }
    }
    if (!what) return cli_usage_error(C, "expected 'path' or 'clear'");
    if (strcmp(what, "path") != 0 && strcmp(what, "clear") != 0)
        return cli_usage_error(C, "unknown action '%s' (expected 'path' or 'clear')", what);
    atmos_context *ctx = cli_context(1, 0);
    if (!ctx) return CLI_EXIT_RUNTIME;
    int rc = CLI_EXIT_OK;
    if (!strcmp(what, "path")) {
        printf("%s\n", atmos_context_cache_dir(ctx));
    } else {
        int removed = 0;
        atmos_status st = atmos_cache_clear(ctx, &removed);
        if (st != ATMOS_OK) rc = cli_runtime_error(C, ctx, st);
        else printf("removed %d cache file%s from %s\n", removed, removed == 1 ? "" : "s", atmos_context_cache_dir(ctx));
    }
    atmos_context_destroy(ctx);
    return rc;
}
