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
 * order (Nakajima & Tanaka 1988), sigma_s p(theta) I with the full phase table (Ams_1: the
 * rainbows, halos and glories as sharp as in low albedo), plus sigma_s* times the field's
 * coefficients toward the eye, both attenuated toward the eye by sigma_t*; xi is 0 (the field is
 * the multiple scattering it stood for). The same sum as the Nishita renderer's with "do"
 * (nishita_render.c), on the slice renderer's grid, slices and light buffer.
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
#include "render/nishita_internal.h"
#include "render/slice_internal.h"

#include <stdlib.h>
#include <string.h>

atmos_status atmos__slice_do_prepare(atmos_plan *p, atmos__slice_plan *sp)
{
    /* the field on the render grid itself (borrowed, not copied: freed with the slice plan) */
    atmos_status st = atmos__nishita_do_plan_create(p, &sp->g, &sp->dop);
    if (st != ATMOS_OK) return st;
    const atmos__nishita_plan *np = sp->dop;
    sp->tab_dm = sp->tab;
    for (int f = 0; f < sp->nf; f++)
        for (int w = 0; w < sp->n; w++) sp->tab_dm.sig[f][w] = np->mc_sig_ms[f][w];
    const atmos__lfield *F = atmos__nishita_mc_field(np);
    const int vq = sp->n == 3 ? 4 : sp->n;
    sp->do_view = calloc((size_t)F->c[0] * F->c[1] * F->c[2] * sp->nf * vq, sizeof(float));
    if (!sp->do_view) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render slice: out of memory for the do field");
    return ATMOS_OK;
}

void atmos__slice_do_free(atmos__slice_plan *sp)
{
    atmos__nishita_plan_destroy(sp->dop);
    free(sp->do_view);
    sp->dop = NULL, sp->do_view = NULL;
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
    return ATMOS_OK;
}

void atmos__slice_do_describe(const atmos__slice_plan *sp, char *buf, size_t cap)
{
    if (sp->dop && sp->dop->mc) atmos__nishita_do_describe(sp->dop, buf, cap);
}
