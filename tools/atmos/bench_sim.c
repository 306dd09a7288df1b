/* atmos bench simulate: wall and CPU time per step of the cloud simulation, with the load. */
#include "bench_sim.h"
#include "cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double load1(void)
{
    FILE *f = fopen("/proc/loadavg", "r");
    double l = -1;
    if (f) {
        if (fscanf(f, "%lf", &l) != 1) l = -1;
        fclose(f);
    }
    return l;
}

static int one(atmos_context *ctx, int grid, int steps)
{
    atmos_sim_desc d = {.preset = "towering_cumulus", .grid = grid, .seed = 1};
    atmos_sim *s = NULL;
    atmos_status st = atmos_sim_create(ctx, &d, &s);
    if (st == ATMOS_OK) st = atmos_sim_step(ctx, s); /* warm-up: first touches, FFTW's first run */
    double wall = 0, best = 1e30;
    const clock_t c0 = clock();
    for (int k = 0; k < steps && st == ATMOS_OK; k++) {
        const double t0 = cli_now_s();
        st = atmos_sim_step(ctx, s);
        const double t = cli_now_s() - t0;
        wall += t;
        if (t < best) best = t;
    }
    const double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    if (st == ATMOS_OK) {
        atmos_sim_stats ss;
        atmos_sim_get_stats(s, &ss);
        printf("bench=simulate preset=towering_cumulus grid=%d cells=%dx%dx%d threads=%d steps=%d ms_per_step=%.1f "
               "best_ms=%.1f cpu_ms_per_step=%.1f load=%.2f\n",
               grid, ss.dims[0], ss.dims[1], ss.dims[2], atmos_context_threads(ctx), steps, 1e3 * wall / steps,
               1e3 * best, 1e3 * cpu / steps, load1());
    }
    atmos_sim_destroy(s);
    return st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error("bench", ctx, st);
}

int bench_simulate(int grid, int steps, int threads)
{
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    int rc = CLI_EXIT_OK;
    const int grids[2] = {grid ? grid : 64, 128};
    for (int g = 0; g < (grid ? 1 : 2) && rc == CLI_EXIT_OK; g++) rc = one(ctx, grids[g], steps);
    atmos_context_destroy(ctx);
    return rc;
}
