/* The aerial-perspective volume (atmosphere_ops.h; after Hillaire 2020 §5.5's froxels): for
 * one eye and sun, what the air between the eye and a distance t along a view direction adds
 * (in-scatter) and keeps (transmittance), on a grid over the directions of a pinhole frustum
 * times distance slices crowded near the eye, interpolated per query.
 *
 * Each node direction gets the running sums at every slice distance from one pass along its
 * ray: the planet kinds whose solver has an `aerial` function march it slice by slice and
 * keep the Rayleigh and aerosol single scattering without their phase functions (applied per
 * query at the query's own scattering angle, so the sun's aureole is as sharp as the phase
 * table, not the grid); any other kind answers from its in-scatter and transmittance at each
 * slice distance (the phase function then at the node's angle). Queries interpolate the
 * in-scatter and the optical depth trilinearly: bilinear over the frustum's plane
 * coordinates, linear in distance between the two slices around t. The slices may start at a
 * distance tmin > 0 (a volume's near side): the air in front of it is then marched as one
 * segment, as the one-ray answer does. */
#include "atmosphere/atmosphere_internal.h"
#include "atmosphere/planet_solver.h"

#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define AP_TAU_MAX 80.0 /* optical depths are kept up to this (transmittance e^-80 ~ 2e-35) */
#define AP_NPH 4096     /* the aerosols' phase function over sin(theta / 2) */

int atmos__aerial_wanted(const atmos_atmosphere *a) { return a->solver != NULL; }

/* Node count along one axis of the frustum: the spread of the rays' vertical component
 * (dy) and of their direction (angle, radians) across it, at 9 points along the axis for each
 * of 3 lines across the other axis. */
static int axis_nodes(const atmos__aerial_grid *g, const double vert[3], int along_u, double across_m)
{
    double dy = 0, ang = 0;
    for (int l = 0; l < 3; l++) {
        double lo = INFINITY, hi = -INFINITY, first[3] = {0, 0, 0}, last[3] = {0, 0, 0};
        for (int i = 0; i < 9; i++) {
            const double a = i / 8.0, b = l / 2.0;
            const double u = g->u0 + (g->u1 - g->u0) * (along_u ? a : b), v = g->v0 + (g->v1 - g->v0) * (along_u ? b : a);
            double d[3];
            for (int c = 0; c < 3; c++) d[c] = g->fwd[c] + u * g->right[c] + v * g->up[c];
            atmos__normalize3(d);
            const double y = atmos__dot3(d, vert);
            lo = fmin(lo, y), hi = fmax(hi, y);
            if (i == 0) memcpy(first, d, sizeof first);
            memcpy(last, d, sizeof last);
        }
        dy = fmax(dy, hi - lo);
        ang = fmax(ang, acos(fmin(1.0, fmax(-1.0, atmos__dot3(first, last)))));
    }
    const double n = fmax(ceil(dy * g->tmax / ATMOS__AERIAL_NODE_SPACING_M),
                          ceil(ang * g->tmax / across_m)) + 1;
    return n < ATMOS__AERIAL_MIN_NODES ? ATMOS__AERIAL_MIN_NODES
                                       : (n > ATMOS__AERIAL_MAX_NODES ? ATMOS__AERIAL_MAX_NODES : (int)n);
}

void atmos__aerial_nodes(const atmos_atmosphere *a, atmos__aerial_grid *g)
{
    double vert[3] = {0, 1, 0}; /* the local vertical where the view's centre ends (a flat earth's y) */
    if (a->planet) {
        for (int c = 0; c < 3; c++) vert[c] = g->eye[c] + g->tmax * g->fwd[c];
        vert[1] += a->planet->r_ground;
        atmos__normalize3(vert);
    }
    /* a low sun: the light of the higher orders changes fast across the view (the twilight
     * sky's light falls off steeply away from the sun's azimuth), so the nodes across halve */
    const double sun_el = atmos__dot3(g->sun, vert);
    const double across = sun_el < ATMOS__AERIAL_LOW_SUN ? 0.5 * ATMOS__AERIAL_NODE_SPACING_ACROSS_M
                                                         : ATMOS__AERIAL_NODE_SPACING_ACROSS_M;
    g->nu = axis_nodes(g, vert, 1, across);
    g->nv = axis_nodes(g, vert, 0, across);
    /* many wavelengths: fewer nodes, so that the table stays within its budget */
    const double per_node = (double)g->nd * a->wl.count * 4 * sizeof(float);
    const double f = sqrt(ATMOS__AERIAL_MAX_BYTES / (per_node * g->nu * g->nv));
    if (f < 1) {
        g->nu = (int)(g->nu * f), g->nv = (int)(g->nv * f);
        g->nu = g->nu < 2 ? 2 : g->nu, g->nv = g->nv < 2 ? 2 : g->nv;
    }
}

/* The aerosols' phase table's node below cos(theta) nu (over x = sin(theta / 2)) and the
 * weight *fp of the next one. */
static int phase_node(double nu, double *fp)
{
    double f = sqrt(fmax(0.0, 0.5 * (1.0 - nu))) * (AP_NPH - 1);
    int ip = (int)f;
    ip = ip > AP_NPH - 2 ? AP_NPH - 2 : ip;
    *fp = f - ip;
    return ip;
}

static double slice_t(const atmos__aerial_grid *g, int j)
{
    const double x = (double)j / (g->nd - 1), f = g->crowd_far ? 1.0 - (1.0 - x) * (1.0 - x) : x * x;
    return g->tmin + (g->tmax - g->tmin) * f;
}

static void node_dir(const atmos__aerial_grid *g, int iu, int iv, double d[3])
{
    const double u = g->u0 + (g->u1 - g->u0) * iu / (g->nu - 1), v = g->v0 + (g->v1 - g->v0) * iv / (g->nv - 1);
    for (int i = 0; i < 3; i++) d[i] = g->fwd[i] + u * g->right[i] + v * g->up[i];
    atmos__normalize3(d);
}

/* Any kind: the in-scatter and transmittance from the eye to each slice distance (to the
 * ground, tg, where the ray meets it first: the segments renderers ask about end there). */
static void node_generic(const atmos_atmosphere *a, const atmos__aerial_grid *g, const double d[3], const double *t,
                         double tg, float *out)
{
    const int n = a->wl.count;
    for (int j = 0; j < g->nd; j++) {
        double S[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
        const double tj = t[j] < tg ? t[j] : tg;
        if (tj > 0) {
            atmos__atm_inscatter_sub(a, g->eye, d, tj, g->sun, n, NULL, S);
            atmos__atm_transmittance_sub(a, g->eye, d, tj, n, NULL, T);
        } else {
            for (int k = 0; k < n; k++) S[k] = 0.0, T[k] = 1.0;
        }
        float *o = out + (size_t)j * n * 4;
        for (int k = 0; k < n; k++) {
            const double tau = T[k] > 0 ? -log(T[k]) : AP_TAU_MAX;
            o[4 * k] = o[4 * k + 1] = 0.0f;
            o[4 * k + 2] = (float)S[k];
            o[4 * k + 3] = (float)(tau < AP_TAU_MAX ? tau : AP_TAU_MAX);
        }
    }
}

/* The aerosols' phase function of each wavelength over x = sin(theta / 2) (AP_NPH nodes),
 * made once per atmosphere (it depends on nothing else): the query's look-up without acos. */
static int mie_table(atmos__aerial *ap, const atmos_atmosphere *a)
{
    if (ap->mie && ap->mie_atm == a) return 1;
    float *m = realloc(ap->mie, sizeof(float) * (size_t)a->wl.count * AP_NPH);
    if (!m) return 0;
    ap->mie = m;
    atmos__planet_mie_phase_table(a->planet, a->wl.count, AP_NPH, m);
    ap->mie_atm = a;
    return 1;
}

int atmos__aerial_build(atmos__aerial *ap, const atmos_atmosphere *a, const atmos__aerial_grid *g, int threads)
{
    if (g->nu < 2 || g->nv < 2 || g->nd < 2 || !(g->tmin >= 0 && g->tmax > g->tmin)) return 0;
    const int n = a->wl.count;
    const size_t node = (size_t)g->nd * n * 4, need = node * g->nu * g->nv;
    if (need > ap->cap) {
        float *b = realloc(ap->tab, sizeof(float) * need);
        if (!b) return 0;
        ap->tab = b, ap->cap = need;
    }
    ap->g = *g;
    ap->atm = a;
    ap->n = n;
    ap->split = a->solver && a->solver->aerial;
    if (ap->split && !mie_table(ap, a)) return 0;
    double t[ATMOS__AERIAL_MAX_SLICES];
    const int nd = g->nd < ATMOS__AERIAL_MAX_SLICES ? g->nd : ATMOS__AERIAL_MAX_SLICES;
    ap->g.nd = nd;
    for (int j = 0; j < nd; j++) t[j] = slice_t(&ap->g, j);
    const int nodes = g->nu * g->nv;
    if ((size_t)nodes > ap->gcap) {
        float *b = realloc(ap->ground, sizeof(float) * nodes);
        if (!b) return 0;
        ap->ground = b, ap->gcap = nodes;
    }
#pragma omp parallel for schedule(dynamic, 2) num_threads(threads)
    for (int e = 0; e < nodes; e++) {
        double d[3];
        node_dir(&ap->g, e % g->nu, e / g->nu, d);
        const double tg = atmos_atmosphere_ground_distance(a, g->eye, d);
        ap->ground[e] = (float)tg;
        float *o = ap->tab + (size_t)e * node;
        if (ap->split) a->solver->aerial(a, g->eye, d, g->sun, nd, t, o);
        else node_generic(a, &ap->g, d, t, tg, o);
    }
    return 1;
}

void atmos__aerial_free(atmos__aerial *ap)
{
    free(ap->tab), free(ap->mie), free(ap->ground);
    memset(ap, 0, sizeof *ap);
}

/* Cell and weight of a coordinate f on nodes 0..N-1; 0 outside (a hair's tolerance). */
static int locate(double f, int N, int *i, double *w)
{
    if (!(f >= -1e-9 && f <= N - 1 + 1e-9)) return 0;
    int c = (int)f;
    if (c > N - 2) c = N - 2;
    if (c < 0) c = 0;
    *i = c;
    *w = f - c;
    *w = *w < 0 ? 0 : (*w > 1 ? 1 : *w);
    return 1;
}

int atmos__aerial_eval(const atmos__aerial *ap, const double d[3], double t, double *inscatter,
                       double *transmittance)
{
    const atmos__aerial_grid *g = &ap->g;
    const double c = atmos__dot3(d, g->fwd);
    if (!ap->tab || !(c > 0) || !(t >= g->tmin) || t > g->tmax) return 0;
    const double u = atmos__dot3(d, g->right) / c, v = atmos__dot3(d, g->up) / c;
    int iu, iv, j;
    double wu, wv, wt;
    if (!locate((u - g->u0) / (g->u1 - g->u0) * (g->nu - 1), g->nu, &iu, &wu) ||
        !locate((v - g->v0) / (g->v1 - g->v0) * (g->nv - 1), g->nv, &iv, &wv))
        return 0;
    /* a node whose ray ends on the ground before t holds the ground's in-scatter there, not
     * the air's up to t: the query is the atmosphere's to answer */
    const float *gd = ap->ground + (size_t)iv * g->nu + iu;
    if (!(t <= gd[0] && t <= gd[1] && t <= gd[g->nu] && t <= gd[g->nu + 1])) return 0;
    const double f = (t - g->tmin) / (g->tmax - g->tmin);
    j = (int)((g->nd - 1) * (g->crowd_far ? 1.0 - sqrt(fmax(0.0, 1.0 - f)) : sqrt(f)));
    if (j > g->nd - 2) j = g->nd - 2;
    const double ta = slice_t(g, j), tb = slice_t(g, j + 1);
    const int n = ap->n;
    const size_t node = (size_t)g->nd * n * 4, row = node * g->nu;
    const float *base = ap->tab + (size_t)iv * row + (size_t)iu * node + (size_t)j * n * 4;
    const float *cn[8];
    double w[8];
    for (int q = 0; q < 4; q++) {
        const int du = q & 1, dv = q >> 1;
        /* linear in t between the slices around it; a node whose ray meets the ground within
         * the slice holds at the next slice what it held there, so its slice ends there */
        const double te = fmin(tb, gd[(dv ? g->nu : 0) + du]);
        wt = te > ta ? (t - ta) / (te - ta) : 0.0;
        wt = wt < 0 ? 0 : (wt > 1 ? 1 : wt);
        cn[q] = base + (dv ? row : 0) + (du ? node : 0);
        cn[q + 4] = cn[q] + (size_t)n * 4;
        const double wd = (du ? wu : 1 - wu) * (dv ? wv : 1 - wv);
        w[q] = wd * (1 - wt), w[q + 4] = wd * wt;
    }
    const double nu = atmos__dot3(d, g->sun);
    double fp;
    const int ip = phase_node(nu, &fp);
    for (int k = 0; k < n; k++) {
        double s[4] = {0, 0, 0, 0};
        for (int q = 0; q < 8; q++)
            for (int ch = 0; ch < 4; ch++) s[ch] += w[q] * cn[q][4 * k + ch];
        double L = s[2];
        if (ap->split) {
            const float *mp = ap->mie + k * AP_NPH + ip;
            L += atmos__planet_rayleigh_phase(ap->atm->planet, k, nu) * s[0] + (mp[0] + fp * (mp[1] - mp[0])) * s[1];
        }
        inscatter[k] = L > 0 ? L : 0.0;
        transmittance[k] = exp(-s[3]);
    }
    return 1;
}

/* The slice at or before distance t (0 before the first), as atmos__aerial_eval finds it. */
static int slice_index(const atmos__aerial_grid *g, double t)
{
    const double f = fmin(1.0, fmax(0.0, (t - g->tmin) / (g->tmax - g->tmin)));
    int j = (int)((g->nd - 1) * (g->crowd_far ? 1.0 - sqrt(fmax(0.0, 1.0 - f)) : sqrt(f)));
    j = j > g->nd - 1 ? g->nd - 1 : (j < 0 ? 0 : j);
    while (j > 0 && slice_t(g, j) > t) j--; /* rounding */
    while (j < g->nd - 1 && slice_t(g, j + 1) <= t) j++;
    return j;
}

int atmos__aerial_single_profile(const atmos__aerial *ap, const double d[3], double t0, double t1, double *t,
                                 float *S)
{
    const atmos__aerial_grid *g = &ap->g;
    const double c = atmos__dot3(d, g->fwd);
    if (!ap->tab || !(c > 0)) return 0;
    const double u = atmos__dot3(d, g->right) / c, v = atmos__dot3(d, g->up) / c;
    int iu, iv;
    double wu, wv;
    if (!locate((u - g->u0) / (g->u1 - g->u0) * (g->nu - 1), g->nu, &iu, &wu) ||
        !locate((v - g->v0) / (g->v1 - g->v0) * (g->nv - 1), g->nv, &iv, &wv))
        return 0;
    const int n = ap->n, nd = g->nd;
    const size_t node = (size_t)nd * n * 4, row = node * g->nu;
    const float *base = ap->tab + (size_t)iv * row + (size_t)iu * node;
    const float *cn[4] = {base, base + node, base + row, base + row + node};
    const double w[4] = {(1 - wu) * (1 - wv), wu * (1 - wv), (1 - wu) * wv, wu * wv};
    float ph[ATMOS_MAX_WAVELENGTHS][2];
    if (ap->split) {
        const double nu = atmos__dot3(d, g->sun);
        double fp;
        const int ip = phase_node(nu, &fp);
        for (int k = 0; k < n; k++) {
            const float *mp = ap->mie + k * AP_NPH + ip;
            ph[k][0] = (float)atmos__planet_rayleigh_phase(ap->atm->planet, k, nu);
            ph[k][1] = (float)(mp[0] + fp * (mp[1] - mp[0]));
        }
    }
    const int ja = slice_index(g, t0), jl = slice_index(g, t1), jb = jl < nd - 1 && slice_t(g, jl) < t1 ? jl + 1 : jl;
    if (jb <= ja) return 0;
    const float wf[4] = {(float)w[0], (float)w[1], (float)w[2], (float)w[3]};
    float acc[ATMOS_MAX_WAVELENGTHS * 4];
    for (int j = ja; j <= jb; j++) {
        t[j - ja] = slice_t(g, j);
        const size_t o = (size_t)j * n * 4;
        /* the four node rays' sums, all wavelengths and terms at once (contiguous: vectorised) */
        for (int i = 0; i < 4 * n; i++)
            acc[i] = wf[0] * cn[0][o + i] + wf[1] * cn[1][o + i] + wf[2] * cn[2][o + i] + wf[3] * cn[3][o + i];
        float *Sj = S + (size_t)(j - ja) * n;
        if (ap->split)
            for (int k = 0; k < n; k++) Sj[k] = ph[k][0] * acc[4 * k] + ph[k][1] * acc[4 * k + 1];
        else
            for (int k = 0; k < n; k++) Sj[k] = acc[4 * k + 2];
        for (int k = 0; k < n; k++) Sj[k] = Sj[k] > 0.0f ? Sj[k] : 0.0f;
    }
    return jb - ja + 1;
}
