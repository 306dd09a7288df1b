/* Spectral Monte Carlo volumetric path tracing. See include/atmos/path.h and docs/path.md.
 *
 * A camera path carries up to PATH_B wavelengths of the scene's set (all of them in rgb
 * mode; in spectral mode a uniformly chosen hero and the wavelengths a quarter, half and
 * three quarters of the set away, each counted with weight N/PATH_B, so every wavelength
 * is estimated without bias). Its segments:
 *
 *   air (everywhere, inside the volume's occupied box too): the atmosphere's
 *       transmittance and single-scattered in-scatter (atmosphere.h), minus the volume's
 *       shadow on it (path_light.c), added along the way;
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
 *       (forced single scattering), in place of the next-event estimates at its first event;
 *   the ground (the atmosphere's): Lambertian; the sun's light (shadowed by the volume) by
 *       next-event estimation, then a cosine-distributed bounce;
 *   escape: the air's in-scatter from the escape point out of the atmosphere and what lies
 *       beyond (a vacuum's background); the sun's disk only on a path that has not
 *       scattered (after a volume event the sun is counted by the two weighted estimates at
 *       the event, after a ground bounce by next-event estimation alone).
 *
 * In a scene of point lights, spotlights, fog and objects the path is path_lamps.c's.
 *
 * Without a volume, over a planet (the DOBASHI and SPHERICAL kinds), a path is instead the
 * atmosphere's own Monte Carlo reference (trace_reference): the reference sky.
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

#include <string.h>

/* Where a camera path is and what it carries. */
typedef struct {
    double w[PATH_B], p[3], d[3];
    double S[PATH_B];    /* the direction strategies' densities so far (path_event) */
    int primary;         /* no scattering yet: the camera ray */
    int depth, order, hero;
    double esc_wt;       /* the weight of the air's light at the path's escape: after a volume event
                            the continuation's share against next-event estimation of the sky */
    double hprev;        /* the path's share of the sun at its next volume event (aureole) */
    int met;             /* the camera ray's forced estimate was made */
} path_state;

/* After a volume event: the new direction, drawn with the hero's strategy (its wavelength or
 * the fallback), a field in proportion to its scattering there, cos(theta) by the table's
 * inverse CDF; the weights of the multiple importance sampling, and the sun's disk when the
 * direction lands in it. Returns 0 when the path ends. */
static int new_direction(const path_run *R, path_state *s, const path_event *ev, const double *E, int lit, int pa_on,
                         double q_rr)
{
    const path_job *J = R->J;
    const path_phase *P = J->ph;
    const int m = R->b->m, nf = J->med->nf;
    if (s->hero < 0) {
        s->hero = m > 1 ? (int)(atmos__stream_u(R->r) * m) : 0;
        if (s->hero >= m) s->hero = m - 1;
    }
    const int j = ev->g[s->hero];
    const int f = atmos__path_pick_field(ev->e, j, nf, R->r);
    double mu = atmos__path_phase_sample(P, f, R->b->k[j], atmos__stream_u(R->r));
    double nd[3];
    atmos__path_around(s->d, mu, 2.0 * ATMOS_PI * atmos__stream_u(R->r), nd);
    const int chroma = nf > 1 || !P->gray[0];
    const int to_sun = lit && atmos__dot3(nd, J->sun) >= J->cos_sun;
    s->esc_wt = 1.0;
    const double hcur = s->hprev;
    s->hprev = 1;
    if ((chroma && m > 1) || to_sun || J->env || pa_on) {
        double pk[PATH_B], pj[PATH_B];
        atmos__path_phase_mix(P, R->b, nf, ev->e, mu, pk);
        const double mean = atmos__path_strategies(m, s->S, ev->g, pk, pj);
        if (!(mean > 0)) return 0;
        for (int i = 0; i < m; i++) {
            s->w[i] *= pk[i] / mean;
            s->S[i] *= pj[i] / mean;
        }
        if (pa_on) {
            const double c = q_rr * mean;
            s->hprev = c / (c + atmos__path_aureole_pdf(J, R->b, ev->e, nd));
        }
        if (J->env) {
            const double pe = atmos__path_env_pdf(J->env, nd);
            s->esc_wt = ev->q * mean / (pe + ev->q * mean);
        }
        if (to_sun) {
            /* The continuation found the sun's disk: its share of the sun's radiance
             * E / sun_omega, through the volume's transmittance. */
            double T[PATH_B];
            const double wm = (1.0 - atmos__path_mis_nee(J, ev->q * mean)) * hcur;
            atmos__path_shadow(R, s->p, nd, T);
            for (int i = 0; i < m; i++) atmos__path_add(R, i, s->w[i] * E[i] / J->sun_omega * T[i] * wm, s->order);
        }
    }
    memcpy(s->d, nd, sizeof s->d);
    s->primary = 0;
    return 1;
}

/* A real scattering event in the volume at distance t along the path (densities dens there;
 * forced: the camera ray's single scattering was estimated by forced single scattering).
 * Returns 0 when the path ends. */
static int volume_event(const path_run *R, path_state *s, double t, const float *dens, int forced)
{
    const path_job *J = R->J;
    const int m = R->b->m;
    R->cnt->events++;
    s->order++;
    for (int a = 0; a < 3; a++) s->p[a] += t * s->d[a];
    path_scatter e;
    int g[PATH_B];
    const int ne = atmos__path_scatter_at(J, R->b, dens, &e, g);
    /* Can the path go on from here (depth limit), and with which probability does it survive
     * the roulette below: the continuation's share of the multiple importance sampling of
     * the sun. */
    const int at_limit = J->max_depth && s->depth + 1 >= J->max_depth;
    const int goes_on = ne > 0 && !at_limit;
    if (ne > 0 && at_limit && J->depth_default) R->cnt->cut++;
    double q_rr = 0;
    if (goes_on)
        for (int i = 0; i < m; i++)
            if (s->w[i] > q_rr) q_rr = s->w[i];
    if (q_rr > 1) q_rr = 1;
    const double q_mis = forced ? (J->max_depth == 1 ? 0.0 : 1.0) : q_rr;
    const path_event ev = {{s->p[0], s->p[1], s->p[2]}, {s->d[0], s->d[1], s->d[2]}, s->w, &e, s->S, g, q_mis, s->order};
    double E[PATH_B];
    atmos__path_sunlight(R, s->p, E);
    const int lit = atmos__path_sun_lit(R, s->w, E);
    if (ne && !forced) atmos__path_nee(R, &ev, lit ? E : NULL, s->hprev);
    if (!goes_on) return 0;
    /* The sun at the next event through the forward peak: see atmos__path_aureole. */
    const int pa_on = J->aureole && lit;
    if (pa_on) {
        path_event ea = ev;
        ea.q = q_rr;
        atmos__path_aureole(R, &ea);
    }
    s->depth++;
    if (!atmos__path_roulette(s->w, m, R->r)) return 0;
    return new_direction(R, s, &ev, E, lit, pa_on, q_rr);
}

/* The path's crossing of the volume's box along its ray (index space q + t qd, [t0, t1]):
 * the air before it, forced single scattering of a camera ray, the free flight, the air
 * inside. Returns -1 when the path ends, 1 after a volume event (the path goes on from
 * there), 0 when it passes through (then p is on the box's far side). */
static int cross_volume(const path_run *R, path_state *s, const double q[3], const double qd[3], double t0, double t1)
{
    const path_job *J = R->J;
    if (t0 > 0) {
        atmos__path_air_scatter(R, s->p, s->d, t0, s->w, 1.0, s->order, NULL);
        atmos__path_air_transmit(R, s->p, s->d, t0, s->w);
    }
    double t, ws[PATH_B];
    float dens[PATH_F];
    memcpy(ws, s->w, sizeof ws);
    const int forced = J->forced && s->primary && atmos__path_forced_single(R, s->p, s->d, q, qd, t0, t1, s->w);
    s->met |= forced;
    const int ev = atmos__path_free_flight(J->med, q, qd, t0, t1, R->b, s->w, R->r, &t, dens, &R->cnt->tentative);
    /* The air inside the box: its light (shadowed by the volume) over the whole crossing,
     * its transmittance up to where the flight ends. */
    const double ps[3] = {s->p[0] + t0 * s->d[0], s->p[1] + t0 * s->d[1], s->p[2] + t0 * s->d[2]};
    const air_view v = {q, qd, t0};
    atmos__path_air_scatter(R, ps, s->d, t1 - t0, ws, 1.0, s->order, &v);
    atmos__path_air_transmit(R, ps, s->d, (ev > 0 ? t : t1) - t0, s->w);
    if (ev < 0) return -1;
    if (ev > 0) return volume_event(R, s, t, dens, forced) ? 1 : -1;
    for (int a = 0; a < 3; a++) s->p[a] += t1 * s->d[a];
    return 0;
}

/* The Lambertian ground at distance K along the path: the air on the way, the sun's light
 * (next-event estimation, shadowed by the volume), then a cosine-distributed bounce about the
 * ground's normal. Returns 0 when the path ends. */
static int ground(const path_run *R, path_state *s, double K)
{
    const path_job *J = R->J;
    const int m = R->b->m;
    double n[3];
    atmos__path_air_transmit(R, s->p, s->d, K, s->w);
    for (int a = 0; a < 3; a++) s->p[a] += K * s->d[a];
    atmos__atm_ground_hit(J->atm, s->p, n);
    if (!(J->albedo > 0)) return 0;
    R->cnt->events++;
    double E[PATH_B];
    atmos__path_sunlight(R, s->p, E);
    int lit = 0;
    for (int i = 0; i < m; i++) lit |= s->w[i] * E[i] > 0;
    if (lit) {
        double ds[3], T[PATH_B];
        atmos__path_sample_sun(R, ds);
        const double cs = atmos__dot3(ds, n);
        if (cs > 0) {
            atmos__path_shadow(R, s->p, ds, T);
            for (int i = 0; i < m; i++) atmos__path_add(R, i, s->w[i] * J->albedo / ATMOS_PI * cs * E[i] * T[i], s->order);
        }
    }
    if (J->max_depth && ++s->depth >= J->max_depth) {
        if (J->depth_default) R->cnt->cut++;
        return 0;
    }
    for (int i = 0; i < m; i++) s->w[i] *= J->albedo;
    if (!atmos__path_roulette(s->w, m, R->r)) return 0;
    const double u1 = atmos__stream_u(R->r);
    atmos__path_cosine(n, u1, atmos__stream_u(R->r), s->d);
    s->primary = 0;
    s->esc_wt = 1.0;
    s->hprev = 1;
    return 1;
}

/* The path leaves along its ray: the air out of the atmosphere, what lies beyond, the sun's
 * disk on a camera ray. */
static void escape(const path_run *R, const path_state *s)
{
    const path_job *J = R->J;
    const int m = R->b->m;
    if (J->bg != 0)
        for (int i = 0; i < m; i++) atmos__path_add(R, i, s->w[i] * J->bg * s->esc_wt, s->order);
    if (s->primary && J->disk_visible && atmos__dot3(s->d, J->sun) >= J->cos_sun) {
        double E[PATH_B];
        atmos__path_sunlight(R, s->p, E);
        for (int i = 0; i < m; i++) R->L[i] += s->w[i] * E[i] / J->sun_omega;
    }
}

/* A planet's air without a volume: the atmosphere's Monte Carlo reference (every order of
 * scattering; atmos__atm_reference_walk), one walk per carried wavelength, at most the
 * scene's max_depth scatterings, and the sun's disk on the camera ray as escape() adds it. */
static void trace_reference(const path_run *R, const double o[3], const double d[3])
{
    const path_job *J = R->J;
    const int max_order = J->depth_default ? 0 : J->max_depth;
    for (int i = 0; i < R->b->m; i++)
        R->L[i] = atmos__atm_reference_walk(J->atm, o, d, J->sun, R->b->k[i], max_order, R->r);
    if (J->disk_visible && atmos__dot3(d, J->sun) >= J->cos_sun && isinf(atmos_atmosphere_ground_distance(J->atm, o, d))) {
        double E[PATH_B];
        atmos__path_sunlight(R, o, E);
        for (int i = 0; i < R->b->m; i++) R->L[i] += E[i] / J->sun_omega;
    }
}

int atmos__path_trace(const path_job *J, const path_bundle *b, const double o[3], const double d0[3], atmos__stream *r,
                      double *L, double *Lo, path_counts *cnt)
{
    if (J->lamps) return atmos__path_trace_lamps(J, b, o, d0, r, L, Lo, cnt);
    const path_run R = {J, b, r, cnt, L, Lo};
    path_state s = {.primary = 1, .hero = -1, .esc_wt = 1.0, .hprev = 1};
    memcpy(s.p, o, sizeof s.p);
    memcpy(s.d, d0, sizeof s.d);
    for (int i = 0; i < b->m; i++) s.w[i] = 1, L[i] = 0, Lo[i] = 0, s.S[i] = 1;
    if (J->reference) {
        trace_reference(&R, o, d0);
        return 0;
    }
    for (int guard = 0; guard < 1 << 24; guard++) {
        /* a path of thousands of events in an optically huge medium can outlast the budget */
        if ((guard & 15) == 15 && J->deadline < INFINITY && atmos__now() >= J->deadline) return PATH_ABANDONED;
        double K = atmos_atmosphere_ground_distance(J->atm, s.p, s.d);
        double q[3], qd[3], t0 = 0, t1 = 0;
        if (J->med) {
            atmos__path_to_index(J->med, s.p, s.d, q, qd);
            if (atmos__path_clip(J->med, q, qd, K, &t0, &t1)) {
                const int c = cross_volume(&R, &s, q, qd, t0, t1);
                if (c < 0) return s.order > 0 || s.met;
                if (c > 0) continue;
                /* through the volume: on from its far side */
                K = atmos_atmosphere_ground_distance(J->atm, s.p, s.d);
                if (K <= 1e-9 * (1.0 + fabs(s.p[1]))) K = 0; /* the box reached the ground */
            }
        }
        atmos__path_air_scatter(&R, s.p, s.d, K, s.w, s.esc_wt, s.order, NULL);
        if (isinf(K)) {
            escape(&R, &s);
            return s.order > 0 || s.met;
        }
        if (!ground(&R, &s, K)) return s.order > 0 || s.met;
    }
    return s.order > 0 || s.met;
}
