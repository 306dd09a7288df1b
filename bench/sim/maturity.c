/* When the cumulonimbus preset is mature (docs/clouds.md, Speed): runs it minute by minute
 * and prints, each simulated minute, its cloud top and largest updraught (atmos_sim_get_stats)
 * and the area of its anvil: the columns with cloud (any cloud the volume keeps, q_c > 1e-7)
 * at or above `--anvil-km` (default 10 km, 2 km under the preset's 12 km tropopause), through
 * the public API only (atmos_sim_to_volume, atmos_volume_sample at the cell centres).
 *
 *   cc -O2 -Iinclude bench/sim/maturity.c -Lbuild -latmos -Wl,-rpath,build -o build/sim_maturity
 *   build/sim_maturity [--grid N] [--minutes M] [--threads T] [--anvil-km Z]
 */
#include "atmos/atmos.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Columns (of the volume's x and z) with cloud at or above height zmin; km^2. */
static double anvil_km2(const atmos_volume *v, double zmin)
{
    const atmos_volume_desc *d = atmos_volume_get_desc(v);
    int cloud = -1;
    for (int f = 0; f < atmos_volume_field_count(v); f++)
        if (!strcmp(atmos_volume_field_name(v, f), "cloud")) cloud = f;
    if (cloud < 0) return 0;
    const double h = d->voxel_size_m;
    long cols = 0;
    for (int k = 0; k < d->dims[2]; k++)
        for (int i = 0; i < d->dims[0]; i++)
            for (int j = 0; j < d->dims[1]; j++) {
                const double p[3] = {d->origin_m[0] + (i + 0.5) * h, d->origin_m[1] + (j + 0.5) * h,
                                     d->origin_m[2] + (k + 0.5) * h};
                if (p[1] - d->origin_m[1] < zmin) continue;
                if (atmos_volume_sample(v, cloud, p) > 0) {
                    cols++;
                    break;
                }
            }
    return cols * h * h * 1e-6;
}

int main(int argc, char **argv)
{
    atmos_sim_desc sd;
    memset(&sd, 0, sizeof sd);
    sd.preset = "cumulonimbus", sd.grid = 64, sd.seed = 1;
    int minutes = 45, threads = 2;
    double zmin = 10e3;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--grid")) sd.grid = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--minutes")) minutes = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--threads")) threads = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--anvil-km")) zmin = 1e3 * atof(argv[i + 1]);
        else {
            fprintf(stderr, "sim_maturity: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.threads = threads;
    cd.log = NULL;
    atmos_context *ctx = NULL;
    atmos_sim *s = NULL;
    if (atmos_context_create(&cd, &ctx) != ATMOS_OK || atmos_sim_create(ctx, &sd, &s) != ATMOS_OK) {
        fprintf(stderr, "sim_maturity: %s\n", ctx ? atmos_context_error(ctx) : "no context");
        return 1;
    }
    printf("minute  top_m  max_w  anvil_km2 (cloud at or above %.1f km)\n", zmin * 1e-3);
    for (int m = 1; m <= minutes; m++) {
        atmos_volume *v = NULL;
        if (atmos_sim_run(ctx, s, 60.0) != ATMOS_OK || atmos_sim_to_volume(ctx, s, &v) != ATMOS_OK) {
            fprintf(stderr, "sim_maturity: %s\n", atmos_context_error(ctx));
            return 1;
        }
        atmos_sim_stats st;
        atmos_sim_get_stats(s, &st);
        printf("%6d %6.0f %6.1f %10.1f\n", m, st.cloud_top_m, st.max_w, anvil_km2(v, zmin));
        fflush(stdout);
        atmos_volume_destroy(v);
    }
    atmos_sim_destroy(s);
    atmos_context_destroy(ctx);
    return 0;
}
