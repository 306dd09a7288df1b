/* The sky benchmarks of atmos bench: the spherical models' cost (bench_sky_models.c) and
 * their accuracy against the reference (bench_sky_accuracy.c, bench_sky_report.c;
 * docs/sky-accuracy.md). */
#ifndef ATMOS_CLI_BENCH_SKY_H
#define ATMOS_CLI_BENCH_SKY_H

#include "cli.h"

/* ------------------------------------------------------------------ accuracy */
enum { ACC_MODELS = 3, ACC_MAX_VIEWS = 128, ACC_MAX_BLOCKS = 64 };

/* One view of the grid: the zenith angle at the observer (0 up, 180 nadir), the azimuth
 * measured from the sun's azimuth, and its class (sky, limb, disk, space). */
typedef struct {
    double zenith_deg, dazimuth_deg;
    const char *cls;
    double param; /* limb: tangent altitude, m; disk: impact parameter / planet radius */
} acc_view;

/* The outcome of one (model, altitude, sun elevation) block. */
typedef struct {
    int views;               /* views compared (0: n/a) */
    double rms[ATMOS_MAX_WAVELENGTHS], worst[ATMOS_MAX_WAVELENGTHS]; /* relative, signed worst */
    double rms_y, worst_y;
    double se_rms_y, se_max_y; /* the reference's relative standard error of Y */
} acc_stats;

typedef struct {
    int quick;
    long paths, max_paths;   /* reference walks per wavelength per batch; the cap */
    double target_se;        /* relative standard error of Y to reach (0: one batch) */
    int spectral;            /* 0: rgb */
    int threads;
    unsigned long long seed;
    int use[ACC_MODELS];     /* riley, dobashi, spherical */
    const char *out;         /* output directory (NULL: tables on stdout only) */
    double map_range;        /* the error maps saturate at +- this relative error */
    double floor;            /* relative errors are divided by max(ref, floor * block max) */
    int nalt, nsun;          /* > 0: these observer altitudes (m) and sun elevations (deg) */
    double alt_m[8], sun_deg[8];
    const char *refine;      /* a previous run's results.csv: its references, its worst views again */
    double refine_above;     /* ... those whose |relative error of Y| exceeds this */
    double refine_sigmas;    /* ... or could, within this many of the reference's standard errors */
} acc_opts;

/* Everything a run measured, for the report. */
typedef struct {
    atmos_wavelengths wl;
    int nalt, nsun;
    double alt_m[8], sun_deg[8];
    int nview[8];
    acc_view view[8][ACC_MAX_VIEWS];
    /* per (altitude, sun, view): reference, its standard error, each model (NAN: n/a) */
    double *ref, *se, *mod[ACC_MODELS];
    long *paths_used;
    /* --refine (per view, NULL otherwise): measured again; the previous run's reference Y,
     * its standard error and walks */
    unsigned char *pick;
    double *prev_y, *prev_se_y, *prev_err; /* prev_err: the largest |error of Y| of the run's models */
    long *prev_paths;
    acc_stats stats[ACC_MODELS][8][8];
    double seconds;
} acc_run;

extern const char *const acc_model_names[ACC_MODELS];

/* The grid's view of (altitude, sun, view) and the index of its per-wavelength values. */
size_t acc_index(const acc_run *r, int a, int s, int v);
/* Relative errors of one view for one model: per wavelength (out[k]) and of Y (return). */
double acc_rel_errors(const acc_run *r, const acc_opts *o, int m, int a, int s, int v, double *out);
double acc_luminance(const atmos_wavelengths *wl, const double *L);
/* The largest reference value of block (a, s) at wavelength k (k = -1: of Y). */
double acc_block_max(const acc_run *r, int a, int s, int k);

/* --refine FILE (bench_sky_refine.c): loads every view's reference from FILE (written by a run
 * with the same grid and wavelengths) and picks the views to measure again; prints a usage
 * error and returns CLI_EXIT_USAGE (or CLI_EXIT_RUNTIME) when FILE does not fit the run. */
int acc_refine_load(acc_run *r, const acc_opts *o);
/* The picked views before and after, as a Markdown table (nothing without --refine). */
void acc_refine_table(FILE *f, const acc_run *r, const acc_opts *o);

/* The report: Markdown tables on stdout (and table.md), results.csv, summary.csv and the
 * error maps (error_map_MODEL.png) in o->out. */
int acc_report(atmos_context *ctx, const acc_run *r, const acc_opts *o);

/* atmos bench sky-accuracy ARGS (argv[0] = "sky-accuracy"). */
int bench_sky_accuracy_main(int argc, char **argv);

/* ------------------------------------------------------------------ cost */
/* atmos bench sky's model lines: precompute_seconds, ns_per_pixel from the ground and from
 * 36 000 km at 720x480, fps of the Earth from space; budget_s bounds each render case. */
int bench_sky_models(int threads, int repeat, double budget_s, const char *models);

#endif
