/* atmos bench sky-accuracy: each atmosphere model's view radiance against the reference
 * (atmos_atmosphere_reference_radiance) on a fixed set of views, observers from the ground
 * to 36 000 km and suns from the zenith to 10 degrees below the horizon
 * (docs/sky-accuracy.md). This file builds the grid and measures; bench_sky_report.c
 * writes the tables, CSV files and error maps. */
#define _POSIX_C_SOURCE 200809L /* strtok_r */
#include "bench_sky.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static const atmos_atmosphere_kind acc_kinds[ACC_MODELS] = {ATMOS_ATMOSPHERE_RILEY, ATMOS_ATMOSPHERE_DOBASHI,
                                                            ATMOS_ATMOSPHERE_SPHERICAL};

#define DEG (3.14159265358979323846 / 180.0)

static void help(void)
{
    printf("Usage: atmos bench sky-accuracy [--quick] [--paths N] [--target-se X] [--max-paths N]\n"
           "                                [--models riley,dobashi,spherical] [--spectral N] [--seed S]\n"
           "                                [--threads T] [--out DIR] [--map-range X] [--floor X]\n"
           "                                [--altitudes LIST] [--suns LIST]\n"
           "                                [--refine FILE [--refine-above X] [--refine-sigmas K]]\n\n"
           "Compares each model's view radiance (atmos_atmosphere_radiance, the sun's disk hidden) with\n"
           "the reference (atmos_atmosphere_reference_radiance: Monte Carlo walks, all orders) on a fixed\n"
           "grid: observers at 0, 10, 100, 1000 and 36 000 km above the ground, suns at 90, 45, 10, 2,\n"
           "-2, -6 and -10 degrees, views of the sky, the limb, the planet's disk and space at 5\n"
           "azimuths from the sun's (docs/sky-accuracy.md). Prints per (model, altitude, sun) the RMS\n"
           "and the worst relative error of the luminance Y and of each wavelength's radiance, with the\n"
           "reference's own relative standard error, as Markdown tables.\n\n"
           "  --quick          a small grid (0 and 36 000 km; suns 45 and -6; 14 views) for tests\n"
           "  --paths N        reference walks per wavelength per batch (default 4096)\n"
           "  --target-se X    add batches until the reference's relative standard error of Y is <= X\n"
           "                   (default 0: one batch)\n"
           "  --max-paths N    cap on the walks per wavelength of one view (default 64 x --paths)\n"
           "  --models LIST    comma-separated models (default riley,dobashi,spherical)\n"
           "  --altitudes LIST observer altitudes in km instead of the grid's (up to 8; e.g. 0,36000)\n"
           "  --suns LIST      sun elevations in degrees instead of the grid's (up to 8; e.g. 10,-6)\n"
           "  --spectral N     N wavelengths in 380-780 nm (default rgb: 680, 550, 440 nm)\n"
           "  --seed S         the reference's seed (default 1); the same seed gives the same figures\n"
           "  --threads T      views computed in parallel (default: all cores); figures do not depend on T\n"
           "  --out DIR        also write DIR/table.md, DIR/results.csv (every view), DIR/summary.csv and\n"
           "                   DIR/error_map_MODEL.png (signed error of Y per view, docs/sky-accuracy.md)\n"
           "  --map-range X    the maps' colours saturate at +-X (default 0.1 = 10 %%)\n"
           "  --floor X        relative errors are |model - ref| / max(ref, X * the block's largest ref)\n"
           "                   (default 1e-3), so that views far darker than the rest do not dominate\n"
           "  --refine FILE    take every view's reference from FILE (the results.csv of a run with the same\n"
           "                   --quick, --altitudes, --suns, --spectral, --seed and --paths) and measure again,\n"
           "                   from their first batch with their own seeds, the views whose |relative error of\n"
           "                   Y| in FILE (for a model of --models) exceeds --refine-above X (default 0.03),\n"
           "                   with --target-se and --max-paths; the report lists them before and after\n"
           "  --refine-sigmas K  ... also the views whose error could exceed X within K of FILE's standard\n"
           "                   errors (|error| + K s.e. > X; default 0)\n");
    fputs(CLI_HELP_EXIT, stdout);
}

/* ------------------------------------------------------------------ the grid */

static void add_view(acc_view *out, int *n, int quick, double zen, const char *cls, double param)
{
    static const double az_full[] = {0, 45, 90, 135, 180}, az_quick[] = {0, 180};
    const double *az = quick ? az_quick : az_full;
    const int naz = quick ? 2 : 5;
    const int degenerate = zen < 1e-9 || zen > 180 - 1e-9;
    for (int i = 0; i < (degenerate ? 1 : naz) && *n < ACC_MAX_VIEWS; i++)
        out[(*n)++] = (acc_view){zen, az[i], cls, param};
}

/* The views of an observer at altitude h (planet radius R, top of the air at top):
 *  - sky: zenith angles 0, 30, 60, 75, 85, 89 degrees that miss the ground (below the top);
 *  - space: from at or above the top, the zenith and the ray passing 150 km above the ground;
 *  - limb: rays descending to a tangent altitude of 1, 3, 6, 10, 20, 35, 60 km (below h);
 *  - disk: rays meeting the ground with impact parameter f R, f = 0, .5, .8, .95, .99, .998
 *    (f = 0: the nadir; f -> 1: grazing the ground at the horizon).
 * Each at azimuths 0, 45, 90, 135, 180 degrees from the sun's (one at the zenith and nadir). */
static int acc_views(double h, double R, double top, int quick, acc_view *out)
{
    static const double sky_full[] = {0, 30, 60, 75, 85, 89}, sky_quick[] = {0, 60, 89};
    static const double limb_full[] = {1e3, 3e3, 6e3, 10e3, 20e3, 35e3, 60e3}, limb_quick[] = {10e3};
    static const double disk_full[] = {0, 0.5, 0.8, 0.95, 0.99, 0.998}, disk_quick[] = {0, 0.9};
    const double r0 = R + h, horizon = 180.0 - asin(fmin(R / r0, 1.0)) / DEG;
    int n = 0;
    if (h < top) {
        const double *z = quick ? sky_quick : sky_full;
        for (int i = 0; i < (quick ? 3 : 6); i++)
            if (z[i] < horizon) add_view(out, &n, quick, z[i], "sky", 0);
    } else {
        add_view(out, &n, quick, 0, "space", 0);
        if (!quick && 150e3 < h) add_view(out, &n, quick, 180.0 - asin((R + 150e3) / r0) / DEG, "space", 150e3);
    }
    const double *l = quick ? limb_quick : limb_full;
    for (int i = 0; i < (quick ? 1 : 7); i++)
        if (l[i] < h - 1.0) add_view(out, &n, quick, 180.0 - asin((R + l[i]) / r0) / DEG, "limb", l[i]);
    const double *f = quick ? disk_quick : disk_full;
    for (int i = 0; i < (quick ? 2 : 6); i++)
        add_view(out, &n, quick, 180.0 - asin(f[i] * R / r0) / DEG, "disk", f[i]);
    return n;
}

static void acc_grid(acc_run *r, const acc_opts *o, double R, double top)
{
    static const double alt_full[] = {0, 10e3, 100e3, 1000e3, 36000e3}, alt_quick[] = {0, 36000e3};
    static const double sun_full[] = {90, 45, 10, 2, -2, -6, -10}, sun_quick[] = {45, -6};
    r->nalt = o->nalt ? o->nalt : o->quick ? 2 : 5;
    r->nsun = o->nsun ? o->nsun : o->quick ? 2 : 7;
    for (int a = 0; a < r->nalt; a++) {
        r->alt_m[a] = o->nalt ? o->alt_m[a] : o->quick ? alt_quick[a] : alt_full[a];
        r->nview[a] = acc_views(r->alt_m[a], R, top, o->quick, r->view[a]);
    }
    for (int s = 0; s < r->nsun; s++) r->sun_deg[s] = o->nsun ? o->sun_deg[s] : o->quick ? sun_quick[s] : sun_full[s];
}

/* ------------------------------------------------------------------ measuring */

static unsigned long long mix64(unsigned long long x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/* The reference along one view: adds batches of o->paths walks (batch b with its own seed)
 * to the view's running estimate (L, se: the batches' mean and the standard error of that
 * mean over *used walks) until the standard error of Y is at most o->target_se times
 * max(Y, y_floor) or the walks would pass o->max_paths; first_only: one batch. */
static atmos_status reference_more(const atmos_atmosphere *ref, const acc_opts *o, const atmos_wavelengths *wl,
                                   const double p[3], const double d[3], const double sun[3],
                                   unsigned long long seed, double y_floor, int first_only, double *L, double *se,
                                   long *used)
{
    const int n = wl->count;
    int batches = (int)(*used / o->paths);
    double sum[ATMOS_MAX_WAVELENGTHS], var[ATMOS_MAX_WAVELENGTHS];
    double b[ATMOS_MAX_WAVELENGTHS], bse[ATMOS_MAX_WAVELENGTHS];
    for (int k = 0; k < n; k++) sum[k] = L[k] * batches, var[k] = se[k] * batches * se[k] * batches;
    for (;;) {
        if (batches > 0) {
            double vy = 0;
            for (int k = 0; k < n; k++) vy += wl->to_xyz[k][1] * wl->to_xyz[k][1] * se[k] * se[k];
            const double y = acc_luminance(wl, L);
            if (first_only || !(o->target_se > 0) || sqrt(vy) <= o->target_se * fmax(fabs(y), y_floor) ||
                (long)(batches + 1) * o->paths > o->max_paths)
                break;
        }
        atmos_status st =
            atmos_atmosphere_reference_radiance(ref, p, d, sun, o->paths, mix64(seed + (unsigned)batches), 0, b, bse);
        if (st != ATMOS_OK) return st;
        batches++;
        for (int k = 0; k < n; k++) {
            sum[k] += b[k], var[k] += bse[k] * bse[k];
            L[k] = sum[k] / batches;
            se[k] = sqrt(var[k]) / batches;
        }
    }
    *used = (long)batches * o->paths;
    return ATMOS_OK;
}

/* The observer, the sun and the view direction of grid point (a, s, v): the observer above
 * the origin (on the planet's axis), the sun at azimuth 180 degrees. */
static void view_geometry(const acc_run *r, int a, int s, int v, double p[3], double sun[3], double d[3])
{
    const acc_view *w = &r->view[a][v];
    p[0] = 0, p[1] = r->alt_m[a], p[2] = 0;
    atmos_direction_from_angles(r->sun_deg[s], 180.0, sun);
    atmos_direction_from_angles(90.0 - w->zenith_deg, 180.0 + w->dazimuth_deg, d);
}

static int omp_threads(const acc_opts *o)
{
    int nt = o->threads;
#ifdef _OPENMP
    if (nt <= 0) nt = omp_get_max_threads();
#endif
    return nt > 0 ? nt : 1;
}

static unsigned long long view_seed(const acc_opts *o, int t)
{
    return o->seed * 0x100000001ull + (unsigned long long)t * 977u;
}

/* Grid point t of the parallel loops: its indices and geometry; 0 past the altitude's views. */
static int grid_point(const acc_run *r, int t, int *a, int *s, double p[3], double sun[3], double d[3], size_t *i)
{
    *a = t / (r->nsun * ACC_MAX_VIEWS), *s = t / ACC_MAX_VIEWS % r->nsun;
    const int v = t % ACC_MAX_VIEWS;
    if (v >= r->nview[*a]) return 0;
    view_geometry(r, *a, *s, v, p, sun, d);
    *i = acc_index(r, *a, *s, v);
    return 1;
}

/* Every view of the grid: one batch of the reference and each model (NAN where a model is
 * n/a: Riley's flat earth from 36 000 km). */
static atmos_status measure_first(acc_run *r, const acc_opts *o, const atmos_atmosphere *ref,
                                  atmos_atmosphere *const *models)
{
    const int total = r->nalt * r->nsun * ACC_MAX_VIEWS, n = r->wl.count;
    int failed = 0, done = 0, views = 0;
    for (int a = 0; a < r->nalt; a++) views += r->nsun * r->nview[a];
#pragma omp parallel for schedule(dynamic, 1) num_threads(omp_threads(o))
    for (int t = 0; t < total; t++) {
        int a, s;
        double p[3], sun[3], d[3];
        size_t i;
        if (!grid_point(r, t, &a, &s, p, sun, d, &i)) continue;
        const size_t j = i / (size_t)n;
        if (r->pick && r->pick[j]) { /* --refine: from the first batch again */
            memset(r->ref + i, 0, sizeof(double) * (size_t)n), memset(r->se + i, 0, sizeof(double) * (size_t)n);
            r->paths_used[j] = 0;
        }
        if ((!r->pick || r->pick[j]) && reference_more(ref, o, &r->wl, p, d, sun, view_seed(o, t), 0, 1, r->ref + i,
                                                       r->se + i, r->paths_used + j) != ATMOS_OK) {
#pragma omp atomic write
            failed = 1;
            continue;
        }
        for (int m = 0; m < ACC_MODELS; m++) {
            if (!models[m]) continue;
            if (m == 0 && r->alt_m[a] > 20000e3) {
                for (int k = 0; k < n; k++) r->mod[m][i + (size_t)k] = NAN;
                continue;
            }
            atmos_atmosphere_radiance(models[m], p, d, sun, r->mod[m] + i, NULL);
        }
#pragma omp critical(acc_progress)
        cli_progress_bar(cli_shared_progress(), "sky accuracy: first batch", (double)++done / views);
    }
    return failed ? ATMOS_E_INVALID_ARG : ATMOS_OK;
}

/* With a target standard error: more batches for each view until its standard error of Y
 * is at most the target times max(Y, floor x the block's largest Y after the first batch),
 * the denominator of its relative errors (views far darker than their block stop early). */
static atmos_status measure_refine(acc_run *r, const acc_opts *o, const atmos_atmosphere *ref)
{
    if (!(o->target_se > 0)) return ATMOS_OK;
    const int total = r->nalt * r->nsun * ACC_MAX_VIEWS, n = r->wl.count;
    double ymax[8][8] = {{0}};
    int failed = 0, views = 0, done = 0;
    for (int a = 0; a < r->nalt; a++)
        for (int s = 0; s < r->nsun; s++) {
            ymax[a][s] = acc_block_max(r, a, s, -1);
            for (int v = 0; v < r->nview[a]; v++) views += !r->pick || r->pick[acc_index(r, a, s, v) / (size_t)n];
        }
#pragma omp parallel for schedule(dynamic, 1) num_threads(omp_threads(o))
    for (int t = 0; t < total; t++) {
        int a, s;
        double p[3], sun[3], d[3];
        size_t i;
        if (!grid_point(r, t, &a, &s, p, sun, d, &i) || (r->pick && !r->pick[i / (size_t)n])) continue;
        if (reference_more(ref, o, &r->wl, p, d, sun, view_seed(o, t), o->floor * ymax[a][s], 0, r->ref + i,
                           r->se + i, r->paths_used + i / (size_t)n) != ATMOS_OK) {
#pragma omp atomic write
            failed = 1;
        }
#pragma omp critical(acc_progress)
        cli_progress_bar(cli_shared_progress(), "sky accuracy: refining", (double)++done / views);
    }
    return failed ? ATMOS_E_INVALID_ARG : ATMOS_OK;
}

/* ------------------------------------------------------------------ statistics */

/* The reference's relative standard error of Y over block (a, s): RMS and max over its
 * views (the same for every model). */
static void block_se(const acc_run *r, const acc_opts *o, int a, int s, acc_stats *st)
{
    const double ymax = acc_block_max(r, a, s, -1);
    st->se_rms_y = st->se_max_y = 0;
    for (int v = 0; v < r->nview[a]; v++) {
        const size_t i = acc_index(r, a, s, v);
        double vy = 0;
        for (int k = 0; k < r->wl.count; k++) vy += pow(r->wl.to_xyz[k][1] * r->se[i + (size_t)k], 2);
        const double y = acc_luminance(&r->wl, r->ref + i), den = fmax(y, o->floor * ymax);
        const double rse = den > 0 ? sqrt(vy) / den : 0.0;
        st->se_rms_y += rse * rse;
        st->se_max_y = fmax(st->se_max_y, rse);
    }
    if (r->nview[a]) st->se_rms_y = sqrt(st->se_rms_y / r->nview[a]);
}

static void acc_block_stats(const acc_run *r, const acc_opts *o, int m, int a, int s, acc_stats *st)
{
    const int n = r->wl.count;
    memset(st, 0, sizeof *st);
    block_se(r, o, a, s, st);
    double e[ATMOS_MAX_WAVELENGTHS];
    for (int v = 0; v < r->nview[a]; v++) {
        const size_t i = acc_index(r, a, s, v);
        if (isnan(r->mod[m][i])) continue;
        const double ey = acc_rel_errors(r, o, m, a, s, v, e);
        st->views++;
        st->rms_y += ey * ey;
        if (fabs(ey) > fabs(st->worst_y)) st->worst_y = ey;
        for (int k = 0; k < n; k++) {
            st->rms[k] += e[k] * e[k];
            if (fabs(e[k]) > fabs(st->worst[k])) st->worst[k] = e[k];
        }
    }
    if (!st->views) return;
    st->rms_y = sqrt(st->rms_y / st->views);
    for (int k = 0; k < n; k++) st->rms[k] = sqrt(st->rms[k] / st->views);
}

/* ------------------------------------------------------------------ the command */

static int parse_models(const char *list, int use[ACC_MODELS])
{
    char buf[256];
    if (!*list || strlen(list) >= sizeof buf) return 0;
    snprintf(buf, sizeof buf, "%s", list);
    memset(use, 0, sizeof(int) * ACC_MODELS);
    for (char *save = NULL, *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        int found = 0;
        for (int m = 0; m < ACC_MODELS; m++)
            if (!strcmp(t, acc_model_names[m])) use[m] = found = 1;
        if (!found) return 0;
    }
    return 1;
}

/* A comma-separated list of at most 8 numbers in [lo, hi], times scale. */
static int parse_list(const char *text, double lo, double hi, double scale, double *out, int *n)
{
    char buf[256];
    if (!*text || strlen(text) >= sizeof buf) return 0;
    snprintf(buf, sizeof buf, "%s", text);
    *n = 0;
    for (char *save = NULL, *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        char *end;
        const double v = strtod(t, &end);
        if (*end || end == t || !(v >= lo && v <= hi) || *n >= 8) return 0;
        out[(*n)++] = v * scale;
    }
    return *n > 0;
}

static int parse_opts(int argc, char **argv, acc_opts *o)
{
    const char *C = "bench sky-accuracy";
    int spectral = 0;
    double seed = 1, paths = 4096, max_paths = 0;
    int refine_knob = 0; /* --refine-above or --refine-sigmas given */
    *o = (acc_opts){.use = {1, 1, 1}, .map_range = 0.1, .floor = 1e-3, .refine_above = 0.03};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help();
            return -1;
        } else if (!strcmp(a, "--quick")) {
            o->quick = 1;
            continue;
        } else if (!val || a[0] != '-') {
            return cli_usage_error(C, "unknown or incomplete option '%s'", a);
        } else if (!strcmp(a, "--paths")) {
            if (!cli_parse_double(C, a, val, &paths) || !(paths >= 1 && paths <= 1e12))
                return cli_usage_error(C, "--paths: expected a count >= 1");
        } else if (!strcmp(a, "--max-paths")) {
            if (!cli_parse_double(C, a, val, &max_paths) || !(max_paths >= 1 && max_paths <= 1e15))
                return cli_usage_error(C, "--max-paths: expected a count >= 1");
        } else if (!strcmp(a, "--target-se")) {
            if (!cli_parse_double(C, a, val, &o->target_se) || !(o->target_se >= 0 && o->target_se < 1))
                return cli_usage_error(C, "--target-se: expected a relative error in [0, 1)");
        } else if (!strcmp(a, "--models")) {
            if (!parse_models(val, o->use))
                return cli_usage_error(C, "--models: expected a list of riley, dobashi, spherical, got '%s'", val);
        } else if (!strcmp(a, "--altitudes")) {
            if (!parse_list(val, 0, 100000, 1e3, o->alt_m, &o->nalt))
                return cli_usage_error(C, "--altitudes: expected up to 8 altitudes in km in [0, 100000], got '%s'", val);
        } else if (!strcmp(a, "--suns")) {
            if (!parse_list(val, -90, 90, 1, o->sun_deg, &o->nsun))
                return cli_usage_error(C, "--suns: expected up to 8 sun elevations in [-90, 90] degrees, got '%s'", val);
        } else if (!strcmp(a, "--spectral")) {
            if (!cli_parse_int(C, a, val, 1, ATMOS_MAX_WAVELENGTHS, &spectral)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--seed")) {
            if (!cli_parse_double(C, a, val, &seed) || !(seed >= 0 && seed < 9e15 && seed == floor(seed)))
                return cli_usage_error(C, "--seed: expected an integer >= 0");
        } else if (!strcmp(a, "--threads")) {
            if (!cli_parse_int(C, a, val, 1, 1024, &o->threads)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--refine")) {
            o->refine = val;
        } else if (!strcmp(a, "--refine-above")) {
            refine_knob = 1;
            if (!cli_parse_double(C, a, val, &o->refine_above) || !(o->refine_above >= 0))
                return cli_usage_error(C, "--refine-above: expected a relative error >= 0");
        } else if (!strcmp(a, "--refine-sigmas")) {
            refine_knob = 1;
            if (!cli_parse_double(C, a, val, &o->refine_sigmas) || !(o->refine_sigmas >= 0 && o->refine_sigmas <= 100))
                return cli_usage_error(C, "--refine-sigmas: expected a number of standard errors in [0, 100]");
        } else if (!strcmp(a, "--out")) {
            o->out = val;
        } else if (!strcmp(a, "--map-range")) {
            if (!cli_parse_double(C, a, val, &o->map_range) || !(o->map_range > 0))
                return cli_usage_error(C, "--map-range: expected a relative error > 0");
        } else if (!strcmp(a, "--floor")) {
            if (!cli_parse_double(C, a, val, &o->floor) || !(o->floor >= 0 && o->floor < 1))
                return cli_usage_error(C, "--floor: expected a fraction in [0, 1)");
        } else {
            return cli_usage_error(C, "unknown option '%s'", a);
        }
        i++;
    }
    if (refine_knob && !o->refine)
        return cli_usage_error(C, "--refine-above and --refine-sigmas choose the views of --refine FILE: give it");
    o->spectral = spectral;
    o->seed = (unsigned long long)seed;
    o->paths = (long)paths;
    o->max_paths = max_paths > 0 ? (long)max_paths : 64 * o->paths;
    return 0;
}

/* Creates the reference (SPHERICAL settings: the reference ignores the tables) and the
 * models, all with the defaults (the same air, ground and sun) and the sun's disk hidden. */
static atmos_status acc_create(atmos_context *ctx, const acc_opts *o, const atmos_wavelengths *wl,
                               atmos_atmosphere **ref, atmos_atmosphere **models)
{
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    d.hide_sun_disk = 1;
    d.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    atmos_status st = atmos_atmosphere_create(ctx, &d, wl, ref);
    for (int m = 0; m < ACC_MODELS && st == ATMOS_OK; m++) {
        if (!o->use[m]) continue;
        d.kind = acc_kinds[m];
        st = atmos_atmosphere_create(ctx, &d, wl, &models[m]);
    }
    return st;
}

static atmos_status acc_alloc(acc_run *r)
{
    const size_t n = (size_t)r->nalt * (size_t)r->nsun * ACC_MAX_VIEWS * (size_t)r->wl.count;
    r->ref = calloc(n, sizeof(double));
    r->se = calloc(n, sizeof(double));
    r->paths_used = calloc(n / (size_t)r->wl.count, sizeof(long));
    int ok = r->ref && r->se && r->paths_used;
    for (int m = 0; m < ACC_MODELS; m++) ok &= (r->mod[m] = calloc(n, sizeof(double))) != NULL;
    return ok ? ATMOS_OK : ATMOS_E_NOMEM;
}

static void acc_free(acc_run *r)
{
    free(r->ref), free(r->se), free(r->paths_used);
    free(r->pick), free(r->prev_y), free(r->prev_se_y), free(r->prev_paths), free(r->prev_err);
    for (int m = 0; m < ACC_MODELS; m++) free(r->mod[m]);
}

int bench_sky_accuracy_main(int argc, char **argv)
{
    acc_opts o;
    int rc = parse_opts(argc, argv, &o);
    if (rc) return rc < 0 ? CLI_EXIT_OK : rc;
    atmos_context *ctx = cli_context(o.threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    acc_run *r = calloc(1, sizeof *r);
    atmos_atmosphere *ref = NULL, *models[ACC_MODELS] = {NULL};
    atmos_status st = r ? ATMOS_OK : ATMOS_E_NOMEM;
    if (st == ATMOS_OK && o.spectral) st = atmos_wavelengths_spectral(o.spectral, &r->wl);
    else if (st == ATMOS_OK) atmos_wavelengths_rgb(&r->wl);
    if (st == ATMOS_OK) { /* the grid, and a --refine file read, before the atmospheres' tables */
        atmos_atmosphere_desc d;
        atmos_atmosphere_defaults(&d);
        acc_grid(r, &o, d.planet_radius_m, d.top_m);
        st = acc_alloc(r);
    }
    if (st == ATMOS_OK && o.refine && (rc = acc_refine_load(r, &o)) != 0) st = ATMOS_E_INVALID_ARG;
    if (st == ATMOS_OK) st = acc_create(ctx, &o, &r->wl, &ref, models);
    const double t0 = cli_now_s();
    if (st == ATMOS_OK) st = measure_first(r, &o, ref, models);
    if (st == ATMOS_OK) st = measure_refine(r, &o, ref);
    if (st == ATMOS_OK) {
        r->seconds = cli_now_s() - t0;
        for (int m = 0; m < ACC_MODELS; m++)
            for (int a = 0; a < r->nalt; a++)
                for (int s = 0; s < r->nsun; s++)
                    if (o.use[m]) acc_block_stats(r, &o, m, a, s, &r->stats[m][a][s]);
        rc = acc_report(ctx, r, &o);
    } else if (!rc) {
        rc = cli_runtime_error("bench", ctx, st);
    }
    atmos_atmosphere_destroy(ref);
    for (int m = 0; m < ACC_MODELS; m++) atmos_atmosphere_destroy(models[m]);
    if (r) acc_free(r);
    free(r);
    atmos_context_destroy(ctx);
    return rc;
}
