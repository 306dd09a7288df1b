/* The beam renderer's benchmark (bench_beams.c) of atmos bench. */
#ifndef ATMOS_CLI_BENCH_BEAMS_H
#define ATMOS_CLI_BENCH_BEAMS_H

#include "cli.h"

/* Frames per second of the scene file (NULL: scenes/dobashi_fig04_spotlight.json from the
 * current folder) and its variants (no sub-planes at three plane spacings, a coarser epsilon,
 * 2 and 4 lights, twice the size), frames frames each with the camera moving; only the case
 * named only when it is not NULL (a usage error when no case has that name). */
int bench_beams(const char *file, int frames, int threads, const char *only);

#endif
