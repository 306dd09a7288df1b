/* atmos bench simulate: the cloud simulation's time per step (docs/clouds.md). */
#ifndef ATMOS_CLI_BENCH_SIM_H
#define ATMOS_CLI_BENCH_SIM_H

/* Steps the towering_cumulus preset `steps` times on grid N (0: 64 and 128) after one warm-up
 * step, on `threads` threads (0: all); one line per grid. Returns the exit status. */
int bench_simulate(int grid, int steps, int threads);

#endif
