/* Nishita et al. 1996's reference patterns (nishita.h, §3.4): in a sample space of uniform
 * mean density around a cell P, every path of order 2 (sun -> P1 -> P -> eye) and order 3
 * (sun -> P3 -> P2 -> P -> eye) is weighted by its phase-weighted form factors (the phase
 * functions at the angles of the path multiplied into the numerical integral of the form
 * factor); the cells inside the beam spread (and P's neighbours) are subdivided into
 * sub-voxels. The paths whose contributions, largest first, add up to the share r of the
 * sample space's total are kept: the pattern, whose bounding box is its size. */
#include "light/nishita.h"

#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define SELF_SUB 8 /* sub-voxels per edge of P's own cell */

/* The beam spread theta_b: the cone around the forward direction holding half the scattered
 * energy of the patterns' phase function, degrees. */
static double beam_spread(const float *ph)
{
    const double d = 0.1 * PI / 180.0;
    double acc = 0;
    for (int i = 0; i < ATMOS__NISHITA_PHASE_N - 1; i++) {
        acc += PI * (ph[i] * sin(i * d) + ph[i + 1] * sin((i + 1) * d)) * d;
        if (acc >= 0.5) return (i + 1) * 0.1;
    }
    return 180.0;
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* int over the cell at offset o (cells; P's centre at the origin) of p(din . u) p(u . dout) /
 * |x|^2 dV, u the direction of x -> P (sign -1) or P -> x (sign +1), on m^3 sub-voxels; the
 * weighted mean |x| in *r. */
static double cell_integral(const float *ph, const int o[3], int m, int sign, const double din[3],
                            const double dout[3], double *r)
{
    const double inv = 1.0 / m, dv = inv * inv * inv;
    double w = 0, wr = 0;
    for (int c = 0; c < m; c++)
        for (int b = 0; b < m; b++)
            for (int a = 0; a < m; a++) {
                const double x[3] = {o[0] - 0.5 + (a + 0.5) * inv, o[1] - 0.5 + (b + 0.5) * inv,
                                     o[2] - 0.5 + (c + 0.5) * inv};
                const double d2 = dot3(x, x), len = sqrt(d2);
                const double u[3] = {sign * x[0] / len, sign * x[1] / len, sign * x[2] / len};
                const double v =
                    atmos__nishita_phase(ph, dot3(din, u)) * atmos__nishita_phase(ph, dot3(u, dout)) / d2 * dv;
                w += v, wr += v * len;
            }
    *r = w > 0 ? wr / w : 0.5;
    return w;
}

typedef struct {
    double c;
    int i;
} ranked;

static int by_contribution(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    if (x->c != y->c) return x->c > y->c ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

/* The entries (of cnt, contributions c) kept, largest first, until their sum reaches ratio of
 * the total; their indices into *keep, the share they carry into *kept. Returns the count
 * (-1: out of memory). Entries below a cut found on a histogram of log2 c are never sorted. */
static int select_paths(const float *c, long long cnt, double ratio, int **keep, double *kept)
{
    double total = 0, cmax = 0;
    for (long long i = 0; i < cnt; i++) total += c[i], cmax = c[i] > cmax ? c[i] : cmax;
    *keep = NULL, *kept = 0;
    if (!(total > 0)) return 0;
    enum { NB = 4096 };
    static const double span = 48.0; /* octaves below the largest */
    double *hist = calloc(NB, sizeof(double));
    if (!hist) return -1;
    const double l0 = log2(cmax);
    for (long long i = 0; i < cnt; i++) {
        if (!(c[i] > 0)) continue;
        int b = (int)((l0 - log2(c[i])) / span * NB);
        hist[b < 0 ? 0 : (b >= NB ? NB - 1 : b)] += c[i];
    }
    double acc = 0, cut = 0;
    for (int b = 0; b < NB; b++) {
        acc += hist[b];
        if (acc >= ratio * total) {
            cut = exp2(l0 - (b + 1) * span / NB);
            break;
        }
    }
    free(hist);
    long long n = 0;
    for (long long i = 0; i < cnt; i++) n += c[i] > 0 && c[i] >= cut;
    ranked *r = malloc(sizeof(ranked) * (size_t)(n ? n : 1));
    int *k = malloc(sizeof(int) * (size_t)(n ? n : 1));
    if (!r || !k || n > 0x7fffffff) {
        free(r), free(k);
        return -1;
    }
    n = 0;
    for (long long i = 0; i < cnt; i++)
        if (c[i] > 0 && c[i] >= cut) r[n].c = c[i], r[n].i = (int)i, n++;
    qsort(r, (size_t)n, sizeof *r, by_contribution);
    double s = 0;
    for (long long i = 0; i < n; i++) k[i] = r[i].i, s += r[i].c;
    free(r);
    *keep = k, *kept = s / total;
    return (int)n;
}

static void decode(int i, int R, int o[3])
{
    const int side = 2 * R + 1;
    o[0] = i % side - R, o[1] = i / side % side - R, o[2] = i / (side * side) - R;
}

static int max_abs(const int o[3])
{
    int a = abs(o[0]);
    if (abs(o[1]) > a) a = abs(o[1]);
    return abs(o[2]) > a ? abs(o[2]) : a;
}

/* Directions of travel u into P with their solid angles, a partition of the sphere: cones of
 * CONE_DEG around the sunlight's direction and around the eye's (rings finer toward the axis:
 * the beam spread of a droplet's phase function is a few degrees), the rest on a Fibonacci
 * lattice. */
#define CONE_DEG 15.0
#define CONE_RINGS 60
#define CONE_AZ 48
#define LATTICE 16000
typedef struct {
    double u[3], dw;
} dirw;

static void basis(const double a[3], double e1[3], double e2[3])
{
    const double t[3] = {fabs(a[0]) < 0.9 ? 1.0 : 0.0, fabs(a[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    e1[0] = a[1] * t[2] - a[2] * t[1], e1[1] = a[2] * t[0] - a[0] * t[2], e1[2] = a[0] * t[1] - a[1] * t[0];
    const double l = sqrt(dot3(e1, e1));
    for (int i = 0; i < 3; i++) e1[i] /= l;
    e2[0] = a[1] * e1[2] - a[2] * e1[1], e2[1] = a[2] * e1[0] - a[0] * e1[2], e2[2] = a[0] * e1[1] - a[1] * e1[0];
}

/* The cone's directions around axis a (skip: inside the cone around axis b, if b). */
static int cone(const double a[3], const double *b, dirw *d)
{
    double e1[3], e2[3];
    basis(a, e1, e2);
    const double tc = CONE_DEG * PI / 180, cc = cos(tc);
    int n = 0;
    for (int i = 0; i < CONE_RINGS; i++) {
        const double t0 = tc * (double)i * i / (CONE_RINGS * CONE_RINGS), t1 = tc * (double)(i + 1) * (i + 1) / (CONE_RINGS * CONE_RINGS);
        const double tm = 0.5 * (t0 + t1), dw = (cos(t0) - cos(t1)) * 2 * PI / CONE_AZ;
        for (int j = 0; j < CONE_AZ; j++) {
            const double ph = 2 * PI * (j + 0.5) / CONE_AZ, s = sin(tm);
            dirw *q = d + n;
            for (int k = 0; k < 3; k++) q->u[k] = cos(tm) * a[k] + s * (cos(ph) * e1[k] + sin(ph) * e2[k]);
            if (b && dot3(q->u, b) >= cc) continue;
            q->dw = dw, n++;
        }
    }
    return n;
}

static int direction_set(const double lt[3], const double ev[3], dirw *d)
{
    int n = cone(lt, NULL, d);
    n += cone(ev, lt, d + n);
    double used = 0;
    for (int i = 0; i < n; i++) used += d[i].dw;
    const int n0 = n;
    const double cc = cos(CONE_DEG * PI / 180), ga = PI * (3.0 - sqrt(5.0));
    for (int i = 0; i < LATTICE; i++) {
        const double z = 1.0 - (2.0 * i + 1.0) / LATTICE, r = sqrt(1.0 - z * z), ph = ga * i;
        dirw *q = d + n;
        q->u[0] = r * cos(ph), q->u[1] = z, q->u[2] = r * sin(ph);
        if (dot3(q->u, lt) >= cc || dot3(q->u, ev) >= cc) continue;
        n++;
    }
    for (int i = n0; i < n; i++) d[i].dw = (4 * PI - used) / (n - n0);
    return n;
}

/* Order 2: the phase-weighted form factor of every cell of the sample space, integrated in
 * directions (the set above) and exactly along each direction: from P's centre back along
 * the light's path, each cell crossed gets p(theta1) p(theta2) dOmega times the length
 * crossed (cells; dV / r^2 = dOmega dr), and its weighted mean distance. */
static void form_factors(const atmos__nishita_in *in, const dirw *d, int nd, int R, double *w, double *wr, float *self)
{
    double acc[ATMOS__NISHITA_SELF_N] = {0};
    const int side = 2 * R + 1;
    for (int e = 0; e < nd; e++) {
        const double *u = d[e].u;
        const double k = d[e].dw * atmos__nishita_phase(in->phase, dot3(in->lt, u)) *
                         atmos__nishita_phase(in->phase, dot3(u, in->ev));
        const double v[3] = {-u[0], -u[1], -u[2]};
        int c[3] = {0, 0, 0};
        double t = 0, tn[3], dtn[3];
        for (int a = 0; a < 3; a++) {
            dtn[a] = v[a] != 0 ? 1.0 / fabs(v[a]) : 1e300;
            tn[a] = v[a] != 0 ? 0.5 / fabs(v[a]) : 1e300;
        }
        for (;;) {
            const int a = tn[0] < tn[1] ? (tn[0] < tn[2] ? 0 : 2) : (tn[1] < tn[2] ? 1 : 2);
            const double t1 = tn[a];
            const size_t i = ((size_t)(c[2] + R) * side + (c[1] + R)) * side + (c[0] + R);
            if (t == 0)
                for (int q = 0; q < ATMOS__NISHITA_SELF_N; q++) {
                    const double tau = pow(10.0, -3.0 + q / 8.0);
                    acc[q] += k * -expm1(-tau * t1) / tau;
                }
            w[i] += k * (t1 - t), wr[i] += k * (t1 - t) * 0.5 * (t + t1);
            t = t1, tn[a] += dtn[a];
            c[a] += v[a] > 0 ? 1 : -1;
            if (abs(c[a]) > R) break;
        }
    }
    for (int q = 0; q < ATMOS__NISHITA_SELF_N; q++) self[q] = (float)acc[q];
}

static int pattern2(const atmos__nishita_in *in, double st, double ss, atmos__nishita_pattern *p)
{
    const int R = in->radius2, side = 2 * R + 1, N = side * side * side;
    const double h = in->m->h;
    float *c = malloc(sizeof(float) * N);
    double *w = calloc((size_t)N, sizeof(double)), *wr = calloc((size_t)N, sizeof(double));
    dirw *d = malloc(sizeof(dirw) * (2 * CONE_RINGS * CONE_AZ + LATTICE));
    int ok = c && w && wr && d;
    if (ok) {
        form_factors(in, d, direction_set(in->lt, in->ev, d), R, w, wr, p->self2);
        for (int i = 0; i < N; i++) {
            wr[i] = w[i] > 0 ? wr[i] / w[i] : 0;
            c[i] = (float)(w[i] * h * ss * exp(-st * wr[i] * h));
        }
        int *keep = NULL;
        const int n = select_paths(c, N, in->ratio, &keep, &p->kept2);
        p->o2 = malloc(sizeof(int16_t) * 3 * (size_t)(n > 0 ? n : 1));
        p->w2 = malloc(sizeof(float) * (size_t)(n > 0 ? n : 1));
        p->r2 = malloc(sizeof(float) * (size_t)(n > 0 ? n : 1));
        ok = n >= 0 && p->o2 && p->w2 && p->r2;
        for (int e = 0; ok && e < n; e++) {
            int o[3];
            decode(keep[e], R, o);
            for (int a = 0; a < 3; a++) p->o2[3 * e + a] = (int16_t)o[a];
            p->w2[e] = (float)w[keep[e]], p->r2[e] = (float)wr[keep[e]];
            if (max_abs(o) > p->box2) p->box2 = max_abs(o);
        }
        p->n2 = ok ? n : 0;
        free(keep);
    }
    free(c), free(w), free(wr), free(d);
    return ok;
}

/* The order-3 sample space's shared factors: the unit directions and lengths of the offsets,
 * the legs inside one cell (sub-voxels: S(din, dout) = int p p / r^2 dV over the cell). */
#define SMOOTH_LEVELS 24  /* leg lengths 1 .. 24 cells */
#define SMOOTH_N 721      /* theta = 0, 0.25, ..., 180 degrees */
typedef struct {
    const atmos__nishita_in *in;
    int R, N;
    float *smooth;  /* [level * SMOOTH_N + i]: the phase averaged over the cone a cell subtends at the
                       leg's length (level + 1 cells): a leg between two cells' centres stands for
                       every direction between their volumes, and a droplet's forward peak is
                       narrower than that cone */
    double *S_kj; /* [q]: first and second scattering in one cell, then on toward P from offset q */
    double *S_jP; /* [q]: from offset q into P's cell, scattered there once more, then to P */
    double S00, K0, rself;
} space3;

/* The phase averaged over a cap of angular radius alpha around the direction at theta_i. */
static void smooth_table(const float *ph, double alpha, float *out)
{
    enum { RINGS = 12, AZ = 16 };
    const double ca = cos(alpha);
    for (int i = 0; i < SMOOTH_N; i++) {
        const double th = i * 0.25 * PI / 180, a[3] = {sin(th), 0, cos(th)};
        double e1[3] = {cos(th), 0, -sin(th)}, e2[3] = {0, 1, 0}, acc = 0;
        for (int r = 0; r < RINGS; r++) {
            const double c = 1.0 - (r + 0.5) / RINGS * (1.0 - ca), sn = sqrt(fmax(0.0, 1.0 - c * c));
            for (int z = 0; z < AZ; z++) {
                const double phi = 2 * PI * (z + 0.5) / AZ;
                acc += atmos__nishita_phase(ph, c * a[2] + sn * (cos(phi) * e1[2] + sin(phi) * e2[2]));
            }
        }
        out[i] = (float)(acc / (RINGS * AZ));
    }
}

/* The smoothed phase for a leg of length len (cells) at cos(theta) mu. */
static double leg_phase(const space3 *s, double len, double mu)
{
    int l = (int)(len + 0.5) - 1;
    l = l < 0 ? 0 : (l >= SMOOTH_LEVELS ? SMOOTH_LEVELS - 1 : l);
    mu = mu > 1.0 ? 1.0 : (mu < -1.0 ? -1.0 : mu);
    const double x = acos(mu) * (720.0 / PI);
    int i = (int)x;
    if (i > SMOOTH_N - 2) i = SMOOTH_N - 2;
    const float *t = s->smooth + (size_t)l * SMOOTH_N;
    return t[i] + (x - i) * (t[i + 1] - t[i]);
}

/* Weight (cells^-2 times the phase functions) and leg lengths of the path with its second
 * scattering at offset index jj from P and its first at offset index kk from that. */
static double path3(const space3 *s, int jj, int kk, double *l1, double *l2)
{
    int j[3], d[3];
    decode(jj, s->R, j), decode(kk, s->R, d);
    const double lj = sqrt((double)j[0] * j[0] + (double)j[1] * j[1] + (double)j[2] * j[2]);
    const double ld = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
    if (lj == 0 && ld == 0) {
        *l1 = *l2 = s->rself;
        return s->S00 * s->K0 / (4.0 * PI);
    }
    const double b[3] = {lj > 0 ? -j[0] / lj : 0, lj > 0 ? -j[1] / lj : 0, lj > 0 ? -j[2] / lj : 0};
    if (ld == 0) { /* k in j's cell */
        *l1 = s->rself, *l2 = lj;
        return s->S_kj[jj] * leg_phase(s, lj, dot3(b, s->in->ev)) / (lj * lj);
    }
    const double a[3] = {-d[0] / ld, -d[1] / ld, -d[2] / ld};
    const double pa = leg_phase(s, ld, dot3(s->in->lt, a)) / (ld * ld);
    if (lj == 0) { /* j in P's cell: its leg to P inside the cell */
        *l1 = ld, *l2 = s->rself;
        return pa * s->S_jP[kk];
    }
    *l1 = ld, *l2 = lj;
    return pa * leg_phase(s, ld < lj ? ld : lj, dot3(a, b)) * leg_phase(s, lj, dot3(b, s->in->ev)) / (lj * lj);
}

static int space3_init(const atmos__nishita_in *in, space3 *s)
{
    const int R = in->radius3, side = 2 * R + 1;
    s->in = in, s->R = R, s->N = side * side * side;
    s->S_kj = calloc((size_t)s->N, sizeof(double));
    s->S_jP = calloc((size_t)s->N, sizeof(double));
    s->smooth = malloc(sizeof(float) * SMOOTH_LEVELS * SMOOTH_N);
    if (!s->S_kj || !s->S_jP || !s->smooth) return 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(in->threads)
    for (int l = 0; l < SMOOTH_LEVELS; l++) smooth_table(in->phase, atan(0.62 / (l + 1)), s->smooth + (size_t)l * SMOOTH_N);
    const int z[3] = {0, 0, 0};
    s->S00 = cell_integral(in->phase, z, SELF_SUB, 1, in->lt, in->ev, &s->rself);
    s->K0 = 0;
    const double inv = 1.0 / SELF_SUB;
    for (int i = 0; i < SELF_SUB * SELF_SUB * SELF_SUB; i++) {
        const double x = (i % SELF_SUB + 0.5) * inv - 0.5, y = (i / SELF_SUB % SELF_SUB + 0.5) * inv - 0.5,
                     w = (i / (SELF_SUB * SELF_SUB) + 0.5) * inv - 0.5;
        s->K0 += inv * inv * inv / (x * x + y * y + w * w);
    }
#pragma omp parallel for schedule(dynamic, 8) num_threads(in->threads)
    for (int q = 0; q < s->N; q++) {
        int o[3];
        decode(q, R, o);
        const double l = sqrt((double)o[0] * o[0] + (double)o[1] * o[1] + (double)o[2] * o[2]);
        if (l == 0) continue;
        const double b[3] = {-o[0] / l, -o[1] / l, -o[2] / l};
        double rr;
        s->S_kj[q] = cell_integral(in->phase, z, SELF_SUB, 1, in->lt, b, &rr);
        s->S_jP[q] = cell_integral(in->phase, z, SELF_SUB, 1, b, in->ev, &rr);
    }
    return 1;
}

static int pattern3(const atmos__nishita_in *in, double st, double ss, atmos__nishita_pattern *p)
{
    space3 s;
    memset(&s, 0, sizeof s);
    const double h = in->m->h;
    int ok = space3_init(in, &s);
    const long long NN = (long long)s.N * s.N;
    float *c = ok ? malloc(sizeof(float) * (size_t)NN) : NULL;
    ok = ok && c;
    if (ok) {
#pragma omp parallel for schedule(dynamic, 4) num_threads(in->threads)
        for (int jj = 0; jj < s.N; jj++)
            for (int kk = 0; kk < s.N; kk++) {
                double l1, l2;
                const double w = path3(&s, jj, kk, &l1, &l2);
                c[(long long)jj * s.N + kk] = (float)(w * h * h * ss * ss * exp(-st * (l1 + l2) * h));
            }
        int *keep = NULL;
        const int n = select_paths(c, NN, in->ratio, &keep, &p->kept3);
        const size_t m = (size_t)(n > 0 ? n : 1);
        p->o3 = malloc(sizeof(int16_t) * 6 * m);
        p->w3 = malloc(sizeof(float) * m);
        p->r3 = malloc(sizeof(float) * 2 * m);
        ok = n >= 0 && p->o3 && p->w3 && p->r3;
        for (int e = 0; ok && e < n; e++) {
            const int jj = (int)(keep[e] / s.N), kk = (int)(keep[e] % s.N);
            int j[3], d[3];
            double l1, l2;
            decode(jj, s.R, j), decode(kk, s.R, d);
            p->w3[e] = (float)path3(&s, jj, kk, &l1, &l2);
            p->r3[2 * e] = (float)l1, p->r3[2 * e + 1] = (float)l2;
            for (int a = 0; a < 3; a++) p->o3[6 * e + a] = (int16_t)j[a], p->o3[6 * e + 3 + a] = (int16_t)(j[a] + d[a]);
            const int bj = max_abs(j), bk = max_abs((int[3]){j[0] + d[0], j[1] + d[1], j[2] + d[2]});
            if (bj > p->box3) p->box3 = bj;
            if (bk > p->box3) p->box3 = bk;
        }
        p->n3 = ok ? n : 0;
        p->space3 = NN;
        free(keep);
    }
    free(c), free(s.S_kj), free(s.S_jP), free(s.smooth);
    return ok;
}

int atmos__nishita_pattern_build(const atmos__nishita_in *in, double sig_t, double sig_s, atmos__nishita_pattern *p)
{
    memset(p, 0, sizeof *p);
    p->theta_b_deg = beam_spread(in->phase);
    int ok = in->orders < 2 || pattern2(in, sig_t, sig_s, p);
    ok = ok && (in->orders < 3 || pattern3(in, sig_t, sig_s, p));
    if (!ok) atmos__nishita_pattern_free(p);
    return ok;
}

void atmos__nishita_pattern_free(atmos__nishita_pattern *p)
{
    free(p->o2), free(p->w2), free(p->r2), free(p->o3), free(p->w3), free(p->r3);
    memset(p, 0, sizeof *p);
}
