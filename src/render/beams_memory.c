/* The beam renderer's memory for an image, estimated before anything of the image's size is
 * allocated (docs/beams.md, "Memory"): a 16384 x 16384 image asks more than most machines have,
 * which the system would otherwise show only by swapping or killing the process. */
#define _DEFAULT_SOURCE /* sysconf's _SC_PHYS_PAGES */
#include "render/plan_internal.h"

#include <stdio.h>
#include <sys/resource.h>
#include <unistd.h>

/* Bytes a pixel: 88 + 12 per wavelength (measured: the largest resident set of `atmos render`,
 * PNG output, 2048^2 less 1024^2, over 3 M pixels: rgb 121, 16 wavelengths 279, 64 wavelengths
 * 861; docs/beams.md), and a fixed 32 MiB for the tables, the maps and the program. */
#define BYTES_PIXEL_BASE 88.0
#define BYTES_PIXEL_WAVELENGTH 12.0
#define BYTES_FIXED (32.0 * 1048576)

double atmos__beams_memory_estimate(int width, int height, int wavelengths)
{
    return BYTES_FIXED + (double)width * height * (BYTES_PIXEL_BASE + BYTES_PIXEL_WAVELENGTH * wavelengths);
}

/* The memory this process can have, in bytes (0 when nothing says), and where that bound comes
 * from: the machine's physical memory, the address-space limit (ulimit -v) or the control group's
 * memory.max, whichever is least. */
static double available_memory(const char **why)
{
    double have = 0;
    *why = "the machine's";
#if defined(_SC_PHYS_PAGES) && defined(_SC_PAGESIZE)
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    if (pages > 0 && size > 0) have = (double)pages * size;
#endif
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY && (have == 0 || (double)rl.rlim_cur < have))
        have = (double)rl.rlim_cur, *why = "the process's address-space limit (ulimit -v)";
    FILE *f = fopen("/sys/fs/cgroup/memory.max", "r");
    double cg = 0;
    if (f && fscanf(f, "%lf", &cg) == 1 && cg > 0 && (have == 0 || cg < have))
        have = cg, *why = "the control group's (memory.max)";
    if (f) fclose(f);
    return have;
}

atmos_status atmos__beams_memory_check(atmos_context *ctx, int width, int height, int wavelengths)
{
    const char *why;
    const double need = atmos__beams_memory_estimate(width, height, wavelengths), have = available_memory(&why);
    const double gb = 1e-9, a_pixel = BYTES_PIXEL_BASE + BYTES_PIXEL_WAVELENGTH * wavelengths;
    char what[256];
    snprintf(what, sizeof what, "a %dx%d image of %d wavelengths needs about %.1f GB (%.0f bytes a pixel)", width,
             height, wavelengths, need * gb, a_pixel);
    if (have > 0 && need > have)
        return atmos__error(ctx, ATMOS_E_LIMIT,
                            "render beams: %s, more than the %.1f GB of memory it may have, %s: render it smaller "
                            "(atmos render --width, --height) or with fewer wavelengths",
                            what, have * gb, why);
    if (have > 0 && need > 0.5 * have)
        atmos__log(ctx, ATMOS_LOG_WARN, "render beams: %s, more than half the %.1f GB of memory it may have, %s", what,
                   have * gb, why);
    return ATMOS_OK;
}
