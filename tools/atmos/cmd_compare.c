/* atmos compare: error statistics of an HDR image against a reference. */
#include "cli.h"
#include "outputs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void help(void)
{
    printf("Usage: atmos compare IMAGE REFERENCE [--heatmap OUT.png] [--by KEY.pfm [--edges E0,E1,...]]\n"
           "                     [--exclude-above L] [--json]\n\n"
           "Compares two HDR images of the same size (OpenEXR .exr or portable float map .pfm)\n"
           "channel by channel, paired by name: R,G,B when both have them, otherwise the same\n"
           "set of names in both, otherwise the only channel of each (a PFM's are R,G,B or Y;\n"
           "alpha, A, is never compared; anything else is an error). It prints per channel and\n"
           "overall:\n"
           "  rmse      root-mean-square difference, in the images' units\n"
           "  rel_rmse  rmse divided by the reference's mean absolute value\n"
           "  bias      mean of IMAGE - REFERENCE\n"
           "and the worst 16x16 region. --heatmap writes a PNG (a .png name that is none of the\n"
           "images read; a missing folder is made) of the per-pixel relative difference (black, red,\n"
           "yellow, white = the largest, at most 10 x the 99th percentile of the pixels' differences:\n"
           "one far-off pixel such as a lamp saturates instead of leaving the rest black). --json prints\n"
           "  {\"rmse\": ..., \"rel_rmse\": ..., \"bias\": [...], \"rmse_per_channel\": [...],\n"
           "   \"rel_rmse_per_channel\": [...], \"channels\": [names],\n"
           "   \"worst_region\": [x, y, w, h] or null (nothing compared),\n"
           "   \"worst_rmse\": ..., \"nonfinite\": N, \"nonfinite_image\": N1, \"nonfinite_reference\": N2}\n"
           "(numbers without a finite value are null: the relative ones of an all-zero reference,\n"
           "printed inf or nan as text). NaN or infinite samples in either image\n"
           "fail the comparison: the statistics over the finite ones are printed, then an error\n"
           "with the counts, and the exit status is 1.\n\n"
           "--by KEY splits the statistics by a per-pixel key image of the same size (channel 0),\n"
           "such as the optical depth written by `atmos render --tau`: pixels with the key in\n"
           "[E_i, E_i+1) form bin i (default edges 0.01,0.1,0.5,1,2,4,8,16,32,64,1e30). Per bin it\n"
           "prints the pixel count, rel_rmse and rel_bias (over the reference's mean in the bin;\n"
           "--edges without --by is warned of and does nothing);\n"
           "--json adds \"bins\": [{\"lo\", \"hi\", \"pixels\", \"rel_rmse\", \"rel_bias\"}, ...].\n\n"
           "--exclude-above L leaves out of every figure (the bins, the worst region; black in the heat\n"
           "map) the pixels where a compared channel of either image exceeds L: the sun's disc, whose\n"
           "radiance is ~10^5 times the sky's, otherwise dominates the RMSE of any image showing it\n"
           "(e.g. 1e5 for a daylight sky in atmos render's units: it also leaves out a path tracer's\n"
           "fireflies, ~1e5 inside thick clouds; the count left out is printed, \"excluded\" in\n"
           "--json). A pixel left out is out for every channel; its NaN and infinities still count\n"
           "and fail the comparison, as does every pixel left out (exit status 1; no worst region).\n");
    fputs(CLI_HELP_EXIT, stdout);
}

/* An image and its channel names (EXR: from the file; PFM: R,G,B or Y). */
typedef struct {
    atmos_image *img;
    char **owned; /* the EXR reader's names, freed with free() */
    const char *const *names;
} named_image;

static atmos_status read_hdr(atmos_context *ctx, const char *path, named_image *out)
{
    static const char *const rgb[3] = {"R", "G", "B"}, *const grey[1] = {"Y"};
    size_t n = strlen(path);
    if (n >= 4 && !strcmp(path + n - 4, ".pfm")) {
        atmos_status st = atmos_read_pfm(ctx, path, &out->img);
        if (st == ATMOS_OK) out->names = out->img->channels == 3 ? rgb : grey;
        return st;
    }
    atmos_status st = atmos_read_exr_named(ctx, path, &out->img, &out->owned);
    out->names = (const char *const *)out->owned;
    return st;
}

/* An 8-bit image given where an HDR one goes: "PNG" or "JPEG" by its first bytes, else NULL. */
static const char *ldr_kind(const char *path)
{
    const char *kind = atmos_image_file_kind(path);
    return kind && (!strcmp(kind, "PNG") || !strcmp(kind, "JPEG")) ? kind : NULL;
}

/* JSON has no NaN or infinity: such numbers are null. */
static void json_number(double v)
{
    if (isfinite(v)) printf("%.9g", v);
    else printf("null");
}

static void json_numbers(const double *v, int n)
{
    putchar('[');
    for (int i = 0; i < n; i++) {
        if (i) printf(", ");
        json_number(v[i]);
    }
    putchar(']');
}

/* A channel name as a JSON string (EXR names may hold any byte but NUL). */
static void json_string(const char *s)
{
    putchar('"');
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\') printf("\\%c", *p);
        else if (*p < 0x20 || *p == 0x7f) printf("\\u%04x", *p);
        else putchar(*p);
    }
    putchar('"');
}

static void print_json(const atmos_image_diff *d, const char *const *names, const atmos_channel_match *m,
                       const atmos_image_bins *bins)
{
    printf("{\"rmse\": ");
    json_number(d->rmse_all);
    printf(", \"rel_rmse\": ");
    json_number(d->rel_rmse_all); /* an all-zero reference: no relative figure (the text's inf or nan) */
    printf(", \"bias\": ");
    json_numbers(d->bias, d->channels);
    printf(", \"rmse_per_channel\": ");
    json_numbers(d->rmse, d->channels);
    printf(", \"rel_rmse_per_channel\": ");
    json_numbers(d->rel_rmse, d->channels);
    printf(", \"channels\": [");
    for (int c = 0; c < m->count; c++) {
        if (c) printf(", ");
        json_string(names[m->image[c]]);
    }
    if (d->worst_w > 0)
        printf("], \"worst_region\": [%d, %d, %d, %d], \"worst_rmse\": ", d->worst_x, d->worst_y, d->worst_w, d->worst_h);
    else printf("], \"worst_region\": null, \"worst_rmse\": "); /* no sample compared */
    json_number(d->worst_rmse);
    printf(", \"nonfinite\": %zu, \"nonfinite_image\": %zu, \"nonfinite_reference\": %zu", d->nonfinite,
           d->nonfinite_image, d->nonfinite_reference);
    if (m->exclude_above > 0) printf(", \"excluded\": %zu", d->excluded);
    if (bins) {
        printf(", \"bins\": [");
        for (int i = 0; i < bins->bins; i++) {
            /* Empty bins say null. */
            printf("%s{\"lo\": %.9g, \"hi\": %.9g, \"pixels\": %zu, ", i ? ", " : "", bins->edges[i], bins->edges[i + 1],
                   bins->count[i]);
            printf("\"rel_rmse\": ");
            json_number(bins->rel_rmse[i]);
            printf(", \"rel_bias\": ");
            json_number(bins->rel_bias[i]);
            printf("}");
        }
        printf("]");
    }
    printf("}\n");
}

static void print_text(const char *const *files, const atmos_image *a, const atmos_image_diff *d,
                       const char *const *names, const atmos_channel_match *m, const char *heat, const char *by,
                       const atmos_image_bins *bins)
{
    printf("%s vs %s (%dx%d, %d channels)\n", files[0], files[1], a->width, a->height, d->channels);
    printf("%10s %14s %14s %14s\n", "channel", "rmse", "rel_rmse", "bias");
    for (int c = 0; c < d->channels; c++)
        printf("%10s %14.6g %14.6g %14.6g\n", names[m->image[c]], d->rmse[c], d->rel_rmse[c], d->bias[c]);
    printf("%10s %14.6g %14.6g\n", "all", d->rmse_all, d->rel_rmse_all);
    if (d->worst_w > 0)
        printf("worst region: x %d..%d, y %d..%d, rmse %.6g\n", d->worst_x, d->worst_x + d->worst_w - 1, d->worst_y,
               d->worst_y + d->worst_h - 1, d->worst_rmse);
    else if (m->exclude_above > 0 && d->excluded == (size_t)a->width * a->height)
        printf("worst region: none (every pixel was excluded by --exclude-above)\n");
    else printf("worst region: none (no finite sample was compared)\n");
    if (heat) printf("heat map: %s (white = %.4g relative difference)\n", heat, d->heat_scale);
    if (m->exclude_above > 0)
        printf("excluded: %zu pixels above %g (--exclude-above)\n", d->excluded, m->exclude_above);
    if (bins) {
        printf("by %s:\n%12s %12s %10s %12s %12s\n", by, "from", "to", "pixels", "rel_rmse", "rel_bias");
        for (int i = 0; i < bins->bins; i++)
            printf("%12.4g %12.4g %10zu %12.5g %12.5g\n", bins->edges[i], bins->edges[i + 1], bins->count[i],
                   bins->rel_rmse[i], bins->rel_bias[i]);
    }
}

int cli_cmd_compare(int argc, char **argv)
{
    const char *C = "compare", *files[2] = {NULL, NULL}, *heat = NULL, *by = NULL;
    int json = 0, nf = 0, n_edges = 11, edges_given = 0;
    double exclude_above = 0;
    double edges[ATMOS_IMAGE_BINS_MAX + 1] = {0.01, 0.1, 0.5, 1, 2, 4, 8, 16, 32, 64, 1e30};
    for (int i = 1; i < argc; i++) {
        const char *v = NULL;
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            help();
            return CLI_EXIT_OK;
        } else if (!strcmp(argv[i], "--json")) {
            json = 1;
        } else if (cli_take_value(argc, argv, &i, "--heatmap", &v)) {
            if (!v || !*v) return cli_usage_error(C, "--heatmap: missing file name");
            heat = v;
        } else if (cli_take_value(argc, argv, &i, "--by", &v)) {
            if (!v || !*v) return cli_usage_error(C, "--by: missing key image");
            by = v;
        } else if (cli_take_value(argc, argv, &i, "--exclude-above", &v)) {
            char *end = NULL;
            exclude_above = v ? strtod(v, &end) : 0;
            if (!v || end == v || *end || !isfinite(exclude_above) || !(exclude_above > 0))
                return cli_usage_error(C, "--exclude-above: expected a radiance > 0, got '%s'", v ? v : "");
        } else if (cli_take_value(argc, argv, &i, "--edges", &v)) {
            if (!v) return cli_usage_error(C, "--edges: missing list");
            n_edges = 0, edges_given = 1;
            const char *q = v;
            while (*q && n_edges <= ATMOS_IMAGE_BINS_MAX) {
                char *end = NULL;
                edges[n_edges] = strtod(q, &end);
                if (end == q || (*end && *end != ',') || !isfinite(edges[n_edges]) ||
                    (n_edges && !(edges[n_edges] > edges[n_edges - 1])))
                    return cli_usage_error(C, "--edges: expected ascending numbers like 0,1,2,4, got '%s'", v);
                n_edges++;
                q = *end ? end + 1 : end;
            }
            if (*q || n_edges < 2) return cli_usage_error(C, "--edges: 2..%d ascending numbers", ATMOS_IMAGE_BINS_MAX + 1);
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "unknown option '%s'", argv[i]);
        } else if (nf < 2) {
            files[nf++] = argv[i];
        } else {
            return cli_usage_error(C, "unexpected argument '%s' (two images)", argv[i]);
        }
    }
    if (nf < 2) return cli_usage_error(C, "need IMAGE and REFERENCE");
    if (edges_given && !by) fprintf(stderr, "atmos %s: warning: --edges does nothing without --by KEY (the bins' edges)\n", C);
    const char *inputs3[3] = {files[0], files[1], by};
    for (int k = 0; k < 3; k++) {
        const char *kind = inputs3[k] ? ldr_kind(inputs3[k]) : NULL;
        if (kind)
            return cli_usage_error(C, "%s: a %s file is not an HDR input: compare reads OpenEXR (.exr) and portable "
                                      "float maps (.pfm), e.g. atmos render's --exr or --pfm output", inputs3[k], kind);
    }
    if (heat) { /* the heat map must not replace an image it compares */
        if (cli_file_kind_of(heat) != CLI_FILE_PNG) return cli_usage_error(C, "--heatmap %s: expected a .png file name", heat);
        cli_outputs out = {0};
        cli_outputs_add(&out, "--heatmap", heat);
        const char *inputs[3] = {files[0], files[1], by};
        if (cli_outputs_check(C, &out, inputs, 3) != CLI_EXIT_OK) return CLI_EXIT_USAGE;
        if (cli_output_folder(C, "--heatmap", heat)) return CLI_EXIT_RUNTIME;
    }
    atmos_context *ctx = cli_context(0, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    named_image a = {0}, b = {0}, key = {0};
    atmos_image *h = NULL;
    atmos_image_diff d;
    atmos_image_bins bins;
    atmos_channel_match m;
    atmos_status st = read_hdr(ctx, files[0], &a);
    if (st == ATMOS_OK) st = read_hdr(ctx, files[1], &b);
    int said = 0; /* a message printed here, not the context's */
    if (st == ATMOS_OK && (a.img->width != b.img->width || a.img->height != b.img->height)) {
        fprintf(stderr, "atmos %s: %s is %dx%d, %s %dx%d: the image and the reference must be the same size\n", C,
                files[0], a.img->width, a.img->height, files[1], b.img->width, b.img->height);
        st = ATMOS_E_INVALID_ARG, said = 1;
    }
    if (st == ATMOS_OK) st = atmos_image_match_channels(ctx, a.names, a.img->channels, b.names, b.img->channels, &m);
    m.exclude_above = exclude_above;
    if (st == ATMOS_OK) st = atmos_image_compare_matched(ctx, a.img, b.img, &m, &d, heat ? &h : NULL);
    if (st == ATMOS_OK && by) st = read_hdr(ctx, by, &key);
    if (st == ATMOS_OK && by) st = atmos_image_compare_binned_matched(ctx, a.img, b.img, &m, key.img, edges, n_edges, &bins);
    if (st == ATMOS_OK && heat) st = atmos_write_png(ctx, h, heat, 8);
    int rc = CLI_EXIT_OK;
    if (st != ATMOS_OK) {
        rc = said ? CLI_EXIT_RUNTIME : cli_runtime_error(C, ctx, st);
    } else {
        if (json) print_json(&d, a.names, &m, by ? &bins : NULL);
        else print_text(files, a.img, &d, a.names, &m, heat, by, by ? &bins : NULL);
        /* A comparison is a test: a NaN or infinity in either image fails it, whatever
         * the statistics over the finite samples say. */
        if (d.nonfinite) {
            char left[96] = ""; /* those of pixels --exclude-above left out were not compared, yet count */
            if (d.nonfinite_excluded)
                snprintf(left, sizeof left, "; %zu of them in pixels left out by --exclude-above", d.nonfinite_excluded);
            fprintf(stderr, "atmos %s: %zu samples are NaN or infinite (%zu in %s, %zu in %s%s): the comparison fails\n",
                    C, d.nonfinite, d.nonfinite_image, files[0], d.nonfinite_reference, files[1], left);
            rc = CLI_EXIT_RUNTIME;
        }
        if (m.exclude_above > 0 && d.excluded == (size_t)a.img->width * a.img->height) {
            fprintf(stderr, "atmos %s: every pixel is above %g (--exclude-above): nothing was compared\n", C,
                    m.exclude_above);
            rc = CLI_EXIT_RUNTIME;
        }
    }
    atmos_image_destroy(a.img);
    atmos_image_destroy(b.img);
    atmos_image_destroy(h);
    atmos_image_destroy(key.img);
    free(a.owned), free(b.owned), free(key.owned);
    atmos_context_destroy(ctx);
    return rc;
}
