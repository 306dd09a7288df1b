/* The slice renderer's spans (slice_internal.h): for every slice, the pixels of each
 * eye-buffer row and the texels of each light-buffer row whose samples may fall in occupied
 * blocks of the render grid, so that the passes visit what the occupied volume covers
 * instead of the whole image and light buffer. */
#include "core/vec.h"
#include "render/slice_internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>

/* Slice indices k whose plane s_k = s0 + (k + 0.5) ds lies in [sa, sb]. */
void atmos__slice_range(double sa, double sb, double s0, double ds, int nslices, int *k0, int *k1)
{
    double a = ceil((sa - s0) / ds - 0.5), b = floor((sb - s0) / ds - 0.5);
    if (a < 0) a = 0;
    if (b > nslices - 1) b = nslices - 1;
    if (!(a <= b)) {
        *k0 = 1, *k1 = 0;
        return;
    }
    *k0 = (int)a, *k1 = (int)b;
}

/* Per-slice spans. Every occupied block (a cube of SLICE_OCC_B render voxels, widened
 * by a small margin for rounding) meets the slices between the planes through its
 * nearest and farthest corners; a sample of slice k can fall in it only at the pixels
 * inside the projection of its corners (and the texels inside their orthographic
 * projection along the light), widened by one pixel. The spans of a row are the union
 * of those footprints, so the passes visit what the occupied volume covers instead of
 * the whole image and light buffer. */
typedef struct {
    int k0, k1;          /* slices */
    int ex0, ex1, ey0, ey1; /* pixels (ex0 > ex1: none) */
    int lx0, lx1, ly0, ly1; /* light texels */
} sfoot;

static int clampi_d(double v, int lo, int hi)
{
    if (!(v > lo)) return lo; /* NaN too */
    if (v > hi) return hi;
    return (int)v;
}

static void block_footprint(const sjob *j, const atmos_camera *cam, const double cf[3], const double cr[3],
                            const double cu[3], int bi, int bj, int bk, sfoot *o)
{
    const sgrid *g = j->g;
    const double mg = 0.05; /* render voxels: float rounding of the sample positions */
    double lo[3], hi[3];
    const int b[3] = {bi, bj, bk};
    for (int a = 0; a < 3; a++) {
        double u0 = (double)b[a] * SLICE_OCC_B - mg, u1 = fmin((double)(b[a] + 1) * SLICE_OCC_B, g->c[a] - 1.0) + mg;
        lo[a] = (u0 - g->off[a]) / g->sc;
        hi[a] = (u1 - g->off[a]) / g->sc;
    }
    double smin = INFINITY, smax = -INFINITY, xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    int behind = 0;
    const double th = cam->tan_half_fov, W = cam->width, H = cam->height;
    for (int c = 0; c < 8; c++) {
        double p[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        double sv = atmos__dot3(p, j->h);
        smin = fmin(smin, sv), smax = fmax(smax, sv);
        double uv = atmos__dot3(p, j->e1), vv = atmos__dot3(p, j->e2);
        umin = fmin(umin, uv), umax = fmax(umax, uv);
        vmin = fmin(vmin, vv), vmax = fmax(vmax, vv);
        double r[3] = {p[0] - j->eye[0], p[1] - j->eye[1], p[2] - j->eye[2]};
        double z = atmos__dot3(r, cf);
        if (!(z > 1e-6)) {
            behind++;
            continue;
        }
        /* Image position (pixels; centres at +0.5) as atmos_camera_ray inverts it, in
         * eye-buffer pixels. */
        double px = 0.5 * (W + atmos__dot3(r, cr) / (z * th) * H) / j->sx, py = 0.5 * (H - atmos__dot3(r, cu) / (z * th) * H) / j->sy;
        xmin = fmin(xmin, px), xmax = fmax(xmax, px);
        ymin = fmin(ymin, py), ymax = fmax(ymax, py);
    }
    atmos__slice_range(smin, smax, j->s0, j->ds, j->nslices, &o->k0, &o->k1);
    if (behind == 8) {
        o->ex0 = o->ey0 = 1, o->ex1 = o->ey1 = 0; /* rays only go forwards */
    } else if (behind) {
        o->ex0 = o->ey0 = 0, o->ex1 = j->W - 1, o->ey1 = j->H - 1; /* straddles the eye: everywhere */
    } else {
        o->ex0 = clampi_d(floor(xmin - 0.5) - 1, 0, j->W), o->ex1 = clampi_d(ceil(xmax - 0.5) + 1, -1, j->W - 1);
        o->ey0 = clampi_d(floor(ymin - 0.5) - 1, 0, j->H), o->ey1 = clampi_d(ceil(ymax - 0.5) + 1, -1, j->H - 1);
    }
    /* Texel a's ray is at u = u0 + (a + 0.5) du. */
    o->lx0 = clampi_d(floor((umin - j->u0) / j->du - 0.5) - 1, 0, j->L);
    o->lx1 = clampi_d(ceil((umax - j->u0) / j->du - 0.5) + 1, -1, j->L - 1);
    o->ly0 = clampi_d(floor((vmin - j->v0) / j->dv - 0.5) - 1, 0, j->L);
    o->ly1 = clampi_d(ceil((vmax - j->v0) / j->dv - 0.5) + 1, -1, j->L - 1);
}

/* Fills j->espan and j->lspan. Returns 0 if out of memory. */
int atmos__slice_build_spans(sjob *j, const atmos_camera *cam, const double cf[3], const double cr[3],
                             const double cu[3], int threads)
{
    const sgrid *g = j->g;
    size_t nb = (size_t)g->ob[0] * g->ob[1] * g->ob[2], nocc = 0;
    for (size_t i = 0; i < nb; i++) nocc += g->occ[i] != 0;
    sfoot *fp = malloc(sizeof *fp * (nocc ? nocc : 1));
    size_t *idx = malloc(sizeof *idx * (nocc ? nocc : 1));
    if (!fp || !idx) {
        free(fp), free(idx);
        return 0;
    }
    nocc = 0;
    for (size_t i = 0; i < nb; i++)
        if (g->occ[i]) idx[nocc++] = i;
    const long long no = (long long)nocc;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long i = 0; i < no; i++) {
        size_t b = idx[i];
        int bi = (int)(b % (size_t)g->ob[0]), bj = (int)((b / (size_t)g->ob[0]) % (size_t)g->ob[1]),
            bk = (int)(b / ((size_t)g->ob[0] * g->ob[1]));
        block_footprint(j, cam, cf, cr, cu, bi, bj, bk, &fp[i]);
    }
    free(idx);
    const int K = j->nslices, H = j->H, L = j->L;
    /* Each thread owns a contiguous range of slices, so the min/max updates do not race. */
#pragma omp parallel num_threads(threads)
    {
        int nt = omp_get_num_threads(), tid = omp_get_thread_num();
        int k0 = (int)((long long)K * tid / nt), k1 = (int)((long long)K * (tid + 1) / nt) - 1;
        for (int k = k0; k <= k1; k++) {
            for (int y = 0; y < H; y++) j->espan[(size_t)k * H + y] = (sspan){j->W, -1};
            for (int b = 0; b < L; b++) j->lspan[(size_t)k * L + b] = (sspan){L, -1};
        }
        for (size_t i = 0; i < nocc; i++) {
            const sfoot *f = &fp[i];
            int a = f->k0 > k0 ? f->k0 : k0, z = f->k1 < k1 ? f->k1 : k1;
            for (int k = a; k <= z; k++) {
                for (int y = f->ey0; y <= f->ey1 && f->ex0 <= f->ex1; y++) {
                    sspan *s = &j->espan[(size_t)k * H + y];
                    if (f->ex0 < s->x0) s->x0 = f->ex0;
                    if (f->ex1 > s->x1) s->x1 = f->ex1;
                }
                for (int y = f->ly0; y <= f->ly1 && f->lx0 <= f->lx1; y++) {
                    sspan *s = &j->lspan[(size_t)k * L + y];
                    if (f->lx0 < s->x0) s->x0 = f->lx0;
                    if (f->lx1 > s->x1) s->x1 = f->lx1;
                }
            }
        }
    }
    free(fp);
    for (int y = 0; y < H; y++) {
        sspan u = {j->W, -1};
        for (int k = 0; k < K; k++) {
            const sspan *e = &j->espan[(size_t)k * H + y];
            if (e->x0 < u.x0) u.x0 = e->x0;
            if (e->x1 > u.x1) u.x1 = e->x1;
        }
        j->erow[y] = u;
    }
    /* Light spans of slices k - batch..k (the texels a ring slot may hold stale). */
    for (int b = 0; b < L; b++)
        for (int k = 0; k < K; k++) {
            sspan u = {L, -1};
            for (int q = k - j->batch < 0 ? 0 : k - j->batch; q <= k; q++) {
                const sspan *e = &j->lspan[(size_t)q * L + b];
                if (e->x0 < u.x0) u.x0 = e->x0;
                if (e->x1 > u.x1) u.x1 = e->x1;
            }
            j->wspan[(size_t)k * L + b] = u;
        }
    for (int b = 0; b < L; b++) {
        sspan u = {L, -1};
        for (int k = 0; k < K; k++) {
            const sspan *e = &j->lspan[(size_t)k * L + b];
            if (e->x0 < u.x0) u.x0 = e->x0;
            if (e->x1 > u.x1) u.x1 = e->x1;
        }
        j->lrow[b] = u;
    }
    return 1;
}

/* Restricts the eye spans to the eye-buffer pixels [x0, x1) x [y0, y1) (a region of the
 * image): pixels outside are neither set up nor sampled. Each pixel's passes depend on
 * itself and the light buffer alone, so the pixels inside come out as in a whole frame. */
void atmos__slice_clip_spans(sjob *j, int x0, int y0, int x1, int y1)
{
    for (int y = 0; y < j->H; y++) {
        const int out = y < y0 || y >= y1;
        sspan *e = &j->erow[y];
        if (out || e->x1 < x0 || e->x0 >= x1) *e = (sspan){j->W, -1};
        if (e->x0 < x0) e->x0 = x0;
        if (e->x1 > x1 - 1) e->x1 = x1 - 1;
        for (int k = 0; k < j->nslices; k++) {
            sspan *s = &j->espan[(size_t)k * j->H + y];
            if (out) *s = (sspan){j->W, -1};
            if (s->x0 < x0) s->x0 = x0;
            if (s->x1 > x1 - 1) s->x1 = x1 - 1;
        }
    }
}
