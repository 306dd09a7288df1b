/* Discrete ordinates on a coarse grid (lfield_do.h; docs/lightfield.md, "A discrete-ordinates
 * field"). Per direction one upwind sweep with the step scheme: a cell's radiance psi =
 * (s h + sum_a |O_a| psi_in,a) / (sig_t h + sum_a |O_a|), its outgoing faces carrying psi
 * (positive, the cell's balance exact); the emission s toward the direction is the degree <= L
 * series of the scattering source, sig_s chi_l phi_lm + q1_lm. The moments phi solve
 * phi = T (S phi + q1) (T: the sweeps and the projection; S: the scattering), by restarted
 * GMRES on (I - T S) phi = T q1, then one last sweep that gives the leaving power. The
 * directions are swept in a fixed number of groups, each summed into its own moments, the
 * groups added in order: the same numbers whatever the threads. */
#include "light/lfield_do.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DO_GROUPS 4

void atmos__sh_eval(int lmax, const double d[3], double *Y)
{
    const double x = d[0], y = d[1], z = d[2];
    Y[0] = 0.28209479177387814;
    if (lmax < 1) return;
    Y[1] = 0.4886025119029199 * y, Y[2] = 0.4886025119029199 * z, Y[3] = 0.4886025119029199 * x;
    if (lmax < 2) return;
    Y[4] = 1.0925484305920792 * x * y, Y[5] = 1.0925484305920792 * y * z;
    Y[6] = 0.31539156525252005 * (3 * z * z - 1), Y[7] = 1.0925484305920792 * x * z;
    Y[8] = 0.5462742152960396 * (x * x - y * y);
    if (lmax < 3) return;
    Y[9] = 0.5900435899266435 * y * (3 * x * x - y * y), Y[10] = 2.890611442640554 * x * y * z;
    Y[11] = 0.4570457994644658 * y * (5 * z * z - 1), Y[12] = 0.3731763325901154 * z * (5 * z * z - 3);
    Y[13] = 0.4570457994644658 * x * (5 * z * z - 1), Y[14] = 1.445305721320277 * z * (x * x - y * y);
    Y[15] = 0.5900435899266435 * x * (x * x - 3 * y * y);
}

int atmos__do_quadrature(int nmu, int nphi, atmos__do_quad *q)
{
    if (nmu < 1 || nphi < 1 || nmu * nphi > ATMOS__DO_NMAX) return 0;
    q->n = 0;
    for (int i = 0; i < nmu; i++) {
        /* the i-th root of P_nmu by Newton's method from Tricomi's estimate */
        double x = cos(ATMOS_PI * (i + 0.75) / (nmu + 0.5)), dp = 1;
        for (int it = 0; it < 100; it++) {
            double p0 = 1, p1 = x;
            for (int l = 2; l <= nmu; l++) {
                const double p2 = ((2 * l - 1) * x * p1 - (l - 1) * p0) / l;
                p0 = p1, p1 = p2;
            }
            dp = nmu * (x * p1 - p0) / (x * x - 1);
            const double dx = p1 / dp;
            x -= dx;
            if (fabs(dx) < 1e-15) break;
        }
        const double wmu = 2.0 / ((1 - x * x) * dp * dp), st = sqrt(fmax(0.0, 1 - x * x));
        for (int j = 0; j < nphi; j++) {
            const double ph = 2 * ATMOS_PI * (j + 0.5) / nphi;
            double *d = q->dir[q->n];
            d[0] = st * cos(ph), d[1] = st * sin(ph), d[2] = x;
            q->w[q->n++] = wmu * 2 * ATMOS_PI / nphi;
        }
    }
    return 1;
}

typedef struct {
    const atmos__do_problem *P;
    int K;
    size_t cells;
    double (*Y)[ATMOS__DO_KMAX]; /* per direction */
    double (*o)[3];              /* per direction, along the cells' axes */
    double *acc[DO_GROUPS], *psi[DO_GROUPS];
    double leak[DO_GROUPS];
    unsigned char *live; /* per cell: it scatters or emits (else its source is 0) */
    unsigned char *need; /* per cell: it or one of its 26 neighbours has a medium or a source (else
                            its moments are left 0: no scattering reads them, nor a trilinear read
                            of the field where there is a medium) */
} do_work;

/* W->need from W->live and the cells' extinction: the cells within one cell (26 neighbours) of a
 * live cell or of one with sigma_t > 0. */
static void mark_needed(do_work *W)
{
    const atmos__do_problem *P = W->P;
    const int nx = P->c[0], ny = P->c[1], nz = P->c[2];
    memset(W->need, 0, W->cells);
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                const size_t c = ((size_t)k * ny + j) * nx + i;
                if (!W->live[c] && !(P->sig_t[c] != 0)) continue;
                for (int z = k > 0 ? k - 1 : 0; z <= k + 1 && z < nz; z++)
                    for (int y = j > 0 ? j - 1 : 0; y <= j + 1 && y < ny; y++)
                        for (int x = i > 0 ? i - 1 : 0; x <= i + 1 && x < nx; x++)
                            W->need[((size_t)z * ny + y) * nx + x] = 1;
            }
}

/* One direction's sweep with the source moments Q (per cell, K each), its radiance into psi,
 * its moments added to acc (weight w), the power leaving through the grid's faces to *leak. */
static inline void sweep_k(const do_work *W, int n, const double *Q, double *psi, double *acc, double *leak,
                           const int K)
{
    const atmos__do_problem *P = W->P;
    const int nx = P->c[0], ny = P->c[1], nz = P->c[2];
    const double *o = W->o[n], *Y = W->Y[n], w = P->quad->w[n], h = P->h;
    double wY[ATMOS__DO_KMAX];
    for (int m = 0; m < K; m++) wY[m] = w * Y[m];
    const double ax = fabs(o[0]), ay = fabs(o[1]), az = fabs(o[2]), as = ax + ay + az;
    const int sx = o[0] >= 0 ? 1 : -1, sy = o[1] >= 0 ? 1 : -1, sz = o[2] >= 0 ? 1 : -1;
    const size_t sxy = (size_t)nx * ny;
    double out = 0;
    for (int kk = 0; kk < nz; kk++) {
        const int k = sz > 0 ? kk : nz - 1 - kk;
        for (int jj = 0; jj < ny; jj++) {
            const int j = sy > 0 ? jj : ny - 1 - jj;
            for (int ii = 0; ii < nx; ii++) {
                const int i = sx > 0 ? ii : nx - 1 - ii;
                const size_t c = k * sxy + (size_t)j * nx + i;
                const double *q = Q + c * K;
                double s = 0;
                if (W->live[c])
                    for (int m = 0; m < K; m++) s += q[m] * Y[m];
                const double px = ii ? psi[c - sx] : 0, py = jj ? psi[c - (ptrdiff_t)sy * nx] : 0,
                             pz = kk ? psi[c - (ptrdiff_t)sz * (ptrdiff_t)sxy] : 0;
                const double v = (s * h + ax * px + ay * py + az * pz) / (P->sig_t[c] * h + as);
                psi[c] = v;
                if (v != 0 && W->need[c]) {
                    double *a = acc + c * K;
                    for (int m = 0; m < K; m++) a[m] += wY[m] * v;
                }
                out += v * ((ii == nx - 1) * ax + (jj == ny - 1) * ay + (kk == nz - 1) * az);
            }
        }
    }
    *leak += w * out * h * h;
}

/* The same with K a constant the compiler can unroll. */
static void sweep_one(const do_work *W, int n, const double *Q, double *psi, double *acc, double *leak)
{
    switch (W->K) {
    case 16: sweep_k(W, n, Q, psi, acc, leak, 16); break;
    case 9: sweep_k(W, n, Q, psi, acc, leak, 9); break;
    case 4: sweep_k(W, n, Q, psi, acc, leak, 4); break;
    default: sweep_k(W, n, Q, psi, acc, leak, 1); break;
    }
}

/* All the directions with the source moments Q: the radiance moments into phi, the leaving power
 * into *leak (if not NULL). */
static void sweep_all(do_work *W, const double *Q, double *phi, double *leak)
{
    const size_t N = W->cells * W->K;
#pragma omp parallel for schedule(static, 1) num_threads(W->P->threads)
    for (int g = 0; g < DO_GROUPS; g++) {
        memset(W->acc[g], 0, sizeof(double) * N);
        W->leak[g] = 0;
        for (int n = g; n < W->P->quad->n; n += DO_GROUPS) sweep_one(W, n, Q, W->psi[g], W->acc[g], &W->leak[g]);
    }
    double l = 0;
    for (size_t i = 0; i < N; i++) {
        double s = 0;
        for (int g = 0; g < DO_GROUPS; g++) s += W->acc[g][i];
        phi[i] = s;
    }
    for (int g = 0; g < DO_GROUPS; g++) l += W->leak[g];
    if (leak) *leak = l;
}

/* The scattering source's moments, sig_s chi_l x_lm (plus q1 when add_q1). */
static void scatter(const do_work *W, const double *x, double *Q, int add_q1)
{
    const atmos__do_problem *P = W->P;
    const int K = W->K;
    for (size_t c = 0; c < W->cells; c++)
        for (int k = 0; k < K; k++) {
            const int l = atmos__sh_degree(k);
            Q[c * K + k] = P->sig_s[c] * P->chi[l] * x[c * K + k] + (add_q1 ? P->q1[c * K + k] : 0);
        }
}

/* y = (I - T S) x */
static void apply(do_work *W, const double *x, double *y, double *tmp)
{
    scatter(W, x, tmp, 0);
    sweep_all(W, tmp, y, NULL);
    for (size_t i = 0; i < W->cells * W->K; i++) y[i] = x[i] - y[i];
}

/* In DOT_CHUNKS fixed pieces added in order: the same sum whatever the threads. */
#define DOT_CHUNKS 64
static double dot(const double *a, const double *b, size_t n, int threads)
{
    double part[DOT_CHUNKS], s = 0;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int c = 0; c < DOT_CHUNKS; c++) {
        double t = 0;
        for (size_t i = n * c / DOT_CHUNKS; i < n * (c + 1) / DOT_CHUNKS; i++) t += a[i] * b[i];
        part[c] = t;
    }
    for (int c = 0; c < DOT_CHUNKS; c++) s += part[c];
    return s;
}

/* y += a x */
static void axpy(double a, const double *x, double *y, size_t n, int threads)
{
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t i = 0; i < n; i++) y[i] += a * x[i];
}

/* Restarted GMRES (Saad & Schultz 1986) on (I - T S) x = b, x holding the start (zero_start: x is 0,
 * its first residual b itself, no sweep). */
static void gmres(do_work *W, const double *b, double *x, double *V, double *tmp, atmos__do_stats *st, int zero_start)
{
    const atmos__do_problem *P = W->P;
    const int m = P->restart;
    const size_t N = W->cells * W->K;
    double H[65][64], cs[64], sn[64], g[65], y[64];
    const int T = 1; /* the vector operations in one thread: on a loaded machine a parallel region per
                        operation costs more in its barriers than it saves */
    const double bn = sqrt(dot(b, b, N, T));
    st->resid = 0;
    if (!(bn > 0)) return;
    while (st->iters < P->max_iter) {
        if (zero_start)
            memcpy(V, b, sizeof(double) * N), zero_start = 0;
        else {
            apply(W, x, V, tmp);
            st->sweeps++;
            for (size_t i = 0; i < N; i++) V[i] = b[i] - V[i];
        }
        const double beta = sqrt(dot(V, V, N, T));
        st->resid = beta / bn;
        if (st->resid <= P->tol) return;
        for (size_t i = 0; i < N; i++) V[i] /= beta;
        memset(g, 0, sizeof g);
        g[0] = beta;
        int j = 0;
        for (; j < m && st->iters < P->max_iter; j++) {
            double *v = V + (size_t)(j + 1) * N;
            apply(W, V + (size_t)j * N, v, tmp);
            st->sweeps++, st->iters++;
            for (int i = 0; i <= j; i++) {
                const double *vi = V + (size_t)i * N;
                H[i][j] = dot(v, vi, N, T);
                axpy(-H[i][j], vi, v, N, T);
            }
            H[j + 1][j] = sqrt(dot(v, v, N, T));
            if (H[j + 1][j] > 0) axpy(1.0 / H[j + 1][j] - 1, v, v, N, T);
            for (int i = 0; i < j; i++) {
                const double t = cs[i] * H[i][j] + sn[i] * H[i + 1][j];
                H[i + 1][j] = -sn[i] * H[i][j] + cs[i] * H[i + 1][j], H[i][j] = t;
            }
            const double r = hypot(H[j][j], H[j + 1][j]);
            cs[j] = r > 0 ? H[j][j] / r : 1, sn[j] = r > 0 ? H[j + 1][j] / r : 0;
            H[j][j] = r, H[j + 1][j] = 0;
            g[j + 1] = -sn[j] * g[j], g[j] = cs[j] * g[j];
            st->resid = fabs(g[j + 1]) / bn;
            if (st->resid <= P->tol || !(r > 0)) {
                j++;
                break;
            }
        }
        for (int i = j - 1; i >= 0; i--) {
            double s = g[i];
            for (int k = i + 1; k < j; k++) s -= H[i][k] * y[k];
            y[i] = H[i][i] != 0 ? s / H[i][i] : 0;
        }
        for (int i = 0; i < j; i++) axpy(y[i], V + (size_t)i * N, x, N, T);
        if (st->resid <= P->tol) return;
    }
}

int atmos__do_solve(const atmos__do_problem *P, double *phi, atmos__do_stats *st)
{
    memset(st, 0, sizeof *st);
    do_work W;
    memset(&W, 0, sizeof W);
    W.P = P, W.K = (P->L + 1) * (P->L + 1), W.cells = (size_t)P->c[0] * P->c[1] * P->c[2];
    const size_t N = W.cells * W.K;
    const int m = P->restart < 1 ? 1 : P->restart > 64 ? 64 : P->restart, nd = P->quad->n;
    atmos__do_problem Pm = *P;
    Pm.restart = m, W.P = &Pm;
    W.Y = malloc(sizeof *W.Y * nd), W.o = malloc(sizeof *W.o * nd);
    double *V = malloc(sizeof(double) * N * (m + 1)), *b = malloc(sizeof(double) * N),
           *tmp = malloc(sizeof(double) * N);
    W.live = malloc(W.cells), W.need = malloc(W.cells);
    int ok = W.Y && W.o && V && b && tmp && W.live && W.need;
    for (int g = 0; g < DO_GROUPS; g++) {
        W.acc[g] = malloc(sizeof(double) * N), W.psi[g] = malloc(sizeof(double) * W.cells);
        ok = ok && W.acc[g] && W.psi[g];
    }
    if (ok) {
        for (size_t c = 0; c < W.cells; c++) {
            W.live[c] = P->sig_s[c] != 0;
            for (int k = 0; k < W.K; k++) W.live[c] |= P->q1[c * W.K + k] != 0;
        }
        mark_needed(&W);
        for (int n = 0; n < nd; n++) {
            const double *d = P->quad->dir[n];
            atmos__sh_eval(P->L, d, W.Y[n]);
            for (int a = 0; a < 3; a++) W.o[n][a] = P->R[a][0] * d[0] + P->R[a][1] * d[1] + P->R[a][2] * d[2];
        }
        sweep_all(&W, P->q1, b, NULL);
        st->sweeps++;
        int zero = 1;
        for (size_t i = 0; i < N && zero; i++) zero = phi[i] == 0;
        gmres(&W, b, phi, V, tmp, st, zero);
        scatter(&W, phi, tmp, 1);
        sweep_all(&W, tmp, phi, &st->leak);
        st->sweeps++;
        for (size_t c = 0; c < W.cells; c++) st->emitted += P->q1[c * W.K] * sqrt(4 * ATMOS_PI);
        st->emitted *= P->h * P->h * P->h;
    }
    for (int g = 0; g < DO_GROUPS; g++) free(W.acc[g]), free(W.psi[g]);
    free(W.Y), free(W.o), free(V), free(b), free(tmp), free(W.live), free(W.need);
    return ok;
}
