/* Phase tables: a particle type's phase function P^lambda(theta) at every wavelength of a
 * set on the shared angular grid (atmos_phase_grid), normalised, with extinction
 * cross-section, albedo and asymmetry, an inverse-CDF sampler and the density it draws from
 * (eval = pdf, angle_table.h), and the disk cache (DESIGN.md §7). Format and conventions:
 * docs/phase-tables.md.
 */
#include "core/cache.h"
#include "core/internal.h"
#include "optics/angle_table.h"
#include "optics/optics_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Bump when anything this file or a per-kind builder computes changes, so old cache
 * entries become stale (their key no longer matches) instead of being reused. */
#define PHASE_TABLE_ALGORITHM_VERSION 1
/* Per-kind algorithm versions: bump the one of a kind whose builder (mie.c /
 * polydisperse.c for water, crystal.c for ice and snow) changes its output. */
static const int kind_version[] = {1 /* air */, 1 /* water */, 1 /* ice */, 1 /* snow */, 1 /* analytic */};
/* Layout of the cache payload (see pack_payload). */
#define PHASE_TABLE_PAYLOAD_VERSION 1

/* Riley et al. 2004 Eq. 9: sea-level number density of air molecules, m^-3. */
#define AIR_ETA_SEA_LEVEL 2.55e25
/* Riley Table 3: sea-level scattering coefficients, m^-1. */
static const double table3_nm[3] = {680.0, 550.0, 440.0};
static const double table3_beta[3] = {5.8e-6, 1.35e-5, 3.31e-5};

struct atmos_phase_table {
    int n_wl, n_ang;
    const atmos__angle_grid *grid; /* atmos__phase_angle_grid() */
    const double *theta_deg;       /* grid->deg */
    double *nm;
    double *values;  /* n_wl x n_ang, P in sr^-1 */
    double *cdf;     /* n_wl x n_ang, CDF over theta at the grid angles, cdf[0] = 0, last = 1 */
    double *total;   /* n_wl: F, the normaliser of the sampled density (angle_table.h) */
    double *sigma_ext, *albedo, *g;
    int from_cache;
};

static const char *kind_name(atmos_particle_kind k)
{
    switch (k) {
    case ATMOS_PARTICLE_AIR: return "air";
    case ATMOS_PARTICLE_WATER: return "water";
    case ATMOS_PARTICLE_ICE: return "ice";
    case ATMOS_PARTICLE_SNOW: return "snow";
    case ATMOS_PARTICLE_ANALYTIC: return "analytic";
    }
    return "?";
}

void atmos_phase_table_destroy(atmos_phase_table *t)
{
    if (!t) return;
    free(t->nm);
    free(t->values);
    free(t->cdf);
    free(t->total);
    free(t->sigma_ext);
    free(t->albedo);
    free(t->g);
    free(t);
}

static atmos_phase_table *table_alloc(int n_wl, const atmos__angle_grid *grid)
{
    atmos_phase_table *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    t->n_wl = n_wl;
    t->n_ang = grid->n;
    t->grid = grid;
    t->theta_deg = grid->deg;
    size_t n = (size_t)n_wl * (size_t)grid->n;
    t->nm = calloc((size_t)n_wl, sizeof *t->nm);
    t->values = calloc(n, sizeof *t->values);
    t->cdf = calloc(n, sizeof *t->cdf);
    t->total = calloc((size_t)n_wl, sizeof *t->total);
    t->sigma_ext = calloc((size_t)n_wl, sizeof *t->sigma_ext);
    t->albedo = calloc((size_t)n_wl, sizeof *t->albedo);
    t->g = calloc((size_t)n_wl, sizeof *t->g);
    if (!t->nm || !t->values || !t->cdf || !t->total || !t->sigma_ext || !t->albedo || !t->g) {
        atmos_phase_table_destroy(t);
        return NULL;
    }
    return t;
}

/* ---------------------------------------------------------------- validation */

static atmos_status check_mixture(atmos_context *ctx, const char *who, const atmos_phase_mixture *m)
{
    if (m->count < 1 || m->count > ATMOS_PHASE_MAX_LOBES)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: analytic.count must be in [1, %d], got %d", who,
                            ATMOS_PHASE_MAX_LOBES, m->count);
    double s = 0.0;
    for (int i = 0; i < m->count; i++) {
        if ((int)m->kind[i] < ATMOS_PHASE_ISOTROPIC || (int)m->kind[i] > ATMOS_PHASE_CORNETTE_SHANKS)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: analytic.kind[%d]: unknown lobe kind %d", who, i,
                                (int)m->kind[i]);
        if (!isfinite(m->weight[i]) || m->weight[i] < 0)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: analytic.weight[%d] must be finite and >= 0, got %g",
                                who, i, m->weight[i]);
        if ((m->kind[i] == ATMOS_PHASE_HG || m->kind[i] == ATMOS_PHASE_CORNETTE_SHANKS) &&
            !(isfinite(m->g[i]) && m->g[i] > -1 && m->g[i] < 1))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: analytic.g[%d] must be in (-1, 1), got %g", who, i,
                                m->g[i]);
        s += m->weight[i];
    }
    if (!(s > 0) || !isfinite(s))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: analytic weights must not all be zero", who);
    return ATMOS_OK;
}

static atmos_status check_inputs(atmos_context *ctx, const char *who, const atmos_particle_desc *p,
                                 const atmos_wavelengths *wl)
{
    if ((int)p->kind < ATMOS_PARTICLE_AIR || (int)p->kind > ATMOS_PARTICLE_ANALYTIC)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: unknown particle kind %d", who, (int)p->kind);
    if (!isfinite(p->sigma_ext_m2) || p->sigma_ext_m2 < 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: sigma_ext_m2 must be finite and >= 0 (0 = computed), got %g",
                            who, p->sigma_ext_m2);
    if (!isfinite(p->albedo) || p->albedo < 0 || p->albedo > 1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: albedo must be in [0, 1] (0 = computed), got %g", who,
                            p->albedo);
    if (wl->count < 1 || wl->count > ATMOS_MAX_WAVELENGTHS)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: wavelength count must be in [1, %d], got %d", who,
                            ATMOS_MAX_WAVELENGTHS, wl->count);
    for (int k = 0; k < wl->count; k++)
        if (!isfinite(wl->nm[k]) || wl->nm[k] <= 0 || wl->nm[k] > 1e5)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: wavelength %d must be in (0, 1e5] nm, got %g", who, k,
                                wl->nm[k]);
    if (p->kind == ATMOS_PARTICLE_ANALYTIC) return check_mixture(ctx, who, &p->analytic);
    return ATMOS_OK;
}

/* ---------------------------------------------------------------- cache key and payload */

typedef struct {
    char *s;
    size_t len, cap;
    int oom;
} strbuf;

static void sb_printf(strbuf *b, const char *fmt, ...) ATMOS_PRINTF(2, 3);
static void sb_printf(strbuf *b, const char *fmt, ...)
{
    if (b->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(b->s ? b->s + b->len : NULL, b->s ? b->cap - b->len : 0, fmt, ap);
        va_end(ap);
        if (n < 0) {
            b->oom = 1;
            return;
        }
        if (b->s && b->len + (size_t)n < b->cap) {
            b->len += (size_t)n;
            return;
        }
        size_t cap = (b->cap ? b->cap * 2 : 1024) + (size_t)n;
        char *s = realloc(b->s, cap);
        if (!s) {
            b->oom = 1;
            return;
        }
        b->s = s;
        b->cap = cap;
    }
}

/* The key describes everything the table depends on: the versions, the byte order of
 * the payload's doubles, the grid, the kind's parameters (only those the kind uses, so
 * irrelevant fields do not split entries), the overrides and the wavelengths. Doubles
 * are written with 17 significant digits so that distinct values give distinct keys. */
static char *make_key(const atmos_particle_desc *p, const atmos_wavelengths *wl, int n_ang, const double *theta)
{
    const uint16_t one = 1;
    unsigned char first;
    memcpy(&first, &one, 1);
    strbuf b = {0};
    sb_printf(&b, "atmos phase table; algorithm %d.%d; payload %d; %s-endian doubles\n", PHASE_TABLE_ALGORITHM_VERSION,
              kind_version[p->kind], PHASE_TABLE_PAYLOAD_VERSION, first ? "little" : "big");
    sb_printf(&b, "grid %d angles, checksum %016llx\n", n_ang,
              (unsigned long long)atmos__cache_checksum(theta, (size_t)n_ang * sizeof *theta));
    sb_printf(&b, "kind %s\n", kind_name(p->kind));
    const atmos_size_distribution *s = &p->size;
    switch (p->kind) {
    case ATMOS_PARTICLE_AIR: break;
    case ATMOS_PARTICLE_WATER:
        sb_printf(&b, "size kind %d r_m %.17g sigma %.17g alpha %.17g gamma %.17g r_min %.17g r_max %.17g\nfast %d\n",
                  (int)s->kind, s->r_m, s->sigma, s->alpha, s->gamma, s->r_min, s->r_max, p->fast != 0);
        break;
    case ATMOS_PARTICLE_ICE:
    case ATMOS_PARTICLE_SNOW:
        sb_printf(&b, "size kind %d r_m %.17g sigma %.17g alpha %.17g gamma %.17g r_min %.17g r_max %.17g\n",
                  (int)s->kind, s->r_m, s->sigma, s->alpha, s->gamma, s->r_min, s->r_max);
        sb_printf(&b, "habit %d aspect %.17g distortion %.17g rays %ld fast %d\n", (int)p->habit, p->aspect_ratio,
                  p->distortion, p->rays, p->fast != 0);
        break;
    case ATMOS_PARTICLE_ANALYTIC:
        sb_printf(&b, "lobes %d\n", p->analytic.count);
        for (int i = 0; i < p->analytic.count; i++)
            sb_printf(&b, "lobe %d kind %d g %.17g weight %.17g\n", i, (int)p->analytic.kind[i], p->analytic.g[i],
                      p->analytic.weight[i]);
        break;
    }
    sb_printf(&b, "sigma_ext_m2 %.17g albedo %.17g\n", p->sigma_ext_m2, p->albedo);
    if (p->albedo_set) sb_printf(&b, "albedo_set 1\n");
    sb_printf(&b, "wavelengths %d nm", wl->count);
    for (int k = 0; k < wl->count; k++) sb_printf(&b, " %.17g", wl->nm[k]);
    if (b.oom) {
        free(b.s);
        return NULL;
    }
    return b.s;
}

/* Payload: per wavelength, 4 + n_ang native doubles: nm, sigma_ext, albedo, g, P[]. The
 * CDF is not stored: it is recomputed on load (microseconds) and cannot go stale. */
static size_t payload_size(int n_wl, int n_ang) { return (size_t)n_wl * (4 + (size_t)n_ang) * sizeof(double); }

static double *pack_payload(const atmos_phase_table *t)
{
    double *d = malloc(payload_size(t->n_wl, t->n_ang));
    if (!d) return NULL;
    double *q = d;
    for (int k = 0; k < t->n_wl; k++) {
        *q++ = t->nm[k];
        *q++ = t->sigma_ext[k];
        *q++ = t->albedo[k];
        *q++ = t->g[k];
        memcpy(q, t->values + (size_t)k * t->n_ang, (size_t)t->n_ang * sizeof *q);
        q += t->n_ang;
    }
    return d;
}

/* Fills t from a payload whose checksum already matched; still checks every value is
 * physically possible, since the checksum cannot tell a bug in an old writer. */
static int unpack_payload(atmos_phase_table *t, const double *d, size_t size, const atmos_wavelengths *wl)
{
    if (size != payload_size(t->n_wl, t->n_ang)) return 0;
    const double *q = d;
    for (int k = 0; k < t->n_wl; k++) {
        t->nm[k] = *q++;
        t->sigma_ext[k] = *q++;
        t->albedo[k] = *q++;
        t->g[k] = *q++;
        if (t->nm[k] != wl->nm[k] || !isfinite(t->sigma_ext[k]) || t->sigma_ext[k] < 0 || !(t->albedo[k] >= 0) ||
            t->albedo[k] > 1 || !(t->g[k] >= -1) || t->g[k] > 1)
            return 0;
        double *v = t->values + (size_t)k * t->n_ang;
        memcpy(v, q, (size_t)t->n_ang * sizeof *q);
        q += t->n_ang;
        for (int i = 0; i < t->n_ang; i++)
            if (!isfinite(v[i]) || v[i] < 0) return 0;
    }
    return 1;
}

/* ---------------------------------------------------------------- sampling */

/* The sampling density over theta is f(theta) = 2 pi P(theta) sin(theta) taken as
 * piecewise linear between grid angles: the same trapezoid rule that normalises the
 * table (atmos__sphere_integral), so the CDF ends at exactly the normalised total.
 * Inside an interval F is then quadratic and is inverted exactly (atmos__angle_invert).
 * atmos_phase_table_eval reads that same function through g_i = P_i sin(theta_i) / F; F
 * (t->total) is summed in radians interval by interval, the sum the path tracer's
 * single-precision copies of g_i have always been divided by (path_phase.c), so that those
 * copies stay what they were. The CDF's own sum (degree steps converted per interval)
 * differs from it in the last bits only; it is kept so that sampled directions stay what
 * they were too. */
static int build_cdf(atmos_phase_table *t, int k)
{
    const double *th = t->theta_deg, *rad = t->grid->rad, *sn = t->grid->sin, *v = t->values + (size_t)k * t->n_ang;
    double *c = t->cdf + (size_t)k * t->n_ang;
    double ft = 0;
    c[0] = 0.0;
    for (int i = 0; i + 1 < t->n_ang; i++) {
        const double a = ATMOS_PI * (v[i] * sn[i] + v[i + 1] * sn[i + 1]);
        c[i + 1] = c[i] + a * (th[i + 1] - th[i]) * ATMOS_DEG2RAD;
        ft += a * (rad[i + 1] - rad[i]);
    }
    double total = c[t->n_ang - 1];
    if (!(total > 0) || !isfinite(total) || !(ft > 0) || !isfinite(ft)) return 0;
    for (int i = 1; i < t->n_ang; i++) c[i] /= total;
    c[t->n_ang - 1] = 1.0;
    t->total[k] = ft;
    return 1;
}

static void compute_g(atmos_phase_table *t, int k)
{
    const double *v = t->values + (size_t)k * t->n_ang;
    double *f = malloc((size_t)t->n_ang * sizeof *f);
    if (!f) return; /* g stays as set by the caller */
    for (int i = 0; i < t->n_ang; i++) f[i] = v[i] * cos(t->theta_deg[i] * ATMOS_DEG2RAD);
    double gg = atmos__sphere_integral(t->n_ang, t->theta_deg, f);
    free(f);
    t->g[k] = gg < -1 ? -1 : gg > 1 ? 1 : gg;
}

/* ---------------------------------------------------------------- building */

/* Air: Rayleigh (Riley Eq. 1). sigma_ext = beta_sl(lambda) / eta_sl: Riley's Table 3
 * values at its three wavelengths, else the lambda^-4 law through 550 nm, divided by
 * the sea-level density of Eq. 9. This reproduces Table 2 (2.28e-31, 5.33e-31,
 * 1.30e-30 m^2) to within 1 % and is consistent with the sky module's coefficients. */
static double air_sigma_ext(double nm)
{
    for (int i = 0; i < 3; i++)
        if (fabs(nm - table3_nm[i]) < 1e-9) return table3_beta[i] / AIR_ETA_SEA_LEVEL;
    return table3_beta[1] * pow(550.0 / nm, 4.0) / AIR_ETA_SEA_LEVEL;
}

/* Asymmetry of a mixture from the lobes' closed forms: <mu> = g for HG (Henyey &
 * Greenstein 1941), 3g(4 + g^2) / (5(2 + g^2)) for Cornette-Shanks (Cornette & Shanks
 * 1992), 0 for isotropic and Rayleigh. */
static double mixture_g(const atmos_phase_mixture *m)
{
    double s = 0.0, w = 0.0;
    for (int i = 0; i < m->count; i++) {
        double g = m->g[i], lg = 0.0;
        if (m->kind[i] == ATMOS_PHASE_HG) lg = g;
        else if (m->kind[i] == ATMOS_PHASE_CORNETTE_SHANKS) lg = 3.0 * g * (4.0 + g * g) / (5.0 * (2.0 + g * g));
        s += m->weight[i] * lg;
        w += m->weight[i];
    }
    return w > 0 ? s / w : 0.0;
}

typedef struct {
    const atmos_context *ctx;
    const char *stage;
    int k, n;
} progress_map;

/* Maps a wavelength's own progress fraction to the whole table's. */
static int map_progress(void *user, double fraction)
{
    const progress_map *m = user;
    if (!(fraction >= 0)) fraction = 0;
    if (fraction > 1) fraction = 1;
    return atmos__progress(m->ctx, m->stage, (m->k + fraction) / m->n);
}

static atmos_status build_one(atmos_context *ctx, const char *who, const atmos_particle_desc *p, double nm,
                              atmos_phase_table *t, int k, progress_map *pm)
{
    double *v = t->values + (size_t)k * t->n_ang;
    atmos__phase_result res = {0, 1, 0};
    atmos_status st = ATMOS_OK;
    switch (p->kind) {
    case ATMOS_PARTICLE_AIR:
        for (int i = 0; i < t->n_ang; i++) v[i] = atmos_phase_rayleigh(cos(t->theta_deg[i] * ATMOS_DEG2RAD));
        res.sigma_ext_m2 = air_sigma_ext(nm);
        res.albedo = 1.0;
        res.g = 0.0;
        break;
    case ATMOS_PARTICLE_ANALYTIC:
        for (int i = 0; i < t->n_ang; i++)
            v[i] = atmos_phase_mixture_eval(&p->analytic, cos(t->theta_deg[i] * ATMOS_DEG2RAD));
        res.sigma_ext_m2 = p->sigma_ext_m2;
        res.albedo = 1.0;
        res.g = mixture_g(&p->analytic);
        break;
    case ATMOS_PARTICLE_WATER:
        st = atmos__water_phase(ctx, p, nm, t->n_ang, t->theta_deg, v, &res, map_progress, pm);
        break;
    case ATMOS_PARTICLE_ICE:
    case ATMOS_PARTICLE_SNOW:
        st = atmos__crystal_phase(ctx, p, nm, t->n_ang, t->theta_deg, v, &res, map_progress, pm);
        break;
    }
    if (st != ATMOS_OK) return st;
    for (int i = 0; i < t->n_ang; i++)
        if (!isfinite(v[i]) || v[i] < 0)
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: phase function at %g nm is %g at %g deg (internal error)", who,
                                nm, v[i], t->theta_deg[i]);
    /* Riley Table 2 presets and user settings override the computed values. */
    t->nm[k] = nm;
    t->sigma_ext[k] = p->sigma_ext_m2 > 0 ? p->sigma_ext_m2 : res.sigma_ext_m2;
    t->albedo[k] = p->albedo > 0 || p->albedo_set ? p->albedo : res.albedo;
    if (!isfinite(t->sigma_ext[k]) || t->sigma_ext[k] < 0) t->sigma_ext[k] = 0.0;
    if (!(t->albedo[k] >= 0) || t->albedo[k] > 1) t->albedo[k] = t->albedo[k] > 1 ? 1.0 : 0.0;

    double raw = atmos__sphere_integral(t->n_ang, t->theta_deg, v);
    if (!(raw > 0) || !isfinite(raw))
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: phase function at %g nm integrates to %g (internal error)", who,
                            nm, raw);
    if (fabs(raw - 1.0) > 1e-3)
        atmos__log(ctx, ATMOS_LOG_WARN, "%s: phase function at %g nm integrated to %.6g before normalisation", who, nm,
                   raw);
    for (int i = 0; i < t->n_ang; i++) v[i] /= raw;
    if (!build_cdf(t, k))
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: cannot build the sampling CDF at %g nm", who, nm);
    /* The builders' own g (from the Mie series or the ray statistics) is more accurate
     * than a quadrature over a very narrow forward peak; fall back to the table's. */
    if (isfinite(res.g) && res.g >= -1 && res.g <= 1) t->g[k] = res.g;
    else compute_g(t, k);
    return ATMOS_OK;
}

atmos_status atmos_phase_table_build(atmos_context *ctx, const atmos_particle_desc *particle,
                                     const atmos_wavelengths *wl, const atmos_phase_table_desc *desc,
                                     atmos_phase_table **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "phase table: out is NULL");
    *out = NULL;
    if (!particle || !wl) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "phase table: particle or wavelengths is NULL");
    char name[40];
    size_t nl = 0; /* the name need not be NUL-terminated within its 32 bytes */
    while (nl < sizeof particle->name && particle->name[nl]) nl++;
    if (nl) snprintf(name, sizeof name, "%.*s", (int)nl, particle->name);
    else snprintf(name, sizeof name, "%s", kind_name(particle->kind));
    char who[64], stage[64];
    snprintf(who, sizeof who, "phase table '%s'", name);
    snprintf(stage, sizeof stage, "phase %s", name);
    atmos_status st = check_inputs(ctx, who, particle, wl);
    if (st != ATMOS_OK) return st;

    const atmos__angle_grid *grid = atmos__phase_angle_grid();
    const double *theta = grid->deg;
    const int n_ang = grid->n;
    atmos_phase_table *t = table_alloc(wl->count, grid);
    if (!t) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", who);

    int use_cache = !(desc && desc->no_cache);
    char *key = use_cache ? make_key(particle, wl, n_ang, theta) : NULL;
    if (use_cache && !key) atmos__log(ctx, ATMOS_LOG_WARN, "%s: out of memory for the cache key; not cached", who);
    if (key) {
        void *data;
        size_t size;
        if (atmos__cache_load(ctx, key, &data, &size)) {
            int ok = unpack_payload(t, data, size, wl);
            for (int k = 0; ok && k < t->n_wl; k++) ok = build_cdf(t, k);
            free(data);
            if (ok) {
                t->from_cache = 1;
                free(key);
                atmos__progress(ctx, stage, 1.0);
                *out = t;
                return ATMOS_OK;
            }
            char path[4096];
            if (atmos__cache_entry_path(ctx, key, path, sizeof path)) {
                atmos__log(ctx, ATMOS_LOG_WARN, "cache: %s: values out of range; ignoring it and rebuilding", path);
                remove(path);
            }
        }
    }

    if (atmos__progress(ctx, stage, 0.0)) {
        st = atmos__error(ctx, ATMOS_E_CANCELLED, "%s: cancelled", who);
        goto fail;
    }
    for (int k = 0; k < wl->count; k++) {
        progress_map pm = {ctx, stage, k, wl->count};
        st = build_one(ctx, who, particle, wl->nm[k], t, k, &pm);
        if (st == ATMOS_E_CANCELLED) {
            if (atmos_context_error_status(ctx) != ATMOS_E_CANCELLED) atmos__error(ctx, st, "%s: cancelled", who);
            goto fail;
        }
        if (st != ATMOS_OK) goto fail;
        if (atmos__progress(ctx, stage, (double)(k + 1) / wl->count)) {
            st = atmos__error(ctx, ATMOS_E_CANCELLED, "%s: cancelled", who);
            goto fail;
        }
    }
    if (key) {
        double *payload = pack_payload(t);
        if (payload) atmos__cache_store(ctx, key, payload, payload_size(t->n_wl, t->n_ang));
        else atmos__log(ctx, ATMOS_LOG_WARN, "%s: out of memory for the cache entry; not cached", who);
        free(payload);
    }
    free(key);
    *out = t;
    return ATMOS_OK;
fail:
    free(key);
    atmos_phase_table_destroy(t);
    return st;
}

/* ---------------------------------------------------------------- accessors */

static int wl_ok(const atmos_phase_table *t, int k) { return t && k >= 0 && k < t->n_wl; }

int atmos_phase_table_wavelength_count(const atmos_phase_table *t) { return t ? t->n_wl : 0; }
double atmos_phase_table_wavelength_nm(const atmos_phase_table *t, int k) { return wl_ok(t, k) ? t->nm[k] : 0.0; }
const double *atmos_phase_table_values(const atmos_phase_table *t, int k)
{
    return wl_ok(t, k) ? t->values + (size_t)k * t->n_ang : NULL;
}
double atmos_phase_table_sigma_ext(const atmos_phase_table *t, int k) { return wl_ok(t, k) ? t->sigma_ext[k] : 0.0; }
double atmos_phase_table_albedo(const atmos_phase_table *t, int k) { return wl_ok(t, k) ? t->albedo[k] : 0.0; }

void atmos_phase_table_cross_sections(const atmos_phase_table *t, int k, double *sigma_ext, double *sigma_sca)
{
    double se = atmos_phase_table_sigma_ext(t, k), al = atmos_phase_table_albedo(t, k);
    if (!(se >= 0) || !isfinite(se)) se = 0;
    if (!(al >= 0)) al = 0;
    if (al > 1) al = 1;
    *sigma_ext = se;
    *sigma_sca = se * al;
}
double atmos_phase_table_g(const atmos_phase_table *t, int k) { return wl_ok(t, k) ? t->g[k] : 0.0; }
int atmos_phase_table_from_cache(const atmos_phase_table *t) { return t ? t->from_cache : 0; }

double atmos__phase_table_total(const atmos_phase_table *t, int k) { return wl_ok(t, k) ? t->total[k] : 0.0; }

/* The density atmos_phase_table_sample draws from, per steradian (angle_table.h). */
double atmos_phase_table_eval(const atmos_phase_table *t, int k, double cos_theta)
{
    if (!wl_ok(t, k) || isnan(cos_theta)) return 0.0;
    atmos__angle_weights a;
    atmos__angle_density_weights(t->grid, cos_theta, &a);
    const double *v = t->values + (size_t)k * t->n_ang, *sn = t->grid->sin;
    return (a.w0 * (v[a.i] * sn[a.i]) + a.w1 * (v[a.i + 1] * sn[a.i + 1])) / t->total[k];
}

double atmos_phase_table_pdf(const atmos_phase_table *t, int k, double cos_theta)
{
    return atmos_phase_table_eval(t, k, cos_theta);
}

double atmos_phase_table_sample(const atmos_phase_table *t, int k, double u)
{
    if (!wl_ok(t, k)) return 1.0;
    const double *c = t->cdf + (size_t)k * t->n_ang, *v = t->values + (size_t)k * t->n_ang, *sn = t->grid->sin;
    const int i = atmos__angle_cdf_find(c, t->n_ang, &u);
    /* f in the units of the CDF's sum (only the ratio f1 / f0 and the interval's mass matter) */
    return atmos__angle_invert(t->grid, c, i, u, v[i] * sn[i], v[i + 1] * sn[i + 1]);
}
