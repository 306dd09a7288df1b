/* Nishita et al. 1996's light field (nishita.h, §3.4 steps 1-2, §3.5): the reference
 * patterns built once for the directions of the sun and the eye, then moved cell by cell
 * over the grid. Their form factors and phase functions are the pattern's; the attenuation
 * between the cells and the sunlight arriving at them are the real medium's. Order 3 computes
 * n1 of the pattern's n2 paths per cell, chosen at random (stratified over the paths sorted
 * by contribution, so that every path has the probability n1/n2), and scales their sum by
 * n2/n1; both orders divide by the share r of the sample space's contribution the pattern
 * keeps. The sky light is Eq. 7 over the sky elements. */
#include "core/rng.h"
#include "light/nishita.h"

#include <stdlib.h>
#include <string.h>

#define DEFAULT_PATHS3 1024

typedef struct {
    const atmos__lmedium *m;
    const float *E; /* the sunlight at each cell's centre, [cell * n + w] */
    const atmos__nishita_pattern *p;
    const atmos__nishita_in *in;
} job;

static int cell_of(const atmos__lmedium *m, const int q[3], size_t *cell)
{
    for (int a = 0; a < 3; a++)
        if (q[a] < 0 || q[a] >= m->c[a]) return 0;
    *cell = ((size_t)q[2] * m->c[1] + q[1]) * m->c[0] + q[0];
    return 1;
}

/* Optical depth per wavelength of the straight line between the centres of cells a and b
 * (distinct), midpoint samples every half cell or less, the nearest cell's extinction. */
static void tau_line(const atmos__lmedium *m, const int a[3], const int b[3], double *tau)
{
    const int n = m->n;
    const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const int steps = (int)ceil(2.0 * len);
    const double ds = len * m->h / steps;
    for (int w = 0; w < n; w++) tau[w] = 0;
    for (int s = 0; s < steps; s++) {
        const double f = (s + 0.5) / steps;
        const int q[3] = {(int)floor(a[0] + f * d[0] + 0.5), (int)floor(a[1] + f * d[1] + 0.5),
                          (int)floor(a[2] + f * d[2] + 0.5)};
        size_t c;
        if (!cell_of(m, q, &c)) continue;
        for (int w = 0; w < n; w++) tau[w] += m->sig_t[c * n + w] * ds;
    }
}

/* Order 2 at cell P: sum over the pattern of w2 h sig_s(P1) E(P1) T(P1 -> P), over r. */
static void order2(const job *J, const int P[3], size_t cp, double *out)
{
    const atmos__lmedium *m = J->m;
    const atmos__nishita_pattern *p = J->p;
    const int n = m->n;
    double tau[ATMOS_MAX_WAVELENGTHS];
    for (int w = 0; w < n; w++) out[w] = 0;
    for (int e = 0; e < p->n2; e++) {
        const int16_t *o = p->o2 + 3 * e;
        const int q[3] = {P[0] + o[0], P[1] + o[1], P[2] + o[2]};
        size_t c;
        if (!cell_of(m, q, &c) || !(m->sig_s[c * n] > 0)) continue;
        if (o[0] == 0 && o[1] == 0 && o[2] == 0) { /* the cell itself: attenuated exactly along each direction */
            for (int w = 0; w < n; w++)
                out[w] += atmos__nishita_self2(p, m->sig_t[cp * n + w] * m->h) * m->h * m->sig_s[c * n + w] * J->E[c * n + w];
            continue;
        }
        tau_line(m, q, P, tau);
        const double k = p->w2[e] * m->h;
        for (int w = 0; w < n; w++) out[w] += k * m->sig_s[c * n + w] * J->E[c * n + w] * exp(-tau[w]);
    }
    for (int w = 0; w < n; w++) out[w] = p->kept2 > 0 ? out[w] / p->kept2 : 0;
}

/* Order 3 at cell P: n1 of the pattern's n2 paths, stratified with one random offset per cell. */
static void order3(const job *J, const int P[3], size_t cp, double *out)
{
    const atmos__lmedium *m = J->m;
    const atmos__nishita_pattern *p = J->p;
    const int n = m->n, n2 = p->n3, n1 = J->in->paths3 < n2 ? J->in->paths3 : n2;
    double t1[ATMOS_MAX_WAVELENGTHS], t2[ATMOS_MAX_WAVELENGTHS];
    for (int w = 0; w < n; w++) out[w] = 0;
    if (n1 < 1) return;
    const double u0 = atmos__u01(atmos__mix64(J->in->seed ^ atmos__mix64(cp + 1)));
    for (int s = 0; s < n1; s++) {
        int e = (int)((s + u0) * n2 / n1);
        if (e >= n2) e = n2 - 1;
        const int16_t *o = p->o3 + 6 * e;
        const int qj[3] = {P[0] + o[0], P[1] + o[1], P[2] + o[2]}, qk[3] = {P[0] + o[3], P[1] + o[4], P[2] + o[5]};
        size_t cj, ck;
        if (!cell_of(m, qj, &cj) || !cell_of(m, qk, &ck) || !(m->sig_s[cj * n] > 0) || !(m->sig_s[ck * n] > 0)) continue;
        if (cj == ck)
            for (int w = 0; w < n; w++) t1[w] = m->sig_t[cj * n + w] * p->r3[2 * e] * m->h;
        else
            tau_line(m, qk, qj, t1);
        if (cj == cp)
            for (int w = 0; w < n; w++) t2[w] = m->sig_t[cp * n + w] * p->r3[2 * e + 1] * m->h;
        else
            tau_line(m, qj, P, t2);
        const double k = p->w3[e] * m->h * m->h;
        for (int w = 0; w < n; w++)
            out[w] += k * m->sig_s[cj * n + w] * m->sig_s[ck * n + w] * J->E[ck * n + w] * exp(-t1[w] - t2[w]);
    }
    const double scale = (double)n2 / n1 / p->kept3;
    for (int w = 0; w < n; w++) out[w] *= scale;
}

/* 1 if a cell within one of P has scattering: the eye rays' trilinear reads reach P's value. */
static int near_medium(const atmos__lmedium *m, const int P[3])
{
    for (int c = -1; c <= 1; c++)
        for (int b = -1; b <= 1; b++)
            for (int a = -1; a <= 1; a++) {
                const int q[3] = {P[0] + a, P[1] + b, P[2] + c};
                size_t cell;
                if (cell_of(m, q, &cell) && m->sig_s[cell * m->n] > 0) return 1;
            }
    return 0;
}

/* The medium's mean extinction and scattering over the cells that scatter (the sample
 * space's uniform density), at the middle wavelength. */
static void mean_medium(const atmos__lmedium *m, double *st, double *ss)
{
    const size_t cells = atmos__lmedium_cells(m);
    const int w = m->n / 2;
    double a = 0, b = 0;
    size_t k = 0;
    for (size_t c = 0; c < cells; c++)
        if (m->sig_s[c * m->n + w] > 0) a += m->sig_t[c * m->n + w], b += m->sig_s[c * m->n + w], k++;
    *st = k ? a / k : 0, *ss = k ? b / k : 0;
}

int atmos__nishita_solve(const atmos__nishita_in *in, int s, atmos__lfield *f, atmos__nishita_stats *st)
{
    const atmos__lmedium *m = in->m;
    const int n = m->n, E = ATMOS__NISHITA_ELEMENTS;
    const size_t cells = atmos__lmedium_cells(m);
    memset(st, 0, sizeof *st);
    if (!atmos__lfield_alloc(f, ATMOS__LFIELD_NISHITA, m->c[0], m->c[1], m->c[2], n, s)) return 0;
    f->part = calloc(cells * n * 4, sizeof(float));
    float *Q = malloc(sizeof(float) * cells * n), *Ec = malloc(sizeof(float) * cells * n);
    float *t = in->sky ? malloc(sizeof(float) * cells * E * n) : NULL;
    atmos__nishita_in cfg = *in;
    if (cfg.paths3 < 1) cfg.paths3 = DEFAULT_PATHS3;
    atmos__nishita_pattern p;
    memset(&p, 0, sizeof p);
    double mst, mss;
    mean_medium(m, &mst, &mss);
    double t0 = atmos__now();
    int ok = f->part && Q && Ec && (t || !in->sky) && atmos__nishita_pattern_build(&cfg, mst, mss, &p);
    st->pattern_s = atmos__now() - t0;
    if (ok) {
        t0 = atmos__now();
        if (in->E) memcpy(Ec, in->E, sizeof(float) * cells * n);
        else atmos__lfield_sun_source(m, in->lt, in->sun, atmos__lkeep_none, NULL, Q, NULL, Ec, in->threads);
        const double to_sun[3] = {-in->lt[0], -in->lt[1], -in->lt[2]};
        if (t) ok = atmos__nishita_sky_attenuation(m, to_sun, t, in->threads);
        st->sky_s = atmos__now() - t0;
    }
    t0 = atmos__now();
    const job J = {m, Ec, &p, &cfg};
#pragma omp parallel for schedule(dynamic, 16) num_threads(in->threads) if (ok)
    for (long long ci = 0; ci < (ok ? (long long)cells : 0); ci++) {
        const size_t cp = (size_t)ci;
        const int P[3] = {(int)(cp % (size_t)m->c[0]), (int)(cp / (size_t)m->c[0] % (size_t)m->c[1]),
                          (int)(cp / ((size_t)m->c[0] * m->c[1]))};
        double j2[ATMOS_MAX_WAVELENGTHS] = {0}, j3[ATMOS_MAX_WAVELENGTHS] = {0}, js[ATMOS_MAX_WAVELENGTHS] = {0};
        if (near_medium(m, P)) {
            if (cfg.orders >= 2) order2(&J, P, cp, j2);
            if (cfg.orders >= 3) order3(&J, P, cp, j3);
            for (int l = 0; t && l < E; l++)
                for (int w = 0; w < n; w++) js[w] += t[(cp * E + l) * n + w] * in->sky[l * n + w];
        }
        for (int w = 0; w < n; w++) {
            float *q = f->part + (cp * n + w) * 4;
            q[0] = Ec[cp * n + w], q[1] = (float)j2[w], q[2] = (float)j3[w], q[3] = (float)js[w];
            f->L[cp * n + w] = q[1] + q[2] + q[3];
        }
    }
    st->apply_s = atmos__now() - t0;
    st->n2 = p.n2, st->n3 = p.n3, st->n3_space = p.space3, st->kept2 = p.kept2, st->kept3 = p.kept3;
    st->box2 = p.box2, st->box3 = p.box3, st->theta_b_deg = p.theta_b_deg;
    atmos__nishita_pattern_free(&p);
    free(Q), free(Ec), free(t);
    if (!ok) atmos__lfield_free(f);
    return ok;
}
