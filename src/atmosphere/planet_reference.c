/* Ground truth for the spherical kinds (atmos_atmosphere_reference_radiance, docs/sky.md
 * "The reference"): Monte Carlo random walks from the eye through the planet's air (the
 * planet description only, never a solver's tables), one wavelength per walk.
 *
 * A walk starts at the eye (moved to where the view ray enters the air when it is outside)
 * and repeats: the sunlight scattered once toward the walk by the air of its segment to the
 * ground or the top (one importance-sampled point, its transmittances by quadrature,
 * planet_segment.c: the walk's next-event estimation of the sun, made along the segment rather
 * than at a collision), then a free flight by delta tracking of the extinction
 * (planet_track.c) to the first real collision, the ground, or the top;
 *  - in the air: the weight is multiplied by the single-scattering albedo there
 *    (sigma_s / sigma_t: aerosol and ozone absorption) and a new direction is
 *    drawn from the Rayleigh / aerosol mixture (a component in proportion to its
 *    scattering, Rayleigh's 3/(16 pi)(1 + cos^2) by exact inversion of its cubic CDF, the
 *    aerosols' from their tabulated CDF);
 *  - on the ground: its emission is counted, the sun estimated (albedo / pi cos E T), the
 *    weight multiplied by the albedo and a direction drawn from the cosine distribution;
 *  - at the top: the walk ends (no light comes from space but the sun, which as a
 *    directional light only next-event estimation can reach).
 * Every event (air or ground) is one order of scattering; max_order stops the walk after
 * that many. Russian roulette on weights below 0.1 (the weight never exceeds 1).
 *
 * Determinism: walk i of wavelength k draws from the counter-based stream (seed, k, i);
 * the walks are summed in fixed blocks, and the blocks in their order, whatever the
 * threads. */
#include "atmosphere/planet_solver.h"
#include "atmosphere/planet_track.h"

#include "core/vec.h"

#include <stdlib.h>
#include <string.h>

/* Weight below which the roulette plays, and the weight a survivor takes. */
#define RR_WEIGHT 0.1
/* Events per walk beyond which it is cut (a conservative atmosphere over a white ground
 * has walks of a few tens of events). */
#define MAX_EVENTS 100000
/* Blocks of walks summed apart (the unit of the threads' work). */
#define NBLOCK 64

/* A unit vector at cosine mu and azimuth phi about the unit vector n. */
static void around(const double n[3], double mu, double phi, double out[3])
{
    double t[3], b[3];
    const double a[3] = {fabs(n[0]) < 0.6 ? 1.0 : 0.0, fabs(n[0]) < 0.6 ? 0.0 : 1.0, 0.0};
    atmos__cross3(n, a, t);
    atmos__normalize3(t);
    atmos__cross3(n, t, b);
    const double s = sqrt(fmax(0.0, 1.0 - mu * mu)), c = cos(phi), sn = sin(phi);
    for (int i = 0; i < 3; i++) out[i] = mu * n[i] + s * (c * t[i] + sn * b[i]);
    atmos__normalize3(out);
}

/* cos theta drawn from Rayleigh's phase function: F(mu) = (4 + 3 mu + mu^3) / 8 = u, the
 * real root of mu^3 + 3 mu - z = 0 (z = 8u - 4) by Cardano: mu = A - 1/A,
 * A^3 = z/2 + sqrt(z^2/4 + 1). */
static double rayleigh_sample(double u)
{
    const double z = 8.0 * u - 4.0, A = cbrt(0.5 * z + sqrt(0.25 * z * z + 1.0));
    const double mu = A - 1.0 / A;
    return mu > 1 ? 1 : (mu < -1 ? -1 : mu);
}

/* A scattering in the air at p (reached along d with weight *w; the sunlight scattered here
 * is counted along the segment, by atmos__planet_segment_sun). Returns 0 when the walk ends. */
static int air_event(const atmos_atmosphere *a, const double p[3], double d[3], int k, int last, double *w,
                     atmos__stream *r)
{
    const atmos__planet *pl = a->planet;
    const double h = atmos__planet_altitude(pl, p);
    const double sR = pl->rayleigh[k] * atmos__planet_rho_rayleigh(pl, h);
    const double sM = pl->mie_sca[k] * atmos__planet_rho_mie(pl, h);
    const double ext = atmos__planet_extinction(pl, h, k);
    if (last || !(ext > 0) || !(sR + sM > 0)) return 0;
    *w *= fmin((sR + sM) / ext, 1.0);
    const double mu = atmos__stream_u(r) * (sR + sM) < sR ? rayleigh_sample(atmos__stream_u(r))
                                                          : atmos__planet_mie_sample(pl, k, atmos__stream_u(r));
    /* drawn from the mixture with Rayleigh's own phase function; the air's is depolarized
     * (planet.h): the weight is the ratio of the two mixtures (within ~3 % of 1) */
    const double PM = atmos__planet_mie_phase(pl, k, mu);
    *w *= (sR * atmos__planet_rayleigh_phase(pl, k, mu) + sM * PM) / (sR * atmos_phase_rayleigh(mu) + sM * PM);
    const double dir[3] = {d[0], d[1], d[2]};
    around(dir, mu, 2.0 * ATMOS_PI * atmos__stream_u(r), d);
    return 1;
}

/* The ground at p (moved onto it; reached with weight *w): its emission, the sun's
 * reflection, the bounce. Returns 0 when the walk ends here. */
static int ground_event(const atmos_atmosphere *a, double p[3], double d[3], const double sun[3], int k, int last,
                        double *w, double *L, atmos__stream *r)
{
    const atmos__planet *pl = a->planet;
    double n[3];
    atmos__planet_ground_point(pl, p, n);
    /* a hair above the ground, so that the walk leaves it cleanly */
    for (int i = 0; i < 3; i++) p[i] += 1e-6 * n[i];
    *L += *w * atmos__planet_ground_lights(pl, p, sun, k);
    const double alb = atmos__planet_ground_albedo(pl, p, k);
    if (!(alb > 0)) return 0;
    const double cs = atmos__dot3(n, sun);
    if (cs > 0) {
        *L += *w * alb / ATMOS_PI * cs * a->sun_e[k] *
              exp(-atmos__planet_depth1(pl, p, sun, 0.0, atmos__planet_exit_top(pl, p, sun), k));
    }
    if (last) return 0;
    *w *= alb;
    const double u = atmos__stream_u(r);
    around(n, sqrt(u), 2.0 * ATMOS_PI * atmos__stream_u(r), d);
    return 1;
}

double atmos__atm_reference_walk(const atmos_atmosphere *a, const double eye[3], const double dir[3],
                                 const double sun[3], int k, int max_order, atmos__stream *r)
{
    const atmos__planet *pl = a->planet;
    if (!pl) return 0.0;
    double p[3] = {eye[0], eye[1], eye[2]}, d[3] = {dir[0], dir[1], dir[2]};
    atmos__normalize3(d);
    if (atmos__planet_radius(pl, p) > pl->r_top) {
        /* from outside the air: on to where the ray enters it, if it does */
        const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
        const double b = atmos__dot3(q, d), c = atmos__dot3(q, q) - pl->r_top * pl->r_top, disc = b * b - c;
        if (b >= 0 || disc < 0) return 0.0;
        const double t = c / (sqrt(disc) - b);
        for (int i = 0; i < 3; i++) p[i] += t * d[i];
    } else if (atmos__planet_radius(pl, p) < pl->r_ground) {
        /* from under the ground: from the ground point above */
        double n[3];
        atmos__planet_ground_point(pl, p, n);
        for (int i = 0; i < 3; i++) p[i] += 1e-6 * n[i];
    }
    double L = 0, w = 1;
    for (int order = 1; order <= MAX_EVENTS; order++) {
        const int last = max_order > 0 && order >= max_order;
        const double K = atmos__planet_hit_ground(pl, p, d);
        const double tex = K < INFINITY ? K : atmos__planet_exit_top(pl, p, d);
        L += w * a->sun_e[k] * atmos__planet_segment_sun(pl, p, d, tex, sun, k, r);
        const double t = atmos__planet_free_flight(pl, p, d, tex, k, r);
        for (int i = 0; i < 3; i++) p[i] += t * d[i];
        int go;
        if (t < tex) go = air_event(a, p, d, k, last, &w, r);
        else if (K < INFINITY) go = ground_event(a, p, d, sun, k, last, &w, &L, r);
        else go = 0;
        if (!go || !(w > 0)) break;
        if (w < RR_WEIGHT) {
            if (atmos__stream_u(r) * RR_WEIGHT >= w) break;
            w = RR_WEIGHT;
        }
    }
    return L;
}

atmos_status atmos_atmosphere_reference_radiance(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                                                 const double sun_dir[3], long paths, unsigned long long seed,
                                                 int max_order, double *out, double *std_error)
{
    if (!atm || !atm->planet || !p || !dir || !sun_dir || !out || paths < 1) return ATMOS_E_INVALID_ARG;
    const int n = atm->wl.count;
    double sun[3] = {sun_dir[0], sun_dir[1], sun_dir[2]};
    const double ls = atmos__dot3(sun, sun), ld = atmos__dot3(dir, dir);
    if (!(ls > 0) || !(ld > 0) || !isfinite(ls) || !isfinite(ld) || !isfinite(p[0] + p[1] + p[2]))
        return ATMOS_E_INVALID_ARG;
    atmos__normalize3(sun);
    double *sums = calloc((size_t)n * NBLOCK * 2, sizeof(double));
    if (!sums) return ATMOS_E_NOMEM;
#pragma omp parallel for schedule(dynamic, 1)
    for (int job = 0; job < n * NBLOCK; job++) {
        const int k = job / NBLOCK, blk = job % NBLOCK;
        const long i0 = (long)((double)paths * blk / NBLOCK), i1 = (long)((double)paths * (blk + 1) / NBLOCK);
        double s = 0, s2 = 0;
        for (long i = i0; i < i1; i++) {
            atmos__stream r;
            atmos__stream_seed(&r, seed, (uint64_t)k, (uint64_t)i);
            const double v = atmos__atm_reference_walk(atm, p, dir, sun, k, max_order, &r);
            s += v, s2 += v * v;
        }
        sums[2 * job] = s, sums[2 * job + 1] = s2;
    }
    for (int k = 0; k < n; k++) {
        double s = 0, s2 = 0;
        for (int blk = 0; blk < NBLOCK; blk++) s += sums[2 * (k * NBLOCK + blk)], s2 += sums[2 * (k * NBLOCK + blk) + 1];
        const double mean = s / (double)paths;
        const double var = paths > 1 ? (s2 / (double)paths - mean * mean) / (double)(paths - 1) : 0.0;
        out[k] = mean;
        if (std_error) std_error[k] = var > 0 ? sqrt(var) : 0.0;
    }
    free(sums);
    return ATMOS_OK;
}
