/* The diffuse light field over a render grid (dfield.h, docs/lightfield.md): the light that
 * Riley et al. 2004's forward model (Eq. 24/25) drops at each scattering, the side- and
 * back-scattered part, taken as the source of a diffuse field of all orders and solved by
 * diffusion on a grid coarser than the render grid (src/light/). The medium on that grid is
 * built once per plan; the field once per sun direction, warm-started from the last one.
 * The eye passes add what it scatters toward the eye, sca (L + g A) per field (slice_pass.c,
 * nishita_render.c), A from the view's flux (field_keep_view), faded out where the medium is
 * thin (field_fade). */
#include "render/dfield.h"

#include "render/sky_inflow.h"

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
static float keep_share(const atmos__dfield *df, size_t cell, int w, float n, float *mu, float share)
{
    const int nf = df->nf;
    const float *d = df->dens + cell * (size_t)nf;
    float num = 0, den = 0, mnum = 0, mden = 0;
    for (int f = 0; f < nf; f++) {
        const float bs = d[f] * df->tab->sca[f][w];
        if (!(bs > 0.0f)) continue;
        const size_t row = (size_t)w * (SLICE_F_ORDERS + 1);
        const float F = order_lerp(df->tab->F[f] + row, n, 0), drop = bs * (1.0f - F);
        num += bs * F;
        den += bs;
        if (!mu || !(drop > 0.0f)) continue;
        const float g = df->fg[f][w], lo = order_lerp(df->tab->B[f] + row, n, 0);
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
static void field_medium(atmos__dfield *df, int s)
{
    const sgrid *g = df->g;
    atmos__lmedium *m = &df->med;
    const int nf = df->nf, n = df->n, cx = m->c[0], cy = m->c[1], cz = m->c[2];
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
                float *d = df->dens + cell * nf;
                for (int f = 0; f < nf; f++) d[f] = cnt ? (float)(sum[f] / cnt) : 0.0f;
                for (int w = 0; w < n; w++) {
                    double st = 0, ss = 0, sg = 0;
                    for (int f = 0; f < nf; f++) {
                        st += d[f] * df->tab->sig[f][w];
                        ss += d[f] * df->tab->sca[f][w];
                        sg += d[f] * df->tab->sca[f][w] * df->fg[f][w];
                    }
                    m->sig_t[cell * n + w] = (float)st;
                    m->sig_s[cell * n + w] = (float)ss;
                    m->g[cell * n + w] = ss > 0 ? (float)(sg / ss) : 0.0f;
                }
            }
}

/* The field's weight per cell (df->fade), docs/lightfield.md "Thin media". The diffusion
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

static int field_fade(atmos__dfield *df)
{
    const atmos__lmedium *m = &df->med;
    const int n = m->n;
    const size_t cells = atmos__lmedium_cells(m), cnt = cells * (size_t)n;
    float *t = df->fade, *line = malloc(sizeof(float) * cnt);
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
        df->fade_any |= t[i] > 0.0f;
    }
    return 1;
}

void atmos__dfield_free(atmos__dfield *df)
{
    atmos__lmedium_free(&df->med), atmos__lfield_free(&df->field);
    free(df->dens), free(df->fade), free(df->beam), free(df->view);
    memset(df, 0, sizeof *df);
}

atmos_status atmos__dfield_prepare(atmos_context *ctx, atmos__dfield *df, const sgrid *g, const stables *tab,
                                   const atmos__vol_xform *x, const atmos_volume_optics *o, const char *who)
{
    df->g = g, df->tab = tab, df->x = x, df->who = who;
    df->n = tab->n, df->nf = tab->nf;
    int big = g->c[0] > g->c[1] ? g->c[0] : g->c[1];
    big = big > g->c[2] ? big : g->c[2];
    /* cells of s render voxels: at least 2, at most FIELD_CELLS_MAX per axis */
    int s = (big + FIELD_CELLS_MAX - 1) / FIELD_CELLS_MAX;
    s = s < 2 ? 2 : s;
    const int cx = (g->c[0] + s - 1) / s, cy = (g->c[1] + s - 1) / s, cz = (g->c[2] + s - 1) / s;
    for (int f = 0; f < df->nf; f++)
        for (int w = 0; w < df->n; w++) df->fg[f][w] = (float)atmos_phase_table_g(o->phase[f], w);
    const size_t cells = (size_t)cx * cy * cz;
    df->dens = malloc(sizeof(float) * cells * (size_t)df->nf);
    df->fade = malloc(sizeof(float) * cells * (size_t)df->n);
    df->vq = df->n == 3 ? 4 : df->n;
    df->view = calloc(cells * (size_t)df->nf * df->vq, sizeof(float));
    if (!df->dens || !df->fade || !df->view || !atmos__lmedium_alloc(&df->med, cx, cy, cz, df->n, s / (double)g->sc) ||
        !(df->med.jin = calloc((size_t)6 * df->n, sizeof(float))) ||
        !atmos__lfield_alloc(&df->field, ATMOS__LFIELD_DIFFUSION, cx, cy, cz, df->n, s))
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory for the diffuse light field", who);
    field_medium(df, s);
    if (!field_fade(df)) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory for the diffuse light field", who);
    return ATMOS_OK;
}

void atmos__dfield_view(atmos__dfield *df, const double eye[3], int threads)
{
    atmos__lfield *fl = &df->field;
    atmos__lfield_toward(fl, eye, threads);
    const int n = df->n, nf = df->nf, q = df->vq;
    const long long cells = (long long)atmos__lmedium_cells(&df->med);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long long cell = 0; cell < cells; cell++) {
        const float *la = fl->LA + (size_t)cell * 2 * n;
        for (int f = 0; f < nf; f++) {
            float *o = df->view + ((size_t)cell * nf + f) * q;
            for (int c = 0; c < q; c++)
                o[c] = c < n ? df->tab->sca[f][c] * (la[c] + df->fg[f][c] * la[n + c]) : 0.0f;
        }
    }
}

/* The sky's and the ground's light coming in through each face of the field's box: the
 * inward partial current J_in = int L(d) max(0, d . n) dOmega over the directions d looking
 * out through the face (normal n), L what a view ray from the box's centre cw sees
 * (sky_inflow.h: the sky, the lit ground; the sun's disk left out, the sun is the forward
 * beam's), on SKY_NMU x SKY_NPHI cells of equal solid angle. */
#define SKY_NMU 16
#define SKY_NPHI 32
static void field_sky(atmos__dfield *df, const atmos_atmosphere *atm, const double cw[3], const double sun_w[3])
{
    const int n = df->n;
    float *jin = df->med.jin;
    for (int i = 0; i < 6 * n; i++) jin[i] = 0.0f;
    const double dom = 4.0 * 3.14159265358979323846 / (SKY_NMU * SKY_NPHI);
    double acc[6 * ATMOS_MAX_WAVELENGTHS] = {0};
    for (int a = 0; a < SKY_NMU; a++)
        for (int b = 0; b < SKY_NPHI; b++) {
            const double mu = -1.0 + 2.0 * (a + 0.5) / SKY_NMU, sn = sqrt(1.0 - mu * mu),
                         ph = 2.0 * 3.14159265358979323846 * (b + 0.5) / SKY_NPHI;
            const double d[3] = {sn * cos(ph), mu, sn * sin(ph)};
            double L[ATMOS_MAX_WAVELENGTHS], dg[3];
            atmos__sky_seen(atm, cw, d, sun_w, n, L);
            atmos__vol_dir_to_frame(df->x, d, dg);
            for (int f = 0; f < 6; f++) {
                const double c = (f & 1 ? 1.0 : -1.0) * dg[f / 2];
                if (c > 0)
                    for (int w = 0; w < n; w++) acc[f * n + w] += L[w] * c * dom;
            }
        }
    for (int i = 0; i < 6 * n; i++) jin[i] = (float)acc[i];
}

/* df->beam: Riley's beam Ib (its march with F, as the light buffer's) less the unscattered
 * sunlight (the same march with F = 0), per cell; Q is scratch of the source's size. */
static int field_beam(atmos__dfield *df, const double lt[3], const double *sl, const float *Ib, float *Q, int threads)
{
    const size_t cnt = atmos__lmedium_cells(&df->med) * (size_t)df->n;
    if (!df->beam && !(df->beam = malloc(sizeof(float) * cnt))) return 0;
    atmos__lfield_sun_source(&df->med, lt, sl, atmos__lkeep_none, NULL, Q, NULL, df->beam, threads);
    for (size_t i = 0; i < cnt; i++) {
        const float d = Ib[i] - df->beam[i];
        df->beam[i] = d > 0.0f ? d * df->fade[i] : 0.0f;
    }
    return 1;
}

atmos_status atmos__dfield_update(atmos_context *ctx, atmos__dfield *df, const atmos_atmosphere *atm,
                                  const double sun_w[3], int warm, int want_beam, int *built)
{
    atmos__lfield *fl = &df->field;
    *built = 0;
    if (fl->valid && memcmp(fl->sun, sun_w, sizeof fl->sun) == 0 && (!want_beam || df->beam) && !(fl->warm && !warm))
        return ATMOS_OK;
    const int n = df->n;
    const size_t cnt = atmos__lmedium_cells(&df->med) * (size_t)n;
    if (!df->fade_any) {
        /* thin everywhere: the field is faded out in every cell and stays zero, no solve */
        memcpy(fl->sun, sun_w, sizeof fl->sun);
        fl->valid = 1, fl->warm = 0, fl->sweeps = 0, fl->build_s = fl->source_s = fl->solve_s = 0;
        if (want_beam && !df->beam && !(df->beam = calloc(cnt, sizeof(float))))
            return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory for the diffuse light field", df->who);
        *built = 1;
        atmos__log(ctx, ATMOS_LOG_INFO, "%s: diffuse field faded out everywhere (an optically thin medium), not solved",
                   df->who);
        return ATMOS_OK;
    }
    const double t0 = atmos__now();
    const int threads = atmos__threads(ctx);
    const sgrid *g = df->g;
    float *Q = malloc(sizeof(float) * cnt * 9), *Q1 = Q + cnt, *Qv = Q + 4 * cnt, *Q1v = Qv + cnt, *Ib = Q + 8 * cnt;
    if (!Q) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory for the diffuse light field", df->who);
    double sun_g[3], lt[3], sl[ATMOS_MAX_WAVELENGTHS], cen[3], cw[3];
    atmos__vol_dir_to_frame(df->x, sun_w, sun_g);
    for (int a = 0; a < 3; a++) lt[a] = -sun_g[a], cen[a] = 0.5 * (g->box_lo[a] + g->box_hi[a]);
    /* the sunlight at the box's centre (the light buffer's per-texel entry points would
     * differ by the air's attenuation across the box) */
    atmos__sky_inflow_point(atm, df->x, cen, cw);
    atmos_atmosphere_sunlight(atm, cw, sun_w, sl);
    atmos__lfield_sun_source(&df->med, lt, sl, field_keep, df, Q, Q1, Ib, threads);
    const atmos__lsource src = {Q, Q1};
    field_sky(df, atm, cw, sun_w);
    const double t1 = atmos__now();
    atmos__ldiffusion_opts o = {0};
    o.limiter = 1; /* measured better than without (docs/lightfield.md) */
    o.cascade = fl->valid && warm ? 0 : 2; /* a cold start from coarser grids' solutions; else the last sun's field */
    fl->warm = o.cascade == 0;
    fl->sweeps = atmos__lfield_diffuse(&df->med, &src, fl->phi, &o, threads);
    if (fl->sweeps < 0) {
        free(Q);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory for the diffusion solve", df->who);
    }
    const float inv4pi = (float)(1.0 / (4.0 * 3.14159265358979323846));
    /* the view's flux: the same Q, the source's moment toward mu1 (field_keep_view) */
    atmos__lfield_sun_source(&df->med, lt, sl, field_keep_view, df, Qv, Q1v, NULL, threads);
    const atmos__lsource view = {Q, Q1v};
    atmos__lfield_flux(&df->med, &view, fl->phi, &o, fl->J, threads);
    /* faded where the medium is thin (field_fade); phi, the warm start, is the solve's */
    for (size_t i = 0; i < cnt; i++) {
        fl->L[i] = fl->phi[i] * inv4pi * df->fade[i];
        for (int a = 0; a < 3; a++) fl->J[i * 3 + a] *= df->fade[i];
    }
    const int beam_ok = !want_beam || field_beam(df, lt, sl, Ib, Qv, threads);
    free(Q);
    if (!beam_ok) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory for the diffuse light field", df->who);
    memcpy(fl->sun, sun_w, sizeof fl->sun);
    fl->valid = 1;
    *built = 1;
    fl->source_s = t1 - t0;
    fl->solve_s = atmos__now() - t1;
    fl->build_s = atmos__now() - t0;
    atmos__log(ctx, ATMOS_LOG_INFO, "%s: diffuse field %dx%dx%d cells of %d voxels, source %.3f s, %d sweeps %.3f s",
               df->who, fl->c[0], fl->c[1], fl->c[2], fl->s, fl->source_s, fl->sweeps, fl->solve_s);
    return ATMOS_OK;
}
