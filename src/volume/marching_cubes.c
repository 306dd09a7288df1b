/* Marching cubes (Lorensen & Cline 1987, as used by Nishita et al. 1996 §4 to
 * triangulate the metaball isosurface before fractal refinement).
 *
 * Instead of the usual 256-entry triangle table we build each cube's polygons
 * from its faces, which is what the table encodes: on every face the sign changes
 * along its four edges give 0, 1 or 2 segments; every crossed cube edge belongs to
 * exactly two faces, so the segments link into closed loops, and each loop is
 * triangulated as a fan. A face with four crossings (the ambiguous case) is
 * resolved by the mean of its corners (the bilinear saddle test in its simplest
 * form): both cubes sharing the face see the same values and choose the same
 * connection, so the surface has no cracks. Triangle orientation does not matter
 * here: normals come from the field gradient.
 */
#include "volume/generator.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Corner c of a cube: bit 0 = +x, bit 1 = +y, bit 2 = +z. */
static const int edge_corners[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                        {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
/* The four corners of each face in cyclic order. */
static const int face_corners[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};

static int edge_between(int a, int b)
{
    for (int e = 0; e < 12; e++)
        if ((edge_corners[e][0] == a && edge_corners[e][1] == b) || (edge_corners[e][0] == b && edge_corners[e][1] == a))
            return e;
    return -1;
}

static float grid_at(const gen_grid *g, int i, int j, int k, int floor_j)
{
    if (i < 0) i = 0;
    if (j < 0) j = 0;
    if (k < 0) k = 0;
    if (i >= g->n[0]) i = g->n[0] - 1;
    if (j >= g->n[1]) j = g->n[1] - 1;
    if (k >= g->n[2]) k = g->n[2] - 1;
    if (j < floor_j) return 0;
    return g->v[((size_t)k * g->n[1] + j) * g->n[0] + i];
}

static int push(gen_mesh *m, const gen_tri *t, size_t max_tris)
{
    if (m->n >= max_tris) return 1;
    if (m->n == m->cap) {
        size_t nc = m->cap ? m->cap * 2 : 4096;
        gen_tri *p = realloc(m->t, nc * sizeof *p);
        if (!p) return 0;
        m->t = p;
        m->cap = nc;
    }
    m->t[m->n++] = *t;
    return 1;
}

/* Each grid row's (j, k) largest value into rmax[k n1 + j], at least 0 (the value outside the grid)
 * and 0 below floor_j: a row of cubes whose four grid rows are at most iso has no corner inside,
 * so none of its cubes makes a polygon (most rows of a cloud's box). */
static void row_max(const gen_grid *g, int floor_j, float *rmax)
{
    for (int k = 0; k < g->n[2]; k++)
        for (int j = 0; j < g->n[1]; j++) {
            const float *r = g->v + ((size_t)k * g->n[1] + j) * g->n[0];
            float m = 0;
            for (int i = 0; j >= floor_j && i < g->n[0]; i++) m = r[i] > m ? r[i] : m;
            rmax[(size_t)k * g->n[1] + j] = m;
        }
}

/* The largest of row_max's values over the grid rows that the row of cubes (j, k) reads. */
static float cube_row_max(const gen_grid *g, const float *rmax, int stride, int j, int k)
{
    float m = 0;
    for (int dk = 0; dk <= stride; dk += stride)
        for (int dj = 0; dj <= stride; dj += stride) {
            const int cj = j + dj, ck = k + dk;
            if (cj >= 0 && ck >= 0 && cj < g->n[1] && ck < g->n[2] && rmax[(size_t)ck * g->n[1] + cj] > m)
                m = rmax[(size_t)ck * g->n[1] + cj];
        }
    return m;
}

/* atmos__gen_marching_cubes's triangles into out (emptied by the caller), the rows of cubes with no
 * corner above iso skipped (rmax: row_max). 0: out of memory. */
static int march(const gen_grid *g, const float *rmax, int stride, float iso, int floor_j, size_t max_tris,
                 gen_mesh *out)
{
    int edge_tab[8][8];
    for (int a = 0; a < 8; a++)
        for (int b = 0; b < 8; b++) edge_tab[a][b] = edge_between(a, b);
    const double s = g->voxel;
    for (int k = -stride; k < g->n[2]; k += stride)
        for (int j = -stride; j < g->n[1]; j += stride) {
            if (!(cube_row_max(g, rmax, stride, j, k) > iso)) continue; /* no corner inside */
            for (int i = -stride; i < g->n[0]; i += stride) {
                /* Samples outside the grid read as 0 so the surface closes at the borders. */
                float v[8];
                int inside = 0;
                for (int c = 0; c < 8; c++) {
                    int ci = i + (c & 1) * stride, cj = j + (c >> 1 & 1) * stride, ck = k + (c >> 2 & 1) * stride;
                    int out_of = ci < 0 || cj < 0 || ck < 0 || ci >= g->n[0] || cj >= g->n[1] || ck >= g->n[2];
                    v[c] = out_of ? 0.0f : grid_at(g, ci, cj, ck, floor_j);
                    inside |= (v[c] > iso) << c;
                }
                if (inside == 0 || inside == 255) continue;
                /* Segments per face, linked through the crossed edges. */
                int link[12][2], nl[12];
                memset(nl, 0, sizeof nl);
                for (int f = 0; f < 6; f++) {
                    const int *fc = face_corners[f];
                    int cross[4], nc = 0;
                    for (int q = 0; q < 4; q++) {
                        int a = fc[q], b = fc[(q + 1) & 3];
                        if (((inside >> a) & 1) != ((inside >> b) & 1)) cross[nc++] = q;
                    }
                    int seg[2][2], ns = 0;
                    if (nc == 2) {
                        seg[0][0] = edge_tab[fc[cross[0]]][fc[(cross[0] + 1) & 3]];
                        seg[0][1] = edge_tab[fc[cross[1]]][fc[(cross[1] + 1) & 3]];
                        ns = 1;
                    } else if (nc == 4) {
                        /* Cut off the corners that are NOT connected across the face centre. */
                        float mean = 0.25f * (v[fc[0]] + v[fc[1]] + v[fc[2]] + v[fc[3]]);
                        int cut_inside = !(mean > iso);
                        for (int q = 0; q < 4; q++)
                            if (((inside >> fc[q]) & 1) == cut_inside) {
                                seg[ns][0] = edge_tab[fc[(q + 3) & 3]][fc[q]];
                                seg[ns][1] = edge_tab[fc[q]][fc[(q + 1) & 3]];
                                ns++;
                            }
                    }
                    for (int q = 0; q < ns; q++) {
                        int a = seg[q][0], b = seg[q][1];
                        if (nl[a] < 2) link[a][nl[a]++] = b;
                        if (nl[b] < 2) link[b][nl[b]++] = a;
                    }
                }
                /* Edge crossing points in world space. */
                float pos[12][3];
                for (int e = 0; e < 12; e++) {
                    if (nl[e] != 2) continue;
                    int a = edge_corners[e][0], b = edge_corners[e][1];
                    float t = (iso - v[a]) / (v[b] - v[a]);
                    for (int ax = 0; ax < 3; ax++) {
                        int ia = (ax == 0 ? i : ax == 1 ? j : k) + ((a >> ax) & 1) * stride;
                        int ib = (ax == 0 ? i : ax == 1 ? j : k) + ((b >> ax) & 1) * stride;
                        double x = ia + t * (ib - ia) + 0.5;
                        pos[e][ax] = (float)(g->origin[ax] + x * s);
                    }
                }
                int used[12] = {0};
                for (int e0 = 0; e0 < 12; e0++) {
                    if (nl[e0] != 2 || used[e0]) continue;
                    int loop[12], n = 0, prev = -1, cur = e0;
                    while (!used[cur] && n < 12) {
                        used[cur] = 1;
                        loop[n++] = cur;
                        int next = link[cur][0] == prev ? link[cur][1] : link[cur][0];
                        prev = cur;
                        cur = next;
                    }
                    for (int q = 1; q + 1 < n; q++) {
                        gen_tri t;
                        memcpy(t.p[0], pos[loop[0]], sizeof t.p[0]);
                        memcpy(t.p[1], pos[loop[q]], sizeof t.p[1]);
                        memcpy(t.p[2], pos[loop[q + 1]], sizeof t.p[2]);
                        double e1[3], e2[3], cr[3], cen[3];
                        for (int ax = 0; ax < 3; ax++) {
                            e1[ax] = t.p[1][ax] - t.p[0][ax];
                            e2[ax] = t.p[2][ax] - t.p[0][ax];
                            cen[ax] = (t.p[0][ax] + t.p[1][ax] + t.p[2][ax]) / 3.0;
                        }
                        cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
                        cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
                        cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
                        t.area = (float)(0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]));
                        if (!(t.area > 0)) continue;
                        /* Outward normal: minus the gradient at the nearest grid point. */
                        int gi = (int)floor((cen[0] - g->origin[0]) / s), gj = (int)floor((cen[1] - g->origin[1]) / s),
                            gk = (int)floor((cen[2] - g->origin[2]) / s);
                        double gr[3] = {grid_at(g, gi + 1, gj, gk, floor_j) - grid_at(g, gi - 1, gj, gk, floor_j),
                                        grid_at(g, gi, gj + 1, gk, floor_j) - grid_at(g, gi, gj - 1, gk, floor_j),
                                        grid_at(g, gi, gj, gk + 1, floor_j) - grid_at(g, gi, gj, gk - 1, floor_j)};
                        double gl = sqrt(gr[0] * gr[0] + gr[1] * gr[1] + gr[2] * gr[2]);
                        if (gl > 0) {
                            for (int ax = 0; ax < 3; ax++) t.n[ax] = (float)(-gr[ax] / gl);
                        } else {
                            double cl = 2 * t.area;
                            for (int ax = 0; ax < 3; ax++) t.n[ax] = (float)(cr[ax] / cl);
                        }
                        if (!push(out, &t, max_tris)) return 0;
                    }
                }
            }
        }
    return 1;
}

int atmos__gen_marching_cubes(const gen_grid *g, int stride, float iso, int floor_j, size_t max_tris, gen_mesh *out)
{
    memset(out, 0, sizeof *out);
    float *rmax = malloc(sizeof(float) * (size_t)g->n[1] * g->n[2]);
    if (!rmax) return 0;
    row_max(g, floor_j, rmax);
    const int ok = march(g, rmax, stride, iso, floor_j, max_tris, out);
    free(rmax);
    return ok;
}
