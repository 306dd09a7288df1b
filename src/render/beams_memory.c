/* The beam renderer's memory for an image, estimated before anything of the image's size is
 * allocated (docs/beams.md, "Memory"): a 16384 x 16384 image asks more than most machines have,
 * which the system would otherwise show only by swapping or killing the process. */
#define _DEFAULT_SOURCE /* sysconf's _SC_PHYS_PAGES */
#include "render/plan_internal.h"

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

/* The machine's physical memory in bytes; 0 when the system does not say. */
static double physical_memory(void)
{
#if defined(_SC_PHYS_PAGES) && defined(_SC_PAGESIZE)
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    if (pages > 0 && size > 0) return (double)pages * size;
#endif
    return 0;
}

atmos_status atmos__beams_memory_check(atmos_context *ctx, int width, int height, int wavelengths)
{
    const double need = atmos__beams_memory_estimate(width, height, wavelengths), have = physical_memory();
    const double gb = 1e-9, a_pixel = BYTES_PIXEL_BASE + BYTES_PIXEL_WAVELENGTH * wavelengths;
    if (have > 0 && need > have)
        return atmos__error(ctx, ATMOS_E_LIMIT,
                            "render beams: a %dx%d image of %d wavelengths needs about %.1f GB (%.0f bytes a pixel), "
                            "more than the machine's %.1f GB of memory: render it smaller (atmos render --width, "
                            "--height) or with fewer wavelengths",
                            width, height, wavelengths, need * gb, a_pixel, have * gb);
    if (have > 0 && need > 0.5 * have)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "render beams: a %dx%d image of %d wavelengths needs about %.1f GB (%.0f bytes a pixel), more than "
                   "half the machine's %.1f GB of memory",
                   width, height, wavelengths, need * gb, a_pixel, have * gb);
    return ATMOS_OK;
}
