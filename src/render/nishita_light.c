/* The Nishita renderer's light field (nishita_internal.h): the medium on the field's grid
 * (nishita_plan.c), the sky elements' radiance (Eq. 7's I_l, from the atmosphere interface:
 * the sky and the lit ground as a view ray from the box's centre sees them, the sun's disk
 * left out, it is the sunlight's), the patterns' phase function, and the solve
 * (src/light/nishita_field.c). */
#include "atmosphere/atmosphere_check.h"
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "render/nishita_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SKY_NMU 64   /* sky directions: SKY_NMU x SKY_NPHI cells of equal solid angle */
#define SKY_NPHI 128
#define SKY_SUB 8    /* cells within SKY_NEAR_DEG of the forward direction: the phase averaged on SKY_SUB^2 points */
#define SKY_NEAR_DEG 20.0
#define SKY_PEAK_DEG 4.0 /* the cone around the forward direction integrated apart */
#define TRUNC_DEG 3.0    /* the orders 2-3: the phase's forward peak cut here (as the path tracer's --truncate) */

/* The medium's phase function at wavelength w and cos(theta) mu: the fields' mixed by their
 * share of the scattering in the mean cell (mix[f]: the fields' mean densities). */
static double mixed_phase(const atmos__nishita_plan *np, const double *mix, int w, double mu)
{
    double num = 0, den = 0;
    for (int f = 0; f < np->nf; f++) {
        const double b = mix[f] * np->sca[f][w];
        if (b > 0) num += b * atmos_phase_table_eval(np->phase[f], w, mu), den += b;
    }
    return den > 0 ? num / den : 1.0 / (4.0 * ATMOS_PI);
}

/* The patterns' phase table: at theta_i = i / 10 degrees the mean of the phase over the
 * directions of theta_i +- 0.05 degrees (weighted by solid angle), so that a forward peak
 * narrower than the table's step (ice crystals, raindrops: hundredths of a degree) keeps its
 * integral instead of being sampled at its top. */
static void pattern_phase(const atmos__nishita_plan *np, const double *mix, int w, float *ph)
{
    enum { SUB = 64 };
    for (int i = 0; i < ATMOS__NISHITA_PHASE_N; i++) {
        const double a = fmax(0.0, (i - 0.5) * 0.1), b = fmin(180.0, (i + 0.5) * 0.1);
        double num = 0, den = 0;
        for (int k = 0; k < SUB; k++) {
            const double t = (a + (b - a) * (k + 0.5) / SUB) * ATMOS_DEG2RAD, s = sin(t);
            num += s * mixed_phase(np, mix, w, cos(t)), den += s;
        }
        ph[i] = (float)(num / den);
    }
    /* truncated: min(P, P(TRUNC_DEG)), renormalised (the peak's share counts as not scattered) */
    const int ic = (int)(TRUNC_DEG * 10 + 0.5);
    for (int i = 0; i < ic; i++) ph[i] = ph[i] < ph[ic] ? ph[i] : ph[ic];
    const double f = np->trunc[w];
    for (int i = 0; i < ATMOS__NISHITA_PHASE_N; i++) ph[i] = (float)(ph[i] / (1 - f));
}

/* The fields' mean densities over the cells that hold any. */
static void mean_mix(const atmos__nishita_plan *np, double *mix);

/* The share of the scattering above the phase's value at TRUNC_DEG inside that cone. */
static double peak_share(const atmos__nishita_plan *np, const double *mix, int w)
{
    enum { STEPS = 4096 };
    const double dt = TRUNC_DEG * ATMOS_DEG2RAD / STEPS, pc = mixed_phase(np, mix, w, cos(TRUNC_DEG * ATMOS_DEG2RAD));
    double f = 0;
    for (int k = 0; k < STEPS; k++) {
        const double t = (k + 0.5) * dt;
        f += fmax(0.0, mixed_phase(np, mix, w, cos(t)) - pc) * 2 * ATMOS_PI * sin(t) * dt;
    }
    return fmin(f, 0.99);
}

void atmos__nishita_truncate(atmos__nishita_plan *np)
{
    double mix[ATMOS_VOLUME_MAX_FIELDS];
    mean_mix(np, mix);
    atmos__lmedium *m = &np->med;
    const int n = np->n;
    for (int w = 0; w < n; w++) np->trunc[w] = peak_share(np, mix, w);
    for (size_t c = 0; c < atmos__lmedium_cells(m); c++)
        for (int w = 0; w < n; w++) {
            const double f = np->trunc[w], ss = m->sig_s[c * n + w];
            m->sig_t[c * n + w] = (float)(m->sig_t[c * n + w] - f * ss), m->sig_s[c * n + w] = (float)(ss * (1 - f));
        }
}

/* The phase integrated over the cone of SKY_PEAK_DEG around the forward direction, per
 * wavelength (fine steps in theta: the peak's integral, however narrow). */
static void peak_integral(const atmos__nishita_plan *np, const double *mix, double *out)
{
    enum { STEPS = 4096 };
    const double dt = SKY_PEAK_DEG * ATMOS_DEG2RAD / STEPS;
    for (int w = 0; w < np->n; w++) {
        out[w] = 0;
        for (int k = 0; k < STEPS; k++) {
            const double t = (k + 0.5) * dt;
            out[w] += mixed_phase(np, mix, w, cos(t)) * 2 * ATMOS_PI * sin(t) * dt;
        }
    }
}

/* The mean of the phase over sky cell (a, b) toward the eye direction ev (grid frame), per
 * wavelength: the cell's centre, or SKY_SUB^2 points near the forward peak. */
static void cell_phase(const atmos__nishita_plan *np, const double *mix, int a, int b, const double ev[3],
                       double *out)
{
    const int n = np->n;
    double dir[3], dg[3];
    const double mu = -1.0 + 2.0 * (a + 0.5) / SKY_NMU, ph = 2.0 * ATMOS_PI * (b + 0.5) / SKY_NPHI;
    dir[0] = sqrt(1 - mu * mu) * cos(ph), dir[1] = mu, dir[2] = sqrt(1 - mu * mu) * sin(ph);
    atmos__vol_dir_to_frame(&np->x, dir, dg);
    const int m = -atmos__dot3(dg, ev) > cos(SKY_NEAR_DEG * ATMOS_DEG2RAD) ? SKY_SUB : 1;
    for (int w = 0; w < n; w++) out[w] = 0;
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            const double u = -1.0 + 2.0 * (a + (i + 0.5) / m) / SKY_NMU, p = 2.0 * ATMOS_PI * (b + (j + 0.5) / m) / SKY_NPHI;
            dir[0] = sqrt(1 - u * u) * cos(p), dir[1] = u, dir[2] = sqrt(1 - u * u) * sin(p);
            atmos__vol_dir_to_frame(&np->x, dir, dg);
            for (int w = 0; w < n; w++) out[w] += mixed_phase(np, mix, w, -atmos__dot3(dg, ev)) / (m * m);
        }
}

/* I_l of Eq. 7: per element l and wavelength, the sky's radiance over the element's
 * directions times the phase toward the eye, integrated over solid angle. Rows of the sky in
 * parallel, summed in order. */
static void sky_elements(const atmos__nishita_plan *np, const atmos_atmosphere *atm, const double cw[3],
                         const double sun_w[3], const double sun_g[3], const double ev[3], const double *mix,
                         double *I, int threads)
{
    const int n = np->n, E = ATMOS__NISHITA_ELEMENTS;
    const double dom = 4.0 * ATMOS_PI / (SKY_NMU * SKY_NPHI);
    double *row = calloc((size_t)SKY_NMU * E * n, sizeof(double));
    memset(I, 0, sizeof(double) * E * n);
    if (!row) return;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int a = 0; a < SKY_NMU; a++)
        for (int b = 0; b < SKY_NPHI; b++) {
            const double mu = -1.0 + 2.0 * (a + 0.5) / SKY_NMU, sn = sqrt(1.0 - mu * mu),
                         ph = 2.0 * ATMOS_PI * (b + 0.5) / SKY_NPHI;
            const double d[3] = {sn * cos(ph), mu, sn * sin(ph)};
            double L[ATMOS_MAX_WAVELENGTHS], P[ATMOS_MAX_WAVELENGTHS], dg[3];
            atmos_atmosphere_hit info;
            atmos_atmosphere_radiance(atm, cw, d, sun_w, L, &info);
            if (info.in_sun_disk) continue;
            atmos__vol_dir_to_frame(&np->x, d, dg);
            if (-atmos__dot3(dg, ev) > cos(SKY_PEAK_DEG * ATMOS_DEG2RAD)) continue; /* the peak's cone, below */
            const int l = atmos__nishita_sky_element(dg, sun_g);
            cell_phase(np, mix, a, b, ev, P);
            for (int w = 0; w < n; w++) row[((size_t)a * E + l) * n + w] += L[w] * P[w] * dom;
        }
    for (int a = 0; a < SKY_NMU; a++)
        for (int i = 0; i < E * n; i++) I[i] += row[(size_t)a * E * n + i];
    free(row);
    /* the cone around the forward direction: the sky straight behind the volume (seen from the
     * eye) times the phase's integral over the cone */
    double back_g[3], back_w[3], L[ATMOS_MAX_WAVELENGTHS], pk[ATMOS_MAX_WAVELENGTHS];
    for (int k = 0; k < 3; k++) back_g[k] = -ev[k];
    atmos__vol_index_to_dir(&np->x, back_g, back_w);
    const double lb = sqrt(atmos__dot3(back_w, back_w));
    for (int k = 0; k < 3; k++) back_w[k] /= lb;
    atmos_atmosphere_hit info;
    atmos_atmosphere_radiance(atm, cw, back_w, sun_w, L, &info);
    if (info.in_sun_disk) return; /* the sun behind the volume: its disk is the sunlight's */
    peak_integral(np, mix, pk);
    const int l = atmos__nishita_sky_element(back_g, sun_g);
    for (int w = 0; w < n; w++) I[l * n + w] += L[w] * pk[w];
}

/* The fields' mean densities over the cells that hold any. */
static void mean_mix(const atmos__nishita_plan *np, double *mix)
{
    const size_t cells = atmos__lmedium_cells(&np->med);
    size_t k = 0;
    for (int f = 0; f < np->nf; f++) mix[f] = 0;
    for (size_t c = 0; c < cells; c++) {
        double any = 0;
        for (int f = 0; f < np->nf; f++) any += np->fdens[c * np->nf + f];
        if (!(any > 0)) continue;
        for (int f = 0; f < np->nf; f++) mix[f] += np->fdens[c * np->nf + f];
        k++;
    }
    for (int f = 0; f < np->nf; f++) mix[f] = k ? mix[f] / k : 0;
}

/* The sunlight reaching each cell: over its render voxels the sunlight attenuated by their
 * column density, weighted by their scattering (the light the cell scatters is the mean of
 * sig_s E over it, which in a dense cell comes from its sunlit side, not its centre). */
static void cell_sunlight(const atmos__nishita_plan *np, const double *sl, float *E)
{
    const sgrid *g = &np->g;
    const atmos__lmedium *m = &np->med;
    const int nf = np->nf, n = np->n, s = np->s;
    for (size_t cell = 0; cell < atmos__lmedium_cells(m); cell++) {
        const int I = (int)(cell % (size_t)m->c[0]), J = (int)(cell / (size_t)m->c[0] % (size_t)m->c[1]),
                  K = (int)(cell / ((size_t)m->c[0] * m->c[1]));
        double num[ATMOS_MAX_WAVELENGTHS] = {0}, den[ATMOS_MAX_WAVELENGTHS] = {0};
        for (int k = K * s; k < (K + 1) * s && k < g->c[2]; k++)
            for (int j = J * s; j < (J + 1) * s && j < g->c[1]; j++)
                for (int i = I * s; i < (I + 1) * s && i < g->c[0]; i++) {
                    const size_t v = (((size_t)k * g->c[1] + j) * g->c[0] + i) * nf;
                    for (int w = 0; w < n; w++) {
                        double b = 0, tau = 0;
                        for (int f = 0; f < nf; f++)
                            b += g->v[v + f] * np->sca[f][w],
                                tau += np->col[v + f] * (np->sig[f][w] - np->trunc[w] * np->sca[f][w]);
                        num[w] += b * exp(-tau), den[w] += b;
                    }
                }
        for (int w = 0; w < n; w++) E[cell * n + w] = (float)(den[w] > 0 ? sl[w] * num[w] / den[w] : 0.0);

    }
}

atmos_status atmos__nishita_field_update(atmos_plan *p, const double sun_w[3], const double eye_w[3])
{
    atmos__nishita_plan *np = p->nishita;
    const sgrid *g = &np->g;
    const int threads = atmos__threads(p->ctx), n = np->n;
    double sun_g[3], cen[3], cw[3], rel[3], eye_g[3], ev[3];
    atmos__vol_dir_to_frame(&np->x, sun_w, sun_g);
    for (int a = 0; a < 3; a++) cen[a] = 0.5 * (g->box_lo[a] + g->box_hi[a]), rel[a] = eye_w[a] - np->x.org[a];
    atmos__vol_dir_to_frame(&np->x, rel, eye_g);
    for (int a = 0; a < 3; a++) ev[a] = eye_g[a] - cen[a];
    const double l = sqrt(atmos__dot3(ev, ev));
    for (int a = 0; a < 3; a++) ev[a] = l > 0 ? ev[a] / l : (a == 2);
    if (np->field_valid && !memcmp(np->field_sun, sun_w, sizeof np->field_sun) &&
        !memcmp(np->field_ev, ev, sizeof np->field_ev))
        return ATMOS_OK;
    atmos__vol_frame_to_point(&np->x, cen, cw);
    atmos__atm_onto_ground(p->atm, cw, cw); /* the sky seen from above the ground */
    double mix[ATMOS_VOLUME_MAX_FIELDS], sl[ATMOS_MAX_WAVELENGTHS];
    mean_mix(np, mix);
    atmos_atmosphere_sunlight(p->atm, cw, sun_w, sl);
    float *ph = malloc(sizeof(float) * ATMOS__NISHITA_PHASE_N);
    double *sky = calloc((size_t)ATMOS__NISHITA_ELEMENTS * n, sizeof(double));
    float *E = malloc(sizeof(float) * atmos__lmedium_cells(&np->med) * n);
    if (!ph || !sky || !E) {
        free(ph), free(sky), free(E);
        return atmos__error(p->ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the light field");
    }
    pattern_phase(np, mix, n / 2, ph);
    const double t0 = atmos__now();
    if (p->scene.nishita.sky) sky_elements(np, p->atm, cw, sun_w, sun_g, ev, mix, sky, threads);
    /* the eye pass multiplies the field by the truncated scattering sig_s (1 - f); the sky's
     * light is scattered with the whole phase function */
    for (int e = 0; e < ATMOS__NISHITA_ELEMENTS; e++)
        for (int w = 0; w < n; w++) sky[e * n + w] /= 1 - np->trunc[w];
    const double tsky = atmos__now() - t0;
    const atmos_scene_nishita *ns = &p->scene.nishita;
    atmos__nishita_in in = {0};
    in.m = &np->med;
    for (int a = 0; a < 3; a++) in.lt[a] = -sun_g[a], in.ev[a] = ev[a];
    cell_sunlight(np, sl, E);
    in.sun = sl, in.E = E, in.phase = ph, in.sky = ns->sky ? sky : NULL;
    in.orders = ns->orders, in.ratio = ns->ratio, in.paths3 = ns->paths;
    int big = np->med.c[0] > np->med.c[1] ? np->med.c[0] : np->med.c[1];
    big = big > np->med.c[2] ? big : np->med.c[2];
    in.radius2 = big - 1, in.radius3 = big - 1 < 5 ? big - 1 : 5;
    in.seed = 1, in.threads = threads;
    atmos__lfield_free(&np->field);
    const int ok = atmos__nishita_solve(&in, np->s, &np->field, &np->stats);
    np->stats.sky_s += tsky;
    free(ph), free(sky), free(E);
    if (!ok) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render nishita: out of memory for the light field");
    memcpy(np->field_sun, sun_w, sizeof np->field_sun), memcpy(np->field_ev, ev, sizeof np->field_ev);
    np->field_valid = 1;
    atmos__log(p->ctx, ATMOS_LOG_INFO,
               "render nishita: field %dx%dx%d cells of %d voxels; patterns: order 2 %d paths (%.0f %%, half-size %d), "
               "order 3 %d of %lld (%.0f %%, half-size %d), beam spread %.1f deg, %.3f s; sky %.3f s; cells %.3f s",
               np->med.c[0], np->med.c[1], np->med.c[2], np->s, np->stats.n2, 100 * np->stats.kept2, np->stats.box2,
               np->stats.n3, np->stats.n3_space, 100 * np->stats.kept3, np->stats.box3, np->stats.theta_b_deg,
               np->stats.pattern_s, np->stats.sky_s, np->stats.apply_s);
    return ATMOS_OK;
}
