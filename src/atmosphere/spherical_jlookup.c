/* The look-up of the production sky's scattering density of the higher orders J_ms
 * (spherical.h; built by spherical_ms.c, whose header states the parametrization): the
 * mappings of its coordinates, and the quadrilinear interpolation of its logarithm that the
 * march reads at every step. */
#include "atmosphere/spherical.h"
#include "core/clones.h"
#include "core/vec.h"

#include <math.h>

#define JR ATMOS__SPH_J_R
#define JS ATMOS__SPH_J_MUS
#define JG ATMOS__SPH_J_G
#define JP ATMOS__SPH_J_P
#define GA ATMOS__SPH_J_GA
#define MUS_LO (-0.3) /* the columns' lowest sun (17.5 degrees below the horizon) */
#define XS 0.4404240774995806 /* sqrt(asin(0.3) / (pi / 2)): u of the lowest column */
#define JFADE 60.0 /* J's decay per unit of mu_s below the lowest column (e^-6 at -0.4) */
#define JFLOOR ATMOS__SPH_J_FLOOR

/* ------------------------------------------------------------------ mappings */
#define GE ATMOS__SPH_J_GE
#define GC (GE + GA - 2.0)      /* the cubic's coefficients: gamma(1) = pi, */
#define GB (1.0 - GA - GC)     /* slopes GA and GE at the ends */
double atmos__sph_j_x_to_gamma(double x) { return ATMOS_PI * x * (GA + x * (GB + x * GC)); }
/* The inverse by Newton's method from x = gamma / pi (the slope stays >= min(GA, GE)). */
static double gamma_to_x(double g)
{
    const double u = atmos__clampd(g / ATMOS_PI, 0.0, 1.0);
    double x = u;
    for (int it = 0; it < 6; it++) {
        const double f = x * (GA + x * (GB + x * GC)) - u, df = GA + x * (2.0 * GB + 3.0 * x * GC);
        x = atmos__clampd(x - f / df, 0.0, 1.0);
    }
    return x;
}
/* The sun columns: u = sign(e) sqrt(|e| / (pi / 2)) of the sun's elevation e, uniform in
 * u from the lowest column to the zenith (spherical_ms.c). */
static double mus_x(double mus)
{
    const double e = asin(atmos__clampd(mus, -1, 1)), u = copysign(sqrt(fabs(e) / (0.5 * ATMOS_PI)), e);
    return atmos__clampd((u + XS) / (1.0 + XS), 0.0, 1.0);
}
double atmos__sph_j_x_mus(double x)
{
    const double u = -XS + (1.0 + XS) * x;
    return sin(0.5 * ATMOS_PI * u * fabs(u));
}

/* ------------------------------------------------------------------ look-up */
void atmos__sph_j_gamma(double nu, atmos__sph_jg *g)
{
    const double gm = acos(atmos__clampd(nu, -1.0, 1.0));
    const double f = gamma_to_x(gm) * (JG - 1);
    int i = (int)f;
    if (i > JG - 2) i = JG - 2;
    g->i = i, g->a = f - i;
    g->cg = nu, g->sg = sin(gm);
}

ATMOS_CLONES void atmos__sph_j(const atmos__sph_model *m, double r, double mu, double mus, const atmos__sph_jg *g,
                               int cnt, const int *k, double *jr, double *jm)
{
    const int n = m->n;
    const double xr = sqrt(atmos__clampd((r - m->R) / (m->Rt - m->R), 0.0, 1.0)) * (JR - 1);
    const double xs = mus_x(mus) * (JS - 1);
    const double den = g->sg * sqrt(fmax(0.0, 1.0 - mus * mus));
    const double cp = den > 1e-9 ? atmos__clampd((mu - mus * g->cg) / den, -1.0, 1.0) : 1.0;
    const double xp = 0.5 * (1.0 - cp) * (JP - 1);
    int ir = (int)xr, is = (int)xs, ip = (int)xp;
    if (ir > JR - 2) ir = JR - 2;
    if (is > JS - 2) is = JS - 2;
    if (ip > JP - 2) ip = JP - 2;
    const double ar = xr - ir, as = xs - is, ap = xp - ip, ag = g->a;
    const double wr[2] = {1 - ar, ar}, ws[2] = {1 - as, as}, wg[2] = {1 - ag, ag};
    /* the table's strides; the two psi nodes of a corner are adjacent */
    const size_t sp = 2 * (size_t)n, sg = JP * sp, ss = JG * sg, sr = JS * ss;
    const float *base = m->jms + (size_t)ir * sr + (size_t)is * ss + (size_t)g->i * sg + (size_t)ip * sp;
    double acc[2 * ATMOS_MAX_WAVELENGTHS];
    for (int i = 0; i < 2 * cnt; i++) acc[i] = 0.0;
    for (int c = 0; c < 8; c++) { /* the (r, mu_s, gamma) corners, each with its two psi nodes */
        const int br = c & 1, bs = (c >> 1) & 1, bg = (c >> 2) & 1;
        const double w = wr[br] * ws[bs] * wg[bg], w0 = w * (1 - ap), w1 = w * ap;
        const float *t = base + br * sr + bs * ss + bg * sg;
        if (!k) /* all wavelengths: one contiguous run of (air, aerosols) pairs */
            for (int i = 0; i < 2 * cnt; i++) acc[i] += w0 * t[i] + w1 * t[i + sp];
        else
            for (int i = 0; i < cnt; i++)
                for (int part = 0; part < 2; part++) {
                    const size_t o = 2 * (size_t)k[i] + part;
                    acc[2 * i + part] += w0 * t[o] + w1 * t[o + sp];
                }
    }
    /* below the lowest column a steep fade, not the column's light: the night side keeps
     * its darkness (the night lights stay the brightest thing there) */
    const double fade = mus < MUS_LO ? exp(-JFADE * (MUS_LO - mus)) : 1.0;
    for (int i = 0; i < cnt; i++) jr[i] = (exp(acc[2 * i]) - JFLOOR) * fade, jm[i] = (exp(acc[2 * i + 1]) - JFLOOR) * fade;
}

