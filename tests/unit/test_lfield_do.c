/* The discrete-ordinates solve of the diffuse light (light/lfield_do.c, docs/lightfield.md "A
 * discrete-ordinates field"): the quadrature integrates the products of the harmonics of degree
 * <= 3 exactly; in a closed conservative cloud the power leaving the grid is the power the first
 * order emitted (nothing is absorbed; one sweep alone, the first order's transport without the
 * scattering, falls far short, so the check can fail); an absorbing cloud loses some; the same
 * bytes with 1 and 2 threads; light entering through the grid's faces (the sky's). */
#include "light/lfield_do.h"
#include "test.h"

#define NC 14
#define LO 2
#define HI 12 /* the cloud: cells LO..HI-1 on every axis */

static void check_quadrature(int nmu, int nphi)
{
    atmos__do_quad q;
    CHECK(atmos__do_quadrature(nmu, nphi, &q));
    double sw = 0, worst = 0;
    for (int n = 0; n < q.n; n++) sw += q.w[n];
    for (int a = 0; a < 16; a++)
        for (int b = 0; b < 16; b++) {
            double s = 0, Y[16];
            for (int n = 0; n < q.n; n++) {
                atmos__sh_eval(3, q.dir[n], Y);
                const double ya = Y[a], yb = Y[b];
                s += q.w[n] * ya * yb;
            }
            worst = fmax(worst, fabs(s - (a == b)));
        }
    printf("  quadrature %d x %d: sum of weights - 4 pi %.1e, worst error of the harmonics' products %.1e\n", nmu,
           nphi, sw - 4 * 3.14159265358979323846, worst);
    CHECK(fabs(sw - 4 * 3.14159265358979323846) < 1e-12);
    CHECK(worst < 1e-12);
}

/* The sweeps' scheme of the checks: 0 the step scheme (theta unset), 1 the renderers' weighted
 * diamond (ATMOS__DO_THETA, ATMOS__DO_THETA_TAU) */
/* the largest difference of the field's moments from a reference's, over the reference's largest */
static double max_rel_diff(const double *phi, const double *ref, size_t n)
{
    double worst = 0, big = 0;
    for (size_t i = 0; i < n; i++) worst = fmax(worst, fabs(phi[i] - ref[i])), big = fmax(big, fabs(ref[i]));
    return big > 0 ? worst / big : INFINITY;
}

static int diamond;

typedef struct {
    float st[NC * NC * NC], ss[NC * NC * NC];
    double q1[NC * NC * NC * 16], phi[NC * NC * NC * 16];
    atmos__do_quad q;
    atmos__do_problem P;
} cloud;

/* A cube of side 10 cells (10 m each) of extinction 0.5 / m (50 optical depths across) and albedo
 * omega in a grid with 2 empty cells around it, its top layer emitting the first order of a sun
 * at the zenith (travelling down), HG g 0.5's moments. */
static void make_cloud(cloud *C, double omega, int threads, int max_iter)
{
    memset(C, 0, sizeof *C);
    atmos__do_quadrature(8, 16, &C->q);
    atmos__do_problem *P = &C->P;
    P->c[0] = P->c[1] = P->c[2] = NC, P->h = 10, P->L = 3;
    P->chi[0] = 1, P->chi[1] = 0.5, P->chi[2] = 0.25, P->chi[3] = 0.125;
    const double down[3] = {0, 0, -1};
    double Y[16];
    atmos__sh_eval(3, down, Y);
    for (int k = 0; k < NC; k++)
        for (int j = 0; j < NC; j++)
            for (int i = 0; i < NC; i++) {
                const size_t c = ((size_t)k * NC + j) * NC + i;
                const int in = i >= LO && i < HI && j >= LO && j < HI && k >= LO && k < HI;
                C->st[c] = in ? 0.5f : 0.0f, C->ss[c] = (float)(C->st[c] * omega);
                for (int m = 0; m < 16 && in && k == HI - 1; m++) {
                    const int l = m >= 9 ? 3 : m >= 4 ? 2 : m >= 1 ? 1 : 0;
                    C->q1[c * 16 + m] = 0.3 * P->chi[l] * Y[m];
                }
            }
    P->sig_t = C->st, P->sig_s = C->ss, P->q1 = C->q1, P->quad = &C->q;
    P->R[0][0] = P->R[1][1] = P->R[2][2] = 1;
    P->tol = 1e-6, P->max_iter = max_iter, P->restart = 30, P->threads = threads, P->leak = 1;
    if (diamond) P->theta = ATMOS__DO_THETA, P->theta_tau = ATMOS__DO_THETA_TAU;
}

static void check_balance(cloud *C)
{
    atmos__do_stats S;
    make_cloud(C, 1.0, 2, 0);
    CHECK(atmos__do_solve(&C->P, C->phi, &S));
    const double one = S.leak / S.emitted;
    make_cloud(C, 1.0, 2, 400);
    CHECK(atmos__do_solve(&C->P, C->phi, &S));
    printf("  closed conservative cloud, 50 optical depths across: leaving / emitted %.6f after %d GMRES "
           "iterations (%d sweeps, residual %.1e); without the scattering's solve (one sweep) %.3f\n",
           S.leak / S.emitted, S.iters, S.sweeps, S.resid, one);
    CHECK(S.emitted > 0);
    CHECK(fabs(S.leak / S.emitted - 1) < 1e-3);
    CHECK(one < 0.9);
    make_cloud(C, 0.9, 2, 400);
    CHECK(atmos__do_solve(&C->P, C->phi, &S));
    printf("  albedo 0.9: leaving / emitted %.4f after %d iterations\n", S.leak / S.emitted, S.iters);
    CHECK(S.leak / S.emitted < 0.9 && S.leak > 0);
}

static void check_threads(cloud *C)
{
    static double phi1[NC * NC * NC * 16];
    atmos__do_stats S;
    make_cloud(C, 1.0, 1, 20);
    CHECK(atmos__do_solve(&C->P, C->phi, &S));
    memcpy(phi1, C->phi, sizeof phi1);
    make_cloud(C, 1.0, 2, 20);
    CHECK(atmos__do_solve(&C->P, C->phi, &S));
    CHECK(!memcmp(phi1, C->phi, sizeof phi1));
    /* from phi = 0 (no restart within 20): the sweep of the first order, one per iteration, the last
       one; the zero start's residual costs none */
    printf("  from 0: %d iterations, %d sweeps\n", S.iters, S.sweeps);
    CHECK(S.sweeps == S.iters + 2);
}

/* The moments of the cells more than one cell from the cloud are left 0 (no scattering and no
 * trilinear read of the field where there is a medium reads them), those next to it not; a start
 * at the solution needs no GMRES iteration (at a tolerance above the single precision's rounding)
 * and gives the same leaving power. */
static void check_needed_and_start(cloud *C)
{
    atmos__do_stats S, S2;
    make_cloud(C, 1.0, 2, 400);
    CHECK(atmos__do_solve(&C->P, C->phi, &S));
    const size_t corner = 0, next = ((size_t)(LO - 1) * NC + LO) * NC + LO; /* (0,0,0); (LO,LO,LO-1) */
    double far = 0, near = 0;
    for (int m = 0; m < 16; m++) far += fabs(C->phi[corner * 16 + m]), near += fabs(C->phi[next * 16 + m]);
    printf("  moments 2 cells from the cloud %.1e, next to it %.3e\n", far, near);
    CHECK(far == 0);
    CHECK(near > 0);
    C->P.tol = 1e-5; /* the sweeps are in single precision: at the solution, their rounding's residual */
    CHECK(atmos__do_solve(&C->P, C->phi, &S2));
    printf("  started at the solution: %d GMRES iterations (residual %.1e), leaving power %.6f of the first "
           "start's\n",
           S2.iters, S2.resid, S2.leak / S.leak);
    CHECK(S2.iters == 0);
    CHECK(fabs(S2.leak / S.leak - 1) < 1e-5);
}

/* The last source iteration from GMRES's own residual (no sweep, the problem's leak 0) gives the
 * moments the last sweep gives (within the sweeps' single precision), one sweep fewer: after 20 iterations without restart, and after
 * 400 (converged) with restarts of 30. */
static void check_last_iteration(cloud *C)
{
    static double phi1[NC * NC * NC * 16];
    for (int t = 0; t < 2; t++) {
        const int max_iter = t ? 400 : 20;
        atmos__do_stats S, S2;
        make_cloud(C, 1.0, 2, max_iter);
        CHECK(atmos__do_solve(&C->P, C->phi, &S));
        memcpy(phi1, C->phi, sizeof phi1);
        make_cloud(C, 1.0, 2, max_iter);
        C->P.leak = 0;
        CHECK(atmos__do_solve(&C->P, C->phi, &S2));
        const double rel = max_rel_diff(C->phi, phi1, NC * NC * NC * 16);
        printf("  the last iteration without a sweep (%d iterations at most): %d sweeps instead of %d, largest "
               "difference %.1e of the largest moment\n",
               max_iter, S2.sweeps, S.sweeps, rel);
        CHECK(rel <= 1e-6); /* the sweeps' single precision */
        CHECK(S2.iters == S.iters && S2.sweeps == S.sweeps - 1);
    }
}

/* Light entering through the grid's faces (the sky's and the ground's, the problem's inflow), no
 * source inside. A conservative cloud under a uniform radiance L from every direction: the
 * radiance is L everywhere, inside the cloud too (its degree-0 moment sqrt(4 pi) L, the others 0;
 * the step scheme's fixed point exactly), and the power leaving is the power entering; without
 * the inflow the moments are 0. The same cloud lit from above alone (a black ground): all that
 * enters leaves (nothing is absorbed), the cloud's bottom darker than its top; albedo 0.9 keeps
 * some. */
static void check_inflow(cloud *C)
{
    double in[ATMOS__DO_NMAX];
    const double L = 2.0, sq = sqrt(4 * 3.14159265358979323846);
    atmos__do_stats S;
    make_cloud(C, 1.0, 2, 400);
    memset(C->q1, 0, sizeof C->q1);
    CHECK(atmos__do_solve(&C->P, C->phi, &S));
    double none = 0;
    for (size_t i = 0; i < NC * NC * NC * 16; i++) none = fmax(none, fabs(C->phi[i]));
    for (int n = 0; n < C->q.n; n++) in[n] = L;
    C->P.inflow = in;
    memset(C->phi, 0, sizeof C->phi);
    CHECK(atmos__do_solve(&C->P, C->phi, &S));
    double worst0 = 0, worst = 0;
    /* the cells the solve keeps the moments of: within one cell of the cloud */
    for (int k = LO - 1; k <= HI; k++)
        for (int j = LO - 1; j <= HI; j++)
            for (int i = LO - 1; i <= HI; i++) {
                const size_t c = ((size_t)k * NC + j) * NC + i;
                worst0 = fmax(worst0, fabs(C->phi[c * 16] / (sq * L) - 1));
                for (int m = 1; m < 16; m++) worst = fmax(worst, fabs(C->phi[c * 16 + m]) / (sq * L));
            }
    printf("  a uniform inflow on a conservative cloud: radiance / L - 1 at worst %.1e, the other moments %.1e; "
           "leaving / entering %.6f (%d iterations); without the inflow the moments %.1e\n",
           worst0, worst, S.leak / S.entering, S.iters, none);
    CHECK(none == 0);
    CHECK(worst0 < 1e-4 && worst < 1e-4);
    CHECK(S.entering > 0 && fabs(S.leak / S.entering - 1) < 1e-4);
    for (int n = 0; n < C->q.n; n++) in[n] = C->q.dir[n][2] < 0 ? L : 0; /* travelling down: the sky */
    for (int t = 0; t < 2; t++) {
        make_cloud(C, t ? 0.9 : 1.0, 2, 400);
        memset(C->q1, 0, sizeof C->q1);
        C->P.inflow = in;
        CHECK(atmos__do_solve(&C->P, C->phi, &S));
        const size_t top = ((size_t)(HI - 1) * NC + NC / 2) * NC + NC / 2, bot = ((size_t)LO * NC + NC / 2) * NC + NC / 2;
        double least = 0; /* the most negative mean radiance of a cell */
        double col = 0; /* the mean radiance down the cloud's central column, below its top layer */
        for (size_t c = 0; c < NC * NC * NC; c++) least = fmin(least, C->phi[c * 16]);
        for (int k = LO; k < HI - 1; k++) col += C->phi[(((size_t)k * NC + NC / 2) * NC + NC / 2) * 16] / (HI - 1 - LO);
        const double rb = C->phi[bot * 16] / C->phi[top * 16], rl = least / C->phi[top * 16],
                     rc = col / C->phi[top * 16];
        printf("  lit from above, albedo %.1f: leaving / entering %.6f (%d iterations); radiance / the top layer's "
               "in the bottom layer %.4f, the central column below the top %.4f, the least of a cell %.4f\n",
               t ? 0.9 : 1.0, S.leak / S.entering, S.iters, rb, rc, rl);
        CHECK(S.entering > 0);
        if (!t) CHECK(fabs(S.leak / S.entering - 1) < 1e-3);
        else CHECK(S.leak / S.entering < 0.9);
        CHECK(rb < 0.5 && rc > 0);
        /* the step scheme is positive; the diamond is not (its cells of 5 optical depths at theta
           0.503): at albedo 0.9 the central column's mean radiance alternates in sign from layer to
           layer about its small mean (the bottom -0.0015 of the top's), the most negative cell (a
           bottom corner's neighbour) -0.095 of the top's; the eye pass clamps the field at 0
           (docs/lightfield.md, "The step scheme in thick cells") */
        if (diamond) CHECK(rl > -0.15 && rb > -0.01);
        else CHECK(rl == 0 && rb > 0);
    }
}

/* The diffusion preconditioner (lfield_dsa.h): on the closed cube of 50 optical depths, conservative
 * and at albedo 0.99, with the sky's inflow too, the preconditioned solve reaches the plain one's
 * moments (both to a residual of 1e-6) in fewer than half its sweeps; the same bytes with 1 and 2
 * threads. */
static void check_dsa(cloud *C)
{
    static double plain[NC * NC * NC * 16], one[NC * NC * NC * 16];
    double in[ATMOS__DO_NMAX];
    for (int n = 0; n < C->q.n; n++) in[n] = C->q.dir[n][2] < 0 ? 1.0 : 0; /* q's: make_cloud's */
    for (int t = 0; t < 3; t++) {
        const double omega = t == 1 ? 0.99 : 1.0;
        atmos__do_stats S, S2;
        make_cloud(C, omega, 2, 2000);
        C->P.inflow = t == 2 ? in : NULL;
        CHECK(atmos__do_solve(&C->P, C->phi, &S));
        memcpy(plain, C->phi, sizeof plain);
        for (int th = 1; th <= 2; th++) {
            make_cloud(C, omega, th, 2000);
            C->P.inflow = t == 2 ? in : NULL, C->P.dsa = 1;
            CHECK(atmos__do_solve(&C->P, C->phi, &S2));
            if (th == 1) memcpy(one, C->phi, sizeof one);
        }
        CHECK(!memcmp(one, C->phi, sizeof one));
        const double rel = max_rel_diff(C->phi, plain, NC * NC * NC * 16);
        printf("  the diffusion preconditioner, albedo %.2f%s: %d sweeps (%d GMRES iterations, %d of the "
               "diffusion's) against %d plain, largest difference %.1e of the largest moment, leaving power "
               "%.6f of the plain one's\n",
               omega, t == 2 ? ", the sky's inflow" : "", S2.sweeps, S2.iters, S2.dsa_iters, S.sweeps, rel,
               S2.leak / S.leak);
        CHECK(S2.resid <= 1e-6 && S.resid <= 1e-6);
        CHECK(rel <= 1e-4);
        CHECK(fabs(S2.leak / S.leak - 1) < 1e-5);
        CHECK(2 * S2.sweeps < S.sweeps);
        CHECK(S.dsa_at == -1 && S2.dsa_at == 0);
    }
}

/* The preconditioner's switch (ATMOS__DO_DSA_AUTO): on the thick cube (conservative) plain GMRES's
 * rate soon predicts more than ATMOS__DO_DSA_AFTER iterations, the preconditioner comes on and the
 * solve takes fewer sweeps than the plain one, to its moments; the cube 100 times thinner converges
 * fast, the switch stays off and the bytes are the plain solve's. The same bytes with 1 and 2 threads. */
static void check_dsa_switch(cloud *C)
{
    static double plain[NC * NC * NC * 16];
    for (int t = 0; t < 2; t++) {
        atmos__do_stats S, S2;
        make_cloud(C, 1.0, 2, 2000);
        for (size_t c = 0; c < NC * NC * NC && t; c++) C->st[c] *= 0.01f, C->ss[c] *= 0.01f;
        CHECK(atmos__do_solve(&C->P, C->phi, &S));
        memcpy(plain, C->phi, sizeof plain);
        memset(C->phi, 0, sizeof plain);
        C->P.dsa = ATMOS__DO_DSA_AUTO;
        CHECK(atmos__do_solve(&C->P, C->phi, &S2));
        const double rel = max_rel_diff(C->phi, plain, NC * NC * NC * 16);
        printf("  the preconditioner's switch, %s cube: on after %d GMRES iterations, %d sweeps against %d "
               "plain, largest difference %.1e of the largest moment\n",
               t ? "the thin" : "the thick", S2.dsa_at, S2.sweeps, S.sweeps, rel);
        CHECK(S2.resid <= 1e-6 && rel < INFINITY);
        if (t) CHECK(S2.dsa_at == -1 && S2.dsa_iters == 0 && !memcmp(plain, C->phi, sizeof plain));
        else CHECK(S2.dsa_at >= 3 && S2.sweeps < S.sweeps && rel <= 1e-4);
        if (t) continue;
        memcpy(plain, C->phi, sizeof plain); /* one thread: the same switch, the same bytes */
        make_cloud(C, 1.0, 1, 2000);
        C->P.dsa = ATMOS__DO_DSA_AUTO;
        CHECK(atmos__do_solve(&C->P, C->phi, &S) && S.dsa_at == S2.dsa_at && !memcmp(plain, C->phi, sizeof plain));
    }
}

/* Source iterations instead of GMRES (the problem's richardson) in an optically thin cube (its
 * extinction scaled down, the sky's inflow from above too): one sweep from 0, and one from a warm
 * start (the solution for half the emission and the inflow: its error half the field), against
 * GMRES to 1e-9; the moments' largest error within atmos__do_rho's bound times the start's (so
 * the bound holds), but for float rounding; and one sweep is not the answer where the medium is
 * not thin (the check can fail: the cube x 5e-3, rho 7.6, 5 % off; the bound about 150 times the
 * error measured). */
static void check_richardson(cloud *C)
{
    static double ref[NC * NC * NC * 16];
    double in[ATMOS__DO_NMAX], half[ATMOS__DO_NMAX];
    const double scales[3] = {1e-6, 1e-4, 5e-3};
    for (int t = 0; t < 3; t++) {
        atmos__do_stats S;
        make_cloud(C, 0.9, 2, 400);
        for (size_t c = 0; c < NC * NC * NC; c++) C->st[c] *= (float)scales[t], C->ss[c] *= (float)scales[t];
        for (int n = 0; n < C->q.n; n++) in[n] = C->q.dir[n][2] < 0 ? 1e-3 : 0, half[n] = 0.5 * in[n];
        C->P.inflow = in, C->P.tol = 1e-9;
        CHECK(atmos__do_solve(&C->P, C->phi, &S));
        memcpy(ref, C->phi, sizeof ref);
        const double rho = atmos__do_rho(&C->P);
        C->P.richardson = 1;
        memset(C->phi, 0, sizeof C->phi);
        CHECK(atmos__do_solve(&C->P, C->phi, &S) && S.sweeps == 1 && S.iters == 0);
        const double e0 = max_rel_diff(C->phi, ref, NC * NC * NC * 16);
        /* the warm start: the field of half the emission and the inflow */
        for (size_t i = 0; i < NC * NC * NC * 16; i++) C->q1[i] *= 0.5;
        C->P.inflow = half, C->P.richardson = 0;
        memset(C->phi, 0, sizeof C->phi);
        CHECK(atmos__do_solve(&C->P, C->phi, &S));
        for (size_t i = 0; i < NC * NC * NC * 16; i++) C->q1[i] *= 2;
        C->P.inflow = in, C->P.richardson = 1;
        const double start = max_rel_diff(C->phi, ref, NC * NC * NC * 16);
        CHECK(atmos__do_solve(&C->P, C->phi, &S) && S.sweeps == 1);
        const double ew = max_rel_diff(C->phi, ref, NC * NC * NC * 16);
        printf("  thin cube x %.0e (rho %.1e): one sweep from 0 %.1e from the field, from a start %.2f off %.1e\n",
               scales[t], rho, e0, start, ew);
        CHECK(e0 <= rho + 1e-6 && ew <= rho * start + 1e-6);
        if (t == 2) CHECK(rho > 0.5 && e0 > 0.01);
    }
}

int main(void)
{
    check_quadrature(8, 16);
    check_quadrature(4, 8);
    cloud *C = malloc(sizeof *C);
    CHECK(C != NULL);
    /* the sanitizer copy (TEST_SANITIZED, test.h: there for memory errors) the renderers' weighted
       diamond alone: the step scheme is the same code but for its faces' arithmetic */
    for (diamond = TEST_SANITIZED; diamond < 2 && C; diamond++) {
        printf("%s\n", diamond ? "the renderers' weighted diamond:" : "the step scheme:");
        check_balance(C), check_threads(C), check_needed_and_start(C), check_last_iteration(C), check_inflow(C);
        check_dsa(C), check_dsa_switch(C), check_richardson(C);
    }
    free(C);
    return test_summary("test_lfield_do");
}
