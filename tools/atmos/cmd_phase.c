/* atmos phase: list the particle presets; print, summarise or plot a preset's phase table. */
#define _POSIX_C_SOURCE 200809L /* mkstemp, popen, fdopen, access */
#include "cli.h"
#include "outputs.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void help(void)
{
    printf("Usage: atmos phase                      list the particle presets\n"
           "       atmos phase PRESET [options]     build (or load from the cache) and show its phase table\n\n"
           "Options:\n"
           "  --wavelengths rgb|spectral:N   the paper's three channels (default) or N samples in 380-780 nm\n"
           "  --csv                          print the table: header theta_deg,<nm>,<nm>,... then one row\n"
           "                                 per tabulated angle, P in 1/sr (integral over the sphere = 1)\n"
           "  --plot OUT.png                 plot log P against the scattering angle, one curve per\n"
           "                                 wavelength, as a PNG (a .png name; a missing folder is made;\n"
           "                                 needs gnuplot: Debian package gnuplot-nox)\n"
           "  --orders                       multiple-scattering phase functions Ams_n (Riley et al. 2004\n"
           "                                 Eq. 20) instead: --csv prints n,theta_deg,<nm>,... for every\n"
           "                                 order n >= 1 and angle; --plot draws several orders; the\n"
           "                                 summary gives the highest order N and the forward fractions\n"
           "                                 F_n (Eq. 23, forward-scattered fraction) of orders 1..N if\n"
           "                                 N <= 6, else of orders 1, 2, 5, 10, 26 below N and the last order N\n"
           "  --max-order N                  with --orders: stop at order N (default: until isotropic to 1e-6)\n"
           "  --scene FILE                   also look PRESET up among the user-defined particle types of a\n"
           "                                 scene file (its \"particles\" section, docs/scene-format.md)\n"
           "  --no-cache                     neither read nor write the table cache (see 'atmos cache')\n"
           "  --fast                         preview quality (coarser size integration, fewer rays)\n"
           "  --threads N                    worker threads (default: all cores)\n"
           "  -q, --quiet                    no progress bar or status lines (warnings are still printed)\n"
           "  -h, --help                     show this help\n\n"
           "Without --csv or --plot, prints per wavelength the extinction cross-section, the albedo,\n"
           "the asymmetry g and P at 0 and 180 degrees.\n\n"
           "Examples:\n"
           "  atmos phase rain --plot rain.png\n"
           "  atmos phase cloud --wavelengths spectral:16 --csv > cloud.csv\n"
           "  atmos phase rain --orders --csv > rain_ams.csv\n");
    fputs(CLI_HELP_EXIT, stdout);
}

/* One line describing a preset, from its resolved description. */
static void describe(const atmos_particle_desc *p, char *buf, size_t cap)
{
    static const char *const sizes[] = {"radius", "lognormal median radius", "gamma mode radius"};
    const char *sk = (unsigned)p->size.kind < 3 ? sizes[p->size.kind] : "radius";
    char sigma[48] = "";
    if (p->sigma_ext_m2 > 0) snprintf(sigma, sizeof sigma, ", sigma_ext %.3g m^2", p->sigma_ext_m2);
    switch (p->kind) {
    case ATMOS_PARTICLE_AIR: snprintf(buf, cap, "air molecules: Rayleigh scattering, sigma_ext ~ lambda^-4%s", sigma); break;
    case ATMOS_PARTICLE_WATER:
        snprintf(buf, cap, "water spheres (Mie theory), %s %.4g um%s", sk, p->size.r_m * 1e6, sigma);
        break;
    case ATMOS_PARTICLE_ICE:
        if (p->size.r_m > 0)
            snprintf(buf, cap, "hexagonal ice %s, radius %.4g um (ray tracing + diffraction)%s",
                     p->habit == ATMOS_CRYSTAL_PLATE ? "plates" : "columns", p->size.r_m * 1e6, sigma);
        else
            snprintf(buf, cap, "hexagonal ice %s sized by their cross-section (ray tracing + diffraction)%s",
                     p->habit == ATMOS_CRYSTAL_PLATE ? "plates" : "columns", sigma);
        break;
    case ATMOS_PARTICLE_SNOW:
        if (p->size.r_m > 0)
            snprintf(buf, cap, "irregular (distorted) ice crystals, radius %.4g um%s", p->size.r_m * 1e6, sigma);
        else
            snprintf(buf, cap, "irregular (distorted) ice crystals sized by their cross-section%s", sigma);
        break;
    case ATMOS_PARTICLE_ANALYTIC: snprintf(buf, cap, "analytic mixture of %d lobes%s", p->analytic.count, sigma); break;
    default: snprintf(buf, cap, "particle kind %d", (int)p->kind); break;
    }
}

static void known_presets(char *buf, size_t cap)
{
    const char *const *names = atmos_particle_preset_names();
    size_t n = 0;
    buf[0] = '\0';
    for (int i = 0; names && names[i] && n < cap; i++) n += (size_t)snprintf(buf + n, cap - n, "%s%s", i ? ", " : "", names[i]);
}

static int list_presets(void)
{
    const char *const *names = atmos_particle_preset_names();
    atmos_context *ctx = cli_context(1, 0);
    if (!ctx) return CLI_EXIT_RUNTIME;
    printf("Particle presets (atmos phase PRESET --help for options):\n");
    for (int i = 0; names && names[i]; i++) {
        atmos_particle_desc p;
        char line[256];
        if (atmos_particle_preset(ctx, names[i], &p) == ATMOS_OK) describe(&p, line, sizeof line);
        else snprintf(line, sizeof line, "(cannot resolve: %s)", atmos_context_error(ctx));
        printf("  %-8s %s\n", names[i], line);
    }
    atmos_context_destroy(ctx);
    return CLI_EXIT_OK;
}

/* Parses rgb | spectral | spectral:N. */
static int parse_wavelengths(const char *C, const char *text, atmos_wavelengths *wl)
{
    if (!strcmp(text, "rgb")) {
        atmos_wavelengths_rgb(wl);
        return 1;
    }
    int n = ATMOS_SPECTRAL_DEFAULT;
    if (!strcmp(text, "spectral") ||
        (!strncmp(text, "spectral:", 9) && cli_parse_int(C, "--wavelengths spectral:N", text + 9, 1, ATMOS_MAX_WAVELENGTHS, &n))) {
        return atmos_wavelengths_spectral(n, wl) == ATMOS_OK;
    }
    if (strncmp(text, "spectral:", 9) != 0)
        fprintf(stderr, "atmos %s: --wavelengths: expected rgb or spectral:N, got '%s'\n", C, text);
    return 0;
}

static void print_csv(const atmos_phase_table *t)
{
    const double *theta;
    int n = atmos_phase_grid(&theta), nw = atmos_phase_table_wavelength_count(t);
    printf("theta_deg");
    /* %.10g: 680 prints as "680", a bin centre as "392.5". */
    for (int k = 0; k < nw; k++) printf(",%.10g", atmos_phase_table_wavelength_nm(t, k));
    putchar('\n');
    for (int i = 0; i < n; i++) {
        printf("%.10g", theta[i]);
        for (int k = 0; k < nw; k++) printf(",%.9g", atmos_phase_table_values(t, k)[i]);
        putchar('\n');
    }
}

static void print_summary(const char *preset, const atmos_phase_table *t)
{
    int nw = atmos_phase_table_wavelength_count(t);
    printf("phase table '%s'%s: %d wavelengths, P in 1/sr normalised over the sphere\n", preset,
           atmos_phase_table_from_cache(t) ? " (from the cache)" : "", nw);
    printf("%10s %14s %8s %9s %14s %14s\n", "nm", "sigma_ext_m2", "albedo", "g", "P(0)", "P(180)");
    for (int k = 0; k < nw; k++) {
        const double *v = atmos_phase_table_values(t, k);
        const double *theta;
        int n = atmos_phase_grid(&theta);
        printf("%10.6g %14.6g %8.5f %9.6f %14.6g %14.6g\n", atmos_phase_table_wavelength_nm(t, k),
               atmos_phase_table_sigma_ext(t, k), atmos_phase_table_albedo(t, k), atmos_phase_table_g(t, k), v[0],
               v[n - 1]);
    }
}

/* ------------------------------------------------------------------ plotting with gnuplot */

static int find_in_path(const char *prog)
{
    const char *path = getenv("PATH");
    if (!path) return 0;
    char dir[4096];
    while (*path) {
        size_t n = strcspn(path, ":");
        if (n > 0 && n + strlen(prog) + 2 < sizeof dir) {
            snprintf(dir, sizeof dir, "%.*s/%s", (int)n, path, prog);
            if (access(dir, X_OK) == 0) return 1;
        }
        path += n;
        if (*path == ':') path++;
    }
    return 0;
}

/* A gnuplot double-quoted string (backslash escapes). */
/* A gnuplot single-quoted string: no escapes and, unlike double quotes, no backquote
 * command substitution; a quote is written twice; control characters are dropped. */
static void gp_quote(FILE *f, const char *s)
{
    fputc('\'', f);
    for (; *s; s++) {
        if ((unsigned char)*s < 0x20) continue;
        if (*s == '\'') fputc('\'', f);
        fputc(*s, f);
    }
    fputc('\'', f);
}

/* Line colour of a wavelength: its CIE 1931 colour in sRGB, brightened. */
static unsigned wavelength_colour(double nm)
{
    double xyz[3], rgb[3];
    atmos_cie_xyz_cmf(nm, xyz);
    atmos_xyz_to_srgb(xyz, rgb);
    double m = 0;
    for (int c = 0; c < 3; c++) {
        if (!(rgb[c] > 0)) rgb[c] = 0;
        if (rgb[c] > m) m = rgb[c];
    }
    unsigned out = 0;
    for (int c = 0; c < 3; c++) {
        double v = m > 0 ? pow(rgb[c] / m, 1 / 2.2) * 0.85 : 0.4;
        out = (out << 8) | (unsigned)lround(v * 255);
    }
    return out;
}

/* Curves to plot: n_curves columns over the angles theta[0..n). */
typedef struct {
    int n, n_curves;
    const double *theta;
    const double *(*column)(const void *src, int curve);
    void (*label)(const void *src, int curve, char *buf, size_t cap, unsigned *colour);
    const void *src;
    const char *ylabel;
} plot_data;

static const double *table_column(const void *src, int k) { return atmos_phase_table_values(src, k); }
static void table_label(const void *src, int k, char *buf, size_t cap, unsigned *colour)
{
    double nm = atmos_phase_table_wavelength_nm(src, k);
    snprintf(buf, cap, "%.10g nm", nm);
    *colour = wavelength_colour(nm);
}

/* Orders shown by --orders --plot: a few, spread over the tabulated range. */
static const int plot_orders[] = {1, 2, 3, 5, 10, 20, 50, 100, 200, 500};
typedef struct {
    const atmos_msphase *m;
    int k;
} orders_src;
static const double *orders_column(const void *src, int c)
{
    const orders_src *o = src;
    return atmos_msphase_values(o->m, o->k, plot_orders[c]);
}
static void orders_label(const void *src, int c, char *buf, size_t cap, unsigned *colour)
{
    (void)src;
    static const unsigned colours[] = {0x1b3a8c, 0x2166ac, 0x4393c3, 0x1a9850, 0x66bd63, 0xa6d96a, 0xfdae61, 0xf46d43, 0xd73027, 0x7f0000};
    snprintf(buf, cap, "n = %d", plot_orders[c]);
    *colour = colours[c % 10];
}

static int plot_png(const char *C, const char *title_text, const plot_data *pd, const char *out)
{
    if (strchr(out, '\n')) return cli_usage_error(C, "--plot: file name contains a newline");
    if (!find_in_path("gnuplot")) {
        fprintf(stderr, "atmos %s: --plot needs gnuplot, which is not installed or not on PATH "
                        "(Debian: apt-get install gnuplot-nox)\n", C);
        return CLI_EXIT_RUNTIME;
    }
    const char *tmpdir = getenv("TMPDIR");
    char data[4096];
    snprintf(data, sizeof data, "%s/atmos-phase-XXXXXX", tmpdir && *tmpdir ? tmpdir : "/tmp");
    int fd = mkstemp(data);
    FILE *df = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!df) {
        fprintf(stderr, "atmos %s: cannot create a temporary file: %s\n", C, strerror(errno));
        if (fd >= 0) close(fd), remove(data);
        return CLI_EXIT_RUNTIME;
    }
    const double *theta = pd->theta;
    int n = pd->n, nw = pd->n_curves;
    for (int i = 0; i < n; i++) {
        fprintf(df, "%.10g", theta[i]);
        for (int k = 0; k < nw; k++) {
            double v = pd->column(pd->src, k)[i];
            fprintf(df, " %.9g", v > 0 ? v : 1e-300); /* log axis: no zeros */
        }
        fputc('\n', df);
    }
    int data_ok = fclose(df) == 0;
    /* gnuplot writes into a private temporary file whose name we made (mkstemp: no
     * characters gnuplot would interpret, e.g. backquotes, which it executes); the PNG is
     * then copied to the user's path by the library's atomic writer, so a bad output path
     * gives one clear error and never a partial file. */
    char tmp_png[4096];
    snprintf(tmp_png, sizeof tmp_png, "%s/atmos-plot-XXXXXX", tmpdir && *tmpdir ? tmpdir : "/tmp");
    int pfd = mkstemp(tmp_png);
    if (pfd >= 0) close(pfd);
    int rc = CLI_EXIT_RUNTIME;
    FILE *gp = data_ok && pfd >= 0 ? popen("gnuplot", "w") : NULL;
    if (gp) {
        fprintf(gp, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) { set terminal pngcairo size 1000,640 } "
                    "else { set terminal png size 1000,640 }\n");
        fprintf(gp, "set output ");
        gp_quote(gp, tmp_png);
        fprintf(gp, "\nset title ");
        gp_quote(gp, title_text);
        fprintf(gp, " noenhanced\nset logscale y\nset format y '10^{%%L}'\nset xrange [0:180]\nset xtics 20\n"
                    "set mxtics 2\nset grid\nset xlabel 'scattering angle (degrees)'\n"
                    "set ylabel ");
        gp_quote(gp, pd->ylabel);
        fprintf(gp, "\nset key top right\nplot ");
        for (int k = 0; k < nw; k++) {
            char label[64];
            unsigned colour = 0;
            pd->label(pd->src, k, label, sizeof label, &colour);
            fprintf(gp, "%s", k ? ", " : "");
            gp_quote(gp, data);
            fprintf(gp, " using 1:%d with lines lw 1.5 lc rgb '#%06x' title ", k + 2, colour);
            gp_quote(gp, label);
        }
        fprintf(gp, "\nset output\n");
        int st = pclose(gp);
        if (st != 0) {
            fprintf(stderr, "atmos %s: gnuplot failed (status %d)\n", C, st);
        } else {
            atmos_context *ctx = cli_context(1, 1);
            atmos_status ws = ctx ? atmos_copy_file_atomic(ctx, tmp_png, out) : ATMOS_E_NOMEM;
            if (ws == ATMOS_OK) rc = CLI_EXIT_OK;
            else cli_runtime_error(C, ctx, ws);
            atmos_context_destroy(ctx);
        }
    } else {
        fprintf(stderr, "atmos %s: cannot run gnuplot: %s\n", C, strerror(errno));
    }
    if (pfd >= 0) remove(tmp_png);
    remove(data);
    return rc;
}

/* Ams_n as CSV: n,theta_deg,<nm>,... for n = 1..max_order (Ams_0 is the collimated
 * beam, a delta function, and has no table). */
static void print_orders_csv(const atmos_phase_table *t, const atmos_msphase *m)
{
    int nw = atmos_msphase_wavelength_count(m), N = atmos_msphase_max_order(m);
    const double *grid;
    int ng = atmos_msphase_grid(m, &grid);
    printf("n,theta_deg");
    for (int k = 0; k < nw; k++) printf(",%.10g", atmos_phase_table_wavelength_nm(t, k));
    putchar('\n');
    for (int n = 1; n <= N; n++)
        for (int j = 0; j < ng; j++) {
            printf("%d,%.10g", n, grid[j]);
            for (int k = 0; k < nw; k++) printf(",%.9g", atmos_msphase_values(m, k, n)[j]);
            putchar('\n');
        }
}

/* The orders whose forward fraction the summary shows: all of 1..N for N <= 6, else 1, 2,
 * 5, 10, 26 up to N and N itself (beyond N every order is isotropic, F = 0.5). */
static int summary_orders(int N, int *ord)
{
    static const int fixed[] = {1, 2, 5, 10, 26};
    int n = 0;
    if (N <= 6) {
        for (int i = 1; i <= N; i++) ord[n++] = i;
        return n;
    }
    for (int i = 0; i < 5 && fixed[i] < N; i++) ord[n++] = fixed[i];
    ord[n++] = N;
    return n;
}

static void print_orders_summary(const char *preset, const atmos_phase_table *t, const atmos_msphase *m, double secs)
{
    int nw = atmos_msphase_wavelength_count(m), N = atmos_msphase_max_order(m), ord[6];
    int no = summary_orders(N, ord);
    printf("multiple-scattering phase functions '%s': orders 1..%d (isotropic beyond), %s in %.3f s\n", preset, N,
           atmos_msphase_from_cache(m) ? "loaded from the cache" : "built", secs);
    printf("%10s", "nm");
    for (int i = 0; i < no; i++) {
        char h[16];
        snprintf(h, sizeof h, "F_%d", ord[i]);
        printf(" %10s", h);
    }
    printf(" %12s\n", "legendre_l");
    for (int k = 0; k < nw; k++) {
        printf("%10.10g", atmos_phase_table_wavelength_nm(t, k));
        for (int i = 0; i < no; i++) printf(" %10.6f", atmos_msphase_forward(m, k, ord[i]));
        printf(" %12d\n", atmos_msphase_legendre_count(m, k));
    }
}

/* ------------------------------------------------------------------ the command */

int cli_cmd_phase(int argc, char **argv)
{
    const char *C = "phase";
    const char *preset = NULL, *plot = NULL, *scene_path = NULL;
    int csv = 0, no_cache = 0, fast = 0, threads = 0, quiet = 0, orders = 0, max_order = 0;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help();
            return CLI_EXIT_OK;
        } else if (!strcmp(a, "--wavelengths") && i + 1 < argc) {
            if (!parse_wavelengths(C, argv[++i], &wl)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--plot") && i + 1 < argc) {
            plot = argv[++i];
        } else if (!strcmp(a, "--threads") && i + 1 < argc) {
            if (!cli_parse_int(C, "--threads", argv[++i], 1, 1024, &threads)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--scene") && i + 1 < argc) {
            scene_path = argv[++i];
        } else if (!strcmp(a, "--orders")) {
            orders = 1;
        } else if (!strcmp(a, "--max-order") && i + 1 < argc) {
            if (!cli_parse_int(C, "--max-order", argv[++i], 1, 1000, &max_order)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--csv")) {
            csv = 1;
        } else if (!strcmp(a, "--no-cache")) {
            no_cache = 1;
        } else if (!strcmp(a, "--fast")) {
            fast = 1;
        } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            quiet = 1;
        } else if (a[0] == '-') {
            return cli_usage_error(C, "unknown or incomplete option '%s'", a);
        } else if (!preset) {
            preset = a;
        } else {
            return cli_usage_error(C, "unexpected argument '%s' (one preset at a time)", a);
        }
    }
    if (!preset) {
        if (csv || plot || no_cache || fast || orders) return cli_usage_error(C, "which preset? ('atmos phase' lists them)");
        return list_presets();
    }
    const char *const *names = atmos_particle_preset_names();
    int known = 0;
    for (int i = 0; names && names[i]; i++) known |= !strcmp(names[i], preset);
    if (!known && !scene_path) {
        char list[256];
        known_presets(list, sizeof list);
        return cli_usage_error(C, "unknown preset '%s' (known presets: %s; user-defined types need --scene)", preset, list);
    }
    if (plot && !*plot) return cli_usage_error(C, "--plot: empty file name");
    /* the rules between the options and the output's name, before any work */
    if (max_order && !orders) return cli_usage_error(C, "--max-order goes with --orders");
    if (plot && cli_png_output(C, "--plot", plot)) return CLI_EXIT_USAGE;
    if (plot && cli_output_folder(C, "--plot", plot)) return CLI_EXIT_RUNTIME;

    cli_progress prog;
    cli_progress_init(&prog, quiet);
    atmos_context *ctx = cli_context_with_progress(threads, 0, cli_progress_bar, &prog); /* -q keeps warnings */
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_particle_desc p;
    atmos_phase_table *t = NULL;
    atmos_status st;
    if (scene_path) {
        /* User-defined particle types of a scene file ("particles"), or presets. */
        static atmos_scene scene;
        st = atmos_scene_load(ctx, scene_path, &scene);
        if (st == ATMOS_OK) st = atmos_scene_particle(ctx, &scene, preset, &p);
    } else {
        st = atmos_particle_preset(ctx, preset, &p);
    }
    if (st == ATMOS_OK) {
        if (fast) p.fast = 1;
        atmos_phase_table_desc td = {no_cache};
        st = atmos_phase_table_build(ctx, &p, &wl, &td, &t);
    }
    if (st != ATMOS_OK) {
        int rc = cli_runtime_error(C, ctx, st);
        atmos_context_destroy(ctx);
        return rc;
    }
    int rc = CLI_EXIT_OK;
    char title[160];
    if (orders) {
        atmos_msphase *m = NULL;
        atmos_msphase_desc md = {0};
        md.max_order = max_order;
        md.no_cache = no_cache;
        double t0 = cli_now_s();
        st = atmos_msphase_build(ctx, t, &md, &m);
        double secs = cli_now_s() - t0;
        if (st != ATMOS_OK) {
            rc = cli_runtime_error(C, ctx, st);
        } else {
            if (csv) print_orders_csv(t, m);
            if (plot) {
                int nc = 0;
                while (nc < (int)(sizeof plot_orders / sizeof *plot_orders) && plot_orders[nc] <= atmos_msphase_max_order(m)) nc++;
                int k = atmos_msphase_wavelength_count(m) / 2;
                orders_src os = {m, k};
                const double *grid;
                int ng = atmos_msphase_grid(m, &grid);
                snprintf(title, sizeof title, "multiple-scattering phase functions Ams_n: %s, %.10g nm", preset,
                         atmos_phase_table_wavelength_nm(t, k));
                plot_data pd = {ng, nc, grid, orders_column, orders_label, &os, "Ams_n (1/sr)"};
                rc = plot_png(C, title, &pd, plot);
            }
            if (!csv && !plot) print_orders_summary(preset, t, m, secs);
        }
        atmos_msphase_destroy(m);
    } else {
        if (csv) print_csv(t);
        if (plot) {
            const double *theta;
            int n = atmos_phase_grid(&theta);
            snprintf(title, sizeof title, "phase function: %s", preset);
            plot_data pd = {n, atmos_phase_table_wavelength_count(t), theta, table_column, table_label, t,
                            "P (1/sr), integral over the sphere = 1"};
            rc = plot_png(C, title, &pd, plot);
        }
        if (!csv && !plot) print_summary(preset, t);
    }
    if (plot && rc == CLI_EXIT_OK && !quiet) fprintf(stderr, "atmos %s: wrote %s\n", C, plot);
    atmos_phase_table_destroy(t);
    atmos_context_destroy(ctx);
    return rc;
}
