/* The diffuse light of all orders by a diffusion solve on the light field's grid (lfield.h,
 * atmos__lfield_diffuse).
 *
 * With the forward beam taken apart (sun_source.c), the rest of the light is diffuse. Its
 * fluence phi obeys the diffusion approximation of radiative transfer (e.g. Ishimaru 1978,
 * ch. 9; Stam 1995 "Multiple scattering as a diffusion process"):
 *     -div(D grad phi) + sig_a phi = Q,   D = 1 / (3 sig_tr),   sig_tr = sig_t - g sig_s,
 * sig_tr being the similarity-scaled (delta-Eddington, Joseph et al. 1976) extinction, which
 * carries the anisotropy of scattering into an isotropic transport. Where the medium is thin
 * D grows without bound and the flux |D grad phi| may exceed phi (faster than light); the
 * flux limiter of Levermore & Pomraning 1981 in its "sum" form, D = 1 / (3 sig_tr +
 * |grad phi| / phi), bounds it by phi (the streaming limit). At a face to vacuum the Marshak
 * condition (no diffuse light coming in: phi/4 - D/2 dphi/dn = 0 with n inward) gives the
 * outgoing flux phi_b / 2 at the face; with the face value reached from the cell's centre
 * over h/2 that is phi a / ((2 a + 1)) per area, a = 2 D / h. Light coming in through the
 * face (the partial current J_in: the sky, the ground) makes it (phi - 4 J_in) a / (2 a + 1).
 *
 * An anisotropic source (the light the forward beam drops goes mostly back toward the sun)
 * enters through its first moment Q1 = int q(w) w dw: the P1 equations div J + sig_a phi = Q,
 * grad phi / 3 + sig_tr J = Q1 give J = -D grad phi + 3 D Q1 and
 *     -div(D grad phi) + sig_a phi = Q - div(3 D Q1)
 * (e.g. Ishimaru 1978, §9-2). At a vacuum face the Marshak condition with this J adds
 * 3 D Q1 . n / (2 a + 1) to the outgoing net flux.
 *
 * Cell-centred finite volumes (harmonic mean of D at a face), red-black successive
 * over-relaxation (each colour's update reads only the other colour: the result does not
 * depend on the thread count), the diffusion coefficient lagged and refreshed every few
 * sweeps when the limiter is on. phi holds the previous solution (the warm start). */
#include "light/lfield.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DIFF_OMEGA 1.8    /* over-relaxation */
#define DIFF_REFRESH 4    /* sweeps between refreshes of the flux-limited D */
#define DIFF_LEVELS 4     /* most coarse grids of a cold start's cascade */


/* The six neighbours of a cell: offsets, -1: a vacuum face, -2: none (a periodic axis of one
 * cell, which is its own neighbour: no exchange). */
static void neighbours(const atmos__lmedium *m, int i, int j, int k, long long nb[6])
{
    const int ix[3] = {i, j, k};
    const long long st[3] = {1, m->c[0], (long long)m->c[0] * m->c[1]};
    const long long cell = ((long long)k * m->c[1] + j) * m->c[0] + i;
    for (int a = 0; a < 3; a++) {
        const int c = m->c[a];
        for (int s = 0; s < 2; s++) {
            int x = ix[a] + (s ? 1 : -1);
            if (m->periodic[a]) x = (x + c) % c;
            nb[2 * a + s] = x < 0 || x >= c ? -1 : (x == ix[a] ? -2 : cell + (long long)(x - ix[a]) * st[a]);
        }
    }
}

/* d phi / d axis a at a cell of wavelength w: the central difference, one-sided where a
 * neighbour is missing (the face value of the Marshak condition is not known here), 0 with
 * neither. */
static double cell_grad(const atmos__lmedium *m, const float *phi, const long long nb[6], size_t cell, int w, int a)
{
    const int n = m->n;
    const long long lo = nb[2 * a], hi = nb[2 * a + 1];
    if (lo >= 0 && hi >= 0) return (phi[(size_t)hi * n + w] - phi[(size_t)lo * n + w]) / (2 * m->h);
    if (hi >= 0) return (phi[(size_t)hi * n + w] - phi[cell * n + w]) / m->h;
    if (lo >= 0) return (phi[cell * n + w] - phi[(size_t)lo * n + w]) / m->h;
    return 0.0;
}

/* The diffusion coefficient of a cell (its neighbours nb), wavelength w. */
static double cell_D(const atmos__lmedium *m, const float *phi, const long long nb[6], size_t cell, int w,
                     int limiter)
{
    const int n = m->n, cx = m->c[0], cy = m->c[1], cz = m->c[2];
    double str = m->sig_t[cell * n + w] - m->g[cell * n + w] * m->sig_s[cell * n + w];
    double den = 3.0 * (str > 0 ? str : 0);
    if (limiter) {
        const double p = phi[cell * n + w];
        double g2 = 0;
        for (int a = 0; a < 3; a++) {
            const double d = cell_grad(m, phi, nb, cell, w, a);
            g2 += d * d;
        }
        if (p > 0) den += sqrt(g2) / p;
    }
    /* D at most the grid's largest extent: a void's coupling stays finite without the limiter */
    const int big = cx > cy ? (cx > cz ? cx : cz) : (cy > cz ? cy : cz);
    const double dmin = 1.0 / (big * m->h);
    return 1.0 / (den > dmin ? den : dmin);
}

/* The lagged coefficients of wavelength w: D per cell and, with a first moment of the
 * source, the flux it drives, P = 3 D Q1 ([cell * 3 + axis]). damp: D becomes the mean of
 * the old and the new value (the same fixed point): refreshed outright, the limiter's D and
 * phi could chase each other without end (the generated storm's field after a sun move ran
 * into the 2000-sweep cap twice in nine moves). */
static void refresh_D(const atmos__lmedium *m, const atmos__lsource *q, const float *phi, int w, int limiter, float *D,
                      float *P, int damp)
{
    const int n = m->n, cx = m->c[0], cy = m->c[1], cz = m->c[2];
    for (int k = 0; k < cz; k++)
        for (int j = 0; j < cy; j++)
            for (int i = 0; i < cx; i++) {
                long long nb[6];
                neighbours(m, i, j, k, nb);
                const size_t cell = ((size_t)k * cy + j) * cx + i;
                const double d0 = cell_D(m, phi, nb, cell, w, limiter), d = damp ? 0.5 * (d0 + D[cell]) : d0;
                D[cell] = (float)d;
                if (P)
                    for (int a = 0; a < 3; a++) P[cell * 3 + a] = (float)(3.0 * d * q->Q1[(cell * n + w) * 3 + a]);
            }
}

/* One colour's half-sweep of wavelength w; returns the largest change, *top the largest value
 * of the colour's cells. */
static double half_sweep(const atmos__lmedium *m, const float *Q, float *phi, const float *D, const float *P, int w,
                         int colour, double *top)
{
    const int n = m->n, cx = m->c[0], cy = m->c[1], cz = m->c[2];
    const double h = m->h, ih2 = 1.0 / (h * h);
    double big = 0, most = 0;
    for (int k = 0; k < cz; k++)
        for (int j = 0; j < cy; j++)
            for (int i = (j + k + colour) & 1; i < cx; i += 2) {
                const size_t cell = ((size_t)k * cy + j) * cx + i;
                long long nb[6];
                neighbours(m, i, j, k, nb);
                const double Di = D[cell];
                double diag = m->sig_t[cell * n + w] - m->sig_s[cell * n + w], sum = Q[cell * n + w];
                diag = diag > 0 ? diag : 0;
                for (int f = 0; f < 6; f++) {
                    if (nb[f] == -2) continue;
                    const double sg = f & 1 ? 1.0 : -1.0; /* the face's outward normal along axis f / 2 */
                    if (nb[f] == -1) {
                        const double a = 2.0 * Di / h, b = a / ((2.0 * a + 1.0) * h);
                        diag += b;
                        if (m->jin) sum += b * 4.0 * m->jin[f * n + w];
                        if (P) sum -= sg * P[cell * 3 + f / 2] / ((2.0 * a + 1.0) * h);
                    } else {
                        const double Dn = D[nb[f]], c = 2.0 * Di * Dn / (Di + Dn) * ih2;
                        diag += c;
                        sum += c * phi[(size_t)nb[f] * n + w];
                        if (P) sum -= sg * 0.5 * (P[cell * 3 + f / 2] + P[(size_t)nb[f] * 3 + f / 2]) / h;
                    }
                }
                const double old = phi[cell * n + w];
                if (!(diag > 0)) {
                    most = old > most ? old : most;
                    continue;
                }
                double v = old + DIFF_OMEGA * (sum / diag - old);
                v = v > 0 ? v : 0;
                phi[cell * n + w] = (float)v;
                const double d = fabs(v - old), vf = phi[cell * n + w];
                big = d > big ? d : big;
                most = vf > most ? vf : most;
            }
    *top = most;
    return big;
}

/* The solve of wavelength w; returns its sweeps (-1: out of memory). */
static int solve_one(const atmos__lmedium *m, const atmos__lsource *q, float *phi, int w, int maxs, double tol,
                     int limiter)
{
    const size_t cells = atmos__lmedium_cells(m);
    float *D = malloc(sizeof(float) * cells), *P = q->Q1 ? malloc(sizeof(float) * cells * 3) : NULL;
    if (!D || (q->Q1 && !P)) {
        free(D), free(P);
        return -1;
    }
    int s = 0;
    for (; s < maxs; s++) {
        if (s == 0 || (limiter && s % DIFF_REFRESH == 0)) refresh_D(m, q, phi, w, limiter, D, P, s > 0);
        double top0, top1;
        double ch = half_sweep(m, q->Q, phi, D, P, w, 0, &top0);
        const double ch1 = half_sweep(m, q->Q, phi, D, P, w, 1, &top1);
        ch = ch1 > ch ? ch1 : ch;
        const double top = top1 > top0 ? top1 : top0;
        if (!(top > 0) || ch <= tol * top) {
            s++;
            break;
        }
    }
    free(D), free(P);
    return s;
}

/* A level of the cascade: a coarse medium, its source and its solution. */
typedef struct {
    atmos__lmedium m;
    float *Q, *Q1, *phi;
} dlevel;

static void levels_free(dlevel *lv, int nl)
{
    for (int l = 0; l < nl; l++) free(lv[l].Q), free(lv[l].Q1), free(lv[l].phi), atmos__lmedium_free(&lv[l].m);
}

/* Up to `want` coarse levels below m (lv[0] the finest of them), their phi zero; returns how
 * many (-1: out of memory). */
static int levels_make(const atmos__lmedium *m, const atmos__lsource *q, int want, dlevel *lv)
{
    int nl = 0;
    const atmos__lmedium *fm = m;
    atmos__lsource fq = *q;
    while (nl < want && nl < DIFF_LEVELS && atmos__lmedium_can_coarsen(fm)) {
        dlevel *l = &lv[nl];
        memset(l, 0, sizeof *l);
        if (!atmos__lmedium_coarsen(fm, &fq, &l->m, &l->Q, &l->Q1) ||
            !(l->phi = calloc(atmos__lmedium_cells(&l->m) * (size_t)m->n, sizeof(float)))) {
            levels_free(lv, nl + 1);
            return -1;
        }
        nl++;
        fm = &l->m, fq.Q = l->Q, fq.Q1 = l->Q1;
    }
    return nl;
}

/* Wavelength w's cascade: the coarsest level from zero, each finer one from the prolonged
 * solution of the one below, phi (the fine grid) from lv[0]'s; -1: out of memory. */
static int cascade_one(const atmos__lmedium *m, float *phi, const dlevel *lv, int nl, int w, int maxs, double tol,
                       int limiter)
{
    for (int l = nl - 1; l >= 0; l--) {
        const atmos__lsource cq = {lv[l].Q, lv[l].Q1};
        if (solve_one(&lv[l].m, &cq, lv[l].phi, w, maxs, tol, limiter) < 0) return -1;
        if (l > 0) atmos__lfield_prolong(&lv[l].m, lv[l].phi, &lv[l - 1].m, lv[l - 1].phi, w);
        else atmos__lfield_prolong(&lv[0].m, lv[0].phi, m, phi, w);
    }
    return 0;
}

int atmos__lfield_diffuse(const atmos__lmedium *m, const atmos__lsource *q, float *phi, const atmos__ldiffusion_opts *o,
                          int threads)
{
    const int n = m->n, maxs = o && o->max_sweeps > 0 ? o->max_sweeps : 2000, limiter = o ? o->limiter : 0;
    const double tol = o && o->tol > 0 ? o->tol : 1e-4;
    int most = 0, fail = 0;
    dlevel lv[DIFF_LEVELS];
    const int nl = o && o->cascade > 0 ? levels_make(m, q, o->cascade, lv) : 0;
    if (nl < 0) return -1;
    /* the wavelengths in parallel, each solved by one thread: no barrier per sweep (which
     * costs a time slice whenever the machine is busy), the same result for any thread count */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(max : most) reduction(| : fail)
    for (int w = 0; w < n; w++) {
        if (nl > 0 && cascade_one(m, phi, lv, nl, w, maxs, tol, limiter) < 0) {
            fail = 1;
            continue;
        }
        const int s = solve_one(m, q, phi, w, maxs, tol, limiter);
        if (s < 0) fail = 1;
        most = s > most ? s : most;
    }
    levels_free(lv, nl);
    return fail ? -1 : most;
}

void atmos__lfield_leak(const atmos__lmedium *m, const atmos__lsource *q, const float *phi,
                        const atmos__ldiffusion_opts *o, int w, double out[6])
{
    const int n = m->n, cx = m->c[0], cy = m->c[1], cz = m->c[2], limiter = o ? o->limiter : 0;
    const double h = m->h;
    for (int f = 0; f < 6; f++) out[f] = 0;
    for (int k = 0; k < cz; k++)
        for (int j = 0; j < cy; j++)
            for (int i = 0; i < cx; i++) {
                long long nb[6];
                neighbours(m, i, j, k, nb);
                const size_t cell = ((size_t)k * cy + j) * cx + i;
                const double D = cell_D(m, phi, nb, cell, w, limiter), a = 2.0 * D / h;
                for (int f = 0; f < 6; f++) {
                    if (nb[f] != -1) continue;
                    const double in4 = m->jin ? 4.0 * m->jin[f * n + w] : 0.0;
                    const double src = q->Q1 ? (f & 1 ? 3.0 : -3.0) * D * q->Q1[(cell * n + w) * 3 + f / 2] : 0.0;
                    out[f] += ((phi[cell * n + w] - in4) * a + src) / (2.0 * a + 1.0) * h * h;
                }
            }
}

void atmos__lfield_flux(const atmos__lmedium *m, const atmos__lsource *q, const float *phi,
                        const atmos__ldiffusion_opts *o, float *J, int threads)
{
    const int n = m->n, cx = m->c[0], cy = m->c[1], cz = m->c[2], limiter = o ? o->limiter : 0;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int k = 0; k < cz; k++)
        for (int j = 0; j < cy; j++)
            for (int i = 0; i < cx; i++) {
                const size_t cell = ((size_t)k * cy + j) * cx + i;
                long long nb[6];
                neighbours(m, i, j, k, nb);
                for (int w = 0; w < n; w++) {
                    const double D = cell_D(m, phi, nb, cell, w, limiter);
                    for (int a = 0; a < 3; a++) {
                        const double d = cell_grad(m, phi, nb, cell, w, a);
                        const double src = q->Q1 ? 3.0 * D * q->Q1[(cell * n + w) * 3 + a] : 0.0;
                        J[(cell * n + w) * 3 + a] = (float)(-D * d + src);
                    }
                }
            }
}
