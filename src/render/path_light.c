/* The light a path tracer's path gathers besides what it finds by itself (path_trace.h):
 * the sun and the air seen through the volume and the atmosphere, the air's single
 * scattering along a segment with the volume's shadows on it, next-event estimation of the
 * sun and the sky, the aureole estimate in droplet clouds, forced single scattering. */
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "render/path_trace.h"

#include <string.h>

/* Majorant optical depth of a camera ray's crossing of the box up to which it uses forced
 * single scattering. */
#define FORCED_TAU_MAX 2.0

/* Sunlight (W m^-2 nm^-1 on a surface facing the sun) at p for the carried wavelengths. */
void atmos__path_sunlight(const path_run *R, const double p[3], double *E)
{
    atmos__atm_sunlight_sub(R->J->atm, p, R->J->sun, R->b->m, R->b->k, E);
}

/* The air's transmittance over p + t d, t in [0, K], multiplied into w. */
void atmos__path_air_transmit(const path_run *R, const double p[3], const double d[3], double K, double *w)
{
    if (!(K > 0)) return;
    double T[PATH_B];
    atmos__atm_transmittance_sub(R->J->atm, p, d, K, R->b->m, R->b->k, T);
    for (int i = 0; i < R->b->m; i++) w[i] *= T[i];
}

/* Volume transmittance from world point p along unit d (to the box's far side). */
void atmos__path_shadow(const path_run *R, const double p[3], const double d[3], double *T)
{
    for (int i = 0; i < R->b->m; i++) T[i] = 1;
    if (!R->J->med) return;
    double q[3], qd[3], t0, t1;
    atmos__path_to_index(R->J->med, p, d, q, qd);
    if (!atmos__path_clip(R->J->med, q, qd, INFINITY, &t0, &t1)) return;
    R->cnt->shadow++;
    atmos__path_transmittance(R->J->med, q, qd, t0, t1, R->b, R->r, T);
}

/* A direction in the sun's cone, uniformly (pdf 1 / sun_omega). */
void atmos__path_sample_sun(const path_run *R, double d[3])
{
    double mu = 1.0 - atmos__stream_u(R->r) * (1.0 - R->J->cos_sun);
    atmos__path_around(R->J->sun, mu, 2.0 * ATMOS_PI * atmos__stream_u(R->r), d);
}

/* Does the sun (sunlight E) light anything the weights w carry? */
int atmos__path_sun_lit(const path_run *R, const double *w, const double *E)
{
    int lit = 0;
    for (int i = 0; i < R->b->m; i++) lit |= w[i] * E[i] > 0;
    return lit && R->J->sun_omega > 0;
}

/* Balance heuristic between the two ways a path finds the sun's disk from a scattering
 * event: next-event estimation (pdf 1 / sun_omega over the cone) and the phase-sampled
 * continuation (pdf q p_dir: survival probability of the roulette times the direction
 * sampler's density). Returns the weight of next-event estimation; the continuation
 * gets 1 minus it. */
double atmos__path_mis_nee(const path_job *J, double q_pdir)
{
    const double pl = 1.0 / J->sun_omega;
    return q_pdir > 0 ? pl / (pl + q_pdir) : 1.0;
}

/* The part [*a, *b] of the segment p + t d, t in [0, K], whose points see the sun through
 * the volume's box: the t for which some s >= 0 puts p + t d + s sun in the box. In index
 * space (q + t qd, sun qs) each axis bounds s from below and above by lines in t (or t
 * alone where qs is 0 on that axis); s exists where every lower bound is below every upper
 * one, an interval of t (the box is convex). Returns 0 when no point of the segment does. */
static int sun_shadow_span(const path_medium *M, const double p[3], const double d[3], const double sun[3], double K,
                           double *a, double *b)
{
    double q[3], qd[3], q2[3], qs[3];
    atmos__path_to_index(M, p, d, q, qd);
    atmos__path_to_index(M, p, sun, q2, qs);
    double lo[4][2] = {{0, 0}}, hi[3][2]; /* bounds on s: c0 + c1 t; s >= 0 is the first lower one */
    int nl = 1, nh = 0;
    double t0 = 0, t1 = K;
    for (int x = 0; x < 3; x++) {
        const double l = M->box_lo[x] - q[x], h = M->box_hi[x] - q[x]; /* l <= t qd + s qs <= h */
        if (qs[x] == 0) {
            if (qd[x] == 0) {
                if (l > 0 || h < 0) return 0;
                continue;
            }
            double ta = l / qd[x], tb = h / qd[x];
            if (ta > tb) {
                const double c = ta;
                ta = tb, tb = c;
            }
            if (ta > t0) t0 = ta;
            if (tb < t1) t1 = tb;
            continue;
        }
        const double lo0 = (qs[x] > 0 ? l : h) / qs[x], hi0 = (qs[x] > 0 ? h : l) / qs[x], c1 = -qd[x] / qs[x];
        lo[nl][0] = lo0, lo[nl][1] = c1, nl++;
        hi[nh][0] = hi0, hi[nh][1] = c1, nh++;
    }
    for (int i = 0; i < nl; i++)
        for (int j = 0; j < nh; j++) { /* lo_i(t) <= hi_j(t): e0 + e1 t <= 0 */
            const double e0 = lo[i][0] - hi[j][0], e1 = lo[i][1] - hi[j][1];
            if (e1 == 0) {
                if (e0 > 0) return 0;
            } else if (e1 > 0) {
                if (-e0 / e1 < t1) t1 = -e0 / e1;
            } else if (-e0 / e1 > t0) {
                t0 = -e0 / e1;
            }
        }
    if (!(t0 < t1)) return 0;
    *a = t0, *b = t1;
    return 1;
}

/* The air's single scattering of sunlight along p + t d, t in [0, K], added to L (times
 * w[i] wt), with the volume's shadows on it: the integral of the in-scatter f(t) T_view(t)
 * T_sun(t), T_view the volume's transmittance from p to p + t d (view: the segment is inside
 * the box; else 1) and T_sun the volume's transmittance from there toward the sun.
 *  - Outside the box, only the part [s0, s1] of the segment whose way to the sun crosses the
 *    box can be shadowed (sun_shadow_span): the rest is the atmosphere's analytic in-scatter
 *    (exact for the closed-form kinds) without noise, the part by one point that the
 *    atmosphere draws on it in proportion to the air's scattering times its transmittance
 *    (of the carried wavelength that scatters least, so that the others' ratios stay
 *    bounded) times T_sun there.
 *  - Inside the box the whole segment is estimated so, times T_view too.
 *  - Over a planet (the spherical kinds) the model's in-scatter holds every order of
 *    scattering, of which the volume shadows only the sun's single scattering: the higher
 *    orders come from the whole sky, which the volume mostly does not hide. The shadowed
 *    part's single scattering is computed by quadrature (atmos__path_air_single), the rest
 *    of the model's in-scatter (every other order, and the single scattering elsewhere) is
 *    added as it is, and the point is drawn from the quadrature's cells. Inside the box
 *    that rest is seen through the volume too: it rides on the point, spread along the
 *    segment as the single scattering is (the sunlight changes little across a box).
 * Every sample is >= 0. (The first version added the analytic value of the whole segment and
 * subtracted f (1 - T_view T_sun) / pdf at one point drawn over all of it: unbiased too, but
 * where nearly everything is shadowed, as inside a cloud, a sample was the analytic value
 * minus its one-point estimate, negative about half the time: pixels with little other
 * light came out negative at low sample counts, and a ray to space beside a cloud
 * subtracted the whole sky's in-scatter at a point in the cloud's shadow. Over a planet the
 * span's whole in-scatter was shadowed until the single scattering was told apart: shadows
 * in the air too dark and too blue, docs/gallery.md, "A cumulus field from above".) */
void atmos__path_air_scatter(const path_run *R, const double p[3], const double d[3], double K, const double *w,
                             double wt, int order, const air_view *view)
{
    const path_job *J = R->J;
    const path_bundle *b = R->b;
    const int m = b->m;
    if (!(K > 0) || !(wt > 0)) return;
    double f[PATH_B], fs[PATH_B], s0 = 0, s1 = K;
    if (!atmos__atm_inscatter_sub(J->atm, p, d, K, J->sun, m, b->k, f)) return;
    const int span = J->med && (view || sun_shadow_span(J->med, p, d, J->sun, K, &s0, &s1));
    const atmos_atmosphere_kind kind = atmos_atmosphere_get_kind(J->atm);
    const int planet = kind == ATMOS_ATMOSPHERE_SPHERICAL || kind == ATMOS_ATMOSPHERE_DOBASHI;
    const double p0[3] = {p[0] + s0 * d[0], p[1] + s0 * d[1], p[2] + s0 * d[2]};
    air_single S;
    for (int i = 0; i < m; i++) fs[i] = 0;
    if (span && planet) { /* what the volume can take: the span's single scattering */
        atmos__path_air_single(R, p, d, s0, s1, &S);
        memcpy(fs, S.sum, sizeof fs);
    } else if (view) {
        memcpy(fs, f, sizeof fs); /* the span is the whole segment */
    } else if (span) { /* the analytic in-scatter of the span, seen through the air from p */
        atmos__atm_inscatter_sub(J->atm, p0, d, s1 - s0, J->sun, m, b->k, fs);
        atmos__path_air_transmit(R, p, d, s0, fs);
    }
    /* inside the box over a planet the higher orders are not shadowed but still seen through
     * the volume: carried with the single scattering's point, as hi[i] times its share */
    double hi[PATH_B];
    for (int i = 0; i < m; i++) {
        hi[i] = 0;
        if (w[i] == 0) continue;
        const double rest = f[i] - fs[i];
        if (view && planet && fs[i] > 0) hi[i] = rest > 0 ? rest / fs[i] : 0.0;
        else if (rest > 0) atmos__path_add(R, i, w[i] * wt * rest, order);
    }
    if (!span) return;
    double ta, ratio[PATH_B];
    if (planet) { /* ratio: the single scattering's integrand over the density, sunlight included */
        if (!atmos__path_air_single_point(R, &S, w, &ta, ratio)) return;
    } else {
        if (!atmos__atm_scatter_point(J->atm, p0, d, s1 - s0, m, b->k, w, R->r, &ta, ratio)) return;
        atmos__path_air_transmit(R, p, d, s0, ratio); /* the point's ratio counts the air from p0 on */
        ta += s0;
    }
    const double pa[3] = {p[0] + ta * d[0], p[1] + ta * d[1], p[2] + ta * d[2]};
    double T[PATH_B], Tv[PATH_B], E[PATH_B];
    atmos__path_shadow(R, pa, J->sun, T);
    int lit = 0;
    for (int i = 0; i < m; i++) {
        T[i] += hi[i];
        lit |= w[i] != 0 && T[i] > 0;
    }
    if (!lit) return;
    if (view) {
        atmos__path_transmittance(J->med, view->q, view->qd, view->t0, view->t0 + ta, b, R->r, Tv);
        for (int i = 0; i < m; i++) T[i] *= Tv[i];
    }
    if (!planet) {
        atmos__path_sunlight(R, pa, E);
        const double P = atmos_atmosphere_phase(J->atm, pa, atmos__dot3(d, J->sun));
        for (int i = 0; i < m; i++) ratio[i] *= P * E[i];
    }
    for (int i = 0; i < m; i++)
        if (w[i] != 0 && T[i] > 0) atmos__path_add(R, i, w[i] * wt * ratio[i] * T[i], order);
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
static void nee_sun(const path_run *R, const path_event *ev, const double *E, double hs)
{
    const path_job *J = R->J;
    const int m = R->b->m;
    const double *w = ev->w;
    double pk[PATH_B], T[PATH_B], ds[3];
    atmos__path_sample_sun(R, ds);
    atmos__path_phase_mix(J->ph, R->b, J->med->nf, ev->e, atmos__dot3(ev->d, ds), pk);
    const double pdir = atmos__path_strategies(m, ev->S, ev->g, pk, NULL);
    int any = 0;
    for (int i = 0; i < m; i++) any |= w[i] * pk[i] * E[i] > 0;
    if (!any) return;
    const double wm = atmos__path_mis_nee(J, ev->q * pdir) * hs;
    atmos__path_shadow(R, ev->p, ds, T);
    for (int i = 0; i < m; i++) atmos__path_add(R, i, w[i] * pk[i] * E[i] * T[i] * wm, ev->order);
}

void atmos__path_nee(const path_run *R, const path_event *ev, const double *E, double hs)
{
    const path_job *J = R->J;
    const path_bundle *b = R->b;
    const int m = b->m;
    const double *w = ev->w, *p = ev->p;
    double pk[PATH_B], T[PATH_B];
    if (E) nee_sun(R, ev, E, hs);
    if (J->env) { /* the sky (J->env exists only where the sky has light) */
        double de[3];
        const double pe = atmos__path_env_sample(J->env, atmos__stream_u(R->r), atmos__stream_u(R->r),
                                                 atmos__stream_u(R->r), de);
        atmos__path_phase_mix(J->ph, b, J->med->nf, ev->e, atmos__dot3(ev->d, de), pk);
        const double pdir = atmos__path_strategies(m, ev->S, ev->g, pk, NULL);
        int any = 0;
        for (int i = 0; i < m; i++) any |= w[i] * pk[i] > 0;
        if (!any || !(pe > 0)) return;
        const double wm = pe / (pe + ev->q * pdir);
        const double Kd = atmos_atmosphere_ground_distance(J->atm, p, de);
        double q2[3], qd2[3], a0, a1, ex = 0, c[PATH_B];
        for (int i = 0; i < m; i++) T[i] = 1;
        atmos__path_to_index(J->med, p, de, q2, qd2);
        if (atmos__path_clip(J->med, q2, qd2, Kd, &a0, &a1)) {
            R->cnt->shadow++;
            atmos__path_transmittance(J->med, q2, qd2, a0, a1, b, R->r, T);
            ex = a1;
        }
        int on = 0;
        for (int i = 0; i < m; i++) {
            c[i] = w[i] * pk[i] * T[i] / pe * wm;
            on |= c[i] > 0;
        }
        if (on && ex < Kd) {
            atmos__path_air_transmit(R, p, de, ex, c);
            const double px[3] = {p[0] + ex * de[0], p[1] + ex * de[1], p[2] + ex * de[2]};
            atmos__path_air_scatter(R, px, de, Kd - ex, c, 1.0, ev->order, NULL);
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
 * Used where some phase function has a forward peak, or had one before truncation
 * (J->aureole: path_plan.c). */
void atmos__path_aureole(const path_run *R, const path_event *ev)
{
    const path_job *J = R->J;
    const path_bundle *b = R->b;
    const path_scatter *e = ev->e;
    const double *p = ev->p, *w = ev->w;
    atmos__stream *r = R->r;
    const path_medium *M = J->med;
    const path_phase *P = J->ph;
    const int m = b->m, nf = M->nf;
    int elig[PATH_B], ne = 0;
    for (int i = 0; i < m; i++)
        if (e->ss[i] > 0) elig[ne++] = i;
    if (!ne) return;
    const int j = elig[ne > 1 ? (int)(atmos__stream_u(r) * ne) % ne : 0], f = atmos__path_pick_field(e, j, nf, r);
    double a[3], pk[PATH_B], wa[PATH_B];
    atmos__path_around(J->sun, atmos__path_phase_sample(P, f, b->k[j], atmos__stream_u(r)),
                       2.0 * ATMOS_PI * atmos__stream_u(r), a);
    atmos__path_phase_mix(P, b, nf, e, atmos__dot3(ev->d, a), pk);
    const double den = ev->q * atmos__path_strategies(m, ev->S, ev->g, pk, NULL) + atmos__path_aureole_pdf(J, b, e, a);
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
    if (atmos__path_free_flight(M, qi, qd, t0, t1, b, wa, r, &t, dens, &R->cnt->tentative) <= 0) return;
    atmos__path_air_transmit(R, p, a, t, wa);
    path_scatter e2;
    int g2[PATH_B];
    if (!atmos__path_scatter_at(J, b, dens, &e2, g2)) return;
    double E[PATH_B], S2[PATH_B];
    for (int i = 0; i < m; i++) S2[i] = 1;
    /* the whole disk by next-event estimation (q = 0: no continuation shares it) */
    path_event at = {{p[0] + t * a[0], p[1] + t * a[1], p[2] + t * a[2]}, {a[0], a[1], a[2]}, wa, &e2, S2, g2, 0.0,
                     ev->order + 1};
    atmos__path_sunlight(R, at.p, E);
    nee_sun(R, &at, E, 1.0);
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
int atmos__path_forced_single(const path_run *R, const double p[3], const double d[3], const double q[3],
                              const double qd[3], double t0, double t1, const double *w)
{
    const path_job *J = R->J;
    const path_bundle *b = R->b;
    double t, pdf;
    const double u0 = atmos__stream_u(R->r), u1 = atmos__stream_u(R->r);
    if (!atmos__path_majorant_point(J->med, q, qd, t0, t1, b, FORCED_TAU_MAX, u0, u1, &t, &pdf)) return 0;
    float dens[PATH_F];
    atmos__path_density(J->med, q[0] + t * qd[0], q[1] + t * qd[1], q[2] + t * qd[2], dens);
    path_scatter e;
    int g[PATH_B];
    if (!atmos__path_scatter_at(J, b, dens, &e, g)) return 1;
    const int m = b->m;
    double T[PATH_B], c[PATH_B], S[PATH_B], E[PATH_B];
    atmos__path_transmittance(J->med, q, qd, t0, t, b, R->r, T);
    int any = 0;
    for (int i = 0; i < m; i++) {
        S[i] = 1;
        c[i] = w[i] * T[i] * e.ss[i] / pdf;
        any |= c[i] > 0;
    }
    if (!any) return 1;
    const double x0[3] = {p[0] + t0 * d[0], p[1] + t0 * d[1], p[2] + t0 * d[2]};
    atmos__path_air_transmit(R, x0, d, t - t0, c);
    /* the continuation's share: as if the roulette always let it go on (the first event's
     * continuations use that too), unless no path goes on after one event */
    const path_event ev = {{p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]}, {d[0], d[1], d[2]}, c, &e, S, g,
                           J->max_depth == 1 ? 0.0 : 1.0, 1};
    atmos__path_sunlight(R, ev.p, E);
    atmos__path_nee(R, &ev, atmos__path_sun_lit(R, c, E) ? E : NULL, 1.0);
    return 1;
}
