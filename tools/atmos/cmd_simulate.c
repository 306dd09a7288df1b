/* atmos simulate: runs the cloud simulation and writes its volume as raw float32 files
 * plus a JSON sidecar (like 'atmos volume generate'). No physics here. */
#include "cli.h"
#include "outputs.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *C = "simulate";

static void help(void)
{
    printf("Usage: atmos simulate PRESET -o NAME.json [--minutes M] [--grid N] [--seed S] [--threads T]\n"
           "                      [--refine R] [--detail A] [--ice] [--quiet] [--bench K]\n\n"
           "Runs the cloud-physics simulation (docs/clouds.md): a 3-D anelastic fluid with potential\n"
           "temperature, water vapour, condensate and precipitation; Kessler warm rain and a simple ice\n"
           "phase (the condensate partly ice below 0 C, wholly below -23 C: saturation over ice, its latent\n"
           "heat, snow and falling cloud ice), saturation adjustment, periodic sides. Writes the state at\n"
           "time M as a volume of \"cloud\" and \"rain\" (rain and snow) number densities (m^-3; mixing\n"
           "ratio x air density / the particle type's mean mass; \"ice\" too with --ice), raw float32 files\n"
           "next to the JSON sidecar (-o must name a .json file, whose folder is made if missing; nothing\n"
           "else is written), y up, the ground at y = 0. Every file is checked before the run (an existing\n"
           "folder in the way or a place that cannot be written fails at once), and all are written or\n"
           "none. A volume with no cloud and no rain is written with a warning.\n\n"
           "Presets (default simulated time; a shorter run may end before any cloud has formed, and the\n"
           "volume is then empty: at least the first-cloud time, better twice it; coarser grids take\n"
           "longer, e.g. cumulus_field ~7 min at --grid 32):\n");
    for (const char *const *n = atmos_sim_preset_names(); *n; n++) {
        const double first = atmos_sim_preset_first_cloud_minutes(*n);
        printf("  %-17s %g min; ", *n, atmos_sim_preset_minutes(*n));
        if (first > 0) printf("first cloud after ~%g min at the default grid\n", first);
        else printf("first cloud after 0 min: the deck is there from the start\n");
    }
    printf("\n  --minutes M  simulated time (default: the preset's, above), 0 < M <= %g\n"
           "  --grid N     cells along each horizontal side, %d..%d (default 64); the domain's size is the\n"
           "               preset's, so a larger N gives smaller cells, but at least 8 levels: a coarse\n"
           "               grid makes a shallow domain taller (stratocumulus below N = 32: 3.2 km at 16\n"
           "               instead of 1.6 km); the volume holds at most 64 M\n"
           "               voxels (N x levels x N x R^3), refused at once past that: at --refine 1\n"
           "               towering_cumulus to about N = 400, cumulonimbus to about 470\n"
           "  --seed S     the random perturbations (default 1); the same seed gives the same bytes\n"
           "  --refine R   voxels per model cell along each axis, 1..%d (default 1): the mixing ratios\n"
           "               interpolated in their logarithm between cell centres, so that edges fall\n"
           "               between the cells instead of on their faces; at most 64 M voxels in all\n"
           "  --detail A   0..1 (default 0), for artists: the fields sampled at places moved by a fractal\n"
           "               noise of up to A cells (ragged edges below the grid that the model does not hold)\n"
           "  --ice        write cloud water colder than 0 C partly, below -23 C wholly, as \"ice\" (the\n"
           "               fraction by temperature the model's own saturation, latent heat and snow use;\n"
           "               without --ice the whole condensate is written as \"cloud\")\n"
           "  --threads T  worker threads (default: all cores); the result does not depend on T\n"
           "  -q, --quiet  no progress bar\n"
           "  --bench K    instead of writing a volume: K time steps, then the mean time of one step and the\n"
           "               state (simulated time, largest updraught, cloud base and top); with --minutes, runs\n"
           "               that long first and reports the time taken (bench/sim/run.sh)\n" CLI_HELP_EXIT,
           ATMOS_SIM_MAX_MINUTES, ATMOS_SIM_MIN_GRID, ATMOS_SIM_MAX_GRID, ATMOS_SIM_MAX_REFINE);
}

static void print_state(const atmos_sim *s)
{
    atmos_sim_stats st;
    atmos_sim_get_stats(s, &st);
    printf("  state: %d x %d x %d cells of %g m, t = %.0f s after %ld steps, max w %.1f m/s, max q_c %.2g, max q_r %.2g, "
           "cloud base %.0f m, top %.0f m, rain on the ground %.3f kg/m^2\n",
           st.dims[0], st.dims[1], st.dims[2], st.cell_m, st.time_s, st.steps, st.max_w, st.max_qc, st.max_qr,
           st.cloud_base_m, st.cloud_top_m, st.rain_out);
}

/* --bench: the run to --minutes (timed), then K steps (timed each). */
static int run_bench(const atmos_sim_desc *d, int threads, int steps)
{
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_sim *s = NULL;
    double t0 = cli_now_s();
    atmos_status st = atmos_sim_create(ctx, d, &s);
    if (st == ATMOS_OK) {
        printf("atmos simulate --bench: %s, grid %d, %d threads; create %.3f s\n", d->preset, d->grid ? d->grid : 64,
               atmos_context_threads(ctx), cli_now_s() - t0);
        if (d->minutes > 0) {
            t0 = cli_now_s();
            st = atmos_sim_run(ctx, s, d->minutes * 60.0);
            printf("  %g simulated minutes in %.2f s\n", d->minutes, cli_now_s() - t0);
            print_state(s);
        }
    }
    if (st == ATMOS_OK) {
        t0 = cli_now_s();
        for (int k = 0; k < steps && st == ATMOS_OK; k++) st = atmos_sim_step(ctx, s);
        printf("  %d steps: %.1f ms per step\n", steps, 1e3 * (cli_now_s() - t0) / steps);
        print_state(s);
    }
    int rc = st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error(C, ctx, st);
    atmos_sim_destroy(s);
    atmos_context_destroy(ctx);
    return rc;
}

/* Says on stderr when the state has no cloud and no rain a renderer would see (every mixing
 * ratio under 1e-5 kg/kg, the stats' cloud threshold): the run was too short. */
static void warn_if_empty(const atmos_sim *s, const atmos_sim_desc *d, double minutes)
{
    atmos_sim_stats st;
    atmos_sim_get_stats(s, &st);
    if (st.max_qc >= 1e-5 || st.max_qr >= 1e-5) return;
    const double first = atmos_sim_preset_first_cloud_minutes(d->preset);
    fprintf(stderr,
            "atmos simulate: warning: the volume is empty: no cloud or rain after %g simulated minutes (largest cloud "
            "water %.2g g/kg); %s's first cloud forms after about %g minutes at the default grid: try --minutes %g or "
            "more\n",
            minutes, 1e3 * st.max_qc, d->preset, first, first > 0 ? 2 * first : 1);
}

/* The files one run writes (cli_raw_outputs): the sidecar and a raw file for each of the
 * simulation's fields, cloud, rain and with --ice ice. */
typedef struct {
    char raw[3][CLI_OUTPUT_PATH_MAX];
    cli_outputs set;
} sim_outputs;

static int check_outputs(const char *out, int ice, sim_outputs *o)
{
    static const char *const fields[3] = {"cloud", "rain", "ice"};
    memset(&o->set, 0, sizeof o->set);
    return cli_raw_outputs(C, out, fields, 2 + (ice != 0), o->raw, &o->set);
}

/* The run and the volume written as NAME.json + raw files. */
static int run_write(const atmos_sim_desc *d, int threads, int quiet, const char *out)
{
    cli_progress prog;
    cli_progress_init(&prog, quiet);
    atmos_context *ctx = cli_context_with_progress(threads, 0, cli_progress_bar, &prog); /* --quiet keeps warnings */
    if (!ctx) return CLI_EXIT_RUNTIME;
    const double minutes = d->minutes > 0 ? d->minutes : atmos_sim_preset_minutes(d->preset);
    atmos_sim *s = NULL;
    atmos_volume *v = NULL;
    const double t0 = cli_now_s();
    atmos_status st = atmos_sim_create(ctx, d, &s);
    int rc = CLI_EXIT_OK;
    if (st == ATMOS_E_LIMIT) { /* the options' voxels, refused before the run: a usage error */
        const char *msg = atmos_context_error(ctx);
        if (!strncmp(msg, "simulate: ", 10)) msg += 10;
        const int g = d->grid ? d->grid : 64;
        rc = d->refine > 1 ? cli_usage_error(C, "--grid %d --refine %d: %s", g, d->refine, msg)
                           : cli_usage_error(C, "--grid %d: %s", g, msg);
    }
    if (st == ATMOS_OK) st = atmos_sim_run(ctx, s, minutes * 60.0);
    if (st == ATMOS_OK) st = atmos_sim_to_volume(ctx, s, &v);
    if (st == ATMOS_OK) st = atmos_volume_write_raw(ctx, v, out);
    if (rc == CLI_EXIT_OK) rc = st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error(C, ctx, st);
    if (rc == CLI_EXIT_OK) warn_if_empty(s, d, minutes);
    if (rc == CLI_EXIT_OK && !quiet)
        fprintf(stderr, "atmos simulate: %s, %g min on a %d grid in %.1f s: wrote %s\n", d->preset, minutes,
                d->grid ? d->grid : 64, cli_now_s() - t0, out);
    atmos_volume_destroy(v);
    atmos_sim_destroy(s);
    atmos_context_destroy(ctx);
    return rc;
}

int cli_cmd_simulate(int argc, char **argv)
{
    atmos_sim_desc d;
    memset(&d, 0, sizeof d);
    d.seed = 1;
    const char *out = NULL;
    int threads = 0, quiet = 0, bench = 0, rc;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help();
            return CLI_EXIT_OK;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            quiet = 1;
        } else if (!strcmp(a, "-o") && i + 1 < argc) {
            out = argv[++i];
            if (!*out) return cli_usage_error(C, "-o: expected a file name");
        } else if (!strcmp(a, "--minutes") && i + 1 < argc) {
            if (!cli_parse_double(C, "--minutes", argv[++i], &d.minutes)) return CLI_EXIT_USAGE;
            if (!(d.minutes > 0 && d.minutes <= ATMOS_SIM_MAX_MINUTES))
                return cli_usage_error(C, "--minutes: expected 0 < M <= %g, got %s", ATMOS_SIM_MAX_MINUTES, argv[i]);
        } else if (!strcmp(a, "--grid") && i + 1 < argc) {
            if (!cli_parse_int(C, "--grid", argv[++i], ATMOS_SIM_MIN_GRID, ATMOS_SIM_MAX_GRID, &d.grid))
                return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--seed") && i + 1 < argc) {
            unsigned long long s = 0;
            if (!cli_parse_seed(C, argv[++i], &s)) return CLI_EXIT_USAGE;
            d.seed = s;
        } else if (!strcmp(a, "--refine") && i + 1 < argc) {
            if (!cli_parse_int(C, "--refine", argv[++i], 1, ATMOS_SIM_MAX_REFINE, &d.refine)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--detail") && i + 1 < argc) {
            if (!cli_parse_double(C, "--detail", argv[++i], &d.detail)) return CLI_EXIT_USAGE;
            if (!(d.detail >= 0 && d.detail <= 1)) return cli_usage_error(C, "--detail: expected 0 <= A <= 1, got %s", argv[i]);
        } else if (!strcmp(a, "--ice")) {
            d.ice = 1;
        } else if (!strcmp(a, "--bench") && i + 1 < argc) {
            if (!cli_parse_int(C, "--bench", argv[++i], 1, 1000000, &bench)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--threads") && i + 1 < argc) {
            if (!cli_parse_int(C, "--threads", argv[++i], 1, 1024, &threads)) return CLI_EXIT_USAGE;
        } else if (a[0] == '-') {
            return cli_usage_error(C, "unknown or incomplete option '%s'", a);
        } else if (!d.preset) {
            d.preset = a;
        } else {
            return cli_usage_error(C, "unexpected argument '%s'", a);
        }
    }
    if (!d.preset) return cli_usage_error(C, "which preset?");
    if (!atmos_sim_preset_minutes(d.preset)) {
        char list[256] = "";
        for (const char *const *n = atmos_sim_preset_names(); *n; n++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", *n, n[1] ? ", " : "");
        return cli_usage_error(C, "unknown preset '%s' (known: %s)", d.preset, list);
    }
    if (bench) return run_bench(&d, threads, bench);
    if (!out) return cli_usage_error(C, "missing -o NAME.json");
    if (cli_volume_output(C, "-o", out)) return CLI_EXIT_USAGE;
    static sim_outputs files; /* 45 kB: kept off the stack */
    if ((rc = check_outputs(out, d.ice, &files)) != CLI_EXIT_OK) return rc;
    rc = run_write(&d, threads, quiet, out);
    cli_outputs_discard(&files.set);
    return rc;
}
