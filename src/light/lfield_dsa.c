/* The diffusion preconditioner of the discrete-ordinates solve (lfield_dsa.h). Cell-centred finite
 * volumes on the cells of edge h, r = h / (2 D) a half cell's resistance: between two cells of the
 * medium the face's conductance 1 / (h (r_a + r_b)), the harmonic mean of D over h^2; a face toward
 * vacuum (the grid's edge, a cell without medium) the Marshak condition, outgoing flux phi_b / 2 at
 * the face, 1 / (h (r + 2)) (diffusion.c's). h / (2 D) = 3/2 sig_tr h floored at DSA_TAU_MIN: the
 * conductance of optically thin cells bounded (the diffusion overshoots there: with the floor at 0.05
 * the Disney cloud took 10 GMRES iterations after a sun move instead of 7, with 0.5 7, with 2 11). The operator is
 * symmetric positive definite: conjugate gradients. */
#include "light/lfield_dsa.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DSA_TAU_MIN 0.5
#define DSA_PI 3.14159265358979323846

struct atmos__dsa {
    size_t n;
    int nm;        /* moments corrected: 4 (degree <= 1, the P1 equations), or 1 (degree 0) */
    double h, chi1, R[3][3];
    double *q1;    /* per cell: sig_s chi_1 times the first moment (flux) of v along the cells' axes */
    long long *nb; /* per cell 6 neighbours: their index among the n, -1 none (vacuum) */
    double *g;     /* per cell 6 face conductances (toward vacuum the Marshak face's; 0 without medium) */
    double *diag;  /* per cell: sig_a + the faces' conductances */
    double *ss;    /* per cell: sig_s */
    double *r, *z, *p, *q, *phi; /* conjugate gradients' vectors; the correction's fluence */
};

void atmos__dsa_free(atmos__dsa *d)
{
    if (!d) return;
    free(d->nb), free(d->g), free(d->diag), free(d->ss);
    free(d->r), free(d->z), free(d->p), free(d->q), free(d->q1), free(d->phi);
    free(d);
}

/* The index among idx[0 .. n - 1] of cell c, -1 when not there (idx increasing). */
static long long find(const size_t *idx, size_t n, size_t c)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (idx[mid] < c) lo = mid + 1;
        else hi = mid;
    }
    return lo < n && idx[lo] == c ? (long long)lo : -1;
}

/* h / (2 D) of cell c: 3/2 sig_tr h, floored. */
static double half_r(const atmos__do_problem *P, size_t c)
{
    const double chi1 = P->L >= 1 ? P->chi[1] : 0;
    const double tr = 1.5 * (P->sig_t[c] - chi1 * P->sig_s[c]) * P->h;
    return tr > DSA_TAU_MIN ? tr : DSA_TAU_MIN;
}

atmos__dsa *atmos__dsa_create(const atmos__do_problem *P, const size_t *idx, size_t n)
{
    atmos__dsa *d = calloc(1, sizeof *d);
    if (!d) return NULL;
    d->n = n, d->h = P->h, d->chi1 = P->L >= 1 ? P->chi[1] : 0, d->nm = d->chi1 != 0 ? 4 : 1;
    memcpy(d->R, P->R, sizeof d->R);
    d->nb = malloc(sizeof *d->nb * 6 * (n + 1)), d->g = malloc(sizeof *d->g * 6 * (n + 1));
    d->diag = malloc(sizeof(double) * (n + 1)), d->ss = malloc(sizeof(double) * (n + 1));
    d->r = malloc(sizeof(double) * (n + 1)), d->z = malloc(sizeof(double) * (n + 1));
    d->p = malloc(sizeof(double) * (n + 1)), d->q = malloc(sizeof(double) * (n + 1));
    d->q1 = malloc(sizeof(double) * 3 * (n + 1)), d->phi = malloc(sizeof(double) * (n + 1));
    if (!d->nb || !d->g || !d->diag || !d->ss || !d->r || !d->z || !d->p || !d->q || !d->q1 || !d->phi) {
        atmos__dsa_free(d);
        return NULL;
    }
    const long long nx = P->c[0], ny = P->c[1], nz = P->c[2], st[3] = {1, nx, nx * ny}, ext[3] = {nx, ny, nz};
    for (size_t i = 0; i < n; i++) {
        const size_t c = idx[i];
        const long long ix[3] = {(long long)(c % nx), (long long)(c / nx % ny), (long long)(c / (nx * ny))};
        const int med = P->sig_t[c] > 0;
        const double sa = P->sig_t[c] - P->sig_s[c], ri = half_r(P, c);
        d->ss[i] = P->sig_s[c], d->diag[i] = sa > 0 ? sa : 0;
        for (int f = 0; f < 6; f++) {
            const int a = f / 2, s = f % 2 ? 1 : -1;
            const long long x = ix[a] + s;
            long long j = -1;
            if (med && x >= 0 && x < ext[a]) j = find(idx, n, (size_t)((long long)c + s * st[a]));
            if (j >= 0 && !(P->sig_t[idx[j]] > 0)) j = -1;
            d->nb[6 * i + f] = j;
            d->g[6 * i + f] = !med ? 0 : 1 / (P->h * (ri + (j >= 0 ? half_r(P, idx[j]) : 2)));
            d->diag[i] += d->g[6 * i + f];
        }
        if (!med) d->diag[i] = 1; /* no medium: no scattering, its correction 0 */
    }
    return d;
}

/* q = A p */
static void op(const atmos__dsa *d, const double *p, double *q)
{
    for (size_t i = 0; i < d->n; i++) {
        double s = d->diag[i] * p[i];
        for (int f = 0; f < 6; f++) {
            const long long j = d->nb[6 * i + f];
            if (j >= 0) s -= d->g[6 * i + f] * p[j];
        }
        q[i] = s;
    }
}

static double dotn(const double *a, const double *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

int atmos__dsa_moments(const atmos__dsa *d) { return d->nm; }

/* Conjugate gradients (Jacobi-preconditioned, from 0) on A phi = r (r overwritten). */
static int cg(atmos__dsa *d, double *r, double *phi)
{
    const size_t n = d->n;
    double *z = d->z, *p = d->p, *q = d->q;
    for (size_t i = 0; i < n; i++) phi[i] = 0, z[i] = r[i] / d->diag[i], p[i] = z[i];
    const double bn = sqrt(dotn(r, r, n));
    if (!(bn > 0)) return 0;
    double rz = dotn(r, z, n);
    int it = 0;
    while (it < ATMOS__DSA_MAX_ITER) {
        op(d, p, q);
        const double pq = dotn(p, q, n);
        if (!(pq > 0)) break;
        const double al = rz / pq;
        for (size_t i = 0; i < n; i++) phi[i] += al * p[i], r[i] -= al * q[i];
        it++;
        if (sqrt(dotn(r, r, n)) <= ATMOS__DSA_TOL * bn) break;
        for (size_t i = 0; i < n; i++) z[i] = r[i] / d->diag[i];
        const double rz1 = dotn(r, z, n), be = rz1 / rz;
        rz = rz1;
        for (size_t i = 0; i < n; i++) p[i] = z[i] + be * p[i];
    }
    return it;
}

/* The outward flux through face f of cell i (per area) with the correction's fluence phi and the
 * source's first moments d->q1: (phi_i - phi_j + 3/2 h (q_i + q_j) . n) / (r_i + r_j), toward vacuum
 * (phi_i + 3/2 h q_i . n) / (r_i + 2) (J continuous across the face, -D grad phi + 3 D Q1 on either
 * side); times h g_f. */
static double face_flux(const atmos__dsa *d, const double *phi, size_t i, int f)
{
    const long long j = d->nb[6 * i + f];
    const int a = f / 2;
    const double sg = f % 2 ? 1 : -1, qn = sg * (d->q1[3 * i + a] + (j >= 0 ? d->q1[3 * j + a] : 0));
    const double dp = !phi ? 0 : j >= 0 ? phi[i] - phi[j] : phi[i];
    return d->g[6 * i + f] * d->h * (dp + 1.5 * d->h * qn);
}

int atmos__dsa_apply(atmos__dsa *d, const double *v, int K, double *out)
{
    const size_t n = d->n;
    const double s4 = sqrt(4 * DSA_PI), s3 = sqrt(4 * DSA_PI / 3); /* phi per moment 00, J per moment 1m */
    for (size_t i = 0; i < n; i++) {
        double jw[3] = {0, 0, 0}; /* the first moment in the harmonics' frame: x, y, z */
        if (d->nm == 4) jw[0] = s3 * v[i * K + 3], jw[1] = s3 * v[i * K + 1], jw[2] = s3 * v[i * K + 2];
        for (int a = 0; a < 3; a++)
            d->q1[3 * i + a] = d->ss[i] * d->chi1 * (d->R[a][0] * jw[0] + d->R[a][1] * jw[1] + d->R[a][2] * jw[2]);
    }
    /* the balance sum_f J_f / h + sig_a phi = sig_s phi_0(v): the faces' terms of Q1 to the right */
    for (size_t i = 0; i < n; i++) {
        d->r[i] = d->ss[i] * s4 * v[i * K];
        for (int f = 0; f < 6 && d->nm == 4; f++) d->r[i] -= face_flux(d, NULL, i, f) / d->h;
    }
    const int it = cg(d, d->r, d->phi);
    for (size_t i = 0; i < n; i++) {
        out[i * d->nm] = d->phi[i] / s4;
        if (d->nm == 1) continue;
        double jc[3], jw[3] = {0, 0, 0}; /* the correction's flux along the cells' axes: the faces' mean */
        for (int a = 0; a < 3; a++) jc[a] = 0.5 * (face_flux(d, d->phi, i, 2 * a + 1) - face_flux(d, d->phi, i, 2 * a));
        for (int b = 0; b < 3; b++)
            for (int a = 0; a < 3; a++) jw[b] += d->R[a][b] * jc[a];
        out[i * 4 + 1] = jw[1] / s3, out[i * 4 + 2] = jw[2] / s3, out[i * 4 + 3] = jw[0] / s3;
    }
    return it;
}
