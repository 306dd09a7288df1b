/* atmos bench sky-accuracy --refine FILE (docs/sky-accuracy.md, "Re-measuring the worst
 * views"): every view's reference comes from a previous run's results.csv, and the views
 * whose error exceeds a threshold are measured again from their first batch with their own
 * seeds, so that a finer reference replaces the noisy one where it decides the verdict. */
#define _POSIX_C_SOURCE 200809L /* strtok_r */
#include "bench_sky.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { COL_MODEL, COL_ALT, COL_SUN, COL_ZEN, COL_AZ, COL_PATHS, COL_ERR, COL_FIXED };

/* Splits line (modified in place) at commas into at most max fields; returns the count. */
static int split(char *line, char **field, int max)
{
    int n = 0;
    for (char *p = line; n < max;) {
        field[n++] = p;
        char *c = strchr(p, ',');
        if (!c) break;
        *c = 0, p = c + 1;
    }
    return n;
}

static int find_col(char **head, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(head[i], name)) return i;
    return -1;
}

/* The grid's view (a, s, v) of a row's altitude, sun and direction; 0 if none. */
static int match_view(const acc_run *r, const double *x, int *a, int *s, int *v)
{
    for (*a = 0; *a < r->nalt; (*a)++) {
        if (fabs(x[COL_ALT] - r->alt_m[*a]) > 0.5) continue;
        for (*s = 0; *s < r->nsun; (*s)++) {
            if (fabs(x[COL_SUN] - r->sun_deg[*s]) > 1e-4) continue;
            for (*v = 0; *v < r->nview[*a]; (*v)++) {
                const acc_view *w = &r->view[*a][*v];
                if (fabs(x[COL_ZEN] - w->zenith_deg) < 2e-6 && fabs(x[COL_AZ] - w->dazimuth_deg) < 1e-4) return 1;
            }
        }
    }
    return 0;
}

static int model_used(const acc_opts *o, const char *name)
{
    for (int m = 0; m < ACC_MODELS; m++)
        if (o->use[m] && !strcmp(name, acc_model_names[m])) return 1;
    return 0;
}

/* The header's columns: the fixed ones and each wavelength's reference and its error. */
static int header_cols(const acc_run *r, const acc_opts *o, char **head, int nh, int *col, int *ref, int *se)
{
    static const char *const fixed[COL_FIXED] = {"model", "altitude_m", "sun_elevation_deg", "view_zenith_deg",
                                                 "view_azimuth_from_sun_deg", "paths", "rel_err_Y"};
    for (int c = 0; c < COL_FIXED; c++)
        if ((col[c] = find_col(head, nh, fixed[c])) < 0)
            return cli_usage_error("bench sky-accuracy", "--refine %s: no column '%s' (not a results.csv)", o->refine,
                                   fixed[c]);
    for (int k = 0; k < r->wl.count; k++) {
        char name[32];
        snprintf(name, sizeof name, "ref_%.0f", r->wl.nm[k]);
        if ((ref[k] = find_col(head, nh, name)) >= 0) {
            snprintf(name, sizeof name, "ref_se_%.0f", r->wl.nm[k]);
            se[k] = find_col(head, nh, name);
        }
        if (ref[k] < 0 || se[k] < 0)
            return cli_usage_error("bench sky-accuracy",
                                   "--refine %s: no column '%s': written with other wavelengths (--spectral)",
                                   o->refine, name);
    }
    return 0;
}

/* One row: its view's reference, standard errors and walks, and its error of Y when the
 * row's model is one of the run's. */
static int load_row(acc_run *r, const acc_opts *o, char **f, const int *col, const int *ref, const int *se,
                    unsigned char *have, int line)
{
    double x[COL_FIXED];
    for (int c = 1; c < COL_FIXED; c++) {
        char *end;
        x[c] = strtod(f[col[c]], &end);
        if (end == f[col[c]] || (*end && *end != '\r'))
            return cli_usage_error("bench sky-accuracy", "--refine %s: line %d: '%s' is not a number", o->refine, line,
                                   f[col[c]]);
    }
    int a, s, v;
    if (!match_view(r, x, &a, &s, &v))
        return cli_usage_error("bench sky-accuracy",
                               "--refine %s: line %d is not a view of this run's grid (give the --quick, --altitudes "
                               "and --suns of the run that wrote it)",
                               o->refine, line);
    const size_t i = acc_index(r, a, s, v), j = i / (size_t)r->wl.count;
    double vy = 0;
    for (int k = 0; k < r->wl.count; k++) {
        r->ref[i + (size_t)k] = strtod(f[ref[k]], NULL);
        r->se[i + (size_t)k] = strtod(f[se[k]], NULL);
        vy += pow(r->wl.to_xyz[k][1] * r->se[i + (size_t)k], 2);
    }
    r->paths_used[j] = r->prev_paths[j] = (long)x[COL_PATHS];
    r->prev_y[j] = acc_luminance(&r->wl, r->ref + i);
    r->prev_se_y[j] = sqrt(vy);
    have[j] = 1;
    if (model_used(o, f[col[COL_MODEL]])) r->prev_err[j] = fmax(r->prev_err[j], fabs(x[COL_ERR]));
    return 0;
}

static int load_rows(acc_run *r, const acc_opts *o, char *text, unsigned char *have)
{
    enum { MAXF = 8 + 4 * ATMOS_MAX_WAVELENGTHS };
    char *head[MAXF], *f[MAXF], *save = NULL;
    char *line = strtok_r(text, "\n", &save);
    const int nh = line ? split(line, head, MAXF) : 0;
    if (nh > 0) head[nh - 1][strcspn(head[nh - 1], "\r")] = 0;
    int col[COL_FIXED], ref[ATMOS_MAX_WAVELENGTHS], se[ATMOS_MAX_WAVELENGTHS];
    int rc = header_cols(r, o, head, nh, col, ref, se);
    int ln = 1;
    while (!rc && (line = strtok_r(NULL, "\n", &save)) != NULL) {
        ln++;
        if (split(line, f, MAXF) != nh)
            return cli_usage_error("bench sky-accuracy", "--refine %s: line %d has not the header's %d fields",
                                   o->refine, ln, nh);
        rc = load_row(r, o, f, col, ref, se, have, ln);
    }
    return rc;
}

/* The views to measure again: |error of Y| + sigmas x the reference's relative standard
 * error of Y (over the errors' denominator, max(Y, floor x the block's largest Y)) above
 * the threshold. */
static void pick_views(acc_run *r, const acc_opts *o)
{
    for (int a = 0; a < r->nalt; a++)
        for (int s = 0; s < r->nsun; s++) {
            const double ymax = acc_block_max(r, a, s, -1);
            for (int v = 0; v < r->nview[a]; v++) {
                const size_t j = acc_index(r, a, s, v) / (size_t)r->wl.count;
                const double den = fmax(r->prev_y[j], o->floor * ymax);
                const double rse = den > 0 ? r->prev_se_y[j] / den : 0.0;
                r->pick[j] = r->prev_err[j] + o->refine_sigmas * rse > o->refine_above;
            }
        }
}

int acc_refine_load(acc_run *r, const acc_opts *o)
{
    const size_t nv = (size_t)r->nalt * (size_t)r->nsun * ACC_MAX_VIEWS;
    char *text = cli_read_text(o->refine, CLI_TEXT_MAX);
    unsigned char *have = calloc(nv, 1);
    r->pick = calloc(nv, 1);
    r->prev_y = calloc(nv, sizeof(double));
    r->prev_se_y = calloc(nv, sizeof(double));
    r->prev_paths = calloc(nv, sizeof(long));
    r->prev_err = calloc(nv, sizeof(double));
    int rc = 0;
    if (!text) {
        fprintf(stderr, "atmos bench: --refine: cannot read %s\n", o->refine);
        rc = CLI_EXIT_RUNTIME;
    } else if (!have || !r->pick || !r->prev_y || !r->prev_se_y || !r->prev_paths || !r->prev_err) {
        rc = CLI_EXIT_RUNTIME;
    } else {
        rc = load_rows(r, o, text, have);
    }
    for (int a = 0; !rc && a < r->nalt; a++)
        for (int s = 0; !rc && s < r->nsun; s++)
            for (int v = 0; !rc && v < r->nview[a]; v++)
                if (!have[acc_index(r, a, s, v) / (size_t)r->wl.count])
                    rc = cli_usage_error("bench sky-accuracy",
                                         "--refine %s lacks the view at %g m, sun %g°, zenith %g°, azimuth %g° of "
                                         "this run's grid",
                                         o->refine, r->alt_m[a], r->sun_deg[s], r->view[a][v].zenith_deg,
                                         r->view[a][v].dazimuth_deg);
    if (!rc) pick_views(r, o);
    free(text);
    free(have);
    return rc;
}

/* The relative error of Y of model m at view (a, s, v) against reference Y y. */
static double err_against(const acc_run *r, const acc_opts *o, int m, int a, int s, int v, double y)
{
    const double den = fmax(y, o->floor * acc_block_max(r, a, s, -1));
    const double my = acc_luminance(&r->wl, r->mod[m] + acc_index(r, a, s, v));
    return den > 0 ? (my - y) / den : 0.0;
}

void acc_refine_table(FILE *f, const acc_run *r, const acc_opts *o)
{
    if (!r->pick) return;
    fprintf(f, "\nViews measured again (--refine %s: |error of Y| + %g standard errors > %g), each model's error "
               "of Y against the previous reference and the new one, with their relative standard errors:\n\n"
               "| altitude | sun | class | zenith | azimuth | walks before | walks now |",
            o->refine, o->refine_sigmas, o->refine_above);
    for (int m = 0; m < ACC_MODELS; m++)
        if (o->use[m]) fprintf(f, " %s before | %s now |", acc_model_names[m], acc_model_names[m]);
    fprintf(f, " s.e. before | s.e. now |\n|---|---|---|---|---|---|---|");
    for (int m = 0; m < ACC_MODELS; m++)
        if (o->use[m]) fprintf(f, "---|---|");
    fprintf(f, "---|---|\n");
    for (int a = 0; a < r->nalt; a++)
        for (int s = 0; s < r->nsun; s++)
            for (int v = 0; v < r->nview[a]; v++) {
                const size_t i = acc_index(r, a, s, v), j = i / (size_t)r->wl.count;
                if (!r->pick[j]) continue;
                const acc_view *w = &r->view[a][v];
                const double y = acc_luminance(&r->wl, r->ref + i), ymax = acc_block_max(r, a, s, -1);
                double vy = 0;
                for (int k = 0; k < r->wl.count; k++) vy += pow(r->wl.to_xyz[k][1] * r->se[i + (size_t)k], 2);
                fprintf(f, "| %g km | %+g° | %s %g | %.3f° | %g° | %ld | %ld |", r->alt_m[a] / 1e3, r->sun_deg[s],
                        w->cls, w->param, w->zenith_deg, w->dazimuth_deg, r->prev_paths[j], r->paths_used[j]);
                for (int m = 0; m < ACC_MODELS; m++)
                    if (o->use[m] && !isnan(r->mod[m][i]))
                        fprintf(f, " %+.2f %% | %+.2f %% |", 100 * err_against(r, o, m, a, s, v, r->prev_y[j]),
                                100 * err_against(r, o, m, a, s, v, y));
                    else if (o->use[m])
                        fprintf(f, " n/a | n/a |");
                const double den0 = fmax(r->prev_y[j], o->floor * ymax), den = fmax(y, o->floor * ymax);
                fprintf(f, " %.2g %% | %.2g %% |\n", den0 > 0 ? 100 * r->prev_se_y[j] / den0 : 0.0,
                        den > 0 ? 100 * sqrt(vy) / den : 0.0);
            }
}
