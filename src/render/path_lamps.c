/* The path tracer in a scene of point lights, spotlights, fog and objects (docs/path.md,
 * "Lights, fog and objects"): the ground truth of the beam renderer (docs/beams.md).
 *
 * A camera path walks through the fog (homogeneous: sigma_s, sigma_a, a Henyey-Greenstein
 * phase function, filling all space) and between the objects (opaque, Lambertian, two-sided,
 * through the meshes' bounding volume hierarchies). Per segment, from the path's point to the
 * first object ahead (or to infinity):
 *   - the lights' single scattering in the fog along it: per light one point by equi-angular
 *     sampling on the part inside a spot's cone (fog_lights), then next-event estimation there;
 *   - the object at its end: next-event estimation of every light, weighted by the fog's
 *     transmittance exp(-sigma_t T);
 *   - next-event estimation (nee) is the light's intensity toward the point (light/lamp.h: the
 *     spot's falloff, the spectrum, the projected image), 1 / r^2, exp(-sigma_t r), a shadow
 *     ray through the meshes, times the phase function (fog) or albedo cos / pi (surface).
 *     The lights are points (delta lights): next-event estimation is the only way to see them;
 *   - then, unless the path has path.max_depth vertices (1: single scattering, what the beam
 *     renderer computes), the continuation: the distance to the next scattering drawn from
 *     sigma_s exp(-sigma_s t) with the absorption exp(-sigma_a t) carried in the weights (a
 *     pure absorber needs no random number), a new direction from the phase function in the
 *     fog or cosine-distributed about the normal at the object (weight times the albedo),
 *     Russian roulette (roulette(): on the weights, and from the 4th event on the lights'
 *     nearness, so that paths in a fog that absorbs nothing end);
 *   - a path that leaves (no fog, no object ahead) sees the vacuum's uniform background.
 * The sun, the atmosphere's air and a cloud volume are not part of such a scene here
 * (path_plan.c refuses the air, the volume, a fog thinning with height and the beam
 * renderer's sun, all in one error). */
#include "core/vec.h"
#include "render/path_trace.h"

#include <stdlib.h>
#include <string.h>

atmos_status atmos__path_lamps_build(atmos_context *ctx, const atmos_scene *s, const atmos_wavelengths *wl,
                                     path_lamps *L)
{
    memset(L, 0, sizeof *L);
    atmos_status st = atmos__objects_load(ctx, s, wl, &L->obj);
    if (st != ATMOS_OK) return st;
    atmos__objects_warn_dark_lights(ctx, s, &L->obj);
    L->lamp = calloc((size_t)(s->light_count ? s->light_count : 1), sizeof *L->lamp);
    if (!L->lamp) return atmos__error(ctx, ATMOS_E_NOMEM, "render path: out of memory for the lights");
    L->nlamps = s->light_count;
    for (int i = 0; i < s->light_count; i++) {
        atmos__lamp_make(&s->lights[i], wl, &L->lamp[i]);
        if ((st = atmos__lamp_load_image(ctx, s, i, &L->lamp[i])) != ATMOS_OK) return st;
    }
    if ((st = atmos__fog_optics_build(ctx, s, wl, &L->fog)) != ATMOS_OK) return st;
    L->sigma_s = L->fog.sigma_s, L->sigma_a = L->fog.sigma_t - L->fog.sigma_s;
    return ATMOS_OK;
}

void atmos__path_lamps_free(path_lamps *L)
{
    if (!L) return;
    atmos__objects_free(&L->obj);
    atmos__fog_optics_free(&L->fog);
    for (int i = 0; L->lamp && i < L->nlamps; i++) atmos__lamp_free(&L->lamp[i]);
    free(L->lamp);
    memset(L, 0, sizeof *L);
}

/* Next-event estimation toward every light from p, reached along d with weights w: in the
 * fog (n NULL) times the phase function, at a surface (normal n facing the path, albedo
 * alb per carried wavelength, shadow rays leaving from p lifted by off along n) times
 * alb cos / pi. Every light, or only light `only` (>= 0). */
static void nee(const path_run *R, const double p[3], const double d[3], const double *n, const double *alb, double off,
                const double *w, int order, int only)
{
    const path_lamps *P = R->J->lamps;
    const int m = R->b->m;
    const double st = P->sigma_s + P->sigma_a;
    double o[3];
    for (int a = 0; a < 3; a++) o[a] = p[a] + (n ? off * n[a] : 0);
    for (int j = only < 0 ? 0 : only; j < (only < 0 ? P->nlamps : only + 1); j++) {
        const atmos__lamp *l = &P->lamp[j];
        double u[3] = {l->pos[0] - p[0], l->pos[1] - p[1], l->pos[2] - p[2]};
        const double r2 = atmos__dot3(u, u), r = sqrt(r2);
        if (!(r > 0)) continue;
        for (int a = 0; a < 3; a++) u[a] /= r;
        double I[PATH_B];
        if (!(atmos__lamp_toward(l, p, m, R->b->k, I) > 0)) continue;
        const double c = n ? atmos__dot3(n, u) / ATMOS_PI : atmos__fog_phase(&P->fog, atmos__dot3(d, u));
        if (!(c > 0)) continue;
        R->cnt->shadow++;
        if (atmos__objects_hit(&P->obj, o, u, 0, r - off, NULL, NULL)) continue;
        const double f = c * exp(-st * r) / r2;
        for (int i = 0; i < m; i++) atmos__path_add(R, i, w[i] * (alb ? alb[i] : 1) * f * I[i], order);
    }
}

/* The fog's single scattering of every light along p + t d, t in [0, T) (T: the object
 * ahead, or INFINITY), added times w: per light one point drawn by equi-angular sampling
 * (Kulla and Fajardo 2012: density D / ((theta_b - theta_a) (D^2 + (t - t_Q)^2)), D the light's
 * distance from the ray, t_Q its foot), on the part of the ray inside a spot's cone, the
 * transmittance exp(-sigma_t t) to it, then the light at the point as nee() sees it. */
static void fog_lights(const path_run *R, const double p[3], const double d[3], double T, const double *w, int order)
{
    const path_lamps *P = R->J->lamps;
    const int m = R->b->m;
    const double st = P->sigma_s + P->sigma_a;
    for (int j = 0; j < P->nlamps; j++) {
        const atmos__lamp *l = &P->lamp[j];
        const double c[3] = {l->pos[0] - p[0], l->pos[1] - p[1], l->pos[2] - p[2]};
        const double tq = atmos__dot3(c, d);
        const double q[3] = {c[0] - tq * d[0], c[1] - tq * d[1], c[2] - tq * d[2]};
        const double D = fmax(sqrt(atmos__dot3(q, q)), 1e-9 * (1 + fabs(tq)));
        /* beyond optical depth 60 from the ray's start nothing is left (exp(-60) = 9e-27) */
        double a = 0, b = fmin(T, fmax(tq, 0) + D + 60 / st);
        if (!atmos__lamp_clip(l, p, d, &a, &b)) continue;
        const double ta = atan((a - tq) / D), tb = atan((b - tq) / D);
        if (!(tb > ta)) continue;
        const double t = tq + D * tan(ta + atmos__stream_u(R->r) * (tb - ta));
        if (!(t >= a && t <= b)) continue;
        const double pdf = D / ((tb - ta) * (D * D + (t - tq) * (t - tq)));
        const double x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
        double wt[PATH_B];
        const double f = P->sigma_s * exp(-st * t) / pdf;
        for (int i = 0; i < m; i++) wt[i] = w[i] * f;
        nee(R, x, d, NULL, NULL, 0, wt, order, j);
    }
}

/* The lights' nearness at p: sum over the lights of their largest intensity / r^2 (the cone,
 * the fog's extinction and the shadows left out: a smooth stand-in for the light a path
 * from p can still gather, which is all the roulette below asks of it). */
static double nearness(const path_lamps *P, const double p[3])
{
    double a = 0;
    for (int j = 0; j < P->nlamps; j++) {
        const atmos__lamp *l = &P->lamp[j];
        const double u[3] = {l->pos[0] - p[0], l->pos[1] - p[1], l->pos[2] - p[2]};
        a += l->I_max / fmax(atmos__dot3(u, u), 1e-12);
    }
    return a;
}

/* The event order from which roulette() also weighs the lights' nearness: orders 1-3, the
 * bulk of the light in the scenes measured (docs/path.md), are never cut by it. */
#define LAMPS_RR_ORDER 4

/* Russian roulette at the path's depth-th event, at p (0: the path ends). Survival
 * q = min(1, max_k w_k rho), the weights divided by q when it survives, with rho = 1 before
 * LAMPS_RR_ORDER and min(1, A(p) / A_ref) from it on, A the lights' nearness and A_ref its
 * value where the path reached LAMPS_RR_ORDER (*aref, 0 until then). In a fog that absorbs
 * nothing the weights stay 1 and the weights alone would never end a path (it wanders to the
 * depth limit); with rho, a path that has survived to p carries weights ~ A_ref / A(p), so
 * its light there stays of the size of its light at A_ref's point, and a path leaving the
 * lights ends. Unbiased for any q > 0 (A > 0 wherever a light has any intensity). */
static int roulette(const path_run *R, const double p[3], int depth, double *aref, double *w)
{
    const path_lamps *P = R->J->lamps;
    const int m = R->b->m;
    if (!R->J->roulette || depth < LAMPS_RR_ORDER) return atmos__path_roulette(w, m, R->r);
    const double a = nearness(P, p);
    if (depth == LAMPS_RR_ORDER || !(*aref > 0)) *aref = a;
    const double rho = *aref > 0 && a < *aref ? a / *aref : 1.0;
    double q = 0;
    for (int i = 0; i < m; i++)
        if (w[i] > q) q = w[i];
    q *= rho;
    if (!(q > 0)) return 0;
    if (q >= 1) return 1;
    if (atmos__stream_u(R->r) >= q) return 0;
    for (int i = 0; i < m; i++) w[i] /= q;
    return 1;
}

int atmos__path_trace_lamps(const path_job *J, const path_bundle *b, const double o[3], const double d0[3],
                            atmos__stream *r, double *L, double *Lo, path_counts *cnt)
{
    const path_run R = {J, b, r, cnt, L, Lo};
    const path_lamps *P = J->lamps;
    const int m = b->m;
    const double st = P->sigma_s + P->sigma_a;
    double w[PATH_B], p[3], d[3];
    memcpy(p, o, sizeof p);
    memcpy(d, d0, sizeof d);
    for (int i = 0; i < m; i++) w[i] = 1, L[i] = 0, Lo[i] = 0;
    int depth = 0;
    double aref = 0; /* the lights' nearness where roulette() began to weigh it */
    for (int guard = 0; guard < 1 << 24; guard++) {
        if ((guard & 15) == 15 && J->deadline < INFINITY && atmos__now() >= J->deadline) return PATH_ABANDONED;
        atmos_mesh_hit h = {0, 0, {0, 0, 0}};
        int which = 0;
        const int hit = atmos__objects_hit(&P->obj, p, d, 0, INFINITY, &h, &which);
        const double T = hit ? h.t : INFINITY, off = 1e-4 * (1 + fabs(p[0]) + fabs(p[1]) + fabs(p[2]) + (hit ? T : 0));
        double alb[PATH_B], ps[3] = {0, 0, 0};
        if (hit)
            for (int i = 0; i < m; i++) alb[i] = P->obj.albedo[which][b->k[i]];
        for (int a = 0; a < 3 && hit; a++) ps[a] = p[a] + T * d[a];
        /* the lights' direct share of this segment's next event: the fog's single scattering
         * along it and the object's surface at its end, both exactly weighted by the fog's
         * transmittance (the free flight below only continues the path) */
        const int goes_on = !J->max_depth || depth + 1 < J->max_depth;
        if (P->sigma_s > 0) fog_lights(&R, p, d, T, w, depth + 1);
        if (hit) {
            double wt[PATH_B];
            for (int i = 0; i < m; i++) wt[i] = w[i] * exp(-st * T);
            nee(&R, ps, d, h.normal, alb, off, wt, depth + 1, -1);
        } else if (st == 0 && J->bg != 0) {
            for (int i = 0; i < m; i++) atmos__path_add(&R, i, w[i] * J->bg, depth);
        }
        if (!goes_on) {
            if (J->depth_default && (hit || P->sigma_s > 0)) cnt->cut++;
            return depth > 0 || hit || P->sigma_s > 0;
        }
        /* the continuation: the next scattering in the fog or the object's surface */
        const double t = P->sigma_s > 0 ? -log(1 - atmos__stream_u(r)) / P->sigma_s : INFINITY;
        if (isinf(t) && !hit) return depth > 0;
        const double s = fmin(t, T), ab = exp(-P->sigma_a * s);
        for (int i = 0; i < m; i++) w[i] *= ab;
        cnt->events++;
        depth++;
        if (t < T) {
            for (int a = 0; a < 3; a++) p[a] += t * d[a];
            if (!roulette(&R, p, depth, &aref, w)) return 1;
            const double mu = atmos__fog_phase_sample(&P->fog, atmos__stream_u(r));
            double nd[3];
            atmos__path_around(d, mu, 2 * ATMOS_PI * atmos__stream_u(r), nd);
            memcpy(d, nd, sizeof d);
        } else {
            for (int i = 0; i < m; i++) w[i] *= alb[i];
            if (!roulette(&R, ps, depth, &aref, w)) return 1;
            const double u1 = atmos__stream_u(r);
            atmos__path_cosine(h.normal, u1, atmos__stream_u(r), d);
            for (int a = 0; a < 3; a++) p[a] = ps[a] + off * h.normal[a];
        }
    }
    return 1;
}
