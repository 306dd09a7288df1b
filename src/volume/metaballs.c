/* Metaballs and their fractal refinement (Nishita et al. 1996 §4).
 *
 * The density field is the sum of the balls' degree-6 falloffs. Refinement: the
 * isosurface is triangulated by marching cubes and new, smaller balls are placed
 * on its triangles; this repeats with decreasing radius. We pick triangles with
 * probability proportional to their area (the expected count per triangle is the
 * same as "balls within each triangle", and the total is bounded), place the ball
 * at a random point of the triangle pushed slightly outward, and shrink radii with
 * distance from the cloud's centre so the smallest balls end up at the fringe, as
 * the paper describes. Growth on downward-facing triangles is limited (none below
 * n_y = -0.25) so that bases stay flat and tops grow upward.
 */
#include "core/internal.h"
#include "volume/generator.h"

#include <math.h>
#include <stdlib.h>

int atmos__gen_balls_add(gen_balls *bl, double x, double y, double z, double r, double w, double squash)
{
    if (bl->n == bl->cap) {
        int nc = bl->cap ? bl->cap * 2 : 256;
        gen_ball *p = realloc(bl->b, (size_t)nc * sizeof *p);
        if (!p) return 0;
        bl->b = p;
        bl->cap = nc;
    }
    bl->b[bl->n++] = (gen_ball){{x, y, z}, r, w, squash > 0 ? squash : 1};
    return 1;
}

void atmos__gen_balls_free(gen_balls *bl)
{
    free(bl->b);
    bl->b = NULL;
    bl->n = bl->cap = 0;
}

void atmos__gen_accumulate(gen_grid *g, const gen_balls *bl, int first, int threads)
{
    const double s = g->voxel;
    /* Each thread owns whole z planes and adds the balls in list order: the sum in
     * every voxel is the same for any thread count. */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int k = 0; k < g->n[2]; k++) {
        double z = g->origin[2] + (k + 0.5) * s;
        for (int b = first; b < bl->n; b++) {
            const gen_ball *ball = &bl->b[b];
            double dz = z - ball->c[2];
            if (fabs(dz) >= ball->r) continue;
            double ry = ball->r / ball->squash;
            int j0 = (int)floor((ball->c[1] - ry - g->origin[1]) / s), j1 = (int)ceil((ball->c[1] + ry - g->origin[1]) / s);
            int i0 = (int)floor((ball->c[0] - ball->r - g->origin[0]) / s),
                i1 = (int)ceil((ball->c[0] + ball->r - g->origin[0]) / s);
            if (j0 < 0) j0 = 0;
            if (i0 < 0) i0 = 0;
            if (j1 > g->n[1] - 1) j1 = g->n[1] - 1;
            if (i1 > g->n[0] - 1) i1 = g->n[0] - 1;
            double inv = 1.0 / (ball->r * ball->r);
            for (int j = j0; j <= j1; j++) {
                double dy = (g->origin[1] + (j + 0.5) * s - ball->c[1]) * ball->squash;
                double ryz = (dy * dy + dz * dz) * inv;
                if (ryz >= 1) continue;
                float *row = g->v + ((size_t)k * g->n[1] + j) * g->n[0];
                for (int i = i0; i <= i1; i++) {
                    double dx = g->origin[0] + (i + 0.5) * s - ball->c[0];
                    double s2 = ryz + dx * dx * inv;
                    if (s2 < 1) row[i] += (float)(ball->w * atmos__wyvill(s2));
                }
            }
        }
    }
}

/* Index of the triangle whose cumulative area first exceeds x. */
static size_t pick(const double *cdf, size_t n, double x)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (cdf[mid] > x) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

int atmos__gen_refine(gen_grid *g, gen_balls *bl, const gen_refine *p, gen_rng *rng, int threads)
{
    /* The cloud's centre and size (from the initial balls) for the fringe rule. */
    double cen[3] = {0, 0, 0}, wsum = 0, ext = 0;
    for (int b = 0; b < bl->n; b++) {
        double w = bl->b[b].r * bl->b[b].r * bl->b[b].r;
        for (int a = 0; a < 3; a++) cen[a] += w * bl->b[b].c[a];
        wsum += w;
    }
    if (wsum > 0)
        for (int a = 0; a < 3; a++) cen[a] /= wsum;
    for (int b = 0; b < bl->n; b++) {
        double d = sqrt(pow(bl->b[b].c[0] - cen[0], 2) + pow(bl->b[b].c[2] - cen[2], 2)) + bl->b[b].r;
        if (d > ext) ext = d;
    }
    if (ext <= 0) ext = 1;
    double r = p->r0;
    for (int level = 0; level < p->levels; level++, r *= p->ratio) {
        /* Sample the surface at about half the new radius, never finer than a voxel. */
        int stride = (int)(0.5 * r / g->voxel);
        if (stride < 1) stride = 1;
        if (stride > 8) stride = 8;
        gen_mesh mesh;
        if (!atmos__gen_marching_cubes(g, stride, p->iso, p->floor_j, 2000000, &mesh)) {
            free(mesh.t);
            return 0;
        }
        if (mesh.n == 0) {
            free(mesh.t);
            break;
        }
        double *cdf = malloc(mesh.n * sizeof *cdf);
        if (!cdf) {
            free(mesh.t);
            return 0;
        }
        double total = 0;
        for (size_t t = 0; t < mesh.n; t++) cdf[t] = (total += mesh.t[t].area);
        long want = (long)(p->coverage * total / (ATMOS_PI * r * r));
        if (want > p->max_balls) want = p->max_balls;
        int first = bl->n;
        for (long n = 0; n < want; n++) {
            const gen_tri *t = &mesh.t[pick(cdf, mesh.n, gen_u01(rng) * total)];
            double u = gen_u01(rng), v = gen_u01(rng), acc = gen_u01(rng), rr = gen_range(rng, 0.7, 1.3);
            double ny = t->n[1];
            if (ny < -0.25) continue;             /* downward: no growth (flat base) */
            if (ny < 0.15 && acc > 0.33) continue; /* sideways: limited growth */
            if (u + v > 1) u = 1 - u, v = 1 - v;
            double x[3];
            for (int a = 0; a < 3; a++)
                x[a] = t->p[0][a] + u * (t->p[1][a] - t->p[0][a]) + v * (t->p[2][a] - t->p[0][a]);
            /* Smaller towards the fringe (Nishita §4). */
            double dist = sqrt(pow(x[0] - cen[0], 2) + pow(x[2] - cen[2], 2)) / ext;
            double rad = r * rr * (p->fringe ? fmax(0.6, 1.15 - 0.5 * dist) : 1.0);
            for (int a = 0; a < 3; a++) x[a] += 0.25 * rad * t->n[a];
            if (!atmos__gen_balls_add(bl, x[0], x[1], x[2], rad, 1.0, 1.0)) {
                free(cdf);
                free(mesh.t);
                return 0;
            }
        }
        free(cdf);
        free(mesh.t);
        atmos__gen_accumulate(g, bl, first, threads);
        atmos__progress(p->ctx, "volume generate", 0.1 + 0.8 * (level + 1.0) / p->levels);
    }
    return 1;
}
