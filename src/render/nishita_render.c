/* The Nishita renderer's eye rays (nishita_internal.h; Nishita et al. 1996 §3.4 step 3, Eq. 1):
 * per pixel a ray through the volume's box in steps of a fraction of a render voxel; at each
 * sample the first order exactly (the fields' own phase functions at the ray's angle to the
 * sun, the sunlight attenuated by the column density stored per render voxel) and the
 * light field's orders 2-3 and sky light (per unit scattering coefficient) interpolated and
 * multiplied by the sample's scattering coefficient; the sky behind attenuated by the volume
 * and the air in front of the volume added as the slice renderer's composite does, less what the
 * volume's shadow takes from the air's single scattering (nishita_air.c). With edge_aa
 * the pixels at the volume's edges (edge_aa.c, as the slice renderer's) take four rays. */
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "render/dm_two_pop.h"
#include "render/edge_aa.h"
#include "render/nishita_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const atmos__nishita_plan *np;
    const atmos_atmosphere *atm;
    const atmos_camera *cam;
    double sun_w[3], eye_g[3], sun_g[3];
    int air_shadow; /* the volume's shadow on the air (the scene's "air_shadows"; nishita_air.c) */
    double E[ATMOS_MAX_WAVELENGTHS]; /* the sunlight at the box's centre */
    double dt;                       /* step, m */
    int use_field;
    int diffuse;                     /* the diffuse field and the scattered beam (dfield.h) */
    const atmos__lfield *mc;         /* the Monte Carlo field (nishita_mc.c), NULL: none */
    int tms; /* delta-M (TMS, Nakajima & Tanaka 1988): the first order, its exact phase, in the scaled
                medium too: sigma_s p E exp(-tau*_sun), attenuated toward the eye by sigma_t* */
    float sig[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* extinction of the first order and the eye
                                                                  rays (truncated with mc) */
    /* with tms, the first order of two populations (dm_two_pop.c): the beam's share exp(-sum col
     * turn) the delta-M peak has not turned scatters with the full phase, the rest with sigma_s*
     * times the scaled phase p* of moments chi */
    double chi[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS][4];
    float turn[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS];
} rjob;

/* Ams_2 of each field at scattering angle acos(mu) (the beam's scattered light, once scattered
 * before, scattered toward the eye), per wavelength. */
static void ams2_at(const stables *t, double mu, double out[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS])
{
    const double th = acos(mu > 1 ? 1 : (mu < -1 ? -1 : mu)) * ATMOS_RAD2DEG;
    for (int f = 0; f < t->nf; f++) {
        int a = 0;
        float wt;
        atmos__angle_locate(t->grid[f], t->ng[f], th, &a, &wt);
        for (int w = 0; w < t->n; w++) {
            const float *p0 = t->ams[f] + ((size_t)a * t->no + 1) * t->n + w, *p1 = p0 + (size_t)t->no * t->n;
            out[f][w] = (1.0 - wt) * *p0 + wt * *p1;
        }
    }
}

/* What the diffuse field and the scattered beam add at render-voxel point u (per wavelength,
 * W m^-3 sr^-1 nm^-1, into S) and the field's weight there (fade: 1 where the medium is thick). */
static void diffuse_at(const atmos__nishita_plan *np, const float *u, const float *dens,
                       double ams2[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS], double *S, float *fade)
{
    const atmos__dfield *df = &np->df;
    const int n = np->n, nf = np->nf, q = df->vq;
    float view[ATMOS_VOLUME_MAX_FIELDS * ATMOS_MAX_WAVELENGTHS], beam[ATMOS_MAX_WAVELENGTHS];
    atmos__lfield_sample(&df->field, df->view, nf * q, u[0], u[1], u[2], view);
    atmos__lfield_sample(&df->field, df->beam, n, u[0], u[1], u[2], beam);
    atmos__lfield_sample(&df->field, df->fade, n, u[0], u[1], u[2], fade);
    for (int w = 0; w < n; w++) {
        double d = 0, b = 0;
        for (int f = 0; f < nf; f++) d += dens[f] * view[f * q + w], b += dens[f] * np->tab.sca[f][w] * ams2[f][w];
        S[w] = (d > 0 ? d : 0) + (beam[w] > 0 ? b * beam[w] : 0);
    }
}

/* The volume's radiance L and transmittance T along direction d (world) from the eye (delta-M
 * scaled with the field's tms), and the distance th of its light's centre (the
 * transmittance-weighted mean). 0 if the ray misses. */
static int march(const rjob *J, const double dw[3], double *L, double *T, double *th)
{
    const atmos__nishita_plan *np = J->np;
    const sgrid *g = &np->g;
    const int n = np->n, nf = np->nf;
    double dg[3], t0, t1;
    atmos__vol_dir_to_frame(&np->x, dw, dg);
    if (!atmos__ray_box(J->eye_g, dg, g->box_lo, g->box_hi, &t0, &t1) || !(t1 > t0)) return 0;
    if (t0 < 0) t0 = 0;
    double pf[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS];
    const double mu = atmos__dot3(dw, J->sun_w); /* cos of the angle between the sunlight's and the ray's travel */
    double ps[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* with tms: sigma_s* p*(mu) */
    for (int f = 0; f < nf; f++)
        for (int w = 0; w < n; w++) {
            pf[f][w] = atmos_phase_table_eval(np->phase[f], w, mu);
            ps[f][w] = J->tms ? np->mc_sca[f][w] * atmos__dm_phase3(J->chi[f][w], 0, mu) : 0;
        }
    double ams2[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS];
    if (J->diffuse) ams2_at(&np->tab, mu, ams2);
    double Tm[ATMOS_MAX_WAVELENGTHS]; /* the Monte Carlo field's transmittance (sig_ms) */
    for (int w = 0; w < n; w++) L[w] = 0, T[w] = 1, Tm[w] = 1;
    const int steps = (int)ceil((t1 - t0) / J->dt);
    const double dt = (t1 - t0) / steps;
    double wsum = 0, tsum = 0;
    for (int s = 0; s < steps; s++) {
        const double t = t0 + (s + 0.5) * dt;
        double u[3];
        for (int a = 0; a < 3; a++) u[a] = (J->eye_g[a] + t * dg[a]) * g->sc + g->off[a];
        float dens[ATMOS_VOLUME_MAX_FIELDS], col[ATMOS_VOLUME_MAX_FIELDS], Lf[ATMOS_MAX_WAVELENGTHS];
        atmos__nishita_grid_at(g, g->v, nf, u[0], u[1], u[2], dens);
        float any = 0;
        for (int f = 0; f < nf; f++) any += dens[f];
        if (!(any > 0)) continue;
        atmos__nishita_grid_at(g, np->col, nf, u[0], u[1], u[2], col);
        if (J->use_field) atmos__lfield_sample(&np->field, np->field.L, n, (float)u[0], (float)u[1], (float)u[2], Lf);
        float Lmc[ATMOS_MAX_WAVELENGTHS];
        if (J->mc) atmos__lfield_sample(J->mc, J->mc->L, n, (float)u[0], (float)u[1], (float)u[2], Lmc);
        double Sd[ATMOS_MAX_WAVELENGTHS]; /* n of them set a sample, not all 128 */
        float fade[ATMOS_MAX_WAVELENGTHS];
        for (int w = 0; w < n; w++) Sd[w] = 0, fade[w] = 0.0f;
        if (J->diffuse) {
            const float uf[3] = {(float)u[0], (float)u[1], (float)u[2]};
            diffuse_at(np, uf, dens, ams2, Sd, fade);
        }
        double Tmax = 0;
        for (int w = 0; w < n; w++) {
            double st = 0, ss = 0, s1 = 0, s1t = 0, nt = 0, tau = 0, sm = 0, Sm = 0;
            for (int f = 0; f < nf; f++) {
                st += dens[f] * J->sig[f][w], ss += dens[f] * np->sca[f][w];
                s1 += dens[f] * np->sca[f][w] * pf[f][w];
                if (J->tms) s1t += dens[f] * ps[f][w], nt += col[f] * J->turn[f][w];
                tau += col[f] * (J->tms ? np->mc_sig_ms[f][w] : J->sig[f][w]);
                if (J->mc)
                    sm += dens[f] * np->mc_sig_ms[f][w], Sm += dens[f] * np->mc_sca[f][w] * (Lmc[w] > 0 ? Lmc[w] : 0);
            }
            if (J->tms) { /* the two populations: the unturned share e^-nt, the turned one */
                const double wu = exp(-nt);
                s1 = wu * s1 + (1 - wu) * s1t;
            }
            /* the field's radiance is per unit truncated scattering, sig_s (1 - f); where the
             * diffuse field is on (fade > 0) it takes the place of the orders 2-3 and the sky */
            double S = s1 * J->E[w] * exp(-tau) + Sd[w] +
                       (J->use_field ? (1.0 - fade[w]) * ss * (1 - np->trunc[w]) * (Lf[w] > 0 ? Lf[w] : 0) : 0);
            if (J->tms) Sm += S, S = 0;
            else S += Sm; /* without delta-M the field's medium is the eye ray's: one transmittance */
            const double a = st > 0 ? -expm1(-st * dt) : 0;
            L[w] += st > 0 ? T[w] * S / st * a : 0;
            if (w == n / 2) wsum += T[w] * a, tsum += t * T[w] * a;
            T[w] *= 1 - a;
            Tmax = T[w] > Tmax ? T[w] : Tmax;
            if (J->tms) { /* delta-M: the Monte Carlo field in the medium its photons saw, sig*, its own Tm */
                const double am = sm > 0 ? -expm1(-sm * dt) : 0;
                L[w] += sm > 0 ? Tm[w] * Sm / sm * am : 0;
                Tm[w] *= 1 - am;
                Tmax = Tm[w] > Tmax ? Tm[w] : Tmax;
            }
        }
        if (Tmax < 1e-5) break;
    }
    *th = wsum > 0 ? tsum / wsum : 0.5 * (t0 + t1);
    /* delta-M: what lies behind is seen through sig*, the peak's share passing straight on. This
     * holds for any delta-M field, the photons' (--nishita-mc-delta-m) as the do sweeps': the
     * field is built counting the peak's share f of each scattering as not scattered, so none of
     * its radiance is that share; seen through the full sig_t the background would lose that
     * share, and the field would not give it back. Whether the field also carries the sky's light
     * (the do sweeps do, the photons do not) changes what it adds, not this transmittance (as
     * the slice renderer's background with "do"). */
    if (J->tms) memcpy(T, Tm, sizeof(double) * n);
    return 1;
}

/* The volume's shadow on the air along the ray d (world) taken from the air in front of the
 * volume's light (front, the eye to th) and from the sky image's value B (the whole ray to the
 * volume's far side or the ground at tg), as the slice renderer's composite over its shadowed
 * sky image (slice_shadow.c): with the sun ahead the air between the eye and a cloud lies in
 * its shadow, and unshadowed it lit the cloud's deep pixels (docs/lightfield.md). Taken in
 * proportion to the volume's opacity 1 - T along the ray: the rays that miss the volume keep
 * the sky image's unshadowed air, so those that graze it join them without a seam (the shafts
 * beside a cloud are not drawn). */
static void air_shadow(const rjob *J, const double d[3], double th, double tg, const double *T, double *front,
                       double *B)
{
    const atmos__nishita_plan *np = J->np;
    const float(*sig)[ATMOS_MAX_WAVELENGTHS] = J->tms ? np->mc_sig_ms : J->sig;
    double dg[3], t0, t1, Df[ATMOS_MAX_WAVELENGTHS], Db[ATMOS_MAX_WAVELENGTHS];
    atmos__vol_dir_to_frame(&np->x, d, dg);
    if (!atmos__ray_box(J->eye_g, dg, np->g.box_lo, np->g.box_hi, &t0, &t1)) return;
    const double tb = t1 < tg ? t1 : tg;
    atmos__nishita_air_shadow(np, J->atm, J->cam->position, d, J->eye_g, dg, J->sun_w, J->sun_g, sig, 0, th, Df);
    atmos__nishita_air_shadow(np, J->atm, J->cam->position, d, J->eye_g, dg, J->sun_w, J->sun_g, sig, th, tb, Db);
    for (int c = 0; c < np->n; c++) {
        const double o = T[c] < 1 ? 1 - T[c] : 0, f = o * Df[c], b = o * (Df[c] + Db[c]);
        front[c] = front[c] > f ? front[c] - f : 0;
        B[c] = B[c] > b ? B[c] - b : 0;
    }
}

/* The ray through image point (x, y): the volume over the sky image's value px (B = front +
 * T_front back) into out: front + T_front L + T (B - front), the air's part "front" in front of
 * the volume's light; px itself where the ray misses the volume. */
static void shade_ray(const rjob *J, double x, double y, const float *px, double *out)
{
    double d[3], L[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS], th;
    const int n = J->np->n;
    for (int c = 0; c < n; c++) out[c] = px[c];
    if (!atmos_camera_ray(J->cam, x, y, d) || !march(J, d, L, T, &th)) return;
    double front[ATMOS_MAX_WAVELENGTHS], Tf[ATMOS_MAX_WAVELENGTHS];
    const double tg = atmos_atmosphere_ground_distance(J->atm, J->cam->position, d);
    if (th > tg) th = tg;
    atmos_atmosphere_inscatter(J->atm, J->cam->position, d, th, J->sun_w, front);
    atmos_atmosphere_transmittance(J->atm, J->cam->position, d, th, Tf);
    double B[ATMOS_MAX_WAVELENGTHS];
    for (int c = 0; c < n; c++) B[c] = px[c];
    if (J->air_shadow) air_shadow(J, d, th, tg, T, front, B);
    for (int c = 0; c < n; c++) {
        const double r = front[c] + Tf[c] * L[c] + T[c] * (B[c] - front[c]);
        out[c] = isfinite(r) && r > 0 ? r : 0.0;
    }
}

/* Pixel (x, y): one ray through its centre, or at the volume's edges (edge set) the mean of four
 * through the centres of its quarters, each over the sky image's value at the pixel (as the
 * slice renderer's edge_aa; the sky is smooth across a pixel). */
static void shade(const rjob *J, int x, int y, int edge, float *px)
{
    const int n = J->np->n;
    double o[ATMOS_MAX_WAVELENGTHS], sum[ATMOS_MAX_WAVELENGTHS] = {0};
    if (!edge) {
        shade_ray(J, x + 0.5, y + 0.5, px, o);
        for (int c = 0; c < n; c++) px[c] = (float)o[c];
        return;
    }
    for (int q = 0; q < 4; q++) {
        shade_ray(J, x + 0.25 + 0.5 * (q & 1), y + 0.25 + 0.5 * (q >> 1), px, o);
        for (int c = 0; c < n; c++) sum[c] += o[c];
    }
    for (int c = 0; c < n; c++) px[c] = (float)(0.25 * sum[c]);
}

/* The edge pixels of region r (edge_aa.c; NULL: edge_aa off), from the plain cross-sections at
 * the middle wavelength along the centre rays. */
static const unsigned char *edges(atmos__nishita_plan *np, const rjob *J, double lim, const atmos__rect *r,
                                  int threads)
{
    if (!(lim > 0)) return NULL;
    atmos__edge_desc e = {&np->g, &np->x, J->atm, J->cam, {J->eye_g[0], J->eye_g[1], J->eye_g[2]}, {0}, lim,
                          NULL, NULL};
    for (int f = 0; f < np->nf; f++) e.sig[f] = np->sig[f][np->n / 2];
    return atmos__edge_flags(&e, r, &np->edge, &np->edge_cap, threads);
}

atmos_status atmos__nishita_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out)
{
    atmos__nishita_plan *np = p->nishita;
    atmos_status st = atmos__sky_render(p->ctx, p->atm, v, r, out, p->sky_keep);
    if (st != ATMOS_OK || !np->g.v) return st;
    const int threads = atmos__threads(p->ctx);
    double sun_g[3], rel[3], cen[3], cw[3];
    atmos__vol_dir_to_frame(&np->x, v->sun, sun_g);
    atmos__nishita_columns(np, sun_g, threads);
    if (!np->col_valid) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the sunlight");
    /* the Monte Carlo field holds every order above the first of the sunlight (by discrete ordinates,
     * with the sky on, the sky's and the ground's light of every order too, nishita_do.c): it
     * replaces the orders 2-3, the sky elements and the diffuse field (counted twice otherwise) */
    const int use_field = !np->mc && (p->scene.nishita.orders > 1 || p->scene.nishita.sky);
    if (use_field && (st = atmos__nishita_field_update(p, v->sun, v->cam.position)) != ATMOS_OK) return st;
    rjob J;
    memset(&J, 0, sizeof J);
    J.np = np, J.atm = p->atm, J.cam = &v->cam, J.use_field = use_field, J.diffuse = np->diffuse && !np->mc;
    memcpy(J.sun_w, v->sun, sizeof J.sun_w), memcpy(J.sun_g, sun_g, sizeof J.sun_g);
    J.air_shadow = p->scene.slice.air_shadows && !v->no_air_shadows &&
                   atmos_atmosphere_get_kind(p->atm) != ATMOS_ATMOSPHERE_VACUUM;
    for (int a = 0; a < 3; a++) rel[a] = v->cam.position[a] - np->x.org[a], cen[a] = 0.5 * (np->g.box_lo[a] + np->g.box_hi[a]);
    atmos__vol_dir_to_frame(&np->x, rel, J.eye_g);
    if (J.diffuse) {
        int built;
        if ((st = atmos__dfield_update(p->ctx, &np->df, p->atm, v->sun, v->warm_field, 1, &built)) != ATMOS_OK) return st;
        double eu[3]; /* the eye in render-voxel coordinates */
        for (int a = 0; a < 3; a++) eu[a] = J.eye_g[a] * np->g.sc + np->g.off[a];
        atmos__dfield_view(&np->df, eu, threads);
    }
    atmos__vol_frame_to_point(&np->x, cen, cw);
    atmos_atmosphere_sunlight(p->atm, cw, v->sun, J.E);
    J.dt = p->scene.nishita.step_scale_pct / 100.0 / np->g.sc;
    memcpy(J.sig, np->mc ? np->mc_sig : np->sig, sizeof J.sig);
    if (np->mc) {
        double dc[3], ot[3];
        if (!atmos_camera_ray(&v->cam, 0.5 * out->width, 0.5 * out->height, dc))
            return atmos__error(p->ctx, ATMOS_E_INVALID_ARG, "render nishita: no central view direction");
        for (int a = 0; a < 3; a++) ot[a] = -dc[a];
        if ((st = atmos__nishita_mc_update(p, np, v->sun, ot, v->cam.position, J.E, threads, v->warm_field)) != ATMOS_OK) return st;
        J.mc = atmos__nishita_mc_field(np);
        J.tms = atmos__nishita_mc_dm_phase(np, J.chi, J.turn);
    }
    const double lim = p->scene.nishita.edge_aa;
    const unsigned char *edge = edges(np, &J, lim, r, threads);
    if (lim > 0 && !edge) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the edge pixels");
    const int W = out->width, C = out->channels;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int y = r->y0; y < r->y1; y++)
        for (int x = r->x0; x < r->x1; x++)
            shade(&J, x, y, edge && edge[(size_t)y * W + x], out->pixels + ((size_t)y * W + x) * C);
    return ATMOS_OK;
}

void atmos__nishita_describe(const atmos_plan *p, char *buf, size_t cap)
{
    const atmos__nishita_plan *np = p->nishita;
    const atmos_scene_nishita *s = &p->scene.nishita;
    snprintf(buf, cap, "orders 1-%d, ratio %g, %d order-3 paths per cell, sky %s; field %dx%dx%d cells of %d voxels; "
             "patterns: order 2 %d paths, order 3 %d of %lld%s",
             s->orders, s->ratio, s->paths, s->sky ? "on" : "off", np->med.c[0], np->med.c[1], np->med.c[2], np->s,
             np->stats.n2, np->stats.n3, np->stats.n3_space, np->diffuse ? "; diffuse field" : "");
    if (np->mc) {
        const atmos__lfield *F = atmos__nishita_mc_field(np);
        const size_t l = strlen(buf);
        if (s->do_field)
            atmos__nishita_do_describe(np, buf, cap);
        else
            snprintf(buf + l, cap - l, "; Monte Carlo field of %d thousand photons, %dx%dx%d cells of %d voxels, %.3f s",
                     s->mc_kphotons, F->c[0], F->c[1], F->c[2], F->s, np->mc_s);
    }
    const size_t l = strlen(buf);
    if (s->edge_aa > 0) snprintf(buf + l, cap - l, "; four eye rays at the volume's edges (edge_aa %g)", s->edge_aa);
}
