/* Discrete ordinates on a coarse grid (lfield_do.h; docs/lightfield.md, "A discrete-ordinates
 * field"). Per direction one upwind sweep with the weighted diamond scheme (cell_faces(); theta 1,
 * the step scheme: a cell's radiance psi = (s h + sum_a |O_a| psi_in,a) / (sig_t h + sum_a |O_a|),
 * its outgoing faces carrying psi, positive; with theta < 1 in thick cells, less numerical
 * diffusion, a face may leave negative; the cell's balance exact either way); the emission s
 * toward the direction is the degree <= L series of the scattering source, sig_s chi_l phi_lm +
 * q1_lm. The moments phi solve phi = T (S phi + q1) (T: the sweeps and the projection; S: the
 * scattering), by restarted GMRES on (I - T S) phi = T q1 + T_in (T_in: the sweeps of the
 * radiance entering through the grid's faces, the problem's inflow, with no source inside; T and
 * S linear, without it), then one last source iteration (a sweep when the leaving power is asked
 * for). The directions are swept in a fixed number of groups, each summed into its own moments, the
 * groups added in order: the same numbers whatever the threads. GMRES's vectors hold the cells
 * needed alone (a medium or a source within one cell), the others' moments 0. */
#include "light/lfield_do.h"
#include "core/clones.h"
#include "light/lfield_dsa.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DO_GROUPS 4
#define DO_PACK 4 /* directions swept together: one vector of 4 floats */
typedef float v4f __attribute__((vector_size(16)));

static inline v4f load4(const float *p)
{
    v4f v;
    memcpy(&v, p, sizeof v);
    return v;
}

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

/* A pack: up to DO_PACK directions of one octant (the same order of the cells in their sweeps),
 * swept together: a cell's source moments are read and its moments written once for all of them
 * (a sweep is bound by those reads and writes). Padded with weight 0 (a direction's copy). */
typedef struct {
    int s[3];                          /* the octant: the sweep's sign along each axis */
    v4f Y[ATMOS__DO_KMAX];             /* the harmonics, per coefficient (the directions in a vector) */
    float wY[DO_PACK][ATMOS__DO_KMAX]; /* times the weight, per direction and coefficient */
    v4f a[3], as;                      /* |the components| along the axes; their sum */
    v4f in;                            /* the radiance entering through the grid's faces */
    double w[DO_PACK];                 /* the weight */
} do_pack;

typedef struct {
    const atmos__do_problem *P;
    int K, npack;
    size_t cells;
    do_pack *pack;
    float *acc[DO_GROUPS], *psi[DO_GROUPS]; /* in single precision; psi per cell, 3 faces of DO_PACK */
    float *Q, *q1;                          /* the sweeps' source moments; q1 in single precision */
    double leak[DO_GROUPS];
    float *theta;        /* per cell: the weighted diamond's weight (cell_faces()) */
    unsigned char *live; /* per cell: it scatters or emits (else its source is 0) */
    unsigned char *need; /* per cell: it or one of its 26 neighbours has a medium or a source (else
                            its moments are left 0: no scattering reads them, nor a trilinear read
                            of the field where there is a medium) */
    size_t *idx, n;      /* the cells needed, in order, and their count: GMRES's vectors hold their
                            moments alone (idx[i] * K + k at i * K + k), the others 0 */
    atmos__dsa *dsa;     /* the diffusion preconditioner (P->dsa), else NULL (or not yet on) */
    double hist[4];      /* ATMOS__DO_DSA_AUTO: the relative residuals after the last 4 iterations */
    double *dz;          /* per GMRES column: its preconditioner's correction (n cells of
                            atmos__dsa_moments() values) */
} do_work;

/* W->need from W->live and the cells' extinction: the cells within one cell (26 neighbours) of a
 * live cell or of one with sigma_t > 0. The box's dilation axis by axis, each pass's result in a
 * bit of its own (bit 0 the seeds, then 1, 2 and 3 after x, y and z). */
static void mark_needed(do_work *W)
{
    const atmos__do_problem *P = W->P;
    const int c[3] = {P->c[0], P->c[1], P->c[2]};
    const size_t stride[3] = {1, (size_t)c[0], (size_t)c[0] * c[1]};
    unsigned char *m = W->need;
    for (size_t i = 0; i < W->cells; i++) m[i] = W->live[i] || P->sig_t[i] != 0;
    for (int a = 0; a < 3; a++) {
        const unsigned char from = (unsigned char)(1u << a), to = (unsigned char)(2u << a);
        for (int k = 0; k < c[2]; k++)
            for (int j = 0; j < c[1]; j++)
                for (int i = 0; i < c[0]; i++) {
                    const int at[3] = {i, j, k};
                    const size_t q = k * stride[2] + j * stride[1] + i;
                    int any = m[q] & from;
                    if (at[a] > 0) any |= m[q - stride[a]] & from;
                    if (at[a] + 1 < c[a]) any |= m[q + stride[a]] & from;
                    if (any) m[q] |= to;
                }
    }
    for (size_t i = 0; i < W->cells; i++) m[i] = m[i] >> 3 & 1;
}

/* The packs: the directions by octant (in a fixed order), DO_PACK at a time. Returns their count;
 * pack must hold ATMOS__DO_NMAX of them. */
static int make_packs(const atmos__do_problem *P, do_pack *pack)
{
    const int nd = P->quad->n;
    int np = 0;
    for (int oct = 0; oct < 8; oct++) {
        int d = DO_PACK;
        for (int n = 0; n < nd; n++) {
            const double *dw = P->quad->dir[n];
            double o[3], Y[ATMOS__DO_KMAX] = {0};
            int in = 1;
            for (int a = 0; a < 3; a++) {
                o[a] = P->R[a][0] * dw[0] + P->R[a][1] * dw[1] + P->R[a][2] * dw[2];
                in = in && (o[a] >= 0) == !(oct >> a & 1);
            }
            if (!in) continue;
            if (d == DO_PACK) {
                do_pack *p = &pack[np++];
                for (int a = 0; a < 3; a++) p->s[a] = oct >> a & 1 ? -1 : 1;
                d = 0;
            }
            do_pack *p = &pack[np - 1];
            atmos__sh_eval(P->L, dw, Y);
            /* this direction in every slot left (the padding: weight 0) */
            for (int e = d; e < DO_PACK; e++) {
                const double w = e == d ? P->quad->w[n] : 0;
                for (int m = 0; m < ATMOS__DO_KMAX; m++) p->Y[m][e] = (float)Y[m], p->wY[e][m] = (float)(w * Y[m]);
                for (int a = 0; a < 3; a++) p->a[a][e] = (float)fabs(o[a]);
                p->as[e] = p->a[0][e] + p->a[1][e] + p->a[2][e], p->w[e] = w;
                p->in[e] = P->inflow ? (float)P->inflow[n] : 0.0f;
            }
            d++;
        }
    }
    return np;
}

/* A cell's radiance psi_c and its outgoing faces' o[a] from its entering faces' in[a] (a pack's 4
 * directions in a vector), by the weighted diamond scheme (theta 1: the step scheme, o[a] = psi_c;
 * 1/2: diamond difference): psi_c = (s theta h + sum_a |O_a| in_a) / (sig_t theta h + sum_a
 * |O_a|), o[a] = (psi_c - (1 - theta) in_a) / theta. Linear (no fixup of negative faces: the
 * sweeps are GMRES's operator, applied to vectors of any sign), so with theta < 1 a face may leave
 * negative. */
static inline __attribute__((always_inline)) v4f cell_faces(const do_pack *pk, v4f src, float st, float h, float theta,
                                                          const v4f in[3], v4f o[3])
{
    const float th = theta * h;
    v4f v = (src * th + pk->a[0] * in[0] + pk->a[1] * in[1] + pk->a[2] * in[2]) / (st * th + pk->as);
    if (theta >= 1.0f) {
        o[0] = o[1] = o[2] = v;
        return v;
    }
    const float r = 1.0f / theta, q = (1.0f - theta) / theta;
    for (int a = 0; a < 3; a++) o[a] = v * r - in[a] * q;
    return v;
}

/* One pack's sweep with the source moments Q (per cell, K each), its radiance's outgoing faces into
 * psi (per cell, 3 faces of DO_PACK), its moments added to acc (first: set, at the cells needed), the power leaving through the
 * grid's faces to *leak; with_in: the inflow entering through the grid's faces (else nothing: the
 * linear part). In single precision but the leaving power (the directions of a pack in one
 * vector). */
static inline __attribute__((always_inline)) void sweep_k(const do_work *W, const do_pack *pk, const float *Q, float *psi, float *acc,
                           double *leak, const int K, const int with_in, const int first)
{
    const atmos__do_problem *P = W->P;
    const int nx = P->c[0], ny = P->c[1], nz = P->c[2], sx = pk->s[0], sy = pk->s[1], sz = pk->s[2];
    const float h = (float)P->h;
    const v4f zero = {0, 0, 0, 0}, bnd = with_in ? pk->in : zero;
    const size_t sxy = (size_t)nx * ny;
    double out[DO_PACK] = {0};
    for (int kk = 0; kk < nz; kk++) {
        const int k = sz > 0 ? kk : nz - 1 - kk;
        for (int jj = 0; jj < ny; jj++) {
            const int j = sy > 0 ? jj : ny - 1 - jj;
            for (int ii = 0; ii < nx; ii++) {
                const int i = sx > 0 ? ii : nx - 1 - ii;
                const size_t c = k * sxy + (size_t)j * nx + i;
                v4f src = {0, 0, 0, 0};
                if (W->live[c]) {
                    const float *q = Q + c * K;
                    for (int m = 0; m < K; m++) src += q[m] * pk->Y[m];
                }
                const v4f in[3] = {ii ? load4(psi + ((c - sx) * 3 + 0) * DO_PACK) : bnd,
                                   jj ? load4(psi + ((c - (ptrdiff_t)sy * nx) * 3 + 1) * DO_PACK) : bnd,
                                   kk ? load4(psi + ((c - (ptrdiff_t)sz * (ptrdiff_t)sxy) * 3 + 2) * DO_PACK) : bnd};
                v4f o[3];
                const v4f v = cell_faces(pk, src, P->sig_t[c], h, W->theta[c], in, o);
                memcpy(psi + c * 3 * DO_PACK, o, sizeof o);
                if (W->need[c] && (first || v[0] != 0 || v[1] != 0 || v[2] != 0 || v[3] != 0)) {
                    /* a vector over the coefficients; the group's first pack sets them (no memset of
                       the sums each sweep: 0 + t = t, the cells not needed never written) */
                    float *a = acc + c * K;
                    int m = 0;
                    for (; m + 4 <= K; m += 4) {
                        v4f t = load4(&pk->wY[0][m]) * v[0];
                        for (int d = 1; d < DO_PACK; d++) t += load4(&pk->wY[d][m]) * v[d];
                        if (!first) t = load4(a + m) + t;
                        memcpy(a + m, &t, sizeof t);
                    }
                    for (; m < K; m++) {
                        float t = pk->wY[0][m] * v[0];
                        for (int d = 1; d < DO_PACK; d++) t += pk->wY[d][m] * v[d];
                        a[m] = first ? t : a[m] + t;
                    }
                }
                const int ex = ii == nx - 1, ey = jj == ny - 1, ez = kk == nz - 1;
                if (ex | ey | ez)
                    for (int d = 0; d < DO_PACK; d++)
                        out[d] += (double)ex * o[0][d] * pk->a[0][d] + (double)ey * o[1][d] * pk->a[1][d] +
                                  (double)ez * o[2][d] * pk->a[2][d];
            }
        }
    }
    double l = 0;
    for (int d = 0; d < DO_PACK; d++) l += pk->w[d] * out[d];
    *leak += l * P->h * P->h;
}

/* The same with K a constant the compiler can unroll (and vectorise, for AVX2 too: the same
 * operations in the same order, no contraction). */
ATMOS_CLONES
static void sweep_one(const do_work *W, const do_pack *pk, const float *Q, float *psi, float *acc, double *leak,
                      int with_in, int first)
{
    switch (W->K) {
    case 16: sweep_k(W, pk, Q, psi, acc, leak, 16, with_in, first); break;
    case 9: sweep_k(W, pk, Q, psi, acc, leak, 9, with_in, first); break;
    case 4: sweep_k(W, pk, Q, psi, acc, leak, 4, with_in, first); break;
    default: sweep_k(W, pk, Q, psi, acc, leak, 1, with_in, first); break;
    }
}

/* All the directions with the source moments Q (and the inflow when with_in): the radiance moments
 * of the cells needed into phi (W->idx's order), or x - them when x is not NULL; the leaving power into *leak (if not NULL). The packs in DO_GROUPS fixed groups, added
 * in order. */
static void sweep_all(do_work *W, const float *Q, double *phi, const double *x, double *leak, int with_in)
{
    const int K = W->K;
    /* the groups' sums per cell in the same region, after the sweeps (each cell's its own) */
#pragma omp parallel num_threads(W->P->threads)
    {
#pragma omp for schedule(static, 1)
        for (int g = 0; g < DO_GROUPS; g++) {
            W->leak[g] = 0;
            for (int p = g; p < W->npack; p += DO_GROUPS)
                sweep_one(W, &W->pack[p], Q, W->psi[g], W->acc[g], &W->leak[g], with_in, p == g);
        }
#pragma omp for schedule(static)
        for (size_t i = 0; i < W->n; i++)
            for (int k = 0; k < K; k++) {
                const size_t a = W->idx[i] * K + k, e = i * K + k;
                double s = 0;
                for (int g = 0; g < DO_GROUPS; g++) s += (double)W->acc[g][a];
                phi[e] = x ? x[e] - s : s;
            }
    }
    double l = 0;
    for (int g = 0; g < DO_GROUPS; g++) l += W->leak[g];
    if (leak) *leak = l;
}

/* The scattering source's moments, sig_s chi_l x_lm (plus q1 when add_q1), into W->Q at the cells
 * needed (x in W->idx's order; the sweeps read Q only where a cell scatters or emits, which is
 * needed). */
static void scatter(const do_work *W, const double *x, int add_q1)
{
    const atmos__do_problem *P = W->P;
    const int K = W->K;
    double chi[ATMOS__DO_KMAX];
    for (int k = 0; k < K; k++) chi[k] = P->chi[atmos__sh_degree(k)];
#pragma omp parallel for schedule(static) num_threads(P->threads) if (P->threads > 1)
    for (size_t i = 0; i < W->n; i++) {
        const size_t c = W->idx[i];
        const double ss = P->sig_s[c];
        if (add_q1)
            for (int k = 0; k < K; k++) W->Q[c * K + k] = (float)(ss * chi[k] * x[i * K + k] + P->q1[c * K + k]);
        else
            for (int k = 0; k < K; k++) W->Q[c * K + k] = (float)(ss * chi[k] * x[i * K + k] + 0);
    }
}

/* y = (I - T S) x */
static void apply(do_work *W, const double *x, double *y)
{
    scatter(W, x, 0);
    sweep_all(W, W->Q, y, x, NULL, 0);
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

/* The residual b - A x after a GMRES cycle of j columns, from its rotations (no sweep): V_{j+1} Q^T
 * (0, ..., 0, g_j) (Saad 2003, Prop. 6.9), into r. */
static void cycle_residual(const double *V, size_t N, int j, const double *g, const double *cs, const double *sn,
                           double *r)
{
    double z[65] = {0};
    z[j] = g[j];
    for (int i = j - 1; i >= 0; i--) {
        const double t = z[i], u = z[i + 1];
        z[i] = cs[i] * t - sn[i] * u, z[i + 1] = sn[i] * t + cs[i] * u;
    }
    memset(r, 0, sizeof(double) * N);
    for (int i = 0; i <= j; i++) axpy(z[i], V + (size_t)i * N, r, N, 1);
}

/* z = M^-1 v = v + C S v (C S: the P1 solve of v's scattering, its moments of degree <= 1 alone,
 * lfield_dsa.h), the correction into dz (nm values a cell). */
static void precondition(do_work *W, const double *v, double *dz, double *z, atmos__do_stats *st)
{
    const int K = W->K, nm = atmos__dsa_moments(W->dsa);
    st->dsa_iters += atmos__dsa_apply(W->dsa, v, K, dz);
    memcpy(z, v, sizeof(double) * W->n * K);
    for (size_t i = 0; i < W->n; i++)
        for (int k = 0; k < nm; k++) z[i * K + k] += dz[i * nm + k];
}

/* ATMOS__DO_DSA_AUTO: after GMRES's iteration it (0: the start) with the relative residual resid,
 * the rate of the last three iterations (plain ones) predicts the iterations to the tolerance; more
 * than ATMOS__DO_DSA_AFTER in all: the preconditioner on from the next column. A fast start (a thin
 * medium, a warm start near the solution) stays plain and pays nothing for it. */
static void dsa_switch(do_work *W, int it, double resid, atmos__do_stats *st)
{
    W->hist[it % 4] = resid;
    if (W->dsa || W->P->dsa != ATMOS__DO_DSA_AUTO || it < 3 || !(resid > W->P->tol)) return;
    const double rho = pow(resid / W->hist[(it - 3) % 4], 1.0 / 3);
    const double left = rho < 1 ? log(W->P->tol / resid) / log(rho) : 1e9;
    if (it + left > ATMOS__DO_DSA_AFTER) {
        W->dsa = atmos__dsa_create(W->P, W->idx, W->n); /* NULL (out of memory): plain on */
        if (W->dsa) st->dsa_at = it;
    }
}

/* The residual b - A x into V at a GMRES cycle's start: b itself from 0 (zero_start), else by a
 * sweep: with b, A x's (apply); with b NULL (not swept: atmos__do_problem's kappa), the source's
 * and the scattering's together, V = T (S x + q1) - x, and *bn, when not known yet (0), taken as
 * kappa ||T (S x + q1)||. */
static void cycle_start(do_work *W, const double *b, const double *x, double *V, int zero_start, double *bn,
                        atmos__do_stats *st)
{
    const size_t N = W->n * W->K;
    if (zero_start) {
        memcpy(V, b, sizeof(double) * N);
        return;
    }
    st->sweeps++;
    if (b) {
        apply(W, x, V);
        for (size_t i = 0; i < N; i++) V[i] = b[i] - V[i];
        return;
    }
    scatter(W, x, 1);
    sweep_all(W, W->Q, V, NULL, NULL, W->P->inflow != NULL);
    if (!(*bn > 0)) *bn = *W->P->kappa * sqrt(dot(V, V, N, 1));
    for (size_t i = 0; i < N; i++) V[i] -= x[i];
}

/* Restarted GMRES (Saad & Schultz 1986) on (I - T S) x = b, x holding the start (zero_start: x is 0,
 * its first residual b itself, no sweep); with W->dsa flexible GMRES (Saad 1993) right-preconditioned
 * by it: the columns' z_j = M^-1 v_j differ from v_j in their moments of degree <= 1 alone
 * (W->dz), the residual the true one (the same tolerance), r the z's room within a cycle. bn =
 * ||b||; b NULL with bn 0: b not swept, bn estimated at the first cycle's start (cycle_start).
 * Returns 1 with the last residual b - A x in r (no source: x = 0, r = 0), else 0. */
static int gmres(do_work *W, const double *b, double bn, double *x, double *V, double *r, atmos__do_stats *st,
                 int zero_start)
{
    const atmos__do_problem *P = W->P;
    const int m = P->restart;
    const size_t N = W->n * W->K;
    double H[65][64], cs[64], sn[64], g[65], y[64];
    unsigned char pre[64] = {0}; /* column j preconditioned */
    const int T = 1; /* the vector operations in one thread: on a loaded machine a parallel region per
                        operation costs more in its barriers than it saves */
    st->resid = 0;
    for (int cyc = 0; st->iters < P->max_iter; cyc++) {
        if (!b || cyc > 0 || bn > 0) cycle_start(W, b, x, V, zero_start, &bn, st);
        zero_start = 0;
        if (!(bn > 0)) { /* no source: the solution is 0 whatever the start (a warm start's last sun) */
            memset(x, 0, sizeof(double) * N), memset(r, 0, sizeof(double) * N);
            return 1;
        }
        const double beta = sqrt(dot(V, V, N, T));
        st->resid = beta / bn;
        dsa_switch(W, st->iters, st->resid, st);
        if (st->resid <= P->tol) {
            memcpy(r, V, sizeof(double) * N);
            return 1;
        }
        for (size_t i = 0; i < N; i++) V[i] /= beta;
        memset(g, 0, sizeof g);
        g[0] = beta;
        int j = 0;
        for (; j < m && st->iters < P->max_iter; j++) {
            double *v = V + (size_t)(j + 1) * N;
            if ((pre[j] = W->dsa != NULL)) {
                const size_t at = (size_t)j * W->n * atmos__dsa_moments(W->dsa);
                precondition(W, V + (size_t)j * N, W->dz + at, r, st);
                apply(W, r, v);
            } else
                apply(W, V + (size_t)j * N, v);
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
            const double rr = hypot(H[j][j], H[j + 1][j]);
            cs[j] = rr > 0 ? H[j][j] / rr : 1, sn[j] = rr > 0 ? H[j + 1][j] / rr : 0;
            H[j][j] = rr, H[j + 1][j] = 0;
            g[j + 1] = -sn[j] * g[j], g[j] = cs[j] * g[j];
            st->resid = fabs(g[j + 1]) / bn;
            dsa_switch(W, st->iters, st->resid, st);
            if (st->resid <= P->tol || !(rr > 0)) {
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
        for (int i = 0; i < j; i++) {
            if (!pre[i]) continue;
            const int nm = atmos__dsa_moments(W->dsa);
            const double *dz = W->dz + (size_t)i * W->n * nm;
            for (size_t c = 0; c < W->n; c++)
                for (int k = 0; k < nm; k++) x[c * W->K + k] += y[i] * dz[c * nm + k];
        }
        if (st->resid <= P->tol || st->iters >= P->max_iter) {
            cycle_residual(V, N, j, g, cs, sn, r);
            return 1;
        }
    }
    return 0;
}

struct atmos__do_ws {
    void *mem, *aux;
    size_t bytes, aux_bytes;
    atmos__do_ws *next; /* the next concurrent solve's */
};

atmos__do_ws *atmos__do_ws_create(void) { return calloc(1, sizeof(atmos__do_ws)); }

atmos__do_ws *atmos__do_ws_at(atmos__do_ws *ws, int i)
{
    for (; ws && i > 0; i--) {
        if (!ws->next) ws->next = atmos__do_ws_create();
        ws = ws->next;
    }
    return ws;
}

void atmos__do_ws_free(atmos__do_ws *ws)
{
    while (ws) {
        atmos__do_ws *next = ws->next;
        free(ws->mem), free(ws->aux), free(ws);
        ws = next;
    }
}

void *atmos__do_ws_aux(atmos__do_ws *ws, size_t bytes)
{
    if (ws->aux_bytes < bytes) {
        free(ws->aux);
        ws->aux_bytes = (ws->aux = malloc(bytes)) ? bytes : 0;
    }
    return ws->aux;
}

/* The next bytes of *at (rounded up to 64) when *at is not NULL; the running size into *total. */
static void *carve(unsigned char **at, size_t bytes, size_t *total)
{
    bytes = (bytes + 63) & ~(size_t)63;
    *total += bytes;
    if (!*at) return NULL;
    void *p = *at;
    *at += bytes;
    return p;
}

/* W's buffers (with P's dsa the preconditioner's corrections) and GMRES's (V, m + 1 vectors; b,
 * tmp, x) from ws's memory, grown when too small (its pages then touched once for many solves).
 * Returns 0 when out of memory. */
static int take_buffers(do_work *W, int m, atmos__do_ws *ws, double **V, double **b, double **tmp, double **x)
{
    const size_t N = W->cells * W->K;
    for (int pass = 0; pass < 2; pass++) {
        unsigned char *at = pass ? ws->mem : NULL;
        size_t total = 0;
        W->pack = carve(&at, sizeof *W->pack * ATMOS__DO_NMAX, &total);
        *V = carve(&at, sizeof(double) * N * (m + 1), &total);
        *b = carve(&at, sizeof(double) * N, &total), *tmp = carve(&at, sizeof(double) * N, &total);
        *x = carve(&at, sizeof(double) * N, &total), W->idx = carve(&at, sizeof(size_t) * W->cells, &total);
        W->live = carve(&at, W->cells, &total), W->need = carve(&at, W->cells, &total);
        W->theta = carve(&at, sizeof(float) * W->cells, &total);
        W->dz = carve(&at, W->P->dsa ? sizeof(double) * W->cells * (W->K >= 4 ? 4 : 1) * m : 0,
                      &total); /* the moments of degree <= 1 (lfield_dsa.c) */
        W->Q = carve(&at, sizeof(float) * N, &total), W->q1 = carve(&at, sizeof(float) * N, &total);
        for (int g = 0; g < DO_GROUPS; g++)
            W->acc[g] = carve(&at, sizeof(float) * N, &total),
            W->psi[g] = carve(&at, sizeof(float) * W->cells * 3 * DO_PACK, &total);
        if (!pass && ws->bytes < total) {
            free(ws->mem);
            ws->bytes = (ws->mem = malloc(total)) ? total : 0;
            if (!ws->mem) return 0;
        }
    }
    return 1;
}

/* The power the inflow brings through the grid's faces: per direction its radiance times the
 * faces' areas projected across it, times its weight. */
static double entering(const atmos__do_problem *P)
{
    double e = 0;
    for (int n = 0; P->inflow && n < P->quad->n; n++) {
        const double *d = P->quad->dir[n];
        double proj = 0;
        for (int a = 0; a < 3; a++) {
            const double o = fabs(P->R[a][0] * d[0] + P->R[a][1] * d[1] + P->R[a][2] * d[2]);
            proj += o * P->c[(a + 1) % 3] * P->c[(a + 2) % 3];
        }
        e += P->quad->w[n] * P->inflow[n] * proj;
    }
    return e * P->h * P->h;
}

/* GMRES on W's needed cells from x (phi's start in W->idx's order; phi all 0: from 0), the source's
 * sweep into b (unless its norm is estimated: atmos__do_problem's kappa), then the last source
 * iteration, x + (b - A x) = T (S x + q1): from GMRES's own
 * residual (tmp), or by a sweep that also gives the leaving power. */
static void solve_gmres(do_work *W, const double *phi, double *b, double *x, double *V, double *tmp,
                        atmos__do_stats *st)
{
    const atmos__do_problem *P = W->P;
    const size_t N = W->cells * W->K, Nn = W->n * W->K;
    int zero = 1;
    for (size_t i = 0; i < N && zero; i++) zero = phi[i] == 0;
    const int est = !zero && P->kappa && *P->kappa > 0; /* ||b|| estimated, b not swept */
    double bn = 0;
    if (!est) {
        for (size_t i = 0; i < N; i++) W->q1[i] = (float)P->q1[i];
        sweep_all(W, W->q1, b, NULL, NULL, P->inflow != NULL);
        st->sweeps++;
        bn = sqrt(dot(b, b, Nn, 1));
    }
    if (gmres(W, est ? NULL : b, bn, x, V, tmp, st, zero) && !P->leak)
        for (size_t i = 0; i < Nn; i++) x[i] += tmp[i];
    else {
        scatter(W, x, 1);
        sweep_all(W, W->Q, x, NULL, &st->leak, P->inflow != NULL);
        st->sweeps++;
    }
    if (!est && P->kappa) { /* x is T (S x + q1) now */
        const double xn = sqrt(dot(x, x, Nn, 1));
        *P->kappa = xn > 0 ? bn / xn : 0;
    }
}

double atmos__do_rho(const atmos__do_problem *P)
{
    const size_t cells = (size_t)P->c[0] * P->c[1] * P->c[2];
    float smax = 0;
    for (size_t c = 0; c < cells; c++) smax = P->sig_s[c] > smax ? P->sig_s[c] : smax;
    double C = 0;
    for (int l = 0; l <= P->L; l++) C += (2 * l + 1) * fabs(P->chi[l]);
    return C * smax * sqrt(3.0) * P->h * (P->c[0] + P->c[1] + P->c[2]);
}

int atmos__do_solve(const atmos__do_problem *P, double *phi, atmos__do_stats *st)
{
    memset(st, 0, sizeof *st);
    do_work W;
    memset(&W, 0, sizeof W);
    W.P = P, W.K = (P->L + 1) * (P->L + 1), W.cells = (size_t)P->c[0] * P->c[1] * P->c[2];
    const int m = P->restart < 1 ? 1 : P->restart > 64 ? 64 : P->restart;
    atmos__do_problem Pm = *P;
    Pm.restart = m, W.P = &Pm;
    atmos__do_ws own = {NULL, NULL, 0, 0, NULL}, *ws = P->ws ? P->ws : &own;
    double *V = NULL, *b = NULL, *tmp = NULL, *x = NULL;
    const int ok = take_buffers(&W, m, ws, &V, &b, &tmp, &x);
    if (ok) {
        /* the loops over the cells on the solve's threads (each cell its own) */
        const double th = P->theta > 0 && P->theta < 1 ? P->theta : 1;
#pragma omp parallel for schedule(static) num_threads(P->threads) if (P->threads > 1)
        for (size_t c = 0; c < W.cells; c++) {
            W.live[c] = P->sig_s[c] != 0;
            for (int k = 0; k < W.K; k++) W.live[c] |= P->q1[c * W.K + k] != 0;
            /* the weighted diamond's weight: theta (P's, in (0, 1), else 1: the step scheme) in
               optically thick cells, toward 1 in thin ones, 1 - (1 - theta) (1 - e^(-tau / tau0)) */
            const double tau = P->sig_t[c] * P->h;
            W.theta[c] = (float)(P->theta_tau > 0 ? 1 - (1 - th) * (1 - exp(-tau / P->theta_tau)) : th);
        }
        mark_needed(&W);
        for (size_t c = 0; c < W.cells; c++)
            if (W.need[c]) W.idx[W.n++] = c;
        if (P->dsa == ATMOS__DO_DSA_ON && P->richardson <= 0)
            W.dsa = atmos__dsa_create(P, W.idx, W.n); /* NULL (no memory): plain */
        st->dsa_at = W.dsa ? 0 : -1;
        /* W.acc not cleared: its cells not needed are never read, each sweep's group's first pack
           sets the needed ones (sweep_k; the clearing was 7 MB a wavelength on the Disney cloud) */
        W.npack = make_packs(P, W.pack);
        for (size_t i = 0; i < W.n; i++) memcpy(x + i * W.K, phi + W.idx[i] * W.K, sizeof(double) * W.K);
        if (P->richardson > 0)
            for (int it = 0; it < P->richardson; it++) { /* x <- T (S x + q1), the inflow's too */
                scatter(&W, x, 1);
                sweep_all(&W, W.Q, x, NULL, &st->leak, P->inflow != NULL);
                st->sweeps++;
            }
        else
            solve_gmres(&W, phi, b, x, V, tmp, st);
        /* the cells not needed 0 (as the sweeps leave them), the others x: each cell written once */
#pragma omp parallel num_threads(P->threads) if (P->threads > 1)
        {
#pragma omp for schedule(static) nowait
            for (size_t c = 0; c < W.cells; c++)
                if (!W.need[c]) memset(phi + c * W.K, 0, sizeof(double) * W.K);
#pragma omp for schedule(static)
            for (size_t i = 0; i < W.n; i++) memcpy(phi + W.idx[i] * W.K, x + i * W.K, sizeof(double) * W.K);
        }
        for (size_t c = 0; c < W.cells; c++) st->emitted += P->q1[c * W.K] * sqrt(4 * ATMOS_PI);
        st->emitted *= P->h * P->h * P->h;
        st->entering = entering(P);
        atmos__dsa_free(W.dsa);
    }
    free(own.mem);
    return ok;
}
