/* atmos volume stats: the shape statistics of cloud fields seen from above
 * (include/atmos/cloudstats.h, docs/clouds.md "Shape statistics"). No physics here. */
#include "cli.h"
#include "outputs.h"
#include "sidecar_inputs.h"


#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *C = "volume";

typedef struct {
    const char *sources[32];
    int nsources, kv, periodic; /* periodic: -1 = the volume's own (a simulation's, a sidecar's) */
    const char *field, *csv, *png;
    double base_tau, minutes;
    uint64_t seed;
    int seeds, grid, threads, seed_given, read_given;
    atmos_cloud_stats_desc sd;
    atmos_volume_load_desc ld; /* how files are read (atmos volume's reading options) */
} opts;

void cli_volume_stats_usage(void)
{
    printf("       atmos volume stats SOURCE... [--threshold T] [--connectivity 4|8] [--periodic|--no-periodic]\n"
           "                 [--min-pixels N] [--size-range DMIN,DMAX] [--field NAME] [--base-tau T]\n"
           "                 [--seed S] [--seeds N] [--minutes M] [--grid N] [--kv] [--csv FILE]\n"
           "                 [--mask-png FILE] [reading options]\n");
}

void cli_volume_stats_help(void)
{
    printf("  stats     the shape statistics of cloud fields seen from above. SOURCE is a volume file,\n"
           "            generate:PRESET or simulate:PRESET (--minutes, --grid as atmos simulate); several\n"
           "            sources, or --seeds N (seeds S..S+N-1 of each generated or simulated source), are\n"
           "            pooled. A column is cloudy where its vertical optical depth (every field, or --field,\n"
           "            with the particle presets' cross-sections; the grid's y axis is up) is at least T\n"
           "            (default 1). Clouds are 4-connected (default) or 8-connected; clouds touching the\n"
           "            grid's edge are counted in the cloud fraction and left out of the fits, except with\n"
           "            --periodic, where the grid wraps round (the default for simulate:PRESET and for a\n"
           "            file whose sidecar says \"periodic\": true, as atmos simulate -o writes it;\n"
           "            --no-periodic: not). Reported: the cloud fraction; the perimeter-area dimension D\n"
           "            (P ~ A^(D/2), least squares of log P on log A over clouds of at least N pixels,\n"
           "            default 10) from the marching-squares outline and from the pixel-edge (crack) perimeter,\n"
           "            with standard errors; the exponent b of the size distribution n(d) ~ d^-b of equivalent\n"
           "            diameters d = sqrt(4 A / pi) over [DMIN, DMAX] metres (default: the smallest fitted\n"
           "            cloud to the largest) by maximum likelihood and by least squares on a log-binned\n"
           "            histogram; the bases' flatness, per cloud the standard deviation of the base height\n"
           "            (where the optical depth from below reaches --base-tau, default 0.1) over its columns\n"
           "            divided by its depth (median and area-weighted mean). --kv prints key=value lines\n"
           "            instead of the summary (nan where a fit has too few clouds, the summary saying so in\n"
           "            words); --csv writes one line per cloud; --mask-png the first source's mask (white\n"
           "            clouds, grey edge clouds, dark grey thinner cloud, black clear; rows along z).\n"
           "            Files are read with the reading options below; each source is measured once.\n");
}

/* Options that would do nothing for the sources given, and a source given twice (it would be
 * pooled twice), are usage errors rather than silently ignored. */
static int check_sources(const opts *o)
{
    int files = 0, gens = 0, sims = 0;
    for (int s = 0; s < o->nsources; s++) {
        const char *a = o->sources[s];
        if (!strncmp(a, "simulate:", 9)) sims++;
        else if (!strncmp(a, "generate:", 9)) gens++;
        else files++;
        for (int t = 0; t < s; t++)
            if (!strcmp(a, o->sources[t]))
                return cli_usage_error(C, "stats: '%s' is given twice: each source is measured once (--seeds N measures "
                                          "N seeds of a generated or simulated one)", a);
    }
    if (o->read_given && !files)
        return cli_usage_error(C, "stats: the reading options (--grids, --time, --density-unit, ...) apply to volume "
                                  "files, and no source is a file");
    if ((o->minutes > 0 || o->grid > 0) && !sims)
        return cli_usage_error(C, "stats: --minutes and --grid apply to simulate:PRESET sources, and none is given");
    if ((o->seed_given || o->seeds > 1) && !gens && !sims)
        return cli_usage_error(C, "stats: --seed and --seeds apply to generate: and simulate: sources, and none is given");
    return CLI_EXIT_OK;
}

static int parse(int argc, char **argv, opts *o)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int ok = 1, r = cli_volume_load_option(argc, argv, &i, &o->ld);
        if (r < 0) return CLI_EXIT_USAGE;
        if (r > 0) {
            o->read_given = 1;
            continue;
        }
        if (!strcmp(a, "--kv")) o->kv = 1;
        else if (!strcmp(a, "--periodic")) o->periodic = 1;
        else if (!strcmp(a, "--no-periodic")) o->periodic = 0;
        else if (a[0] != '-') {
            if (o->nsources == 32) return cli_usage_error(C, "stats: at most 32 sources");
            o->sources[o->nsources++] = a;
        } else if (!v) {
            return cli_usage_error(C, "stats: unknown or incomplete option '%s'", a);
        } else {
            i++;
            if (!strcmp(a, "--threshold")) {
                ok = cli_parse_double(C, a, v, &o->sd.tau_threshold);
                if (ok && !(o->sd.tau_threshold > 0)) return cli_usage_error(C, "--threshold: expected an optical depth > 0");
            } else if (!strcmp(a, "--base-tau")) {
                ok = cli_parse_double(C, a, v, &o->base_tau);
                if (ok && !(o->base_tau > 0)) return cli_usage_error(C, "--base-tau: expected an optical depth > 0");
            } else if (!strcmp(a, "--connectivity")) {
                ok = cli_parse_int(C, a, v, 4, 8, &o->sd.connectivity);
                if (ok && o->sd.connectivity != 4 && o->sd.connectivity != 8)
                    return cli_usage_error(C, "--connectivity: expected 4 or 8");
            } else if (!strcmp(a, "--min-pixels")) {
                int n = 0;
                ok = cli_parse_int(C, a, v, 1, 1000000, &n);
                o->sd.fit_min_pixels = n;
            } else if (!strcmp(a, "--size-range")) {
                char *end = NULL;
                o->sd.size_min_m = strtod(v, &end);
                if (end == v || *end != ',') return cli_usage_error(C, "--size-range: expected DMIN,DMAX in metres");
                const char *t = end + 1;
                o->sd.size_max_m = strtod(t, &end);
                if (end == t || *end || !(o->sd.size_min_m > 0 && o->sd.size_max_m > o->sd.size_min_m && isfinite(o->sd.size_max_m)))
                    return cli_usage_error(C, "--size-range: expected 0 < DMIN < DMAX metres, got '%s'", v);
            } else if (!strcmp(a, "--field")) o->field = v;
            else if (!strcmp(a, "--csv")) o->csv = v;
            else if (!strcmp(a, "--mask-png")) o->png = v;
            else if (!strcmp(a, "--seed")) {
                unsigned long long s = 0;
                if (!cli_parse_seed(C, v, &s)) return CLI_EXIT_USAGE;
                o->seed = s, o->seed_given = 1;
            } else if (!strcmp(a, "--seeds")) ok = cli_parse_int(C, a, v, 1, 1000, &o->seeds);
            else if (!strcmp(a, "--minutes")) {
                ok = cli_parse_double(C, a, v, &o->minutes);
                if (ok && !(o->minutes > 0 && o->minutes <= ATMOS_SIM_MAX_MINUTES))
                    return cli_usage_error(C, "--minutes: expected (0, %g]", ATMOS_SIM_MAX_MINUTES);
            } else if (!strcmp(a, "--grid")) ok = cli_parse_int(C, a, v, ATMOS_SIM_MIN_GRID, ATMOS_SIM_MAX_GRID, &o->grid);
            else if (!strcmp(a, "--threads")) ok = cli_parse_int(C, a, v, 1, 1024, &o->threads);
            else return cli_usage_error(C, "stats: unknown option '%s'", a);
        }
        if (!ok) return CLI_EXIT_USAGE;
    }
    if (!o->nsources) return cli_usage_error(C, "stats: which volume? (a file, generate:PRESET or simulate:PRESET)");
    return check_sources(o);
}

static atmos_status load_source(atmos_context *ctx, const opts *o, const char *src, uint64_t seed, atmos_volume **v)
{
    if (!strncmp(src, "generate:", 9)) {
        atmos_volume_generate_desc g = {.seed = seed};
        return atmos_scene_generate_volume(ctx, src + 9, &g, v);
    }
    if (!strncmp(src, "simulate:", 9)) {
        atmos_sim_desc s = {.preset = src + 9, .minutes = o->minutes, .grid = o->grid, .seed = seed};
        return atmos_simulate(ctx, &s, v);
    }
    return atmos_volume_load(ctx, src, &o->ld, v);
}

/* The fields' extinction cross-sections (0 for fields left out by --field). */
static int cross_sections(atmos_context *ctx, const opts *o, const atmos_volume *v, const char *src, double *sigma)
{
    int used = 0;
    for (int f = 0; f < atmos_volume_field_count(v) && f < ATMOS_VOLUME_MAX_FIELDS; f++) {
        sigma[f] = 0;
        if (o->field && strcmp(o->field, atmos_volume_field_name(v, f))) continue;
        atmos_particle_desc p;
        if (atmos_particle_preset(ctx, atmos_volume_field_particle(v, f), &p) != ATMOS_OK || !(p.sigma_ext_m2 > 0)) {
            fprintf(stderr, "atmos volume: %s: field '%s' has particles '%s' without an extinction cross-section\n", src,
                    atmos_volume_field_name(v, f), atmos_volume_field_particle(v, f));
            return -1;
        }
        sigma[f] = p.sigma_ext_m2;
        used++;
    }
    if (!used) fprintf(stderr, "atmos volume: %s: no field '%s'\n", src, o->field ? o->field : "");
    return used ? 0 : -1;
}

static atmos_status write_mask(atmos_context *ctx, const atmos_cloud_columns *c, const atmos_cloud_stats *s, double tau0,
                               const char *path)
{
    /* pixels repeated to at least 256 wide, so that a 64-column simulation is not a thumbnail */
    int big = c->nx > c->ny ? c->nx : c->ny, z = big < 256 ? (256 + big - 1) / big : 1;
    atmos_image *img = NULL;
    atmos_status st = atmos_image_create(ctx, c->nx * z, c->ny * z, 1, &img);
    if (st != ATMOS_OK) return st;
    for (int r = 0; r < c->ny * z; r++)
        for (int q = 0; q < c->nx * z; q++) {
            size_t p = (size_t)(r / z) * c->nx + q / z;
            int k = s->label[p];
            img->pixels[(size_t)r * c->nx * z + q] =
                k >= 0 ? (s->clouds[k].edge ? 0.45f : 1.0f) : (c->tau[p] > 0.01 * tau0 ? 0.08f : 0.0f);
        }
    st = atmos_write_png(ctx, img, path, 8);
    atmos_image_destroy(img);
    return st;
}

static void print_fit(const opts *o, const atmos_cloud_fit *f, int sources, double dx)
{
    double tau0 = o->sd.tau_threshold > 0 ? o->sd.tau_threshold : 1;
    if (o->kv) {
        printf("sources=%d\npixel_m=%g\nthreshold_tau=%g\nconnectivity=%d\nclouds=%d\nedge_clouds=%d\nfitted_clouds=%d\n"
               "cloud_fraction=%.6g\nD=%.6g\nD_se=%.6g\nD_crack=%.6g\nD_crack_se=%.6g\nfit_area_min_m2=%.6g\n"
               "fit_area_max_m2=%.6g\nsize_slope=%.6g\nsize_slope_se=%.6g\nsize_slope_hist=%.6g\nsize_slope_hist_se=%.6g\n"
               "size_min_m=%.6g\nsize_max_m=%.6g\nsize_clouds=%d\nflatness_median=%.6g\nflatness_mean=%.6g\n"
               "flatness_clouds=%d\n",
               sources, dx, tau0, o->sd.connectivity ? o->sd.connectivity : 4, f->clouds, f->edge_clouds, f->fitted,
               f->cloud_fraction, f->d, f->d_se, f->d_crack, f->d_crack_se, f->fit_area_min_m2, f->fit_area_max_m2,
               f->size_slope, f->size_slope_se, f->size_slope_hist, f->size_slope_hist_se, f->size_min_m, f->size_max_m,
               f->size_n, f->flatness_median, f->flatness_mean, f->flatness_n);
        return;
    }
    printf("%d source(s), pixels of %g m, cloudy where tau >= %g, %d-connected clouds\n", sources, dx, tau0,
           o->sd.connectivity ? o->sd.connectivity : 4);
    printf("  clouds %d (%d touching the edge, left out), cloud fraction %.3f\n", f->clouds, f->edge_clouds, f->cloud_fraction);
    if (!f->fitted) {
        printf("  no cloud of at least %g pixels away from the edge: nothing to fit (a lower --threshold, --min-pixels or "
               "--periodic may find some)\n",
               o->sd.fit_min_pixels > 0 ? o->sd.fit_min_pixels : 10);
        return;
    }
    /* A fit with too few clouds (one cloud's D, an empty size range) is NaN: said in words, as
     * "nothing to fit" is (--kv keeps the NaN). */
    if (isfinite(f->d) && isfinite(f->d_se))
        printf("  perimeter-area dimension D = %.3f +- %.3f (crack perimeter %.3f +- %.3f) over %d clouds of %.3g..%.3g "
               "km^2 (the %d of at least %g pixels away from the edge)\n",
               f->d, f->d_se, f->d_crack, f->d_crack_se, f->fitted, f->fit_area_min_m2 * 1e-6, f->fit_area_max_m2 * 1e-6,
               f->fitted, o->sd.fit_min_pixels > 0 ? o->sd.fit_min_pixels : 10);
    else
        printf("  perimeter-area dimension: too few clouds to fit (%d of at least %g pixels away from the edge)\n", f->fitted,
               o->sd.fit_min_pixels > 0 ? o->sd.fit_min_pixels : 10);
    if (isfinite(f->size_slope) && isfinite(f->size_slope_hist))
        printf("  size distribution n(d) ~ d^-b: b = %.2f +- %.2f (max. likelihood), %.2f +- %.2f (histogram) over %d clouds "
               "of %.0f..%.0f m\n",
               f->size_slope, f->size_slope_se, f->size_slope_hist, f->size_slope_hist_se, f->size_n, f->size_min_m,
               f->size_max_m);
    else
        printf("  size distribution: too few clouds to fit (%d in the size range; --size-range sets it)\n", f->size_n);
    printf("  base flatness (sd of base / depth): median %.3f, area-weighted mean %.3f over %d clouds\n", f->flatness_median,
           f->flatness_mean, f->flatness_n);
}

/* Measures one source, appends its clouds to *all; writes the mask of the first. */
static int measure(atmos_context *ctx, const opts *o, const char *src, uint64_t seed, int first, atmos_cloud **all, int *nall,
                   long *cloudy, long *pixels, double *dx, FILE *csv)
{
    atmos_volume *v = NULL;
    atmos_status st = load_source(ctx, o, src, seed, &v);
    if (st != ATMOS_OK) return cli_runtime_error(C, ctx, st);
    double sigma[ATMOS_VOLUME_MAX_FIELDS];
    if (cross_sections(ctx, o, v, src, sigma)) {
        atmos_volume_destroy(v);
        return CLI_EXIT_RUNTIME;
    }
    atmos_cloud_columns cols;
    st = atmos_cloud_columns_from_volume(ctx, v, sigma, o->base_tau > 0 ? o->base_tau : 0.1, &cols);
    const int periodic = atmos_volume_get_desc(v)->periodic; /* a simulation's, or its sidecar's "periodic" */
    atmos_volume_destroy(v);
    if (st != ATMOS_OK) return cli_runtime_error(C, ctx, st);
    atmos_cloud_stats_desc d = o->sd;
    d.periodic = o->periodic >= 0 ? o->periodic : periodic;
    atmos_cloud_stats s;
    st = atmos_cloud_stats_measure(ctx, &cols, &d, &s);
    if (st == ATMOS_OK && first && o->png) st = write_mask(ctx, &cols, &s, d.tau_threshold > 0 ? d.tau_threshold : 1, o->png);
    atmos_cloud *grown = st == ATMOS_OK ? realloc(*all, (size_t)(*nall + s.nclouds + 1) * sizeof **all) : NULL;
    if (st == ATMOS_OK && !grown) st = ATMOS_E_NOMEM;
    if (st == ATMOS_OK) {
        *all = grown;
        memcpy(*all + *nall, s.clouds, (size_t)s.nclouds * sizeof *s.clouds);
        *nall += s.nclouds;
        *cloudy += s.cloudy_pixels, *pixels += s.pixels, *dx = cols.dx_m;
        for (int k = 0; csv && k < s.nclouds; k++) {
            const atmos_cloud *c = &s.clouds[k];
            fprintf(csv, "%s,%llu,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d\n", src, (unsigned long long)seed, k, c->pixels,
                    c->area_m2, c->perimeter_m, c->crack_perimeter_m, c->diameter_m, c->base_mean_m, c->base_sd_m, c->depth_m,
                    c->edge);
        }
    }
    atmos_cloud_stats_free(&s);
    atmos_cloud_columns_free(&cols);
    return st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error(C, ctx, st);
}

int cli_cmd_volume_stats(int argc, char **argv)
{
    opts o;
    memset(&o, 0, sizeof o);
    o.periodic = -1, o.seed = 1, o.seeds = 1;
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) { /* its own part of atmos volume --help */
            printf("Usage:\n");
            cli_volume_stats_usage();
            printf("\n");
            cli_volume_stats_help();
            return CLI_EXIT_OK;
        }
    int rc = parse(argc, argv, &o);
    if (rc != CLI_EXIT_OK) return rc;
    if (o.png && cli_png_output("volume", "--mask-png", o.png)) return CLI_EXIT_USAGE;
    /* the outputs as atmos render has them: none an input, their folders made and staging files
       written, renamed into place only when every source was measured */
    cli_outputs set = {0};
    const int icsv = cli_outputs_add(&set, "--csv", o.csv), ipng = cli_outputs_add(&set, "--mask-png", o.png);
    const char *inputs[32 + 64];
    static char data[64][CLI_OUTPUT_PATH_MAX]; /* the raw sidecars' data files */
    int ninputs = 0, ndata = 0;
    for (int s = 0; s < o.nsources; s++)
        if (strncmp(o.sources[s], "generate:", 9) && strncmp(o.sources[s], "simulate:", 9)) { /* a file */
            inputs[ninputs++] = o.sources[s];
            cli_sidecar_inputs(o.sources[s], data, 64, &ndata, inputs, &ninputs);
        }
    if ((rc = cli_outputs_check(C, &set, inputs, ninputs)) != CLI_EXIT_OK) return rc;
    if (cli_outputs_prepare(C, &set)) return CLI_EXIT_RUNTIME;
    const char *csv_name = o.csv;
    if (icsv >= 0) o.csv = cli_outputs_stage(&set, icsv);
    if (ipng >= 0) o.png = cli_outputs_stage(&set, ipng);
    atmos_context *ctx = cli_context(o.threads, 1);
    FILE *csv = NULL;
    if (!ctx || (o.csv && !(csv = fopen(o.csv, "w")))) {
        if (ctx) fprintf(stderr, "atmos volume: %s: cannot write\n", csv_name);
        atmos_context_destroy(ctx);
        cli_outputs_discard(&set);
        return CLI_EXIT_RUNTIME;
    }
    if (csv) fprintf(csv, "source,seed,cloud,pixels,area_m2,perimeter_m,crack_perimeter_m,diameter_m,base_m,base_sd_m,depth_m,edge\n");
    atmos_cloud *all = NULL;
    int nall = 0, runs = 0;
    long cloudy = 0, pixels = 0;
    double dx = 0;
    for (int s = 0; s < o.nsources && rc == CLI_EXIT_OK; s++) {
        int file = strncmp(o.sources[s], "generate:", 9) && strncmp(o.sources[s], "simulate:", 9);
        for (int k = 0; k < (file ? 1 : o.seeds) && rc == CLI_EXIT_OK; k++, runs++)
            rc = measure(ctx, &o, o.sources[s], o.seed + (uint64_t)k, runs == 0, &all, &nall, &cloudy, &pixels, &dx, csv);
    }
    if (csv && fclose(csv) != 0 && rc == CLI_EXIT_OK) {
        fprintf(stderr, "atmos volume: %s: write failed\n", csv_name);
        rc = CLI_EXIT_RUNTIME;
    }
    if (rc == CLI_EXIT_OK && cli_outputs_commit(C, &set)) rc = CLI_EXIT_RUNTIME;
    if (rc != CLI_EXIT_OK) cli_outputs_discard(&set); /* no output half written */
    if (rc == CLI_EXIT_OK) {
        atmos_cloud_fit f;
        atmos_cloud_stats_fit(all, nall, cloudy, pixels, dx, &o.sd, &f);
        print_fit(&o, &f, runs, dx);
    }
    free(all);
    atmos_context_destroy(ctx);
    return rc;
}
