/* atmos: command-line front end. Each subcommand lives in its own cmd_*.c. */
#include "cli.h"

#include <stdio.h>
#include <string.h>

typedef struct {
    const char *name;
    int (*fn)(int, char **);
    const char *summary;
} command;

static const command commands[] = {
    {"render", cli_cmd_render, "render a scene (or the built-in default) to PNG/EXR/PFM"},
    {"sky", cli_cmd_sky, "query a sky model along one view direction, or write its tables"},
    {"sun", cli_cmd_sun, "solar elevation and azimuth for a UTC time and place"},
    {"bench", cli_cmd_bench, "benchmarks (e.g. 'atmos bench sky')"},
    {"phase", cli_cmd_phase, "particle phase functions: list presets, print or plot a table"},
    {"cache", cli_cmd_cache, "the table cache: 'atmos cache path', 'atmos cache clear'"},
    {"mie", cli_cmd_mie, "Mie efficiencies and amplitudes of one sphere"},
    {"volume", cli_cmd_volume, "inspect, generate, slice and measure cloud volumes"},
    {"simulate", cli_cmd_simulate, "grow clouds in a cloud-physics simulation, written as a volume"},
    {"compare", cli_cmd_compare, "error statistics of an HDR image against a reference"},
    {"view", cli_cmd_view, "the interactive viewer: fly around a scene, move the sun (SDL2 window)"},
};
#define NCOMMANDS (int)(sizeof commands / sizeof commands[0])

/* The help's list of commands: each name padded to the longest, then two spaces, the layout
 * help2man and scripts/make-man.sh read as "item, description". */
static void usage(FILE *f)
{
    int width = 0;
    for (int i = 0; i < NCOMMANDS; i++)
        if ((int)strlen(commands[i].name) > width) width = (int)strlen(commands[i].name);
    fprintf(f,
            "Usage: atmos COMMAND [OPTIONS]\n"
            "Physically based rendering of atmospheric phenomena.\n\n"
            "Commands:\n");
    for (int i = 0; i < NCOMMANDS; i++) fprintf(f, "  %-*s  %s\n", width, commands[i].name, commands[i].summary);
    fprintf(f,
            "\n  atmos COMMAND --help   help for one command\n"
            "  atmos --version        print the version\n" CLI_HELP_EXIT);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        if (argc > 2 && strcmp(cmd, "help") == 0) {
            for (int i = 0; i < NCOMMANDS; i++)
                if (!strcmp(argv[2], commands[i].name)) {
                    char *sub[] = {argv[2], "--help", NULL};
                    return commands[i].fn(2, sub);
                }
        }
        usage(stdout);
        return CLI_EXIT_OK;
    }
    if (!strcmp(cmd, "--version") || !strcmp(cmd, "-V")) {
        printf("atmos %s\n", atmos_version());
        return CLI_EXIT_OK;
    }
    for (int i = 0; i < NCOMMANDS; i++)
        if (!strcmp(cmd, commands[i].name)) return commands[i].fn(argc - 1, argv + 1);
    fprintf(stderr, "atmos: unknown command '%s'\n", cmd);
    usage(stderr);
    return CLI_EXIT_USAGE;
}
