/* The slice renderer's diffuse light field ("diffuse", docs/lightfield.md): the light that
 * Riley et al. 2004's forward model (Eq. 24/25) drops at each scattering, the side- and
 * back-scattered part, taken as the source of a diffuse field of all orders and solved by
 * diffusion on a grid coarser than the render grid (src/light/). The medium on that grid is
 * built once per plan; the field once per sun direction, warm-started from the last one.
 * The eye passes add what it scatters toward the eye, sca (L + g A) per field (slice_pass.c),
 * A from the view's flux (field_keep_view), faded out where the medium is thin (field_fade). */
#include "atmosphere/atmosphere_ops.h"
#include "render/slice_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FIELD_CELLS_MAX 40 /* the field's grid has at most about this many cells per axis */

/* Riley's kept share F_{n+1} at a cell: the fields' F tables mixed by their scattering; *mu
 * the mean cosine of the dropped rest, mixed by what each field drops.
 *
 * Two momentum balances bound it. The model's: the beam keeps F as if it went straight on
 * (first moment F) and a scattering gives the light the moment g, so the dropped rest carries
 * g - F: mu0 = (g - F)/(1 - F), backward where F > g (the first orders), forward where
 * F -> 1/2 < g (deep inside). The light's: the kept forward hemisphere of Ams_{n+1} really
 * carries g^{n+1} - (1 - F) B_n (B_n the mean cosine of the backward hemisphere of Ams_{n+1},
 * the slice tables' B), less than F; the straight-on beam's surplus is light that goes on
 * diffusing: mu1 = B_n + (g - g^{n+1})/(1 - F) (B_n at the first order, forward sooner).
 * mu = mu0 + share (mu1 - mu0), held between B_n and 1. The diffusion solve takes share 0
 * (mu0: the slabs' fluxes against adding-doubling, docs/lightfield.md); the flux that turns
 * the field toward the eye takes VIEW_SHARE (below). */
static float keep_share(const atmos__slice_plan *sp, size_t cell, int w, float n, float *mu, float share)
{
    const int nf = sp->nf;
    const float *d = sp->fdens + cell * (size_t)nf;
    float num = 0, den = 0, mnum = 0, mden = 0;
    for (int f = 0; f < nf; f++) {
        const float bs = d[f] * sp->tab.sca[f][w];
        if (!(bs > 0.0f)) continue;
        const size_t row = (size_t)w * (SLICE_F_ORDERS + 1);
        const float F = order_lerp(sp->tab.F[f] + row, n, 0), drop = bs * (1.0f - F);
        num += bs * F;
        den += bs;
        if (!mu || !(drop > 0.0f)) continue;
        const float g = sp->fg[f][w], lo = order_lerp(sp->tab.B[f] + row, n, 0);
        float m = (g - F) / (1.0f - F);
        if (share > 0.0f) {
            const float gn = g > 0.0f ? expf(n * logf(g)) : 0.0f; /* g^{n+1}: n is the order n + 1 */
            m += share * (lo + (g - gn) / (1.0f - F) - m);
        }
        mnum += drop * (m < lo ? lo : (m > 1.0f ? 1.0f : m));
        mden += drop;
    }
    if (mu) *mu = mden > 0.0f ? mnum / mden : 0.0f;
    return den > 0.0f ? num / den : 0.0f;
}

/* The diffusion solve's source (mu0). */
static float field_keep(const void *user, size_t cell, int w, float n, float *mu)
{
    return keep_share(user, cell, w, n, mu, 0.0f);
}

/* The flux toward the eye. The P1 field's radiance toward d, L + 3/(4 pi) J . d, with the
 * solve's J (mu0) made the sunlit sides too bright seen from the sun and the shadowed sides
 * too dark seen from the sun's side of the sky (docs/lightfield.md: the accuracy bench's dense
 * clouds +5 ... +15 % and -4 ... -15 %; the diffuse light keeps more of the sunlight's
 * direction than mu0 gives it): the view's J is the solve's with the source's moment
 * VIEW_SHARE of the way to mu1, 3 D (Q1(view) - Q1) added to it. The fluence and the fluxes
 * through the faces stay the solve's. 0.3 measured best on the bench's dense clouds (0.5
 * overturned the sign of the error, 0.3 brought the dense cases' mean |bias| from 10.5 % to
 * 5.1 %). */
#define VIEW_SHARE 0.3f
static float field_keep_view(const void *user, size_t cell, int w, float n, float *mu)
{
    return keep_share(user, cell, w, n, mu, VIEW_SHARE);
}

/* The mean density of each field over the s^3 render voxels of every cell, and the cells'
 * extinction, scattering and asymmetry per wavelength. */
static void field_medium(atmos__slice_plan *sp, int s)
{
    const sgrid *g = &sp->g;
    atmos__lmedium *m = &sp->fmed;
    const int nf = sp->nf, n = sp->n, cx = m->c[0], cy = m->c[1], cz = m->c[2];
    for (int K = 0; K < cz; K++)
        for (int J = 0; J < cy; J++)
            for (int I = 0; I < cx; I++) {
                const size_t cell = ((size_t)K * cy + J) * cx + I;
                double sum[ATMOS_VOLUME_MAX_FIELDS] = {0};
                int cnt = 0;
                for (int k = K * s; k < (K + 1) * s && k < g->c[2]; k++)
                    for (int j = J * s; j < (J + 1) * s && j < g->c[1]; j++)
                        for (int i = I * s; i < (I + 1) * s && i < g->c[0]; i++, cnt++) {
                            const float *p = g->v + (((size_t)k * g->c[1] + j) * g->c[0] + i) * nf;
                            for (int f = 0; f < nf; f++) sum[f] += p[f];
                        }
                float *d = sp->fdens + cell * nf;
                for (int f = 0; f < nf; f++) d[f] = cnt ? (float)(sum[f] / cnt) : 0.0f;
                for (int w = 0; w < n; w++) {
                    double st = 0, ss = 0, sg = 0;
                    for (int f = 0; f < nf; f++) {
                        st += d[f] * sp->tab.sig[f][w];
                        ss += d[f] * sp->tab.sca[f][w];
                        sg += d[f] * sp->tab.sca[f][w] * sp->fg[f][w];
                    }
                    m->sig_t[cell * n + w] = (float)st;
                    m->sig_s[cell * n + w] = (float)ss;
                    m->g[cell * n + w] = ss > 0 ? (float)(sg / ss) : 0.0f;
                }
            }
}

/* The field's weight per cell (sp->ffade), docs/lightfield.md "Thin media". The diffusion
 * solve stands for light that stays in the medium and diffuses; where the medium is optically
 * thin the light Eq. 25 drops mostly leaves it, and the field only added an excess (the bench's
 * thin cirrus +25 % with the field, -1 % without: its flux-limited diffusion spreads the dropped
 * sunlight and the sky's light from the box's faces over cells far larger than the sheet's
 * thickness, and Riley's xi is then counted besides it). Where Eq. 25 alone is accurate, the
 * field is faded out: the medium's optical depth across a cell is the least of the three
 * columns through it (the grid's whole line along each axis: a sheet is thin across however
 * wide it is), a cell takes the largest such depth within FADE_REACH cells (the thin edges of a
 * dense cloud keep the light diffusing out of it), and the weight rises from 0 at optical depth
 * FADE_LO to 1 at FADE_HI (a smoothstep in log depth). The depths are of the extinction at
 * each wavelength. */
#define FADE_LO 0.3
#define FADE_HI 1.5
#define FADE_REACH 2

/* t <- the largest t within r cells along axis a (tmp: scratch of the same size). */
static void fade_dilate(float *t, float *tmp, const atmos__lmedium *m, int a, int r)
{
    const int n = m->n, c = m->c[a];
    const size_t cells = atmos__lmedium_cells(m), st = a == 0 ? 1 : (a == 1 ? (size_t)m->c[0] : (size_t)m->c[0] * m->c[1]);
    for (size_t q = 0; q < cells; q++) {
        const int x = (int)(q / st % (size_t)c), lo = x - r < 0 ? 0 : x - r, hi = x + r >= c ? c - 1 : x + r;
        const size_t base = q - (size_t)x * st;
        for (int w = 0; w < n; w++) {
            float best = 0.0f;
            for (int y = lo; y <= hi; y++) {
                const float v = t[(base + (size_t)y * st) * n + w];
                best = v > best ? v : best;
            }
            tmp[q * n + w] = best;
        }
    }
    memcpy(t, tmp, sizeof(float) * cells * (size_t)n);
}

static int field_fade(atmos__slice_plan *sp)
{
    const atmos__lmedium *m = &sp->fmed;
    const int n = m->n;
    const size_t cells = atmos__lmedium_cells(m), cnt = cells * (size_t)n;
    float *t = sp->ffade, *line = malloc(sizeof(float) * cnt);
    if (!line) return 0;
    for (size_t i = 0; i < cnt; i++) t[i] = INFINITY;
    for (int a = 0; a < 3; a++) {
        /* the line's sum along axis a, kept at its cell of coordinate 0 */
        const int c = m->c[a];
        const size_t st = a == 0 ? 1 : (a == 1 ? (size_t)m->c[0] : (size_t)m->c[0] * m->c[1]);
        memset(line, 0, sizeof(float) * cnt);
        for (size_t q = 0; q < cells; q++) {
            const size_t base = q - (size_t)(q / st % (size_t)c) * st;
            for (int w = 0; w < n; w++) line[base * n + w] += m->sig_t[q * n + w];
        }
        for (size_t q = 0; q < cells; q++) {
            const size_t base = q - (size_t)(q / st % (size_t)c) * st;
            for (int w = 0; w < n; w++) {
                const float d = (float)(line[base * n + w] * m->h);
                t[q * n + w] = d < t[q * n + w] ? d : t[q * n + w];
            }
        }
    }
    for (int a = 0; a < 3; a++) fade_dilate(t, line, m, a, FADE_REACH);
    free(line);
    const double span = log(FADE_HI / FADE_LO);
    for (size_t i = 0; i < cnt; i++) {
        double x = t[i] > 0.0f ? log(t[i] / FADE_LO) / span : 0.0;
        x = x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
        t[i] = (float)(x * x * (3.0 - 2.0 * x));
        sp->ffade_any |= t[i] > 0.0f;
    }
    return 1;
}

atmos_status atmos__slice_field_prepare(atmos_context *ctx, atmos__slice_plan *sp, const atmos_volume_optics *o)
{
    const sgrid *g = &sp->g;
    int big = g->c[0] > g->c[1] ? g->c[0] : g->c[1];
    big = big > g->c[2] ? big : g->c[2];
    /* cells of s render voxels: at least 2, at most FIELD_CELLS_MAX per axis */
    int s = (big + FIELD_CELLS_MAX - 1) / FIELD_CELLS_MAX;
    s = s < 2 ? 2 : s;
    const int cx = (g->c[0] + s - 1) / s, cy = (g->c[1] + s - 1) / s, cz = (g->c[2] + s - 1) / s;
    for (int f = 0; f < sp->nf; f++)
        for (int w = 0; w < sp->n; w++) sp->fg[f][w] = (float)atmos_phase_table_g(o->phase[f], w);
    const size_t cells = (size_t)cx * cy * cz;
    sp->fdens = malloc(sizeof(float) * cells * (size_t)sp->nf);
    sp->ffade = malloc(sizeof(float) * cells * (size_t)sp->n);
    sp->fvq = sp->n == 3 ? 4 : sp->n;
    sp->fview = calloc(cells * (size_t)sp->nf * sp->fvq, sizeof(float));
    if (!sp->fdens || !sp->ffade || !sp->fview || !atmos__lmedium_alloc(&sp->fmed, cx, cy, cz, sp->n, s / (double)g->sc) ||
        !(sp->fmed.jin = calloc((size_t)6 * sp->n, sizeof(float))) ||
        !atmos__lfield_alloc(&sp->field, ATMOS__LFIELD_DIFFUSION, cx, cy, cz, sp->n, s))
        return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the diffuse light field");
    field_medium(sp, s);
    if (!field_fade(sp)) return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the diffuse light field");
    return ATMOS_OK;
}

void atmos__slice_field_view(atmos__slice_plan *sp, const double eye[3], int threads)
{
    atmos__lfield *fl = &sp->field;
    atmos__lfield_toward(fl, eye, threads);
    const int n = sp->n, nf = sp->nf, q = sp->fvq;
    const long long cells = (long long)atmos__lmedium_cells(&sp->fmed);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long cell = 0; cell < cells; cell++) {
        const float *la = fl->LA + (size_t)cell * 2 * n;
        for (int f = 0; f < nf; f++) {
            float *o = sp->fview + ((size_t)cell * nf + f) * q;
            for (int c = 0; c < q; c++)
                o[c] = c < n ? sp->tab.sca[f][c] * (la[c] + sp->fg[f][c] * la[n + c]) : 0.0f;
        }
    }
}

/* The sky's and the ground's light coming in through each face of the field's box: the
 * inward partial current J_in = int L(d) max(0, d . n) dOmega over the directions d looking
 * out through the face (normal n), L what a view ray from the box's centre cw sees
 * (atmos_atmosphere_radiance: the sky, the lit ground; the sun's disk left out, the sun is
 * the forward beam's), on SKY_NMU x SKY_NPHI cells of equal solid angle. */
#define SKY_NMU 16
#define SKY_NPHI 32
static void field_sky(atmos__slice_plan *sp, const atmos_atmosphere *atm, const double cw[3], const double sun_w[3])
{
    const int n = sp->n;
    float *jin = sp->fmed.jin;
    for (int i = 0; i < 6 * n; i++) jin[i] = 0.0f;
    const double dom = 4.0 * 3.14159265358979323846 / (SKY_NMU * SKY_NPHI);
    double acc[6 * ATMOS_MAX_WAVELENGTHS] = {0};
    for (int a = 0; a < SKY_NMU; a++)
        for (int b = 0; b < SKY_NPHI; b++) {
            const double mu = -1.0 + 2.0 * (a + 0.5) / SKY_NMU, sn = sqrt(1.0 - mu * mu),
                         ph = 2.0 * 3.14159265358979323846 * (b + 0.5) / SKY_NPHI;
            const double d[3] = {sn * cos(ph), mu, sn * sin(ph)};
            double L[ATMOS_MAX_WAVELENGTHS], df[3];
            atmos_atmosphere_hit info;
            atmos_atmosphere_radiance(atm, cw, d, sun_w, L, &info);
            if (info.in_sun_disk) continue;
            atmos__vol_dir_to_frame(&sp->x, d, df);
            for (int f = 0; f < 6; f++) {
                const double c = (f & 1 ? 1.0 : -1.0) * df[f / 2];
                if (c > 0)
                    for (int w = 0; w < n; w++) acc[f * n + w] += L[w] * c * dom;
            }
        }
    for (int i = 0; i < 6 * n; i++) jin[i] = (float)acc[i];
}

atmos_status atmos__slice_field_update(atmos_context *ctx, atmos__slice_plan *sp, const atmos_atmosphere *atm,
                                       const double sun_w[3], int warm, int *built)
{
    atmos__lfield *fl = &sp->field;
    *built = 0;
    if (fl->valid && memcmp(fl->sun, sun_w, sizeof fl->sun) == 0) return ATMOS_OK;
    if (!sp->ffade_any) {
        /* thin everywhere: the field is faded out in every cell and stays zero, no solve */
        memcpy(fl->sun, sun_w, sizeof fl->sun);
        fl->valid = 1, fl->sweeps = 0, fl->build_s = fl->source_s = fl->solve_s = 0;
        *built = 1;
        atmos__log(ctx, ATMOS_LOG_INFO, "render slice: diffuse field faded out everywhere (an optically thin medium), not solved");
        return ATMOS_OK;
    }
    const double t0 = atmos__now();
    const int threads = atmos__threads(ctx), n = sp->n;
    const sgrid *g = &sp->g;
    const size_t cnt = atmos__lmedium_cells(&sp->fmed) * (size_t)n;
    float *Q = malloc(sizeof(float) * cnt * 8), *Q1 = Q + cnt, *Qv = Q + 4 * cnt, *Q1v = Qv + cnt;
    if (!Q) return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the diffuse light field");
    double sun_g[3], lt[3], sl[ATMOS_MAX_WAVELENGTHS], cen[3], cw[3];
    atmos__vol_dir_to_frame(&sp->x, sun_w, sun_g);
    for (int a = 0; a < 3; a++) lt[a] = -sun_g[a], cen[a] = 0.5 * (g->box_lo[a] + g->box_hi[a]);
    /* the sunlight at the box's centre (the light buffer's per-texel entry points would
     * differ by the air's attenuation across the box) */
    atmos__vol_frame_to_point(&sp->x, cen, cw);
    atmos_atmosphere_sunlight(atm, cw, sun_w, sl);
    atmos__lfield_sun_source(&sp->fmed, lt, sl, field_keep, sp, Q, Q1, NULL, threads);
    const atmos__lsource src = {Q, Q1};
    field_sky(sp, atm, cw, sun_w);
    const double t1 = atmos__now();
    atmos__ldiffusion_opts o = {0};
    o.limiter = 1; /* measured better than without (docs/lightfield.md) */
    o.cascade = fl->valid && warm ? 0 : 2; /* a cold start from coarser grids' solutions; else the last sun's field */
    fl->sweeps = atmos__lfield_diffuse(&sp->fmed, &src, fl->phi, &o, threads);
    if (fl->sweeps < 0) {
        free(Q);
        return atmos__error(ctx, ATMOS_E_NOMEM, "render slice: out of memory for the diffusion solve");
    }
    const float inv4pi = (float)(1.0 / (4.0 * 3.14159265358979323846));
    /* the view's flux: the same Q, the source's moment toward mu1 (field_keep_view) */
    atmos__lfield_sun_source(&sp->fmed, lt, sl, field_keep_view, sp, Qv, Q1v, NULL, threads);
    const atmos__lsource view = {Q, Q1v};
    atmos__lfield_flux(&sp->fmed, &view, fl->phi, &o, fl->J, threads);
    /* faded where the medium is thin (field_fade); phi, the warm start, is the solve's */
    for (size_t i = 0; i < cnt; i++) {
        fl->L[i] = fl->phi[i] * inv4pi * sp->ffade[i];
        for (int a = 0; a < 3; a++) fl->J[i * 3 + a] *= sp->ffade[i];
    }
    free(Q);
    memcpy(fl->sun, sun_w, sizeof fl->sun);
    fl->valid = 1;
    *built = 1;
    fl->source_s = t1 - t0;
    fl->solve_s = atmos__now() - t1;
    fl->build_s = atmos__now() - t0;
    atmos__log(ctx, ATMOS_LOG_INFO, "render slice: diffuse field %dx%dx%d cells of %d voxels, source %.3f s, %d sweeps %.3f s",
               fl->c[0], fl->c[1], fl->c[2], fl->s, fl->source_s, fl->sweeps, fl->solve_s);
    return ATMOS_OK;
}
