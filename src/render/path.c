/* Spectral Monte Carlo volumetric path tracing. See include/atmos/path.h and docs/path.md.
 *
 * A camera path carries up to PATH_B wavelengths of the scene's set (all of them in rgb
 * mode; in spectral mode a uniformly chosen hero and the wavelengths a quarter, half and
 * three quarters of the set away, each counted with weight N/PATH_B, so every wavelength
 * is estimated without bias). Its segments:
 *
 *   air (everywhere, inside the volume's occupied box too): the analytic sky's
 *       transmittance and single-scattered in-scatter (sky.c), minus the volume's shadow
 *       on it (air_scatter), added along the way;
 *   the volume's box: free flight by delta tracking (path_medium.c); at a real
 *       scattering event next-event estimation of the sun's disk (a direction drawn
 *       uniformly in the disk's cone, the transmittance to it by ratio tracking) and of
 *       the sky (a direction from path_env.c's table), then Russian roulette and a new
 *       direction drawn from the phase function of the path's hero wavelength (multiple
 *       importance sampling over whole paths between the carried wavelengths: weights
 *       never more than PATH_B); a direction that lands in the sun's disk counts the sun
 *       too, and the air's light at the path's escape counts, each weighted against its
 *       next-event estimate by the balance heuristic. A camera ray's crossing of the box
 *       estimates its single scattering at a point drawn by the majorant
 *       (forced_single), in place of the next-event estimates at its first event;
 *   the ground (y = 0, sky background): Lambertian; the sun's light (shadowed by the
 *       volume) by next-event estimation, then a cosine-distributed bounce;
 *   escape: the sky's in-scatter from the escape point to infinity; the sun's disk only
 *       on a path that has not scattered (after a volume event the sun is counted by
 *       the two weighted estimates at the event, after a ground bounce by next-event
 *       estimation alone). A black or uniform background is vacuum: no
 *       air, no ground, the unattenuated sun, background_radiance from every direction.
 *
 * With truncate_deg > 0 the volume is the truncated medium of path_phase.c (forward peak
 * cut at theta_c, that fraction of the scattering counted as unscattered): free flights,
 * shadow rays, next-event estimation and phase sampling all see sigma_s', sigma_t' and P'.
 *
 * Per pixel, samples are added in their index order into double sums (and sums of
 * squares, for the variance); the random numbers of sample s of pixel p come from their
 * own stream. So the image does not depend on the thread count or the schedule.
 */
#define _POSIX_C_SOURCE 200809L
#include "render/path_internal.h"
#include "render/path_trace.h"
#include "core/vec.h"
#include "atmosphere/atmosphere_ops.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Majorant optical depth of a camera ray's crossing of the box up to which it uses forced
 * single scattering. */
#define FORCED_TAU_MAX 2.0

/* ------------------------------------------------------------------ small vector helpers */

/* Orthonormal basis around unit n (Duff et al. 2017). */
static inline void onb(const double n[3], double t[3], double b[3])
{
    double s = n[2] >= 0 ? 1.0 : -1.0;
    double a = -1.0 / (s + n[2]);
    double c = n[0] * n[1] * a;
    t[0] = 1.0 + s * n[0] * n[0] * a, t[1] = s * c, t[2] = -s * n[0];
    b[0] = c, b[1] = s + n[1] * n[1] * a, b[2] = -n[1];
}

/* Direction at cos(theta) = mu, azimuth phi around unit axis n. */
static inline void around(const double n[3], double mu, double phi, double out[3])
{
    double t[3], b[3];
    onb(n, t, b);
    double st = sqrt(fmax(0.0, 1.0 - mu * mu)), c = cos(phi) * st, s = sin(phi) * st;
    for (int a = 0; a < 3; a++) out[a] = mu * n[a] + c * t[a] + s * b[a];
    double l = 1.0 / sqrt(atmos__dot3(out, out));
    for (int a = 0; a < 3; a++) out[a] *= l;
}

/* Sunlight (W m^-2 nm^-1 on a surface facing the sun) at p for the carried wavelengths. */
static void sunlight(const path_job *J, const path_bundle *b, const double p[3], double *E)
{
    atmos__atm_sunlight_sub(J->atm, p, J->sun, b->m, b->k, E);
}

/* The air's transmittance over p + t d, t in [0, K], multiplied into w. */
static void air_transmit(const path_job *J, const path_bundle *b, const double p[3], const double d[3], double K,
                         double *w)
{
    if (!(K > 0)) return;
    double T[PATH_B];
    atmos__atm_transmittance_sub(J->atm, p, d, K, b->m, b->k, T);
    for (int i = 0; i < b->m; i++) w[i] *= T[i];
}

static void shadow(const path_job *J, const path_bundle *b, const double p[3], const double d[3], atmos__stream *r,
                   double *T, path_counts *cnt);

/* Part of a segment lying in the volume's box: the index-space ray and its start there. */
typedef struct {
    const double *q, *qd;
    double t0;
} air_view;

/* The air's single scattering of sunlight along p + t d, t in [0, K], added to L (times
 * w[i] wt): the atmosphere's in-scatter (exact for the closed-form kinds), minus the part
 * the volume takes away. That part, the integral of the in-scatter f(t) (1 - T_view(t)
 * T_sun(t)) with T_view the volume's transmittance from p to p + t d (view: the segment is
 * inside the box; else 1) and T_sun the volume's transmittance from there toward the sun, is
 * estimated with one point the atmosphere draws in proportion to the air's scattering times
 * its transmittance (of the carried wavelength that scatters least, so that the others'
 * ratios stay bounded): shadows of the volume on the air, the light shafts, cost a shadow
 * ray only where the point's way to the sun crosses the box, and light that nothing
 * shadows is the analytic value without noise. A sample can therefore be negative in a
 * shadow; its mean is not. */
static void air_scatter(const path_job *J, const path_bundle *b, const double p[3], const double d[3], double K,
                        const double *w, double wt, double *L, double *Lo, int order, const air_view *view,
                        atmos__stream *r, path_counts *cnt)
{
    if (!(K > 0) || !(wt > 0)) return;
    double f[PATH_B];
    if (!atmos__atm_inscatter_sub(J->atm, p, d, K, J->sun, b->m, b->k, f)) return;
    for (int i = 0; i < b->m; i++) {
        if (w[i] == 0) continue;
        const double c = w[i] * wt * f[i];
        L[i] += c, Lo[i] += order * c;
    }
    double ta, ratio[PATH_B];
    if (!J->med || !atmos__atm_scatter_point(J->atm, p, d, K, b->m, b->k, w, r, &ta, ratio)) return;
    const double pa[3] = {p[0] + ta * d[0], p[1] + ta * d[1], p[2] + ta * d[2]};
    double Ts[PATH_B], Tv[PATH_B], E[PATH_B];
    shadow(J, b, pa, J->sun, r, Ts, cnt);
    int any = 0, lit = 0;
    for (int i = 0; i < b->m; i++) any |= Ts[i] < 1, lit |= Ts[i] > 0;
    if (!any && !view) return; /* nothing in the way to the sun: the analytic value holds */
    for (int i = 0; i < b->m; i++) Tv[i] = 1;
    if (view && lit) atmos__path_transmittance(J->med, view->q, view->qd, view->t0, view->t0 + ta, b, r, Tv);
    sunlight(J, b, pa, E);
    const double P = atmos_atmosphere_phase(J->atm, pa, atmos__dot3(d, J->sun));
    for (int i = 0; i < b->m; i++) {
        const double occl = 1.0 - Tv[i] * Ts[i];
        if (w[i] == 0 || occl == 0) continue;
        const double c = w[i] * wt * P * E[i] * ratio[i] * occl;
        L[i] -= c, Lo[i] -= order * c;
    }
}

/* Volume transmittance from world point p along unit d (to the box's far side). */
static void shadow(const path_job *J, const path_bundle *b, const double p[3], const double d[3], atmos__stream *r,
                   double *T, path_counts *cnt)
{
    for (int i = 0; i < b->m; i++) T[i] = 1;
    if (!J->med) return;
    double q[3], qd[3], t0, t1;
    atmos__path_to_index(J->med, p, d, q, qd);
    if (!atmos__path_clip(J->med, q, qd, INFINITY, &t0, &t1)) return;
    cnt->shadow++;
    atmos__path_transmittance(J->med, q, qd, t0, t1, b, r, T);
}

/* A direction in the sun's cone, uniformly (pdf 1 / sun_omega). */
static void sample_sun(const path_job *J, atmos__stream *r, double d[3])
{
    double mu = 1.0 - atmos__stream_u(r) * (1.0 - J->cos_sun);
    around(J->sun, mu, 2.0 * ATMOS_PI * atmos__stream_u(r), d);
}

/* Russian roulette on the largest weight; returns 0 to stop. */
static int roulette(double *w, int m, atmos__stream *r)
{
    double q = 0;
    for (int i = 0; i < m; i++)
        if (w[i] > q) q = w[i];
    if (!(q > 0)) return 0;
    if (q >= 1) return 1;
    if (atmos__stream_u(r) >= q) return 0;
    for (int i = 0; i < m; i++) w[i] /= q;
    return 1;
}

/* The scattering at a point of the volume for the carried wavelengths: per field ssf and
 * in all ss (m^-1). */
typedef struct {
    double ssf[PATH_F][PATH_B], ss[PATH_B];
} path_scatter;

/* Phase function of the mixture of fields at a scattering event for every carried
 * wavelength: pk[i] = sum_f ssf[f][i] p_f,k(mu) / ss[i], 0 where nothing scatters. */
static void phase_mix(const path_phase *P, const path_bundle *b, int nf, const path_scatter *e, double mu, double *pk)
{
    path_angle ang;
    atmos__path_angle(P, mu, &ang);
    for (int i = 0; i < b->m; i++) {
        double s = 0;
        if (e->ss[i] > 0) {
            for (int f = 0; f < nf; f++)
                if (e->ssf[f][i] > 0) s += e->ssf[f][i] * atmos__path_phase_eval(P, f, b->k[i], &ang);
            s /= e->ss[i];
        }
        pk[i] = s;
    }
}

/* Hero wavelengths, multiple importance sampling over whole paths. A path draws every
 * direction from the phase function of one carried wavelength, its hero h, chosen
 * uniformly once (Wilkie et al. 2014, "Hero wavelength spectral sampling"); where h does
 * not scatter, from the first wavelength that does (a fixed rule, so a function of the
 * path). Wavelength k is then weighted by prod_e p_k(e) / ((1/m) sum_j prod_e pdf_j(e)), the
 * balance heuristic over the m strategies "hero = j": at most m whatever the path's length.
 * (Weighting every event separately, p_k / mean_j p_j, compounds over a path: after twenty
 * events in a droplet cloud, whose phase functions differ between wavelengths by factors of
 * two in the forward peak and more around the glory and the rainbow, single weights of
 * hundreds made the fireflies of the first version.) S[j] holds prod_e pdf_j(e),
 * normalised to mean 1 after every event; the weights w carry the ratio. */
static double strategies(int m, const double *S, const int *g, const double *pd, double *pj)
{
    double D = 0;
    for (int j = 0; j < m; j++) {
        if (pj) pj[j] = pd[g[j]];
        D += S[j] * pd[g[j]];
    }
    return D / m;
}

/* Balance heuristic between the two ways a path finds the sun's disk from a scattering
 * event: next-event estimation (pdf 1 / sun_omega over the cone) and the phase-sampled
 * continuation (pdf q p_dir: survival probability of the roulette times the direction
 * sampler's density). Returns the weight of next-event estimation; the continuation
 * gets 1 minus it. */
static inline double mis_nee(const path_job *J, double q_pdir)
{
    const double pl = 1.0 / J->sun_omega;
    return q_pdir > 0 ? pl / (pl + q_pdir) : 1.0;
}

/* The scattering at a point of the volume (densities dens) for the carried wavelengths:
 * per field ssf and in all ss (m^-1), and for each hero its direction strategy g: itself,
 * or the first carried wavelength that scatters. Returns how many scatter. */
static int scatter_at(const path_job *J, const path_bundle *b, const float *dens, path_scatter *e, int *g)
{
    const path_medium *M = J->med;
    int elig[PATH_B], ne = 0;
    for (int i = 0; i < b->m; i++) {
        e->ss[i] = 0;
        for (int f = 0; f < M->nf; f++) {
            e->ssf[f][i] = (double)dens[f] * M->sca[f][b->k[i]];
            e->ss[i] += e->ssf[f][i];
        }
        if (e->ss[i] > 0) elig[ne++] = i;
    }
    for (int i = 0; i < b->m; i++) g[i] = e->ss[i] > 0 ? i : (ne ? elig[0] : i);
    return ne;
}

/* A field for a new direction of wavelength j: in proportion to its share of the scattering
 * there (no random number with one field). */
static int pick_field(const path_scatter *e, int j, int nf, atmos__stream *r)
{
    int f = 0;
    if (nf > 1) {
        double u = atmos__stream_u(r) * e->ss[j], acc = 0;
        for (f = 0; f < nf - 1; f++) {
            acc += e->ssf[f][j];
            if (u < acc) break;
        }
        while (f > 0 && e->ssf[f][j] <= 0) f--;
    }
    return f;
}

/* Does the sun (sunlight E) light anything the weights w carry? */
static int sun_lit(const path_job *J, const path_bundle *b, const double *w, const double *E)
{
    int lit = 0;
    for (int i = 0; i < b->m; i++) lit |= w[i] * E[i] > 0;
    return lit && J->sun_omega > 0;
}

/* Next-event estimation at a scattering point p of the volume reached along d with weights
 * w (the path's throughput times the scattering coefficient over the density of the point
 * sampled, as after a free flight): the sun's disk (E: its light there, NULL when it does
 * not light the point), a direction drawn uniformly in its cone, the volume's
 * transmittance to it by ratio tracking; and the sky (J->env), a direction drawn from the
 * sky's table, the volume's and the air's transmittance to the box's far side, then the
 * air's light beyond it. Each is weighted against the phase-sampled continuation by the
 * balance heuristic, whose density there is q (its survival probability) times the
 * strategies' mean density; the sun's part is further weighted by hs, the share of the
 * path's own strategies against the aureole estimate made at the previous event. */
static void nee_sun(const path_job *J, const path_bundle *b, const double p[3], const double d[3], const double *w,
                    const path_scatter *e, const double *S, const int *g, double q, const double *E, double hs,
                    int order, double *L, double *Lo, atmos__stream *r, path_counts *cnt)
{
    const int m = b->m;
    double pk[PATH_B], T[PATH_B], ds[3];
    sample_sun(J, r, ds);
    phase_mix(J->ph, b, J->med->nf, e, atmos__dot3(d, ds), pk);
    const double pdir = strategies(m, S, g, pk, NULL);
    int any = 0;
    for (int i = 0; i < m; i++) any |= w[i] * pk[i] * E[i] > 0;
    if (!any) return;
    const double wm = mis_nee(J, q * pdir) * hs;
    shadow(J, b, p, ds, r, T, cnt);
    for (int i = 0; i < m; i++) {
        const double c = w[i] * pk[i] * E[i] * T[i] * wm;
        L[i] += c, Lo[i] += order * c;
    }
}

static void nee(const path_job *J, const path_bundle *b, const double p[3], const double d[3], const double *w,
                const path_scatter *e, const double *S, const int *g, double q, const double *E, double hs, int order,
                double *L, double *Lo, atmos__stream *r, path_counts *cnt)
{
    const int m = b->m;
    double pk[PATH_B], T[PATH_B];
    if (E) nee_sun(J, b, p, d, w, e, S, g, q, E, hs, order, L, Lo, r, cnt);
    if (J->env) { /* the sky (J->env exists only with the sky background) */
        double de[3];
        const double pe = atmos__path_env_sample(J->env, atmos__stream_u(r), atmos__stream_u(r), atmos__stream_u(r), de);
        phase_mix(J->ph, b, J->med->nf, e, atmos__dot3(d, de), pk);
        const double pdir = strategies(m, S, g, pk, NULL);
        int any = 0;
        for (int i = 0; i < m; i++) any |= w[i] * pk[i] > 0;
        if (!any || !(pe > 0)) return;
        const double wm = pe / (pe + q * pdir);
        const double Kd = atmos_atmosphere_ground_distance(J->atm, p, de);
        double q2[3], qd2[3], a0, a1, ex = 0, c[PATH_B];
        for (int i = 0; i < m; i++) T[i] = 1;
        atmos__path_to_index(J->med, p, de, q2, qd2);
        if (atmos__path_clip(J->med, q2, qd2, Kd, &a0, &a1)) {
            cnt->shadow++;
            atmos__path_transmittance(J->med, q2, qd2, a0, a1, b, r, T);
            ex = a1;
        }
        int on = 0;
        for (int i = 0; i < m; i++) {
            c[i] = w[i] * pk[i] * T[i] / pe * wm;
            on |= c[i] > 0;
        }
        if (on && ex < Kd) {
            air_transmit(J, b, p, de, ex, c);
            const double px[3] = {p[0] + ex * de[0], p[1] + ex * de[1], p[2] + ex * de[2]};
            air_scatter(J, b, px, de, Kd - ex, c, 1.0, L, Lo, order, NULL, r, cnt);
        }
    }
}

/* The sun's aureole (docs/path.md, "Fireflies of droplet clouds"). Next-event estimation
 * at an event x' evaluates the phase function at the angle between the path's direction
 * and the sun: inside the forward peak (400-900 sr^-1 for cloud droplets against ~0.05
 * sideways) a path that happens to head within ~2 degrees of the sun collects thousands
 * of times the usual sunlight, and the continuation draws such directions rarely. So from
 * each lit event x (incoming direction d) one more estimate of the light (x, x', sun):
 * a direction a from the phase function of a carried scattering wavelength chosen
 * uniformly, centred on the sun instead of on d (density pa(a) = the mean over those
 * wavelengths of p_k(sun . a)), x' by the free flight the path itself would take along a,
 * at x' next-event estimation of the sun (the whole disk: it stands for both of the path's
 * ways there). The path reaches the same x' with density q p_dir(a) and counts the sun at
 * x' times h = q p_dir / (q p_dir + pa) (trace: hprev); this estimate has 1 - h, i.e. the
 * weight w_k p_k(d . a) / (q p_dir(a) + pa(a)): the balance heuristic between the two.
 * Used where some phase function has a forward peak (J->aureole). */
static double aureole_pdf(const path_job *J, const path_bundle *b, const path_scatter *e, const double a[3])
{
    double pk[PATH_B], s = 0;
    int ne = 0;
    phase_mix(J->ph, b, J->med->nf, e, atmos__dot3(a, J->sun), pk);
    for (int i = 0; i < b->m; i++)
        if (e->ss[i] > 0) s += pk[i], ne++;
    return ne ? s / ne : 0.0;
}

static void aureole(const path_job *J, const path_bundle *b, const double p[3], const double d[3],
                    const path_scatter *e, const double *w, const double *S, const int *g, double q, int order,
                    double *L, double *Lo, atmos__stream *r, path_counts *cnt)
{
    const path_medium *M = J->med;
    const path_phase *P = J->ph;
    const int m = b->m, nf = M->nf;
    int elig[PATH_B], ne = 0;
    for (int i = 0; i < m; i++)
        if (e->ss[i] > 0) elig[ne++] = i;
    if (!ne) return;
    const int j = elig[ne > 1 ? (int)(atmos__stream_u(r) * ne) % ne : 0], f = pick_field(e, j, nf, r);
    double a[3], pk[PATH_B], wa[PATH_B];
    around(J->sun, atmos__path_phase_sample(P, f, b->k[j], atmos__stream_u(r)), 2.0 * ATMOS_PI * atmos__stream_u(r), a);
    phase_mix(P, b, nf, e, atmos__dot3(d, a), pk);
    const double den = q * strategies(m, S, g, pk, NULL) + aureole_pdf(J, b, e, a);
    if (!(den > 0)) return;
    int any = 0;
    for (int i = 0; i < m; i++) any |= (wa[i] = w[i] * pk[i] / den) > 0;
    if (!any) return;
    /* x': the free flight of the path's own continuation (its probabilities do not depend
     * on the weights' common scale), with the air's transmittance on the way */
    double qi[3], qd[3], t0, t1, t;
    const double K = atmos_atmosphere_ground_distance(J->atm, p, a);
    atmos__path_to_index(M, p, a, qi, qd);
    if (!atmos__path_clip(M, qi, qd, K, &t0, &t1)) return;
    float dens[PATH_F];
    if (atmos__path_free_flight(M, qi, qd, t0, t1, b, wa, r, &t, dens, &cnt->tentative) <= 0) return;
    air_transmit(J, b, p, a, t, wa);
    path_scatter e2;
    int g2[PATH_B];
    if (!scatter_at(J, b, dens, &e2, g2)) return;
    double x[3], E[PATH_B], S2[PATH_B];
    for (int k = 0; k < 3; k++) x[k] = p[k] + t * a[k];
    for (int i = 0; i < m; i++) S2[i] = 1;
    sunlight(J, b, x, E);
    /* the whole disk by next-event estimation (q = 0: no continuation shares it) */
    nee_sun(J, b, x, a, wa, &e2, S2, g2, 0.0, E, 1.0, order + 1, L, Lo, r, cnt);
}

/* Forced single scattering on a camera ray's crossing [t0, t1] of the volume's box (index
 * space q + t qd, world p + t d): one point drawn by the majorant (half the time as the
 * first tentative collision forced into the crossing, half uniformly in its optical
 * depth: atmos__path_majorant_point), where the
 * lights are estimated with weights w sigma_s T_view / pdf (T_view by ratio tracking). It
 * replaces next-event estimation at the first free-flight event of camera paths, so in thin
 * media every camera ray that crosses the volume estimates its single scattering, instead
 * of the few that happen to collide. Only on crossings whose majorant optical depth is at
 * most FORCED_TAU_MAX (a function of the ray, so each ray keeps one consistent estimator):
 * in dense media the free flight's collisions, drawn in proportion to sigma T, are better.
 * Returns 1 if it made the estimate (the first event's next-event estimates are then
 * left out). */
static int forced_single(const path_job *J, const path_bundle *b, const double p[3], const double d[3],
                         const double q[3], const double qd[3], double t0, double t1, const double *w, double *L,
                         double *Lo, atmos__stream *r, path_counts *cnt)
{
    double t, pdf;
    const double u0 = atmos__stream_u(r), u1 = atmos__stream_u(r);
    if (!atmos__path_majorant_point(J->med, q, qd, t0, t1, b, FORCED_TAU_MAX, u0, u1, &t, &pdf)) return 0;
    float dens[PATH_F];
    atmos__path_density(J->med, q[0] + t * qd[0], q[1] + t * qd[1], q[2] + t * qd[2], dens);
    path_scatter e;
    int g[PATH_B];
    if (!scatter_at(J, b, dens, &e, g)) return 1;
    const int m = b->m;
    double T[PATH_B], c[PATH_B], S[PATH_B], E[PATH_B];
    atmos__path_transmittance(J->med, q, qd, t0, t, b, r, T);
    int any = 0;
    for (int i = 0; i < m; i++) {
        S[i] = 1;
        c[i] = w[i] * T[i] * e.ss[i] / pdf;
        any |= c[i] > 0;
    }
    if (!any) return 1;
    const double x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
    const double x0[3] = {p[0] + t0 * d[0], p[1] + t0 * d[1], p[2] + t0 * d[2]};
    air_transmit(J, b, x0, d, t - t0, c);
    sunlight(J, b, x, E);
    /* the continuation's share: as if the roulette always let it go on (the first event's
     * continuations use that too), unless no path goes on after one event */
    nee(J, b, x, d, c, &e, S, g, J->max_depth == 1 ? 0.0 : 1.0, sun_lit(J, b, c, E) ? E : NULL, 1.0, 1, L, Lo, r, cnt);
    return 1;
}

/* One camera path through world ray (o, d); adds the radiance of the carried
 * wavelengths to L[] and, for the scattering-order AOV, each contribution times the
 * number of volume scattering events before it to Lo[]. */
void atmos__path_trace(const path_job *J, const path_bundle *b, const double o[3], const double d0[3], atmos__stream *r,
                       double *L, double *Lo, path_counts *cnt)
{
    const int m = b->m;
    double w[PATH_B], p[3] = {o[0], o[1], o[2]}, d[3] = {d0[0], d0[1], d0[2]};
    for (int i = 0; i < m; i++) w[i] = 1, L[i] = 0, Lo[i] = 0;
    int primary = 1, depth = 0, order = 0, hero = -1;
    /* weight of the air's light at the path's escape: after a volume event the
     * continuation's share against next-event estimation of the sky, else 1 */
    double esc_wt = 1.0;
    double hprev = 1; /* the path's share of the sun at its next volume event (aureole) */
    double S[PATH_B];
    for (int i = 0; i < m; i++) S[i] = 1;
    float dens[PATH_F];
    for (int guard = 0; guard < 1 << 24; guard++) {
        double K = atmos_atmosphere_ground_distance(J->atm, p, d);
        double q[3], qd[3], t0 = 0, t1 = 0;
        int inbox = 0;
        if (J->med) {
            atmos__path_to_index(J->med, p, d, q, qd);
            inbox = atmos__path_clip(J->med, q, qd, K, &t0, &t1);
        }
        if (inbox) {
            if (t0 > 0) {
                air_scatter(J, b, p, d, t0, w, 1.0, L, Lo, order, NULL, r, cnt);
                air_transmit(J, b, p, d, t0, w);
            }
            double t, ws[PATH_B];
            memcpy(ws, w, sizeof ws);
            const int forced = J->forced && primary && forced_single(J, b, p, d, q, qd, t0, t1, w, L, Lo, r, cnt);
            int ev = atmos__path_free_flight(J->med, q, qd, t0, t1, b, w, r, &t, dens, &cnt->tentative);
            {
                /* The air inside the box: its light (shadowed by the volume) over the whole
                 * crossing, its transmittance up to where the flight ends. */
                const double ps[3] = {p[0] + t0 * d[0], p[1] + t0 * d[1], p[2] + t0 * d[2]};
                const air_view v = {q, qd, t0};
                air_scatter(J, b, ps, d, t1 - t0, ws, 1.0, L, Lo, order, &v, r, cnt);
                air_transmit(J, b, ps, d, (ev > 0 ? t : t1) - t0, w);
            }
            if (ev < 0) return;
            if (ev > 0) {
                /* A real scattering event in the volume. */
                cnt->events++;
                order++;
                for (int a = 0; a < 3; a++) p[a] += t * d[a];
                const path_phase *P = J->ph;
                const int nf = J->med->nf;
                path_scatter ev_s;
                int g[PATH_B];
                const int ne = scatter_at(J, b, dens, &ev_s, g);
                /* Can the path go on from here (depth limit), and with which probability
                 * does it survive the roulette below: the continuation's share of the
                 * multiple importance sampling of the sun. */
                const int goes_on = ne > 0 && !(J->max_depth && depth + 1 >= J->max_depth);
                double q_rr = 0;
                if (goes_on)
                    for (int i = 0; i < m; i++)
                        if (w[i] > q_rr) q_rr = w[i];
                if (q_rr > 1) q_rr = 1;
                const int first = forced; /* its lights were estimated by forced_single() */
                const double q_mis = first ? (J->max_depth == 1 ? 0.0 : 1.0) : q_rr;
                double E[PATH_B];
                sunlight(J, b, p, E);
                const int lit = sun_lit(J, b, w, E);
                if (ne && !first) nee(J, b, p, d, w, &ev_s, S, g, q_mis, lit ? E : NULL, hprev, order, L, Lo, r, cnt);
                if (!goes_on) return;
                /* The sun at the next event through the forward peak: see aureole(). */
                const int pa_on = J->aureole && lit;
                if (pa_on) aureole(J, b, p, d, &ev_s, w, S, g, q_rr, order, L, Lo, r, cnt);
                depth++;
                if (!roulette(w, m, r)) return;
                /* New direction: the hero's strategy (its wavelength or the fallback), a field
                 * in proportion to its scattering there, cos(theta) by the table's inverse CDF. */
                if (hero < 0) {
                    hero = m > 1 ? (int)(atmos__stream_u(r) * m) : 0;
                    if (hero >= m) hero = m - 1;
                }
                const int j = g[hero];
                const int f = pick_field(&ev_s, j, nf, r);
                double mu = atmos__path_phase_sample(P, f, b->k[j], atmos__stream_u(r));
                double nd[3];
                around(d, mu, 2.0 * ATMOS_PI * atmos__stream_u(r), nd);
                const int chroma = nf > 1 || !P->gray[0];
                const int to_sun = lit && atmos__dot3(nd, J->sun) >= J->cos_sun;
                esc_wt = 1.0;
                const double hcur = hprev;
                hprev = 1;
                if ((chroma && m > 1) || to_sun || J->env || pa_on) {
                    double pk[PATH_B], pj[PATH_B];
                    phase_mix(P, b, nf, &ev_s, mu, pk);
                    const double mean = strategies(m, S, g, pk, pj);
                    if (!(mean > 0)) return;
                    for (int i = 0; i < m; i++) {
                        w[i] *= pk[i] / mean;
                        S[i] *= pj[i] / mean;
                    }
                    if (pa_on) {
                        const double c = q_rr * mean;
                        hprev = c / (c + aureole_pdf(J, b, &ev_s, nd));
                    }
                    if (J->env) {
                        const double pe = atmos__path_env_pdf(J->env, nd);
                        esc_wt = q_mis * mean / (pe + q_mis * mean);
                    }
                    if (to_sun) {
                        /* The continuation found the sun's disk: its share of the sun's
                         * radiance E / sun_omega, through the volume's transmittance. */
                        double T[PATH_B];
                        const double wm = (1.0 - mis_nee(J, q_mis * mean)) * hcur;
                        shadow(J, b, p, nd, r, T, cnt);
                        for (int i = 0; i < m; i++) {
                            const double c = w[i] * E[i] / J->sun_omega * T[i] * wm;
                            L[i] += c, Lo[i] += order * c;
                        }
                    }
                }
                memcpy(d, nd, sizeof d);
                primary = 0;
                continue;
            }
            /* Through the volume: continue from its far side. */
            for (int a = 0; a < 3; a++) p[a] += t1 * d[a];
            K = atmos_atmosphere_ground_distance(J->atm, p, d);
            if (K <= 1e-9 * (1.0 + fabs(p[1]))) K = 0; /* the box reached the ground */
        }
        /* Escape: the air to the ground or out of the atmosphere, and what lies beyond. */
        air_scatter(J, b, p, d, K, w, esc_wt, L, Lo, order, NULL, r, cnt);
        if (isinf(K)) {
            if (J->bg != 0)
                for (int i = 0; i < m; i++) {
                    const double c = w[i] * J->bg * esc_wt;
                    L[i] += c, Lo[i] += order * c;
                }
            if (primary && J->disk_visible && atmos__dot3(d, J->sun) >= J->cos_sun) {
                double E[PATH_B];
                sunlight(J, b, p, E);
                for (int i = 0; i < m; i++) L[i] += w[i] * E[i] / J->sun_omega;
            }
            return;
        }
        /* The Lambertian ground. */
        air_transmit(J, b, p, d, K, w);
        for (int a = 0; a < 3; a++) p[a] += K * d[a];
        p[1] = 0;
        if (!(J->albedo > 0)) return;
        cnt->events++;
        double E[PATH_B];
        sunlight(J, b, p, E);
        int lit = 0;
        for (int i = 0; i < m; i++) lit |= w[i] * E[i] > 0;
        if (lit) {
            double ds[3], T[PATH_B];
            sample_sun(J, r, ds);
            if (ds[1] > 0) {
                shadow(J, b, p, ds, r, T, cnt);
                for (int i = 0; i < m; i++) {
                    const double c = w[i] * J->albedo / ATMOS_PI * ds[1] * E[i] * T[i];
                    L[i] += c, Lo[i] += order * c;
                }
            }
        }
        if (J->max_depth && ++depth >= J->max_depth) return;
        for (int i = 0; i < m; i++) w[i] *= J->albedo;
        if (!roulette(w, m, r)) return;
        {
            /* cosine-distributed about +y */
            double u1 = atmos__stream_u(r), phi = 2.0 * ATMOS_PI * atmos__stream_u(r), st = sqrt(u1);
            d[0] = st * cos(phi), d[2] = st * sin(phi), d[1] = sqrt(fmax(0.0, 1.0 - u1));
        }
        primary = 0;
        esc_wt = 1.0;
        hprev = 1;
    }
}
