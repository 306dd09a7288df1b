/* The clouds of a particle set (pcloud.h, atmos__pcloud_cluster): union-find over the pairs
 * of particles whose splats come within the link distance, the pairs found through a grid of
 * cells as wide as the largest reach, so each particle looks at its 27 neighbouring cells. */
#include "particles/pcloud.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct cell_key {
    int64_t key;
    int p;
} cell_key;

static int by_key(const void *a, const void *b)
{
    const cell_key *x = a, *y = b;
    return x->key < y->key ? -1 : (x->key > y->key ? 1 : (x->p > y->p) - (x->p < y->p));
}

static int root(int *parent, int i)
{
    while (parent[i] != i) parent[i] = parent[parent[i]], i = parent[i];
    return i;
}

static void join(int *parent, int a, int b)
{
    a = root(parent, a), b = root(parent, b);
    if (a != b) parent[a > b ? a : b] = a < b ? a : b; /* the lower index is the root */
}

/* The first entry of keys[0..n) at or after key. */
static int lower(const cell_key *keys, int n, int64_t key)
{
    int lo = 0, hi = n;
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        if (keys[mid].key < key) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

static void link_pairs(const atmos__pcloud *pc, double link, int *parent, cell_key *keys)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, smax = 0;
    for (int p = 0; p < pc->n; p++) {
        lo[0] = fmin(lo[0], pc->x[p]), lo[1] = fmin(lo[1], pc->y[p]), lo[2] = fmin(lo[2], pc->z[p]);
        smax = fmax(smax, pc->s[p]);
    }
    const double cs = 2.0 * ATMOS__PCLOUD_CUT * smax + link; /* the largest reach between centres */
    const int64_t M = 1 << 20;
    for (int p = 0; p < pc->n; p++) {
        const int64_t i = (int64_t)((pc->x[p] - lo[0]) / cs), j = (int64_t)((pc->y[p] - lo[1]) / cs),
                      k = (int64_t)((pc->z[p] - lo[2]) / cs);
        keys[p].key = (i * M + j) * M + k, keys[p].p = p;
    }
    qsort(keys, (size_t)pc->n, sizeof *keys, by_key);
    for (int q = 0; q < pc->n; q++) {
        const int p = keys[q].p;
        const int64_t i = (int64_t)((pc->x[p] - lo[0]) / cs), j = (int64_t)((pc->y[p] - lo[1]) / cs),
                      k = (int64_t)((pc->z[p] - lo[2]) / cs);
        for (int di = -1; di <= 1; di++)
            for (int dj = -1; dj <= 1; dj++)
                for (int dk = -1; dk <= 1; dk++) {
                    const int64_t key = ((i + di) * M + (j + dj)) * M + (k + dk);
                    for (int r = lower(keys, pc->n, key); r < pc->n && keys[r].key == key; r++) {
                        const int o = keys[r].p;
                        if (o <= p) continue;
                        const double dx = pc->x[o] - pc->x[p], dy = pc->y[o] - pc->y[p], dz = pc->z[o] - pc->z[p];
                        const double reach = ATMOS__PCLOUD_CUT * (pc->s[o] + pc->s[p]) + link;
                        if (dx * dx + dy * dy + dz * dz <= reach * reach) join(parent, p, o);
                    }
                }
    }
}

/* Each cloud's box middle and the sphere about it holding its splats. */
static void spheres(const atmos__pcloud *pc, atmos__pclusters *c)
{
    for (int k = 0; k < c->n; k++) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, r = 0;
        for (int q = c->start[k]; q < c->start[k + 1]; q++) {
            const int p = c->idx[q];
            const double v[3] = {pc->x[p], pc->y[p], pc->z[p]};
            for (int a = 0; a < 3; a++) lo[a] = fmin(lo[a], v[a]), hi[a] = fmax(hi[a], v[a]);
        }
        for (int a = 0; a < 3; a++) c->centre[k][a] = 0.5 * (lo[a] + hi[a]);
        for (int q = c->start[k]; q < c->start[k + 1]; q++) {
            const int p = c->idx[q];
            const double dx = pc->x[p] - c->centre[k][0], dy = pc->y[p] - c->centre[k][1], dz = pc->z[p] - c->centre[k][2];
            r = fmax(r, sqrt(dx * dx + dy * dy + dz * dz) + ATMOS__PCLOUD_CUT * pc->s[p]);
        }
        c->radius[k] = r;
    }
}

atmos_status atmos__pcloud_cluster(atmos_context *ctx, const atmos__pcloud *pc, double link, atmos__pclusters *out)
{
    memset(out, 0, sizeof *out);
    const size_t n = (size_t)(pc->n ? pc->n : 1);
    int *parent = malloc(sizeof(int) * n), *id = malloc(sizeof(int) * n);
    cell_key *keys = malloc(sizeof *keys * n);
    out->start = calloc(n + 1, sizeof(int)), out->idx = malloc(sizeof(int) * n);
    if (!parent || !id || !keys || !out->start || !out->idx) goto nomem;
    for (int p = 0; p < pc->n; p++) parent[p] = p;
    link_pairs(pc, fmax(link, 0.0), parent, keys);
    for (int p = 0; p < pc->n; p++) id[p] = root(parent, p) == p ? out->n++ : -1;
    for (int p = 0; p < pc->n; p++) id[p] = id[root(parent, p)];
    for (int p = 0; p < pc->n; p++) out->start[id[p] + 1]++;
    for (int k = 0; k < out->n; k++) out->start[k + 1] += out->start[k];
    memset(parent, 0, sizeof(int) * n); /* now the fill counts */
    for (int p = 0; p < pc->n; p++) out->idx[out->start[id[p]] + parent[id[p]]++] = p;
    out->centre = malloc(sizeof *out->centre * (size_t)(out->n ? out->n : 1));
    out->radius = malloc(sizeof(double) * (size_t)(out->n ? out->n : 1));
    if (!out->centre || !out->radius) goto nomem;
    spheres(pc, out);
    free(parent), free(id), free(keys);
    return ATMOS_OK;
nomem:
    free(parent), free(id), free(keys);
    atmos__pclusters_free(out);
    return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory grouping the clouds");
}

void atmos__pclusters_free(atmos__pclusters *c)
{
    free(c->start), free(c->idx), free(c->centre), free(c->radius);
    memset(c, 0, sizeof *c);
}
