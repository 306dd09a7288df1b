/* Analytic phase functions and their importance sampling: isotropic, Rayleigh,
 * Henyey-Greenstein, Cornette-Shanks, and weighted mixtures of them.
 *
 * Normalisation: every function here is in sr^-1 with integral over the sphere = 1
 * (DESIGN.md §8). The papers normalise differently and are converted here:
 *  - Harris 2002 Eq. 3, p = 3/4 (1 + mu^2), integrates to 4 pi; we use Riley Eq. 1,
 *    3/(16 pi) (1 + mu^2) = Harris / (4 pi), through atmos_phase_rayleigh().
 *  - Harris 2002 Eq. 4 (Henyey-Greenstein) already carries the 1/(4 pi): unchanged.
 *  - Nishita et al. 1996 Eq. 5 (Cornette-Shanks) integrates to 4 pi; divided by 4 pi.
 *
 * Invalid parameters never produce NaN: a scalar function given g outside (-1, 1) or a
 * non-finite argument returns 0; an invalid mixture (see mixture_valid) evaluates to 0,
 * has pdf 0 and samples isotropically.
 */
#include "core/internal.h"
#include "core/rng.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#define INV_4PI (1.0 / (4.0 * ATMOS_PI))

static double clamp_mu(double mu) { return mu < -1.0 ? -1.0 : mu > 1.0 ? 1.0 : mu; }

static int g_valid(double g) { return isfinite(g) && g > -1.0 && g < 1.0; }

/* 1 + g^2 - 2 g mu written as a sum of two non-negative terms, (1 - g)^2 + 2g(1 - mu)
 * for g >= 0 and (1 + g)^2 - 2g(1 + mu) for g < 0: no cancellation as |g| -> 1, where
 * the naive form rounds to 0 at mu = +-1 (g = 1 - 1e-12 gives Inf instead of ~1e24). */
static double hg_denominator(double g, double mu)
{
    return g >= 0.0 ? (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - mu) : (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + mu);
}

double atmos_phase_hg(double cos_theta, double g)
{
    if (!g_valid(g) || isnan(cos_theta)) return 0.0;
    double mu = clamp_mu(cos_theta);
    /* d >= (1 - |g|)^2 > 0 for |g| < 1, so no division by zero. */
    double d = hg_denominator(g, mu);
    return INV_4PI * (1.0 - g) * (1.0 + g) / (d * sqrt(d));
}

double atmos_phase_cornette_shanks(double cos_theta, double g)
{
    if (!g_valid(g) || isnan(cos_theta)) return 0.0;
    double mu = clamp_mu(cos_theta);
    double d = hg_denominator(g, mu);
    /* Nishita Eq. 5 / (4 pi). */
    return 3.0 * (1.0 - g) * (1.0 + g) * (1.0 + mu * mu) / (8.0 * ATMOS_PI * (2.0 + g * g) * d * sqrt(d));
}

/* A mixture is valid when it has 1..ATMOS_PHASE_MAX_LOBES lobes of known kinds, finite
 * weights >= 0 that do not sum to 0, and g in (-1, 1) for the HG and CS lobes. */
static int mixture_valid(const atmos_phase_mixture *p, double *wsum)
{
    if (!p || p->count < 1 || p->count > ATMOS_PHASE_MAX_LOBES) return 0;
    double s = 0.0;
    for (int i = 0; i < p->count; i++) {
        double w = p->weight[i];
        if (!isfinite(w) || w < 0.0) return 0;
        switch (p->kind[i]) {
        case ATMOS_PHASE_ISOTROPIC:
        case ATMOS_PHASE_RAYLEIGH: break;
        case ATMOS_PHASE_HG:
        case ATMOS_PHASE_CORNETTE_SHANKS:
            if (!g_valid(p->g[i])) return 0;
            break;
        default: return 0;
        }
        s += w;
    }
    if (!(s > 0.0) || !isfinite(s)) return 0;
    *wsum = s;
    return 1;
}

static double lobe_eval(atmos_phase_kind kind, double g, double mu)
{
    switch (kind) {
    case ATMOS_PHASE_ISOTROPIC: return INV_4PI;
    case ATMOS_PHASE_RAYLEIGH: return atmos_phase_rayleigh(mu);
    case ATMOS_PHASE_HG: return atmos_phase_hg(mu, g);
    case ATMOS_PHASE_CORNETTE_SHANKS: return atmos_phase_cornette_shanks(mu, g);
    }
    return 0.0;
}

double atmos_phase_mixture_eval(const atmos_phase_mixture *p, double cos_theta)
{
    double wsum;
    if (!mixture_valid(p, &wsum) || isnan(cos_theta)) return 0.0;
    double mu = clamp_mu(cos_theta), s = 0.0;
    for (int i = 0; i < p->count; i++)
        if (p->weight[i] > 0.0) s += p->weight[i] * lobe_eval(p->kind[i], p->g[i], mu);
    return s / wsum;
}

double atmos_phase_mixture_pdf(const atmos_phase_mixture *p, double cos_theta)
{
    /* Every sampler below is exact, so the pdf per steradian is the function itself. */
    return atmos_phase_mixture_eval(p, cos_theta);
}

/* ---------------------------------------------------------------- samplers */

static double clamp_u(double u)
{
    if (!(u >= 0.0)) return 0.0; /* also NaN */
    if (u >= 1.0) return 0x1.fffffffffffffp-1;
    return u;
}

/* Rayleigh: the pdf of mu is 3/8 (1 + mu^2); its CDF 3/8 (mu + mu^3/3) + 1/2 = u gives
 * the depressed cubic mu^3 + 3 mu - 2 z = 0 with z = 4u - 2. Its discriminant is
 * positive, so Cardano's formula gives the one real root mu = A - 1/A with
 * A = cbrt(z + sqrt(z^2 + 1)). The root is odd in z; computing it for |z| avoids the
 * cancellation in z + sqrt(z^2 + 1) for negative z. */
static double sample_rayleigh(double u)
{
    double z = 4.0 * u - 2.0, az = fabs(z);
    double a = cbrt(az + sqrt(az * az + 1.0));
    double mu = a - 1.0 / a;
    return clamp_mu(z < 0 ? -mu : mu);
}

/* Henyey-Greenstein by exact inversion of its CDF. The textbook form
 * mu = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2) / (2 g) divides by g; expanding it
 * with xi = 2u - 1 gives the algebraically identical
 * mu = (xi + g (3 + xi^2 + 2 g xi + g^2 xi^2 - g^2) / 2) / (1 + g xi)^2,
 * which is exact at g = 0 (mu = xi, isotropic) and needs no small-g special case. */
static double sample_hg(double g, double u)
{
    double xi = 2.0 * u - 1.0;
    double d = 1.0 + g * xi;
    if (!(d > 0.0)) return xi < 0 ? -1.0 : 1.0; /* only reachable for |g| -> 1 at the very end */
    double num = xi + 0.5 * g * (3.0 + xi * xi + 2.0 * g * xi + g * g * xi * xi - g * g);
    return clamp_mu(num / (d * d));
}

/* A SplitMix64 stream (core/rng.h) of extra uniforms for the rejection loop, derived
 * from the caller's numbers so sampling stays a pure function of them. */
static double next_uniform(uint64_t *s) { return atmos__u01(atmos__splitmix64(s)); }

/* Cornette-Shanks by rejection from Henyey-Greenstein with the same g:
 * CS / HG = 3 (1 + mu^2) / (2 (2 + g^2)) <= 3 / (2 + g^2), so a HG candidate is kept with
 * probability (1 + mu^2) / 2; the acceptance rate is (1 + <mu^2>_HG) / 2 >= 1/2.
 * The first trial uses the caller's two independent uniforms (ua, ub); further trials
 * draw from SplitMix64 seeded by their bits. */
static double sample_cs(double g, double ua, double ub)
{
    double mu = sample_hg(g, ub);
    if (ua < 0.5 * (1.0 + mu * mu)) return mu;
    uint64_t ba, bb;
    memcpy(&ba, &ua, sizeof ba);
    memcpy(&bb, &ub, sizeof bb);
    uint64_t s = ba ^ (bb * 0x9e3779b97f4a7c15ull) ^ 0x5851f42d4c957f2dull;
    /* P(64 rejections) <= 2^-64: the cap only guarantees termination. */
    for (int i = 0; i < 64; i++) {
        mu = sample_hg(g, next_uniform(&s));
        if (next_uniform(&s) < 0.5 * (1.0 + mu * mu)) return mu;
    }
    return mu;
}

static double sample_lobe(atmos_phase_kind kind, double g, double ua, double ub)
{
    switch (kind) {
    case ATMOS_PHASE_ISOTROPIC: return clamp_mu(1.0 - 2.0 * ub);
    case ATMOS_PHASE_RAYLEIGH: return sample_rayleigh(ub);
    case ATMOS_PHASE_HG: return sample_hg(g, ub);
    case ATMOS_PHASE_CORNETTE_SHANKS: return sample_cs(g, ua, ub);
    }
    return 1.0;
}

double atmos_phase_mixture_sample(const atmos_phase_mixture *p, double u1, double u2)
{
    u1 = clamp_u(u1);
    u2 = clamp_u(u2);
    double wsum;
    if (!mixture_valid(p, &wsum)) return clamp_mu(1.0 - 2.0 * u2);
    /* Pick lobe i with probability w_i / sum(w) from u1; the position of u1 inside the
     * chosen lobe's interval, rescaled to [0, 1), is again uniform and independent of
     * u2, so the lobe may use it as a second number (Cornette-Shanks rejection does). */
    double target = u1 * wsum, acc = 0.0;
    int last = -1;
    for (int i = 0; i < p->count; i++) {
        double w = p->weight[i];
        if (w <= 0.0) continue;
        last = i;
        if (target < acc + w) {
            double ua = clamp_u((target - acc) / w);
            return sample_lobe(p->kind[i], p->g[i], ua, u2);
        }
        acc += w;
    }
    /* Rounding put target at the very end: the last lobe with weight. */
    return sample_lobe(p->kind[last], p->g[last], 0x1.fffffffffffffp-1, u2);
}

/* Riley et al. 2004 Eq. 1: the Rayleigh phase function of air molecules, sr^-1. */
double atmos_phase_rayleigh(double cos_theta) { return 3.0 / (16.0 * ATMOS_PI) * (1.0 + cos_theta * cos_theta); }
