/* Particle clouds from volumes and back (pcloud.h). */
#include "particles/pcloud.h"
#include "core/internal.h"
#include "volume/volume_access.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define S_OVER_H 0.6

typedef struct vframe {
    int dims[3];
    double vs, origin[3], R[9];
} vframe;

static void frame_of(const atmos_volume *vol, vframe *f)
{
    const atmos_volume_desc *d = atmos_volume_get_desc(vol);
    memcpy(f->dims, d->dims, sizeof f->dims);
    f->vs = d->voxel_size_m;
    memcpy(f->origin, d->origin_m, sizeof f->origin);
    int zero = 1;
    for (int i = 0; i < 9; i++) zero &= d->rotation[i] == 0.0;
    for (int i = 0; i < 9; i++) f->R[i] = zero ? (i % 4 == 0) : d->rotation[i];
}

/* World position of index position (i, j, k) (voxel centres at +0.5). */
static void to_world(const vframe *f, double i, double j, double k, double w[3])
{
    const double a[3] = {i * f->vs, j * f->vs, k * f->vs};
    for (int r = 0; r < 3; r++) w[r] = f->origin[r] + f->R[3 * r] * a[0] + f->R[3 * r + 1] * a[1] + f->R[3 * r + 2] * a[2];
}

/* One sweep over the cells of m^3 voxels of a field: counts the cells above thr and, with
 * pc, adds their particles. Returns the count (-1: out of memory). Each voxel's value read
 * as it is stored (the trilinear sample at its centre through the public sampler, from world
 * coordinates and back, was most of a Harris plan of the Disney cloud; it differed from the
 * voxel's value by rounding alone). */
static long sweep(const atmos_volume *vol, const vframe *f, int field, int m, double thr, const double off[3],
                  atmos__pcloud *pc)
{
    const int c[3] = {(f->dims[0] + m - 1) / m, (f->dims[1] + m - 1) / m, (f->dims[2] + m - 1) / m};
    const double h = m * f->vs, s = S_OVER_H * h;
    long count = 0;
    for (int ck = 0; ck < c[2]; ck++)
        for (int cj = 0; cj < c[1]; cj++)
            for (int ci = 0; ci < c[0]; ci++) {
                double sum = 0, cen[3] = {0, 0, 0};
                for (int k = ck * m; k < (ck + 1) * m && k < f->dims[2]; k++)
                    for (int j = cj * m; j < (cj + 1) * m && j < f->dims[1]; j++)
                        for (int i = ci * m; i < (ci + 1) * m && i < f->dims[0]; i++) {
                            double w[3];
                            to_world(f, i + 0.5, j + 0.5, k + 0.5, w);
                            const double v = atmos__vol_voxel(vol, field, i, j, k);
                            sum += v;
                            for (int a = 0; a < 3; a++) cen[a] += v * w[a];
                        }
                const double mean = sum / ((double)m * m * m);
                if (!(mean > thr)) continue;
                count++;
                if (pc && atmos__pcloud_add(pc, cen[0] / sum + off[0], cen[1] / sum + off[1], cen[2] / sum + off[2], s,
                                            atmos__pcloud_peak(mean, h, s), field) != ATMOS_OK)
                    return -1;
            }
    return count;
}

atmos_status atmos__pcloud_from_volume(atmos_context *ctx, const atmos_volume *vol, const double offset[3], double h,
                                       int max_particles, atmos__pcloud *out)
{
    memset(out, 0, sizeof *out);
    vframe f;
    frame_of(vol, &f);
    const int nf = atmos_volume_field_count(vol);
    if (max_particles <= 0) max_particles = 2000000;
    double thr[ATMOS_VOLUME_MAX_FIELDS];
    out->nfields = nf;
    for (int fi = 0; fi < nf; fi++) {
        atmos_volume_field_stats st;
        atmos_status e = atmos_volume_field_stats_get(ctx, vol, fi, &st);
        if (e != ATMOS_OK) return e;
        thr[fi] = 1e-4 * st.max;
        snprintf(out->field_name[fi], sizeof out->field_name[fi], "%s", atmos_volume_field_name(vol, fi));
        snprintf(out->particle[fi], sizeof out->particle[fi], "%s", atmos_volume_field_particle(vol, fi));
    }
    int m = h > 0 ? (int)fmax(1.0, floor(h / f.vs + 0.5)) : 1;
    if (h > 0 && fabs(m * f.vs - h) > 1e-6 * h) /* cells are whole voxels */
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "particles: a spacing of %g m %s the volume's voxel (%g m): the cells are %g m (%d voxel%s)",
                   h, h < f.vs ? "is below" : "is not a multiple of", f.vs, m * f.vs, m, m > 1 ? "s" : "");
    while (!(h > 0)) { /* coarser cells until the particles fit */
        long total = 0;
        for (int fi = 0; fi < nf; fi++) total += sweep(vol, &f, fi, m, thr[fi], offset, NULL);
        if (total <= max_particles) break;
        m++;
    }
    for (int fi = 0; fi < nf; fi++)
        if (sweep(vol, &f, fi, m, thr[fi], offset, out) < 0) {
            atmos__pcloud_free(out);
            return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for the particles of a volume");
        }
    int cloudy = 0; /* a field with any density (its threshold above 0) */
    for (int fi = 0; fi < nf; fi++) cloudy |= thr[fi] > 0;
    if (out->n < 8 && cloudy) /* a volume with a cloud in it, next to none of it made into particles */
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "particles: the volume made %d particle%s (cells of %g m%s): %s; a smaller spacing, or a larger "
                   "max_particles, makes more", out->n, out->n == 1 ? "" : "s", m * f.vs,
                   h > 0 ? ", the spacing's" : ", as coarse as max_particles asks",
                   out->n ? "the cloud is drawn as a few blobs" : "nothing of it is drawn");
    return ATMOS_OK;
}

/* Adds particle p's Gaussian to the dense grid g (dims n, corner lo, voxel v). */
static void splat_grid(const atmos__pcloud *pc, int p, float *g, const int n[3], const double lo[3], double v)
{
    const double c[3] = {pc->x[p], pc->y[p], pc->z[p]}, s = pc->s[p], r = ATMOS__PCLOUD_CUT * s;
    const double k2 = 1.0 / (2.0 * s * s);
    int i0[3], i1[3];
    for (int a = 0; a < 3; a++) {
        i0[a] = (int)fmax(0.0, floor((c[a] - r - lo[a]) / v - 0.5));
        i1[a] = (int)fmin(n[a] - 1.0, ceil((c[a] + r - lo[a]) / v - 0.5));
    }
    for (int k = i0[2]; k <= i1[2]; k++)
        for (int j = i0[1]; j <= i1[1]; j++)
            for (int i = i0[0]; i <= i1[0]; i++) {
                const double dx = lo[0] + (i + 0.5) * v - c[0], dy = lo[1] + (j + 0.5) * v - c[1],
                             dz = lo[2] + (k + 0.5) * v - c[2], d2 = dx * dx + dy * dy + dz * dz;
                if (d2 <= r * r) g[((size_t)k * n[1] + j) * n[0] + i] += (float)(pc->n0[p] * exp(-d2 * k2));
            }
}

atmos_status atmos__pcloud_to_volume(atmos_context *ctx, const atmos__pcloud *pc, double voxel_m, atmos_volume **out)
{
    *out = NULL;
    double lo[3], hi[3];
    atmos__pcloud_bounds(pc, lo, hi);
    if (pc->n == 0 || !(voxel_m > 0)) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "particles: nothing to grid");
    atmos_volume_desc d;
    memset(&d, 0, sizeof d);
    d.voxel_size_m = voxel_m;
    for (int a = 0; a < 3; a++) d.dims[a] = (int)ceil((hi[a] - lo[a]) / voxel_m), d.origin_m[a] = lo[a];
    const size_t cells = (size_t)d.dims[0] * d.dims[1] * d.dims[2];
    float *g = malloc(sizeof(float) * cells);
    atmos_volume *vol = NULL;
    atmos_status st = g ? atmos_volume_create(ctx, &d, &vol) : atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for a grid");
    for (int f = 0; f < pc->nfields && st == ATMOS_OK; f++) {
        int idx;
        if ((st = atmos_volume_add_field(ctx, vol, pc->field_name[f], pc->particle[f], &idx)) != ATMOS_OK) break;
        memset(g, 0, sizeof(float) * cells);
        for (int p = 0; p < pc->n; p++)
            if (pc->field[p] == f) splat_grid(pc, p, g, d.dims, lo, voxel_m);
        const int zero[3] = {0, 0, 0};
        st = atmos_volume_set_dense(ctx, vol, idx, zero, d.dims, g, 1.0f);
    }
    free(g);
    if (st == ATMOS_OK) st = atmos_volume_finalize(ctx, vol);
    if (st != ATMOS_OK) {
        atmos_volume_destroy(vol);
        return st;
    }
    *out = vol;
    return ATMOS_OK;
}
