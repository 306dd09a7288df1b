/* atmos sky --table: the models' look-up tables listed, or one written as an image
 * (EXR: every wavelength, channels "<table>.<nm>nm" (exr_names.h), the table's atmos:axes and
 * atmos:units, no chromaticities; PFM: the first three; PNG: a plot, the first three channels
 * each scaled to its own maximum). */
#include "cli.h"
#include "exr_names.h"

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
    enum { CAP = 64 };
    char **names = malloc(sizeof(char *) * (size_t)t->channels), *buf = malloc((size_t)t->channels * CAP);
    if (!names || !buf) {
        free(names), free(buf);
        return ATMOS_E_NOMEM;
    }
    const char *table = atmos_image_get_meta(t, "atmos:table");
    for (int k = 0; k < t->channels; k++) { /* "transmittance.440nm": the table's layer */
        names[k] = buf + (size_t)k * CAP;
        cli_exr_wavelength_name(names[k], CAP, table ? table : "table", wl->nm[k]);
    }
    atmos_exr_desc d = {0, (const char *const *)names};
    atmos_status st = atmos_write_exr(ctx, t, path, &d);
    free(names), free(buf);
    return st;
}

static const struct {
    const char *name;
    atmos_atmosphere_kind kind;
} sky_models[] = {{"riley", ATMOS_ATMOSPHERE_RILEY},
                  {"homogeneous", ATMOS_ATMOSPHERE_HOMOGENEOUS},
                  {"dobashi", ATMOS_ATMOSPHERE_DOBASHI},
                  {"spherical", ATMOS_ATMOSPHERE_SPHERICAL}};
enum { N_SKY_MODELS = sizeof sky_models / sizeof sky_models[0] };

int cli_sky_model(const char *name, atmos_atmosphere_kind *kind)
{
    for (int i = 0; i < N_SKY_MODELS; i++)
        if (!strcmp(name, sky_models[i].name)) {
            *kind = sky_models[i].kind;
            return 1;
        }
    return 0;
}

const char *cli_sky_model_name(atmos_atmosphere_kind kind)
{
    for (int i = 0; i < N_SKY_MODELS; i++)
        if (sky_models[i].kind == kind) return sky_models[i].name;
    return "?";
}

static int has_name(const char *const *names, const char *name)
{
    for (int i = 0; names[i]; i++)
        if (!strcmp(names[i], name)) return 1;
    return 0;
}

/* Every model with its tables, one line each ("dobashi: a b c", "riley (the default): no tables"). */
static void list_all_models(void)
{
    for (int i = 0; i < N_SKY_MODELS; i++) {
        const char *const *names = atmos_atmosphere_kind_table_names(sky_models[i].kind);
        printf("%s%s:", sky_models[i].name, sky_models[i].kind == ATMOS_ATMOSPHERE_RILEY ? " (the default)" : "");
        if (!names[0]) printf(" no tables");
        for (int k = 0; names[k]; k++) printf(" %s", names[k]);
        putchar('\n');
    }
}

int cli_sky_table_check(const char *C, atmos_atmosphere_kind kind, const char *name, const char *out)
{
    const char *const *names = atmos_atmosphere_kind_table_names(kind);
    if (!strcmp(name, "list")) {
        if (out) return cli_usage_error(C, "--table list: -o goes with a table's name");
        if (names[0]) {
            for (int i = 0; names[i]; i++) printf("%s\n", names[i]);
        } else {
            fprintf(stderr, "atmos %s: the %s model keeps no tables; every model's (--model NAME --table TABLE -o FILE writes one):\n",
                    C, cli_sky_model_name(kind));
            list_all_models();
        }
        return CLI_EXIT_OK;
    }
    if (!has_name(names, name)) {
        for (int i = 0; i < N_SKY_MODELS; i++)
            if (has_name(atmos_atmosphere_kind_table_names(sky_models[i].kind), name))
                return cli_usage_error(C, "--table %s: a table of --model %s, not of the %s model%s", name,
                                       sky_models[i].name, cli_sky_model_name(kind),
                                       names[0] ? "" : " (which keeps none)");
        char known[256] = "";
        for (int i = 0; names[i]; i++)
            if (strlen(known) + strlen(names[i]) + 3 < sizeof known) {
                if (i) strcat(known, ", ");
                strcat(known, names[i]);
            }
        return cli_usage_error(C, "--table %s: unknown; the %s model's tables: %s ('atmos sky --table list' lists every model's)",
                                name, cli_sky_model_name(kind), known[0] ? known : "none");
    }
    if (!out) return cli_usage_error(C, "--table %s: -o FILE.exr|.pfm|.png is required", name);
    if (!ends_with(out, ".exr") && !ends_with(out, ".pfm") && !ends_with(out, ".png"))
        return cli_usage_error(C, "-o %s: expected a .exr, .pfm or .png file", out);
    return -1;
}

int cli_sky_table(const char *C, atmos_context *ctx, const atmos_atmosphere *atm, const char *name,
                  const char *out)
{
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
