/* atmos bench sky-accuracy's indexing and errors, shared by the measuring
 * (bench_sky_accuracy.c) and the report (bench_sky_report.c). */
#include "bench_sky.h"

#include <math.h>

const char *const acc_model_names[ACC_MODELS] = {"riley", "dobashi", "spherical"};
size_t acc_index(const acc_run *r, int a, int s, int v)
{
    return (((size_t)a * (size_t)r->nsun + (size_t)s) * ACC_MAX_VIEWS + (size_t)v) * (size_t)r->wl.count;
}

double acc_luminance(const atmos_wavelengths *wl, const double *L)
{
    double y = 0;
    for (int k = 0; k < wl->count; k++) y += wl->to_xyz[k][1] * L[k];
    return y;
}

/* The largest reference value of block (a, s) at wavelength k (k = -1: of Y). */
double acc_block_max(const acc_run *r, int a, int s, int k)
{
    double mx = 0;
    for (int v = 0; v < r->nview[a]; v++) {
        const double *L = r->ref + acc_index(r, a, s, v);
        mx = fmax(mx, k < 0 ? acc_luminance(&r->wl, L) : L[k]);
    }
    return mx;
}

static double rel_error(double model, double ref, double floor_value)
{
    const double den = fmax(ref, floor_value);
    if (den > 0) return (model - ref) / den;
    return model == ref ? 0.0 : INFINITY;
}

double acc_rel_errors(const acc_run *r, const acc_opts *o, int m, int a, int s, int v, double *out)
{
    const size_t i = acc_index(r, a, s, v);
    const double *L = r->ref + i, *M = r->mod[m] + i;
    for (int k = 0; k < r->wl.count; k++) out[k] = rel_error(M[k], L[k], o->floor * acc_block_max(r, a, s, k));
    return rel_error(acc_luminance(&r->wl, M), acc_luminance(&r->wl, L), o->floor * acc_block_max(r, a, s, -1));
}
