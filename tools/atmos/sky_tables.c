/* atmos sky --table: a spherical model's look-up tables listed, or one written as an image
 * (EXR: every wavelength, channels named by it; PFM: the first three; PNG: a plot, the
 * first three channels each scaled to its own maximum). */
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int ends_with(const char *s, const char *suffix)
{
    const size_t n = strlen(s), m = strlen(suffix);
    return n >= m && !strcmp(s + n - m, suffix);
}

/* A plot of the table: channels 0..2 (grey for one) each divided by its maximum. */
static atmos_status write_plot(atmos_context *ctx, const atmos_image *t, const char *path)
{
    const int C = t->channels < 3 ? 1 : 3;
    atmos_image *p = NULL;
    atmos_status st = atmos_image_create(ctx, t->width, t->height, C, &p);
    if (st != ATMOS_OK) return st;
    const size_t N = (size_t)t->width * t->height;
    for (int c = 0; c < C; c++) {
        double mx = 0;
        for (size_t i = 0; i < N; i++) mx = fmax(mx, t->pixels[i * t->channels + c]);
        for (size_t i = 0; i < N; i++) p->pixels[i * C + c] = mx > 0 ? (float)(t->pixels[i * t->channels + c] / mx) : 0;
    }
    st = atmos_write_png(ctx, p, path, 8);
    atmos_image_destroy(p);
    return st;
}

static atmos_status write_table(atmos_context *ctx, const atmos_image *t, const atmos_wavelengths *wl,
                                const char *path)
{
    if (ends_with(path, ".png")) return write_plot(ctx, t, path);
    if (ends_with(path, ".pfm")) return atmos_write_pfm(ctx, t, path);
    char **names = malloc(sizeof(char *) * (size_t)t->channels), *buf = malloc((size_t)t->channels * 24);
    if (!names || !buf) {
        free(names), free(buf);
        return ATMOS_E_NOMEM;
    }
    for (int k = 0; k < t->channels; k++) {
        names[k] = buf + (size_t)k * 24;
        snprintf(names[k], 24, "%.2fnm", wl->nm[k]);
    }
    atmos_exr_desc d = {0, (const char *const *)names};
    atmos_status st = atmos_write_exr(ctx, t, path, &d);
    free(names), free(buf);
    return st;
}

int cli_sky_table(const char *C, atmos_context *ctx, const atmos_atmosphere *atm, const char *name,
                  const char *out)
{
    const char *const *names = atmos_atmosphere_table_names(atm);
    if (!strcmp(name, "list")) {
        for (int i = 0; names[i]; i++) printf("%s\n", names[i]);
        if (!names[0]) fprintf(stderr, "atmos %s: this model keeps no tables (dobashi and spherical do)\n", C);
        return CLI_EXIT_OK;
    }
    if (!out) return cli_usage_error(C, "--table %s: -o FILE.exr|.pfm|.png is required", name);
    if (!ends_with(out, ".exr") && !ends_with(out, ".pfm") && !ends_with(out, ".png"))
        return cli_usage_error(C, "-o %s: expected a .exr, .pfm or .png file", out);
    atmos_image *t = NULL;
    atmos_status st = atmos_atmosphere_table(ctx, atm, name, &t);
    if (st == ATMOS_OK) st = write_table(ctx, t, atmos_atmosphere_wavelengths(atm), out);
    if (st != ATMOS_OK) {
        atmos_image_destroy(t);
        return cli_runtime_error(C, ctx, st);
    }
    printf("%s: %dx%d, %d wavelengths; %s\n", out, t->width, t->height, t->channels,
           atmos_image_get_meta(t, "atmos:axes") ? atmos_image_get_meta(t, "atmos:axes") : "");
    atmos_image_destroy(t);
    return CLI_EXIT_OK;
}
