/* The aerosol types of the spherical kinds as external mixtures of the OPAC components
 * (Hess, Koepke & Schult 1998, "Optical properties of aerosols and clouds: the software
 * package OPAC", Bull. Amer. Meteor. Soc. 79, 831-844): each component a lognormal number
 * distribution (Table 1c: mode radius, geometric standard deviation, radius limits) of
 * homogeneous spheres of one complex refractive index (OPAC's value at 550 nm, used at every
 * visible wavelength), the hygroscopic ones (water-soluble, sea salt) grown to 80 % relative
 * humidity (mode radius as OPAC tabulates it there, refractive index by volume mixing with
 * water); the mixtures are OPAC's number densities (Table 4). Optics by the library's Mie
 * solver over each distribution (Simpson's rule in ln r; wavelengths on OpenMP threads),
 * cached on disk. */
#include "atmosphere/planet_optics.h"

#include "core/cache.h"

#include "atmos/optics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct component {
    double r_mod_um;   /* number mode radius at 80 % RH (dry for the insoluble ones), um */
    double sigma_g;    /* geometric standard deviation */
    double r_max_um;   /* upper radius limit at 80 % RH (OPAC: 20 um dry, 60 um coarse salt) */
    double growth;     /* radius at 80 % RH / dry radius (1: insoluble) */
    double n_re, n_im; /* dry refractive index at 550 nm (im >= 0 here) */
} component;

/* OPAC components: dry mode radii and sigma from Hess et al. 1998 Table 1c; the radii at
 * 80 % RH from OPAC's humidity tables (water-soluble 0.0212 -> 0.0306 um, sea salt
 * accumulation 0.209 -> 0.416 um, coarse 1.75 -> 3.49 um); refractive indices at 550 nm
 * from OPAC's component files (dry). */
enum { INSO, WASO, SOOT, SSAM, SSCM, MINM, MIAM, MICM, N_COMP };
static const component comps[N_COMP] = {
    [INSO] = {0.471, 2.51, 20.0, 1.0, 1.53, 8.0e-3},
    [WASO] = {0.0306, 2.24, 20.0 * 0.0306 / 0.0212, 0.0306 / 0.0212, 1.53, 6.0e-3},
    [SOOT] = {0.0118, 2.00, 20.0, 1.0, 1.75, 0.44},
    [SSAM] = {0.416, 2.03, 20.0 * 0.416 / 0.209, 0.416 / 0.209, 1.50, 1.0e-8},
    [SSCM] = {3.49, 2.03, 60.0 * 3.49 / 1.75, 3.49 / 1.75, 1.50, 1.0e-8},
    [MINM] = {0.07, 1.95, 20.0, 1.0, 1.53, 5.5e-3},
    [MIAM] = {0.39, 2.00, 20.0, 1.0, 1.53, 5.5e-3},
    [MICM] = {1.90, 2.15, 20.0, 1.0, 1.53, 5.5e-3},
};

typedef struct mixture {
    int n;
    int comp[4];
    double number_cm3[4];
} mixture;

/* OPAC Table 4: continental average, maritime clean, urban, desert. */
static const mixture mixtures[4] = {
    [ATMOS_AEROSOL_CONTINENTAL] = {3, {WASO, INSO, SOOT}, {7000.0, 0.4, 8300.0}},
    [ATMOS_AEROSOL_MARITIME] = {3, {WASO, SSAM, SSCM}, {1500.0, 20.0, 3.2e-3}},
    [ATMOS_AEROSOL_URBAN] = {3, {WASO, INSO, SOOT}, {28000.0, 1.5, 130000.0}},
    [ATMOS_AEROSOL_DESERT] = {4, {WASO, MINM, MIAM, MICM}, {2000.0, 269.5, 30.5, 0.142}},
};

#define NQ 32      /* Simpson intervals in ln r per component for the phase function */
#define NF_MIN 96   /* at least this many for the cross-sections */
#define NF_MAX 4096 /* and at most this many */
#define NP ATMOS__PLANET_PHASE_N

/* The component's refractive index at wavelength nm (MIEV0 sign: im <= 0). */
static atmos_complex comp_index(const component *c, double nm)
{
    atmos_complex m = {c->n_re, -c->n_im};
    if (c->growth > 1.0) {
        const atmos_complex w = atmos_refractive_index_water(nm);
        const double f = 1.0 / (c->growth * c->growth * c->growth); /* dry volume fraction */
        m.re = w.re + (m.re - w.re) * f;
        m.im = w.im + (m.im - w.im) * f;
    }
    return m;
}

/* Simpson's weight of node i of n intervals of width h. */
static double simpson(int i, int n, double h) { return (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0)) * h / 3.0; }

/* Adds one component's cross-sections (m^2 per particle times its number) and
 * differential scattering (m^2 sr^-1) at wavelength nm to the sums. The cross-sections
 * resolve the interference ripple of Q_ext (period ~ pi / (m - 1) in x): steps in ln r of
 * at most 0.5 / x at the mode, without angles (cheap); the phase function, smooth after the
 * size average, takes NQ steps and is scaled to the fine scattering cross-section. */
static atmos_status add_component(atmos_context *ctx, const component *c, double number, double nm,
                                  const double *mu, atmos_complex *s1, atmos_complex *s2, double *ext, double *sca,
                                  double *gsca, double *dsca)
{
    const double s = log(c->sigma_g), lm = log(c->r_mod_um * 1e-6);
    const double lam = nm * 1e-9, k = 2.0 * ATMOS_PI / lam;
    /* the integrand n(ln r) pi r^2 Q peaks at ln r_m + 2 s^2 where Q is ~2 (x > 1) and up to
     * ln r_m + 6 s^2 where Q ~ x^4 (x < 1): integrate 5 s beyond the peak, within OPAC's
     * radius limits */
    const double peak = fmax(lm + 2.0 * s * s, fmin(lm + 6.0 * s * s, log(1.0 / k)));
    const double lo = fmax(lm - 4.0 * s, log(0.005e-6 * c->growth)), hi = fmin(peak + 5.0 * s, log(c->r_max_um * 1e-6));
    const double step = fmin((hi - lo) / NF_MIN, 0.5 / (k * exp(lm)));
    int nf = 2 * (int)ceil(0.5 * (hi - lo) / step);
    if (nf > NF_MAX) nf = NF_MAX;
    const atmos_complex m = comp_index(c, nm);
    double sca_fine = 0;
    for (int pass = 0; pass < (dsca ? 2 : 1); pass++) {
        const int n = pass == 0 ? nf : NQ;
        const double h = (hi - lo) / n;
        double d[NP], sca_coarse = 0;
        if (pass) memset(d, 0, sizeof d);
        for (int i = 0; i <= n; i++) {
            const double lr = lo + i * h, r = exp(lr), z = (lr - lm) / s;
            const double w = number * simpson(i, n, h) * exp(-0.5 * z * z) / (sqrt(2.0 * ATMOS_PI) * s);
            atmos_mie_result res;
            atmos_status st = atmos_mie(ctx, m, k * r, pass ? NP : 0, pass ? mu : NULL, s1, s2, &res);
            if (st != ATMOS_OK) return st;
            const double area = ATMOS_PI * r * r;
            if (pass == 0) {
                *ext += w * area * res.qext;
                sca_fine += w * area * res.qsca;
                *gsca += w * area * res.qsca * res.g;
                continue;
            }
            sca_coarse += w * area * res.qsca;
            for (int j = 0; j < NP; j++)
                d[j] += w * 0.5 * (s1[j].re * s1[j].re + s1[j].im * s1[j].im + s2[j].re * s2[j].re +
                                   s2[j].im * s2[j].im) / (k * k);
        }
        if (pass && sca_coarse > 0)
            for (int j = 0; j < NP; j++) dsca[j] += d[j] * sca_fine / sca_coarse;
    }
    *sca += sca_fine;
    return ATMOS_OK;
}

/* One wavelength of one mixture. */
static atmos_status mixture_optics(atmos_context *ctx, const mixture *mx, double nm, const double *mu,
                                   atmos_complex *s1, atmos_complex *s2, double *ext, double *sca, double *g,
                                   float *phase)
{
    double e = 0, sc = 0, gs = 0, d[NP];
    memset(d, 0, sizeof d);
    for (int c = 0; c < mx->n; c++) {
        atmos_status st = add_component(ctx, &comps[mx->comp[c]], mx->number_cm3[c], nm, phase ? mu : NULL, s1, s2,
                                        &e, &sc, &gs, phase ? d : NULL);
        if (st != ATMOS_OK) return st;
    }
    *ext = e;
    *sca = sc;
    if (g) *g = sc > 0 ? gs / sc : 0.0;
    if (phase)
        for (int j = 0; j < NP; j++) phase[j] = (float)(sc > 0 ? d[j] / sc : 1.0 / (4.0 * ATMOS_PI));
    return ATMOS_OK;
}

/* Cache payload: per wavelength ext, sca, g (doubles), then the phase tables (floats). The
 * key's version (v3) must change whenever the components, mixtures or quadrature do. */
static size_t payload_size(int n) { return (size_t)n * (3 * sizeof(double) + NP * sizeof(float)); }

static char *cache_key(atmos_aerosol_type type, int n, const double *nm, char *buf, size_t cap)
{
    int len = snprintf(buf, cap, "planet-aerosol v3 opac80 type=%d nq=%d nf=%d-%d np=%d n=%d", (int)type, NQ, NF_MIN, NF_MAX, NP, n);
    for (int k = 0; k < n && len > 0 && (size_t)len < cap; k++) len += snprintf(buf + len, cap - len, " %.17g", nm[k]);
    return len > 0 && (size_t)len < cap ? buf : NULL;
}

static int cache_get(atmos_context *ctx, const char *key, int n, double *ext, double *sca, double *g,
                     float (*phase)[NP])
{
    void *data = NULL;
    size_t size = 0;
    if (!atmos__cache_load(ctx, key, &data, &size)) return 0;
    const int ok = size == payload_size(n);
    if (ok) {
        const double *dv = data;
        for (int k = 0; k < n; k++) {
            ext[k] = dv[3 * k];
            sca[k] = dv[3 * k + 1];
            if (g) g[k] = dv[3 * k + 2];
        }
        if (phase) memcpy(phase, dv + 3 * n, (size_t)n * NP * sizeof(float));
    }
    free(data);
    return ok;
}

static void cache_put(atmos_context *ctx, const char *key, int n, const double *ext, const double *sca,
                      const double *g, float (*phase)[NP])
{
    unsigned char *data = malloc(payload_size(n));
    if (!data) return;
    double *dv = (double *)data;
    for (int k = 0; k < n; k++) {
        dv[3 * k] = ext[k];
        dv[3 * k + 1] = sca[k];
        dv[3 * k + 2] = g[k];
    }
    memcpy(dv + 3 * n, phase, (size_t)n * NP * sizeof(float));
    atmos__cache_store(ctx, key, data, payload_size(n));
    free(data);
}

atmos_status atmos__aerosol_optics(atmos_context *ctx, atmos_aerosol_type type, int n, const double *nm, double *ext,
                                   double *sca, float (*phase)[ATMOS__PLANET_PHASE_N], double *g)
{
    if (type < 0 || type >= ATMOS_AEROSOL_NONE) {
        for (int k = 0; k < n; k++) {
            ext[k] = sca[k] = 0.0;
            if (g) g[k] = 0.0;
            if (phase)
                for (int j = 0; j < NP; j++) phase[k][j] = (float)(1.0 / (4.0 * ATMOS_PI));
        }
        return ATMOS_OK;
    }
    char kbuf[2048];
    const char *key = ctx && phase && g && atmos_context_cache_dir(ctx)[0] ? cache_key(type, n, nm, kbuf, sizeof kbuf)
                                                                         : NULL;
    if (key && cache_get(ctx, key, n, ext, sca, g, phase)) return ATMOS_OK;
    double mu[NP];
    for (int j = 0; j < NP; j++) mu[j] = cos(j * ATMOS_PI / (NP - 1));
    /* wavelengths in parallel, each summed in a fixed order: the result does not depend on
     * the thread count */
    atmos_status st = ATMOS_OK;
#pragma omp parallel num_threads(atmos__threads(ctx))
    {
        atmos_complex *s = phase ? malloc(2 * NP * sizeof *s) : NULL;
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < n; k++) {
            atmos_status e = phase && !s ? ATMOS_E_NOMEM
                                         : mixture_optics(ctx, &mixtures[type], nm[k], mu, s, s ? s + NP : NULL,
                                                          &ext[k], &sca[k], g ? &g[k] : NULL, phase ? phase[k] : NULL);
            if (e != ATMOS_OK) {
#pragma omp critical(atmos_aerosol_status)
                st = e;
            }
        }
        free(s);
    }
    if (st == ATMOS_E_NOMEM) return atmos__error(ctx, st, "aerosol optics: out of memory");
    if (st == ATMOS_OK && key) cache_put(ctx, key, n, ext, sca, g, phase);
    return st;
}
