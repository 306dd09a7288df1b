/* A volume seen from above: each column's vertical optical depth and the heights of its
 * cloud's base and top (include/atmos/cloudstats.h, docs/clouds.md "Shape statistics"). */
#include "atmos/cloudstats.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

atmos_status atmos_cloud_columns_create(atmos_context *ctx, int nx, int ny, double dx_m, atmos_cloud_columns *out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "cloud columns: no output");
    memset(out, 0, sizeof *out);
    if (nx < 1 || ny < 1 || nx > 65536 || ny > 65536 || (long long)nx * ny > (1LL << 30) || !(dx_m > 0 && isfinite(dx_m)))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "cloud columns: %d x %d pixels of %g m (expected 1..65536 a side, at most 2^30 in all, of > 0 m)", nx,
                            ny, dx_m);
    size_t n = (size_t)nx * ny;
    out->tau = calloc(n, sizeof *out->tau);
    out->base_m = malloc(n * sizeof *out->base_m);
    out->top_m = malloc(n * sizeof *out->top_m);
    if (!out->tau || !out->base_m || !out->top_m) {
        atmos_cloud_columns_free(out);
        return atmos__error(ctx, ATMOS_E_NOMEM, "cloud columns: out of memory for %d x %d pixels", nx, ny);
    }
    for (size_t i = 0; i < n; i++) out->base_m[i] = out->top_m[i] = NAN;
    out->nx = nx, out->ny = ny, out->dx_m = dx_m;
    return ATMOS_OK;
}

void atmos_cloud_columns_free(atmos_cloud_columns *c)
{
    if (!c) return;
    free(c->tau);
    free(c->base_m);
    free(c->top_m);
    memset(c, 0, sizeof *c);
}

/* Where the optical depth accumulated over the cells b[0..n) (each of depth h, starting at y0
 * and stepping by dir = +1 up or -1 down) first reaches t: linear within the cell. */
static float crossing(const double *b, int n, double h, double y0, int dir, double t)
{
    double acc = 0;
    for (int s = 0; s < n; s++) {
        int j = dir > 0 ? s : n - 1 - s;
        double d = b[j] * h;
        if (d > 0 && acc + d >= t) {
            double f = (t - acc) / d;
            return (float)(dir > 0 ? y0 + (j + f) * h : y0 + (j + 1 - f) * h);
        }
        acc += d;
    }
    return NAN;
}

atmos_status atmos_cloud_columns_from_volume(atmos_context *ctx, const atmos_volume *vol, const double *sigma_ext,
                                             double base_tau, atmos_cloud_columns *out)
{
    if (!vol || !sigma_ext || !out || !(base_tau > 0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "cloud columns: missing volume, cross-sections or base optical depth");
    const atmos_volume_desc *d = atmos_volume_get_desc(vol);
    static const double eye[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    int identity = 1, zero = 1;
    for (int k = 0; k < 9; k++) {
        identity &= fabs(d->rotation[k] - eye[k]) <= 1e-9;
        zero &= d->rotation[k] == 0; /* all zeros means no rotation */
    }
    if (!identity && !zero)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "cloud columns: the volume is rotated; the columns need its y axis vertical");
    int nx = d->dims[0], ny = d->dims[1], nz = d->dims[2];
    double h = d->voxel_size_m;
    atmos_status st = atmos_cloud_columns_create(ctx, nx, nz, h, out);
    if (st != ATMOS_OK) return st;
    double *b = malloc((size_t)ny * sizeof *b);
    if (!b) {
        atmos_cloud_columns_free(out);
        return atmos__error(ctx, ATMOS_E_NOMEM, "cloud columns: out of memory");
    }
    for (int k = 0; k < nz; k++)
        for (int i = 0; i < nx; i++) {
            double p[3] = {d->origin_m[0] + (i + 0.5) * h, 0, d->origin_m[2] + (k + 0.5) * h}, tau = 0;
            for (int j = 0; j < ny; j++) {
                p[1] = d->origin_m[1] + (j + 0.5) * h;
                b[j] = atmos_volume_extinction(vol, sigma_ext, p); /* a voxel centre: its own value */
                tau += b[j] * h;
            }
            size_t px = (size_t)k * nx + i;
            out->tau[px] = (float)tau;
            out->base_m[px] = crossing(b, ny, h, d->origin_m[1], +1, base_tau);
            out->top_m[px] = crossing(b, ny, h, d->origin_m[1], -1, base_tau);
        }
    free(b);
    return ATMOS_OK;
}
