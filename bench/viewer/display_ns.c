/* The viewer's display pass alone (atmos_image_display_into, docs/viewer.md): a 1280 x 720 RGB
 * + alpha frame of sky-like radiances to float display values (mode 1), 8-bit values (2) or
 * both (3), on one thread; prints the least CPU time of N calls, in ns a pixel.
 *
 *   cc -O2 -DATMOS_STATIC -Iinclude bench/viewer/display_ns.c build/libatmos.a -fopenmp -lpng -lz -ljpeg -lm \
 *      -o display_ns && ./display_ns [mode] [N]
 */
#include "atmos/atmos.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double cpu_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    const int W = 1280, H = 720, mode = argc > 1 ? atoi(argv[1]) : 1, calls = argc > 2 ? atoi(argv[2]) : 60;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 1;
    atmos_context *ctx = NULL;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_image *img = NULL, *disp = NULL;
    unsigned char *bytes = malloc((size_t)W * H * 4);
    if (atmos_context_create(&d, &ctx) != ATMOS_OK || atmos_image_create(NULL, W, H, 4, &img) != ATMOS_OK ||
        atmos_image_create(NULL, W, H, 4, &disp) != ATMOS_OK || !bytes || mode < 1 || mode > 3) {
        fprintf(stderr, "display_ns: cannot start (mode 1, 2 or 3)\n");
        return 1;
    }
    unsigned s = 1;
    for (size_t i = 0; i < (size_t)W * H * 4; i++) {
        s = s * 1664525u + 1013904223u;
        img->pixels[i] = i % 4 == 3 ? 1.0f : (float)((s >> 8) / 16777216.0 * 0.3);
    }
    const atmos_tonemap_desc td = {1, 3.0, ATMOS_TONE_FILMIC};
    double best = 1e30;
    for (int r = 0; r < calls; r++) {
        const double t = cpu_s();
        if (atmos_image_display_into(ctx, img, &wl, &td, mode & 1 ? disp : NULL, mode & 2 ? bytes : NULL) != ATMOS_OK)
            return 1;
        best = best < cpu_s() - t ? best : cpu_s() - t;
    }
    printf("mode=%d ms=%.2f ns_per_pixel=%.2f\n", mode, best * 1e3, best * 1e9 / W / H);
    atmos_image_destroy(img), atmos_image_destroy(disp), free(bytes);
    atmos_context_destroy(ctx);
    return 0;
}
