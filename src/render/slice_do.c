/* The slice renderer with the discrete-ordinates field ("slice": {"do": true}, --slice-do;
 * docs/lightfield.md, "The discrete-ordinates field in the slice renderer").
 *
 * What is counted where. The field (nishita_do.c, light/lfield_do.c) is the delta-M scaled
 * problem's (degree 3, on top of the 3-degree cut): the fraction f = chi_4 of the scattering
 * counts as not scattered, sigma_t* = sigma_t' - f sigma_s', sigma_s* = (1 - f) sigma_s', and its
 * coefficients are the emission of the orders >= 2 per unit sigma_s*, started by the first
 * order's sigma_s* E exp(-tau*_sun). Riley's Eq. 24/25 forward lobe is the same idea by other
 * means (the share F_{n+1} of each scattering kept in the beam, its attenuation sigma_t - sigma_s F):
 * kept beside the field it would carry the light of the delta-M peak a second time, and its
 * Ams_{n+1} toward the eye light that the field already holds as orders >= 2. So with "do" the
 * light pass is the delta-M direct beam alone, I = E exp(-tau*) (low albedo's plain attenuation
 * with sigma_t*: F and the scattering count n play no part), and the eye pass is TMS's first
 * order (Nakajima & Tanaka 1988), sigma_s p(theta) I (front to back the share
 * exp(-(tau - tau*)) with the full phase table, Ams_1, the rest smoothed over the forward peak:
 * below; back to front, the sun ahead, two populations: the share the peak has not turned with
 * the full table, the rest with delta-M's smoothed phase, sjob.two_pop), plus sigma_s* times the
 * field's coefficients toward
 * the eye, both attenuated toward the eye by sigma_t*; xi is 0 (the field is the multiple
 * scattering it stood for). The Nishita renderer's sum with "do" (nishita_render.c) is the same
 * but for that split: its first order is the full table's whole, on its own grid; this one is on
 * the slice renderer's grid, slices and light buffer.
 *
 * The first order split in a sharp and a smooth part (since 2026-12-06; docs/lightfield.md, "The
 * phenomena"): the delta-M direct beam E exp(-tau*) holds light that the particles' forward peak
 * has turned (for cloud droplets by a degree or more), and so does the light leaving a scattering
 * toward the eye seen through sigma_t*; drawn with the full phase table, both put the glory's
 * rings on it, twice as strong as the path tracer's. So front to back (the sun behind the eye:
 * the glory, the bows) the eye pass draws the share w = exp(-(tau - tau*)) of the sun's side times
 * the same of the eye's side with the full table and the rest, 1 - w, with the smooth phase (the
 * table averaged over +- the forward peak's median angle, do_ams' order-2 rows, blended as the
 * orders are): w = exp(-share n) T_eye^(kap - 1), n the light buffer's scattering depth from the
 * sun (sjob.sharp_eye). Back to front (the sun ahead: the halos, the silver lining) T_eye is not
 * known ahead of a sample, and there the first order is that of two populations (since 2026-12-06,
 * sjob.two_pop; docs/accuracy.md, "The cumulus in front: where the RMSE is"): TMS's full table
 * times the whole delta-M beam counted the peak's light twice, kept in the beam and sent toward
 * the eye by the phase's forward lobe, +94 % on a slab of depth 4 seen 10 degrees from the sun.
 * The light the delta-M peak has not turned, the share exp(-share_dm n) of the beam (share_dm:
 * delta-M's part of the scattering, the 3-degree cut's left out as the path tracer's references
 * leave it; n the scattering depth from the sun), scatters with the full table; the rest with
 * delta-M's scaled phase p* of degree 3 times sigma_s* / sigma_s (do_ams' rows 2 and 3).
 *
 * The sky's and the ground's light enter the field's sweeps through the grid's faces (nishita_do.c,
 * from the atmosphere interface as the P1 field's boundary, sky_inflow.c): the field then holds
 * their scattered light of every order (the first included: the eye pass's first order is the
 * sun's alone), and the sky seen straight through the volume is the eye pass's background,
 * attenuated by sigma_t* (the delta-M peak's share counts as passing straight on).
 *
 * The field is solved on the slice renderer's render grid itself (borrowed by the field's plan, not
 * copied), from the sunlight's columns of the Nishita plan's sweep and the sunlight
 * at the box's centre: the light buffer is made slice by slice during the eye pass, after the
 * field is needed.
 *
 * The background behind the volume is seen through sigma_t* too (T_eye): the delta-M peak's light
 * passes as if not scattered. Through the true sigma_t it was measured worse (docs/lightfield.md,
 * "The background behind the volume"): the first order does not draw the peak's light at the
 * image's pixel size, so it was lost. */
#include "render/dm_two_pop.h"
#include "render/nishita_internal.h"
#include "render/slice_internal.h"

#include <stdlib.h>
#include <string.h>
#include <math.h>

/* Rows 2 and 3 of field f's Ams in a (do_ams' copy of tab's, stride no): the full table again and
 * sigma_s* / sigma_s times delta-M's scaled phase of degree 3, p* = sum (2l + 1) / (4 pi) chi*_l P_l
 * with chi*_l = (chi_l - share) / (1 - share) (the cut and delta-M together: 1 - share = sigma_s* /
 * sigma_s), chi_l the table's moments; not below 0. The eye pass back to front blends them
 * (sjob.two_pop). */
static void two_pop_rows(const atmos__slice_plan *sp, int f, float *a0)
{
    const stables *t = &sp->tab;
    const int n = sp->n, no = t->no, ng = t->ng[f];
    const double *g = t->grid[f];
    for (int w = 0; w < n; w++) {
        const double sh = t->sca[f][w] > 0 ? 1 - sp->dop->mc_sca[f][w] / t->sca[f][w] : 0;
        double chi[4];
        atmos__dm_moments3(t, f, w, n, chi);
        for (int a = 0; a < ng; a++) {
            a0[((size_t)a * no + 2) * n + w] = t->ams[f][(size_t)a * no * n + w];
            a0[((size_t)a * no + 3) * n + w] = (float)atmos__dm_phase3(chi, sh, cos(g[a] * ATMOS_DEG2RAD));
        }
    }
}

/* sigma_t / sigma_t* per wavelength, the fields weighted by their share of the grid's extinction
 * (sigma_t* times the density summed over the grid), and delta-M's share of the scattering counted
 * as not scattered, 1 - sigma_s* / sigma_s (the middle wavelength's, weighted by sigma_s): the eye
 * pass's sharp first order (sjob.sharp_eye). */
static void do_kappa(atmos__slice_plan *sp)
{
    const sgrid *g = &sp->g;
    const size_t cells = (size_t)g->c[0] * g->c[1] * g->c[2];
    double dsum[ATMOS_VOLUME_MAX_FIELDS] = {0};
    for (size_t v = 0; v < cells; v++)
        for (int f = 0; f < sp->nf; f++) dsum[f] += g->v[v * sp->nf + f];
    for (int w = 0; w < sp->n; w++) {
        double a = 0, b = 0;
        for (int f = 0; f < sp->nf; f++) a += dsum[f] * sp->tab.sig[f][w], b += dsum[f] * sp->tab_dm.sig[f][w];
        sp->do_kap[w] = b > 0 ? (float)(a / b) : 1.0f;
    }
    const int w = sp->n / 2;
    double a = 0, b = 0, c = 0;
    for (int f = 0; f < sp->nf; f++) {
        a += dsum[f] * sp->tab.sca[f][w], b += dsum[f] * sp->dop->mc_sca[f][w];
        c += dsum[f] * sp->tab.sca[f][w] * atmos__dm_cut_share(&sp->tab, f, w, sp->n);
    }
    sp->do_share = a > 0 ? (float)(1 - b / a) : 0.0f;
    sp->do_share_dm = a > 0 && a - b - c > 0 ? (float)((a - b - c) / a) : 0.0f;
}

/* Row r (0: the first order) of tab's Ams for field f, wavelength w at theta (degrees). */
static double ams_at(const stables *t, int f, int w, int n, int r, double theta)
{
    int a = 0;
    float wt;
    atmos__angle_locate(t->grid[f], t->ng[f], theta, &a, &wt);
    const float *A = t->ams[f];
    const size_t i0 = ((size_t)a * t->no + r) * n + w, i1 = i0 + (size_t)t->no * n;
    return A[i0] + wt * (A[i1] - A[i0]);
}

/* The smooth phase's half-width for field f, wavelength w: the median angle of the light in the
 * forward peak that delta-M counts as not scattered (the share 1 - sigma_s* / sigma_s of the
 * scattering), where the phase table's integral from 0 reaches half that share; 0.05-20 degrees.
 * About 1 degree for cloud droplets (their diffraction peak), 0.05 (the floor) for raindrops. */
static double blur_deg(const atmos__slice_plan *sp, int f, int w)
{
    const stables *t = &sp->tab;
    const double sh = t->sca[f][w] > 0 ? 1 - sp->dop->mc_sca[f][w] / t->sca[f][w] : 0;
    const int n = sp->n, no = t->no;
    const double *g = t->grid[f];
    double cum = 0, th = g[t->ng[f] - 1];
    for (int a = 0; a + 1 < t->ng[f]; a++) {
        const double p0 = t->ams[f][(size_t)a * no * n + w], p1 = t->ams[f][(size_t)(a + 1) * no * n + w];
        const double c0 = cos(g[a] * ATMOS_DEG2RAD), c1 = cos(g[a + 1] * ATMOS_DEG2RAD);
        const double d = 2 * ATMOS_PI * 0.5 * (p0 + p1) * (c0 - c1);
        if (cum + d >= 0.5 * sh) {
            th = g[a] + (g[a + 1] - g[a]) * (d > 0 ? (0.5 * sh - cum) / d : 0);
            break;
        }
        cum += d;
    }
    return th < 0.05 ? 0.05 : th > 20 ? 20 : th;
}

/* tab_dm's Ams tables: tab's first order (the full phase table, sharp) and in the order-2 rows the
 * smooth phase, the first order averaged over theta +- blur_deg (reflected at 0 and 180 degrees):
 * the light that the particles' forward peak turns before or after its scattering toward the eye
 * sees the phase smeared by about that much (the cloud droplets' glory rings gone, the raindrops'
 * bows kept). The eye pass blends the two rows by the share of the first order's light that the
 * delta-M peak has turned (sjob.sharp_eye). */
static int do_ams(atmos__slice_plan *sp)
{
    const stables *t = &sp->tab;
    const int n = sp->n, no = t->no, K = 40;
    size_t tot = 0;
    for (int f = 0; f < sp->nf; f++) tot += (size_t)n * t->ng[f] * no + 4;
    if (!(sp->do_ams = malloc(tot * sizeof(float)))) return 0;
    float *a0 = sp->do_ams;
    for (int f = 0; f < sp->nf; f++) {
        const size_t sz = (size_t)n * t->ng[f] * no + 4;
        memcpy(a0, t->ams[f], sz * sizeof(float));
        for (int w = 0; w < n; w++) {
            const double W = blur_deg(sp, f, w);
            for (int a = 0; a < t->ng[f]; a++) {
                double sum = 0;
                for (int i = 0; i <= K; i++) {
                    double th = t->grid[f][a] + W * (2.0 * i / K - 1);
                    th = th < 0 ? -th : th > 180 ? 360 - th : th;
                    sum += ams_at(t, f, w, n, 0, th);
                }
                a0[((size_t)a * no + 1) * n + w] = (float)(sum / (K + 1));
            }
        }
        if (no >= 4) two_pop_rows(sp, f, a0);
        sp->tab_dm.ams[f] = a0, a0 += sz;
    }
    return 1;
}

atmos_status atmos__slice_do_prepare(atmos_plan *p, atmos__slice_plan *sp)
{
    /* the field on the render grid itself (borrowed, not copied: freed with the slice plan) */
    atmos_status st = atmos__nishita_do_plan_create(p, &sp->g, &sp->dop);
    if (st != ATMOS_OK) return st;
    const atmos__nishita_plan *np = sp->dop;
    sp->tab_dm = sp->tab;
    for (int f = 0; f < sp->nf; f++)
        for (int w = 0; w < sp->n; w++) sp->tab_dm.sig[f][w] = np->mc_sig_ms[f][w];
    do_kappa(sp);
    if (!do_ams(sp)) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render slice: out of memory for the do field");
    const atmos__lfield *F = atmos__nishita_mc_field(np);
    const int vq = sp->n == 3 ? 4 : sp->n;
    sp->do_view = calloc((size_t)F->c[0] * F->c[1] * F->c[2] * sp->nf * vq, sizeof(float));
    if (!sp->do_view) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render slice: out of memory for the do field");
    return ATMOS_OK;
}

void atmos__slice_do_free(atmos__slice_plan *sp)
{
    atmos__nishita_plan_destroy(sp->dop);
    free(sp->do_view), free(sp->do_ams);
    sp->dop = NULL, sp->do_view = NULL, sp->do_ams = NULL;
}

/* The field solved for the frame's sun (when it moved: tm->field) and its view. */
static atmos_status do_solve(atmos_plan *p, atmos__slice_plan *sp, const atmos__view *v, atmos_slice_timing *tm)
{
    atmos__nishita_plan *np = sp->dop;
    const int threads = atmos__threads(p->ctx), n = sp->n, nf = sp->nf, vq = n == 3 ? 4 : n;
    double sun_g[3], cen[3], cw[3], E[ATMOS_MAX_WAVELENGTHS];
    atmos__vol_dir_to_frame(&np->x, v->sun, sun_g);
    atmos__nishita_columns(np, sun_g, threads);
    if (!np->col_valid) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render slice: out of memory for the sunlight");
    for (int a = 0; a < 3; a++) cen[a] = 0.5 * (np->g.box_lo[a] + np->g.box_hi[a]);
    atmos__vol_frame_to_point(&np->x, cen, cw);
    atmos_atmosphere_sunlight(p->atm, cw, v->sun, E);
    const int moved = !sp->do_valid || memcmp(sp->do_sun, v->sun, sizeof sp->do_sun);
    /* out_w: the Monte Carlo field's direction toward the eye, unused by spherical harmonics */
    atmos_status st = atmos__nishita_mc_update(p, np, v->sun, v->sun, v->cam.position, E, threads, v->warm_field);
    if (st != ATMOS_OK) return st;
    memcpy(sp->do_sun, v->sun, sizeof sp->do_sun), sp->do_valid = 1;
    if (moved) tm->field = np->mc_s, tm->field_sweeps = np->do_sweeps;
    /* what a unit density of field f scatters toward the eye: sigma_s* times the coefficients' sum
       (of the field alone, not of the eye) */
    const atmos__lfield *F = atmos__nishita_mc_field(np);
    const size_t cells = (size_t)F->c[0] * F->c[1] * F->c[2];
    for (size_t c = 0; c < cells; c++)
        for (int f = 0; f < nf; f++)
            for (int w = 0; w < n; w++) sp->do_view[(c * nf + f) * vq + w] = np->mc_sca[f][w] * F->L[c * n + w];
    return ATMOS_OK;
}

atmos_status atmos__slice_do_update(atmos_plan *p, atmos__slice_plan *sp, const atmos__view *v, sjob *j,
                                    atmos_slice_timing *tm)
{
    /* held (the viewer's preview while the sun moves), as the diffuse field: the last solved sun's
     * field and its view, not solved again */
    if (!(v->hold_field && sp->do_valid)) {
        const atmos_status st = do_solve(p, sp, v, tm);
        if (st != ATMOS_OK) return st;
    }
    atmos__nishita_plan *np = sp->dop;
    j->field = atmos__nishita_mc_field(np), j->fview = sp->do_view, j->fvq = sp->n == 3 ? 4 : sp->n;
    j->fsca = np->mc_sca[0], j->fg = NULL;
    /* the first order's sharp share: T_eye is known ahead of a sample only front to back (the sun
       behind the eye: the glory, the bows) */
    j->sharp_eye = !j->btf;
    j->two_pop = j->btf && sp->tab.no >= 4; /* back to front: the first order's two populations */
    memcpy(j->kap, sp->do_kap, sizeof j->kap), j->share = sp->do_share, j->share_dm = sp->do_share_dm;
    return ATMOS_OK;
}

void atmos__slice_do_describe(const atmos__slice_plan *sp, char *buf, size_t cap)
{
    if (sp->dop && sp->dop->mc) atmos__nishita_do_describe(sp->dop, buf, cap);
}
