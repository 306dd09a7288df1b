/* atmos compare: error statistics of an HDR image against a reference. */
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void help(void)
{
    printf("Usage: atmos compare IMAGE REFERENCE [--heatmap OUT.png] [--json]\n\n"
           "Compares two HDR images of the same size (OpenEXR .exr or portable float map .pfm;\n"
           "the alpha channel of RGBA images is ignored) and prints per channel and overall:\n"
           "  rmse      root-mean-square difference, in the images' units\n"
           "  rel_rmse  rmse divided by the reference's mean absolute value\n"
           "  bias      mean of IMAGE - REFERENCE\n"
           "and the worst 16x16 region. --heatmap writes a PNG of the per-pixel relative\n"
           "difference (black, red, yellow, white = the largest). --json prints\n"
           "  {\"rmse\": ..., \"rel_rmse\": ..., \"bias\": [...], \"rmse_per_channel\": [...],\n"
           "   \"rel_rmse_per_channel\": [...], \"worst_region\": [x, y, w, h], \"worst_rmse\": ...,\n"
           "   \"nonfinite\": N}   (NaN/Inf samples, skipped: statistics are over the finite ones)\n");
}

static atmos_status read_hdr(atmos_context *ctx, const char *path, atmos_image **out)
{
    size_t n = strlen(path);
    if (n >= 4 && !strcmp(path + n - 4, ".pfm")) return atmos_read_pfm(ctx, path, out);
    return atmos_read_exr(ctx, path, out);
}

int cli_cmd_compare(int argc, char **argv)
{
    const char *C = "compare", *files[2] = {NULL, NULL}, *heat = NULL;
    int json = 0, nf = 0;
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
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "unknown option '%s'", argv[i]);
        } else if (nf < 2) {
            files[nf++] = argv[i];
        } else {
            return cli_usage_error(C, "unexpected argument '%s' (two images)", argv[i]);
        }
    }
    if (nf < 2) return cli_usage_error(C, "need IMAGE and REFERENCE");
    atmos_context *ctx = cli_context(0, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_image *a = NULL, *b = NULL, *h = NULL;
    atmos_image_diff d;
    atmos_status st = read_hdr(ctx, files[0], &a);
    if (st == ATMOS_OK) st = read_hdr(ctx, files[1], &b);
    if (st == ATMOS_OK) st = atmos_image_compare(ctx, a, b, &d, heat ? &h : NULL);
    if (st == ATMOS_OK && heat) st = atmos_write_png(ctx, h, heat, 8);
    int rc = CLI_EXIT_OK;
    if (st != ATMOS_OK) {
        rc = cli_runtime_error(C, ctx, st);
    } else if (json) {
        printf("{\"rmse\": %.9g, \"rel_rmse\": %.9g, \"bias\": ", d.rmse_all, isfinite(d.rel_rmse_all) ? d.rel_rmse_all : -1.0);
        cli_print_json_array(d.bias, d.channels);
        printf(", \"rmse_per_channel\": ");
        cli_print_json_array(d.rmse, d.channels);
        printf(", \"rel_rmse_per_channel\": ");
        cli_print_json_array(d.rel_rmse, d.channels);
        printf(", \"worst_region\": [%d, %d, %d, %d], \"worst_rmse\": %.9g, \"nonfinite\": %zu}\n", d.worst_x, d.worst_y,
               d.worst_w, d.worst_h, d.worst_rmse, d.nonfinite);
    } else {
        printf("%s vs %s (%dx%d, %d channels)\n", files[0], files[1], a->width, a->height, d.channels);
        printf("%10s %14s %14s %14s\n", "channel", "rmse", "rel_rmse", "bias");
        for (int c = 0; c < d.channels; c++) printf("%10d %14.6g %14.6g %14.6g\n", c, d.rmse[c], d.rel_rmse[c], d.bias[c]);
        printf("%10s %14.6g %14.6g\n", "all", d.rmse_all, d.rel_rmse_all);
        printf("worst region: x %d..%d, y %d..%d, rmse %.6g\n", d.worst_x, d.worst_x + d.worst_w - 1, d.worst_y,
               d.worst_y + d.worst_h - 1, d.worst_rmse);
        if (d.nonfinite) printf("non-finite samples skipped: %zu\n", d.nonfinite);
        if (heat) printf("heat map: %s (white = %.4g relative difference)\n", heat, d.heat_scale);
    }
    atmos_image_destroy(a);
    atmos_image_destroy(b);
    atmos_image_destroy(h);
    atmos_context_destroy(ctx);
    return rc;
}
