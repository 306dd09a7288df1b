/* Multiple-scattering phase functions of the real particle presets against an
 * independent method: Monte Carlo random walks with exactly n scatterings whose
 * directions are drawn from the same phase table (Riley et al. 2004 Eq. 20). */
#include "atmos/atmos.h"
#include "test.h"

#include <stdint.h>

#define PI 3.14159265358979323846

static uint64_t rng_state;
static double rnd(void)
{
    /* splitmix64 */
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (z >> 11) * (1.0 / 9007199254740992.0);
}

/* Rotates unit d by polar angle acos(mu) and azimuth phi about itself. */
static void scatter(double d[3], double mu, double phi)
{
    double s = sqrt(fmax(0.0, 1 - mu * mu)), cp = cos(phi), sp = sin(phi);
    double a[3] = {1, 0, 0};
    if (fabs(d[0]) > 0.9) a[0] = 0, a[1] = 1;
    double u[3] = {d[1] * a[2] - d[2] * a[1], d[2] * a[0] - d[0] * a[2], d[0] * a[1] - d[1] * a[0]};
    double un = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int i = 0; i < 3; i++) u[i] /= un;
    double v[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]};
    double r[3];
    for (int i = 0; i < 3; i++) r[i] = mu * d[i] + s * (cp * u[i] + sp * v[i]);
    double rn = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int i = 0; i < 3; i++) d[i] = r[i] / rn;
}

/* Integral of Ams_n over theta in [a, b] degrees (2 pi sin theta dtheta), trapezoid on
 * the msphase grid with linear interpolation at the ends. */
static double ams_bin(const atmos_msphase *m, int n, double a, double b)
{
    const int steps = 400;
    double s = 0;
    for (int i = 0; i < steps; i++) {
        double t0 = (a + (b - a) * i / steps) * PI / 180, t1 = (a + (b - a) * (i + 1) / steps) * PI / 180;
        double f0 = atmos_msphase_eval(m, 0, n, cos(t0)) * sin(t0), f1 = atmos_msphase_eval(m, 0, n, cos(t1)) * sin(t1);
        s += 0.5 * (f0 + f1) * (t1 - t0);
    }
    return 2 * PI * s;
}

static void check_preset(const char *name, atmos_context *ctx)
{
    atmos_particle_desc p;
    CHECK_OK(atmos_particle_preset(ctx, name, &p));
    p.fast = 1;
    atmos_wavelengths wl;
    atmos_wavelengths_spectral(1, &wl); /* one wavelength (580 nm) keeps the test quick */
    atmos_phase_table *t = NULL;
    atmos_phase_table_desc td = {1};
    CHECK_OK(atmos_phase_table_build(ctx, &p, &wl, &td, &t));
    if (!t) return;
    atmos_msphase *m = NULL;
    atmos_msphase_desc md = {0};
    md.no_cache = 1;
    CHECK_OK(atmos_msphase_build(ctx, t, &md, &m));
    if (!m) {
        atmos_phase_table_destroy(t);
        return;
    }
    int N = atmos_msphase_max_order(m);
    const double *grid;
    int ng = atmos_msphase_grid(m, &grid);
    /* every order integrates to 1; the last is isotropic */
    double worst = 0;
    for (int n = 1; n <= N; n++) {
        const double *v = atmos_msphase_values(m, 0, n);
        double s = 0;
        for (int j = 0; j + 1 < ng; j++) {
            double a = grid[j] * PI / 180, b = grid[j + 1] * PI / 180;
            s += 0.5 * (v[j] * sin(a) + v[j + 1] * sin(b)) * (b - a);
        }
        worst = fmax(worst, fabs(2 * PI * s - 1));
    }
    CHECK_MSG(worst <= 1e-4, "%s: worst |integral - 1| over %d orders = %.3g", name, N, worst);
    /* a distribution of directions is never negative (series ringing would show here) */
    int negative = 0;
    for (int n = 1; n <= N; n++) {
        const double *v = atmos_msphase_values(m, 0, n);
        for (int j = 0; j < ng; j++) negative += v[j] < -1e-9 * v[0];
    }
    CHECK_MSG(negative == 0, "%s: %d negative values", name, negative);
    const double *vN = atmos_msphase_values(m, 0, N);
    double iso = 0;
    for (int j = 0; j < ng; j++) iso = fmax(iso, fabs(4 * PI * vN[j] - 1));
    CHECK_MSG(iso < 2e-6, "%s: order %d deviates from isotropy by %.3g", name, N, iso);
    /* F_1 against the forward-hemisphere integral of the table, computed here */
    const double *theta;
    int nt = atmos_phase_grid(&theta);
    const double *P = atmos_phase_table_values(t, 0);
    double fwd = 0;
    for (int i = 0; i + 1 < nt && theta[i] < 90.0; i++) {
        double a = theta[i] * PI / 180, b = fmin(theta[i + 1], 90.0) * PI / 180;
        double pb = theta[i + 1] <= 90.0 ? P[i + 1] : P[i] + (P[i + 1] - P[i]) * (90.0 - theta[i]) / (theta[i + 1] - theta[i]);
        fwd += 0.5 * (P[i] * sin(a) + pb * sin(b)) * (b - a);
    }
    fwd *= 2 * PI;
    CHECK_MSG(fabs(atmos_msphase_forward(m, 0, 1) - fwd) < 2e-4, "%s: F_1 %.6f, table integral %.6f", name,
              atmos_msphase_forward(m, 0, 1), fwd);
    CHECK_NEAR(atmos_msphase_forward(m, 0, N), 0.5, 1e-5);
    printf("%s: max order %d, %d Legendre terms, F_1 %.5f (table %.5f), F_2 %.5f, F_10 %.5f\n", name, N,
           atmos_msphase_legendre_count(m, 0), atmos_msphase_forward(m, 0, 1), fwd, atmos_msphase_forward(m, 0, 2),
           atmos_msphase_forward(m, 0, 10));

    /* Monte Carlo: walks of exactly n scatterings, histogram of the angle to the beam. */
    static const double edges[] = {0, 0.05, 0.2, 0.5, 1, 2, 3, 5, 8, 12, 17, 23, 30, 40, 50, 60, 75, 90, 105, 120, 135, 150, 165, 180};
    const int nb = (int)(sizeof edges / sizeof *edges) - 1;
    const int orders[] = {1, 2, 5, 10};
#if defined(__SANITIZE_ADDRESS__)
    const long walks = 20000; /* the sanitizer twin: same paths, less work (chi2 scales with the counts) */
#else
    const long walks = 100000;
#endif
    for (int o = 0; o < 4; o++) {
        int n = orders[o];
        if (n > N) continue;
        long hist[32] = {0};
        rng_state = 12345u + (uint64_t)n * 7919u;
        for (long w = 0; w < walks; w++) {
            double d[3] = {0, 0, 1};
            for (int s = 0; s < n; s++) scatter(d, atmos_phase_table_sample(t, 0, rnd()), 2 * PI * rnd());
            double th = acos(fmax(-1.0, fmin(1.0, d[2]))) * 180 / PI;
            int b = 0;
            while (b + 1 < nb && th >= edges[b + 1]) b++;
            hist[b]++;
        }
        double chi2 = 0, worst_z = 0;
        int dof = 0;
        for (int b = 0; b < nb; b++) {
            double expect = walks * ams_bin(m, n, edges[b], edges[b + 1]);
            if (expect < 20) continue; /* too few for the normal approximation */
            double z = (hist[b] - expect) / sqrt(expect);
            chi2 += z * z;
            dof++;
            worst_z = fmax(worst_z, fabs(z));
        }
        printf("  n = %2d: chi2 = %.1f over %d bins, worst |z| = %.2f\n", n, chi2, dof, worst_z);
        /* chi2 with dof degrees of freedom: mean dof, sd sqrt(2 dof); allow 4 sd */
        CHECK_MSG(chi2 < dof + 4 * sqrt(2.0 * dof) + 5, "%s n=%d: chi2 %.1f over %d bins", name, n, chi2, dof);
        CHECK_MSG(worst_z < 5, "%s n=%d: a bin is off by %.1f sigma", name, n, worst_z);
    }
    atmos_msphase_destroy(m);
    atmos_phase_table_destroy(t);
}

int main(void)
{
    atmos_context *ctx = NULL;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    CHECK_OK(atmos_context_create(&d, &ctx));
    check_preset("cloud", ctx);
    check_preset("rain", ctx);
    check_preset("ice", ctx);
    atmos_context_destroy(ctx);
    return test_summary("test_msphase");
}
