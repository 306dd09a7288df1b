/* The coarse grids of the diffusion solve's cold start (lfield.h, atmos__lfield_diffuse with
 * `cascade`): a medium and its source on a grid of cells twice as large, and the coarse
 * solution carried back to the fine grid.
 *
 * Coarse cell I covers the fine cells 2 I and 2 I + 1 of every axis of more than one cell (an
 * axis of one cell, periodic, stays one cell). A fine grid of an odd count is padded with one
 * cell of vacuum: the coarse box holds the fine box's medium and source exactly (the means
 * below divide by the 2, 4 or 8 children a full coarse cell has), plus an empty margin. */
#include "light/lfield.h"

#include <stdlib.h>
#include <string.h>

/* 1: axis a of m is halved (more than one cell); its coarse count in *cc. */
static int halved(const atmos__lmedium *m, int a, int *cc)
{
    const int c = m->c[a];
    *cc = c > 1 ? (c + 1) / 2 : 1;
    return c > 1;
}

int atmos__lmedium_can_coarsen(const atmos__lmedium *m)
{
    for (int a = 0; a < 3; a++)
        if (m->c[a] < 4 && !(m->c[a] == 1 && m->periodic[a])) return 0;
    return 1;
}

int atmos__lmedium_coarsen(const atmos__lmedium *m, const atmos__lsource *q, atmos__lmedium *cm, float **cq,
                           float **cq1)
{
    int cc[3], hv[3];
    for (int a = 0; a < 3; a++) hv[a] = halved(m, a, &cc[a]);
    *cq = *cq1 = NULL;
    if (!atmos__lmedium_alloc(cm, cc[0], cc[1], cc[2], m->n, 2.0 * m->h)) return 0;
    memcpy(cm->periodic, m->periodic, sizeof cm->periodic);
    const int n = m->n;
    const size_t cnt = atmos__lmedium_cells(cm) * (size_t)n;
    *cq = calloc(cnt, sizeof(float));
    if (q->Q1) *cq1 = calloc(cnt * 3, sizeof(float));
    if (m->jin && (cm->jin = malloc(sizeof(float) * 6 * (size_t)n))) memcpy(cm->jin, m->jin, sizeof(float) * 6 * n);
    float *sg = calloc(cnt, sizeof(float));
    if (!*cq || (q->Q1 && !*cq1) || (m->jin && !cm->jin) || !sg) {
        free(*cq), free(*cq1), free(sg), atmos__lmedium_free(cm);
        *cq = *cq1 = NULL;
        return 0;
    }
    const float inv = 1.0f / (float)((hv[0] ? 2 : 1) * (hv[1] ? 2 : 1) * (hv[2] ? 2 : 1));
    for (int k = 0; k < m->c[2]; k++)
        for (int j = 0; j < m->c[1]; j++)
            for (int i = 0; i < m->c[0]; i++) {
                const size_t f = ((size_t)k * m->c[1] + j) * m->c[0] + i;
                const size_t c = ((size_t)(hv[2] ? k / 2 : k) * cc[1] + (hv[1] ? j / 2 : j)) * cc[0] + (hv[0] ? i / 2 : i);
                for (int w = 0; w < n; w++) {
                    const size_t a = f * n + w, b = c * n + w;
                    cm->sig_t[b] += inv * m->sig_t[a];
                    cm->sig_s[b] += inv * m->sig_s[a];
                    sg[b] += inv * m->sig_s[a] * m->g[a];
                    (*cq)[b] += inv * q->Q[a];
                    if (q->Q1)
                        for (int x = 0; x < 3; x++) (*cq1)[b * 3 + x] += inv * q->Q1[a * 3 + x];
                }
            }
    for (size_t b = 0; b < cnt; b++) cm->g[b] = cm->sig_s[b] > 0 ? sg[b] / cm->sig_s[b] : 0.0f;
    free(sg);
    return 1;
}

/* Fine cell i's centre on the coarse axis of cc cells (halved or not): the lower coarse cell
 * and the weight of the upper one, clamped to the outer cells' centres. */
static void coarse_axis(int i, int hv, int cc, int *lo, float *t)
{
    if (!hv || cc < 2) {
        *lo = hv ? 0 : i, *t = 0.0f;
        return;
    }
    float x = 0.5f * (float)i - 0.25f; /* centre (i + 1/2) h at coarse coordinate (i + 1/2)/2 - 1/2 */
    x = x < 0.0f ? 0.0f : (x > (float)(cc - 1) ? (float)(cc - 1) : x);
    int a = (int)x;
    a = a > cc - 2 ? cc - 2 : a;
    *lo = a, *t = x - (float)a;
}

void atmos__lfield_prolong(const atmos__lmedium *cm, const float *cphi, const atmos__lmedium *m, float *phi, int w)
{
    const int n = m->n;
    int hv[3], cc[3];
    for (int a = 0; a < 3; a++) hv[a] = halved(m, a, &cc[a]);
    const size_t sx = cc[0] > 1 ? 1 : 0, sy = cc[1] > 1 ? (size_t)cc[0] : 0,
                 sz = cc[2] > 1 ? (size_t)cc[0] * cc[1] : 0;
    for (int k = 0; k < m->c[2]; k++)
        for (int j = 0; j < m->c[1]; j++)
            for (int i = 0; i < m->c[0]; i++) {
                int I, J, K;
                float a, b, c;
                coarse_axis(i, hv[0], cc[0], &I, &a);
                coarse_axis(j, hv[1], cc[1], &J, &b);
                coarse_axis(k, hv[2], cc[2], &K, &c);
                const size_t o = ((size_t)K * cm->c[1] + J) * cm->c[0] + I;
                const float *p = cphi + w;
#define PV(d) p[(o + (d)) * (size_t)n]
                const float v = (1 - c) * ((1 - b) * ((1 - a) * PV(0) + a * PV(sx)) + b * ((1 - a) * PV(sy) + a * PV(sx + sy))) +
                                c * ((1 - b) * ((1 - a) * PV(sz) + a * PV(sx + sz)) +
                                     b * ((1 - a) * PV(sy + sz) + a * PV(sx + sy + sz)));
#undef PV
                phi[(((size_t)k * m->c[1] + j) * m->c[0] + i) * n + w] = v;
            }
}
