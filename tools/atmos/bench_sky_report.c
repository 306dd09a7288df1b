/* The report of atmos bench sky-accuracy (bench_sky.h): Markdown tables, CSV files and
 * error maps (docs/sky-accuracy.md describes each). */
#include "bench_sky.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* A percentage cell; signed for worst cases, plain for RMS. */
static void pct(FILE *f, double x, int sign)
{
    if (isnan(x)) fprintf(f, " n/a |");
    else if (fabs(x) >= 9.995) fprintf(f, sign ? " %+.0f %% |" : " %.0f %% |", 100 * x);
    else fprintf(f, sign ? " %+.2f %% |" : " %.2f %% |", 100 * x);
}

static void alt_name(char *buf, size_t n, double alt_m)
{
    if (alt_m == 0) snprintf(buf, n, "ground");
    else snprintf(buf, n, "%g km", alt_m / 1e3);
}

/* One table: rows (altitude, sun), per model the RMS and worst error of Y, then the
 * reference's relative standard error of Y (RMS, max over the views). */
static void table_summary(FILE *f, const acc_run *r, const acc_opts *o)
{
    fprintf(f, "| altitude | sun | views |");
    for (int m = 0; m < ACC_MODELS; m++)
        if (o->use[m]) fprintf(f, " %s RMS | %s worst |", acc_model_names[m], acc_model_names[m]);
    fprintf(f, " ref. s.e. RMS | ref. s.e. max |\n|---|---|---|");
    for (int m = 0; m < ACC_MODELS; m++)
        if (o->use[m]) fprintf(f, "---|---|");
    fprintf(f, "---|---|\n");
    for (int a = 0; a < r->nalt; a++)
        for (int s = 0; s < r->nsun; s++) {
            char an[32];
            alt_name(an, sizeof an, r->alt_m[a]);
            fprintf(f, "| %s | %+g° | %d |", an, r->sun_deg[s], r->nview[a]);
            const acc_stats *any = NULL;
            for (int m = 0; m < ACC_MODELS; m++) {
                if (!o->use[m]) continue;
                const acc_stats *st = &r->stats[m][a][s];
                any = st; /* the reference's figures: the same in every model's stats */
                pct(f, st->views ? st->rms_y : NAN, 0);
                pct(f, st->views ? st->worst_y : NAN, 1);
            }
            fprintf(f, " %.2g %% | %.2g %% |\n", any ? 100 * any->se_rms_y : 0.0, any ? 100 * any->se_max_y : 0.0);
        }
}

/* Per model: the RMS and worst relative error of each wavelength's radiance. */
static void table_model(FILE *f, const acc_run *r, int m)
{
    const int n = r->wl.count;
    fprintf(f, "| altitude | sun | RMS per wavelength (");
    for (int k = 0; k < n; k++) fprintf(f, "%s%.0f", k ? ", " : "", r->wl.nm[k]);
    fprintf(f, " nm) | worst per wavelength |\n|---|---|---|---|\n");
    for (int a = 0; a < r->nalt; a++)
        for (int s = 0; s < r->nsun; s++) {
            const acc_stats *st = &r->stats[m][a][s];
            char an[32];
            alt_name(an, sizeof an, r->alt_m[a]);
            fprintf(f, "| %s | %+g° |", an, r->sun_deg[s]);
            for (int w = 0; w < 2; w++) {
                if (!st->views) {
                    fprintf(f, " n/a |");
                    continue;
                }
                for (int k = 0; k < n; k++)
                    fprintf(f, w ? "%s%+.2f" : "%s%.2f", k ? " / " : " ", 100 * (w ? st->worst[k] : st->rms[k]));
                fprintf(f, " %% |");
            }
            fprintf(f, "\n");
        }
}

static void write_tables(FILE *f, const acc_run *r, const acc_opts *o)
{
    long lo = -1, hi = 0;
    for (int a = 0; a < r->nalt; a++)
        for (int s = 0; s < r->nsun; s++)
            for (int v = 0; v < r->nview[a]; v++) {
                const long u = r->paths_used[acc_index(r, a, s, v) / (size_t)r->wl.count];
                if (lo < 0 || u < lo) lo = u;
                if (u > hi) hi = u;
            }
    fprintf(f, "Relative error of the luminance Y (model - reference) / reference, RMS and worst (signed) "
               "over the views; %s grid, %d wavelengths, reference walks per wavelength and view %ld-%ld "
               "(target s.e. %g), seed %llu, %.1f s.\n\n",
            o->quick ? "quick" : "full", r->wl.count, lo, hi, o->target_se, o->seed, r->seconds);
    table_summary(f, r, o);
    for (int m = 0; m < ACC_MODELS; m++) {
        if (!o->use[m]) continue;
        fprintf(f, "\n%s: relative error of the spectral radiance, per wavelength\n\n", acc_model_names[m]);
        table_model(f, r, m);
    }
    acc_refine_table(f, r, o);
}

static void csv_results(FILE *f, const acc_run *r, const acc_opts *o)
{
    const int n = r->wl.count;
    fprintf(f, "model,altitude_m,sun_elevation_deg,class,class_param,view_zenith_deg,view_azimuth_from_sun_deg,"
               "paths,ref_Y,ref_Y_se,model_Y,rel_err_Y");
    for (int k = 0; k < n; k++) {
        const double nm = r->wl.nm[k];
        fprintf(f, ",ref_%.0f,ref_se_%.0f,model_%.0f,rel_err_%.0f", nm, nm, nm, nm);
    }
    fprintf(f, "\n");
    double e[ATMOS_MAX_WAVELENGTHS];
    for (int m = 0; m < ACC_MODELS; m++)
        for (int a = 0; m < ACC_MODELS && o->use[m] && a < r->nalt; a++)
            for (int s = 0; s < r->nsun; s++)
                for (int v = 0; v < r->nview[a]; v++) {
                    const size_t i = acc_index(r, a, s, v);
                    const acc_view *w = &r->view[a][v];
                    const double *L = r->ref + i, *S = r->se + i, *M = r->mod[m] + i;
                    double vy = 0;
                    for (int k = 0; k < n; k++) vy += pow(r->wl.to_xyz[k][1] * S[k], 2);
                    const int na = isnan(M[0]);
                    const double ey = na ? NAN : acc_rel_errors(r, o, m, a, s, v, e);
                    fprintf(f, "%s,%.0f,%g,%s,%g,%.6f,%g,%ld,%.9g,%.3g,%.9g,%.6g", acc_model_names[m], r->alt_m[a],
                            r->sun_deg[s], w->cls, w->param, w->zenith_deg, w->dazimuth_deg,
                            r->paths_used[i / (size_t)n], acc_luminance(&r->wl, L), sqrt(vy),
                            na ? NAN : acc_luminance(&r->wl, M), ey);
                    for (int k = 0; k < n; k++) fprintf(f, ",%.9g,%.3g,%.9g,%.6g", L[k], S[k], M[k], na ? NAN : e[k]);
                    fprintf(f, "\n");
                }
}

static void csv_summary(FILE *f, const acc_run *r, const acc_opts *o)
{
    const int n = r->wl.count;
    fprintf(f, "model,altitude_m,sun_elevation_deg,views,rms_Y,worst_Y,ref_se_rms_Y,ref_se_max_Y");
    for (int k = 0; k < n; k++) fprintf(f, ",rms_%.0f", r->wl.nm[k]);
    for (int k = 0; k < n; k++) fprintf(f, ",worst_%.0f", r->wl.nm[k]);
    fprintf(f, "\n");
    for (int m = 0; m < ACC_MODELS; m++)
        for (int a = 0; o->use[m] && a < r->nalt; a++)
            for (int s = 0; s < r->nsun; s++) {
                const acc_stats *st = &r->stats[m][a][s];
                const double na = st->views ? 0.0 : NAN;
                fprintf(f, "%s,%.0f,%g,%d,%.6g,%.6g,%.3g,%.3g", acc_model_names[m], r->alt_m[a], r->sun_deg[s],
                        st->views, st->rms_y + na, st->worst_y + na, st->se_rms_y, st->se_max_y);
                for (int k = 0; k < n; k++) fprintf(f, ",%.6g", st->rms[k] + na);
                for (int k = 0; k < n; k++) fprintf(f, ",%.6g", st->worst[k] + na);
                fprintf(f, "\n");
            }
}

/* ------------------------------------------------------------------ error maps */

enum { CELL = 8, GAP = 4, BAR = 12 };

static void put(atmos_image *img, int x0, int y0, int w, int h, const float c[3])
{
    for (int y = y0; y < y0 + h && y < img->height; y++)
        for (int x = x0; x < x0 + w && x < img->width; x++)
            memcpy(img->pixels + ((size_t)y * (size_t)img->width + (size_t)x) * 3, c, 3 * sizeof(float));
}

/* A diverging colour: white at 0, red for too bright (t > 0), blue for too dark; t in
 * [-1, 1] (saturated beyond). */
static void diverging(double t, float c[3])
{
    t = fmax(-1.0, fmin(1.0, t));
    const float u = (float)(1.0 - fabs(t));
    if (t >= 0) c[0] = 1, c[1] = u, c[2] = u;
    else c[0] = u, c[1] = u, c[2] = 1;
}

/* error_map_MODEL.png: one row of cells per (altitude, sun elevation) — altitudes from the
 * ground down, suns in the grid's order within each — and one column per view of that
 * altitude in the grid's order (sky, space, limb, disk; each by zenith angle, then azimuth);
 * the signed relative error of Y as a colour saturating at +-map_range, mid grey where the
 * model is n/a, light grey beyond the altitude's views; a colour bar from -range (left)
 * to +range (right) at the bottom. */
static atmos_status write_map(atmos_context *ctx, const acc_run *r, const acc_opts *o, int m, const char *path)
{
    int cols = 0;
    for (int a = 0; a < r->nalt; a++) cols = r->nview[a] > cols ? r->nview[a] : cols;
    const int W = cols * CELL, H = r->nalt * r->nsun * CELL + (r->nalt - 1) * GAP + GAP + BAR;
    atmos_image *img = NULL;
    atmos_status st = atmos_image_create(ctx, W, H, 3, &img);
    if (st != ATMOS_OK) return st;
    const float sep[3] = {0.2f, 0.2f, 0.2f}, pad[3] = {0.85f, 0.85f, 0.85f}, na[3] = {0.5f, 0.5f, 0.5f};
    put(img, 0, 0, W, H, sep);
    double e[ATMOS_MAX_WAVELENGTHS];
    for (int a = 0; a < r->nalt; a++)
        for (int s = 0; s < r->nsun; s++) {
            const int y = (a * r->nsun + s) * CELL + a * GAP;
            for (int v = 0; v < cols; v++) {
                float c[3];
                if (v >= r->nview[a]) memcpy(c, pad, sizeof c);
                else if (isnan(r->mod[m][acc_index(r, a, s, v)])) memcpy(c, na, sizeof c);
                else diverging(acc_rel_errors(r, o, m, a, s, v, e) / o->map_range, c);
                put(img, v * CELL, y, CELL, CELL, c);
            }
        }
    for (int x = 0; x < W; x++) {
        float c[3];
        diverging(2.0 * (x + 0.5) / W - 1.0, c);
        put(img, x, H - BAR, 1, BAR, c);
    }
    char range[64];
    snprintf(range, sizeof range, "%g", o->map_range);
    atmos_image_set_meta(img, "Title", "atmos bench sky-accuracy: relative error of luminance");
    atmos_image_set_meta(img, "Model", acc_model_names[m]);
    atmos_image_set_meta(img, "Range", range);
    st = atmos_write_png(ctx, img, path, 8);
    atmos_image_destroy(img);
    return st;
}

/* ------------------------------------------------------------------ the report */

static FILE *open_out(const acc_opts *o, const char *name)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", o->out, name);
    FILE *f = fopen(path, "w");
    if (!f) fprintf(stderr, "atmos bench: cannot write %s: %s\n", path, strerror(errno));
    return f;
}

int acc_report(atmos_context *ctx, const acc_run *r, const acc_opts *o)
{
    write_tables(stdout, r, o);
    fflush(stdout);
    if (!o->out) return CLI_EXIT_OK;
    if (mkdir(o->out, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "atmos bench: cannot create %s: %s\n", o->out, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    void (*writers[3])(FILE *, const acc_run *, const acc_opts *) = {write_tables, csv_results, csv_summary};
    static const char *const names[3] = {"table.md", "results.csv", "summary.csv"};
    for (int i = 0; i < 3; i++) {
        FILE *f = open_out(o, names[i]);
        if (!f) return CLI_EXIT_RUNTIME;
        writers[i](f, r, o);
        if (fclose(f) != 0) return CLI_EXIT_RUNTIME;
    }
    for (int m = 0; m < ACC_MODELS; m++) {
        if (!o->use[m]) continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/error_map_%s.png", o->out, acc_model_names[m]);
        atmos_status st = write_map(ctx, r, o, m, path);
        if (st != ATMOS_OK) return cli_runtime_error("bench", ctx, st);
    }
    return CLI_EXIT_OK;
}
