/* atmos volume's options of how a file is read (--grids, --time, --density-unit, ...),
 * shared by its info, slice and stats subcommands (cli.h). */
#include "cli.h"

#include <stdint.h>
#include <string.h>

static const char *C = "volume";

/* Options of how a file is read, shared by info, slice and stats. Returns 1 if argv[*i] was
 * one (consuming its value), 0 if not, -1 after a usage error was printed. */
int cli_volume_load_option(int argc, char **argv, int *i, atmos_volume_load_desc *d)
{
    const char *a = argv[*i];
    if (*i + 1 >= argc) return 0;
    if (!strcmp(a, "--grids")) {
        d->grids = argv[++*i];
    } else if (!strcmp(a, "--as") || !strcmp(a, "--particle")) { /* --particle: atmos render's name */
        d->field = argv[++*i];
    } else if (!strcmp(a, "--time") || !strcmp(a, "--time-index")) { /* --time-index: as atmos render's */
        if (!cli_parse_int(C, a, argv[++*i], 0, 1000000, &d->time_index)) return -1;
    } else if (!strcmp(a, "--voxel-size")) {
        if (!cli_parse_double(C, "--voxel-size", argv[++*i], &d->voxel_size_m)) return -1; /* its message given */
        if (!(d->voxel_size_m > 0)) {
            cli_usage_error(C, "--voxel-size: expected metres > 0");
            return -1;
        }
    } else if (!strcmp(a, "--scale") || !strcmp(a, "--density-scale")) { /* --density-scale: render's */
        if (!cli_parse_double(C, a, argv[++*i], &d->density_scale)) return -1; /* its message given */
        if (!(d->density_scale > 0 && d->density_scale <= 1e30)) {
            cli_usage_error(C, "%s: expected a factor in (0, 1e30] (a scene's volume.density_scale's bound)", a);
            return -1;
        }
    } else if (!strcmp(a, "--density-unit")) {
        static const char *const units[] = {"auto", "per_m3", "g_m3", "fraction"};
        const char *u = argv[++*i];
        int k = 0;
        while (k < 4 && strcmp(u, units[k])) k++;
        if (k == 4) {
            cli_usage_error(C, "--density-unit: expected auto, per_m3, g_m3 or fraction, got '%s'", u);
            return -1;
        }
        d->density_unit = (atmos_density_unit)k;
    } else if (!strcmp(a, "--length-scale") || !strcmp(a, "--volume-scale")) {
        /* --volume-scale: render's name, with its bound (the scene's volume "scale"); --length-scale
           the library's */
        const double top = strcmp(a, "--volume-scale") ? 1e6 : 100;
        if (!cli_parse_double(C, a, argv[++*i], &d->length_scale)) return -1; /* its message given */
        if (!(d->length_scale > 0 && d->length_scale <= top)) {
            cli_usage_error(C, "%s: expected a factor in (0, %g]", a, top);
            return -1;
        }
    } else if (!strcmp(a, "--max-memory")) {
        double mb = 0;
        if (!cli_parse_double(C, "--max-memory", argv[++*i], &mb)) return -1; /* its message given */
        if (mb <= 0) {
            cli_usage_error(C, "--max-memory: expected megabytes > 0");
            return -1;
        }
        d->max_memory = (uint64_t)(mb * 1048576.0);
    } else {
        return 0;
    }
    return 1;
}
