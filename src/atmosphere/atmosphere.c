/* The atmosphere interface (include/atmos/atmosphere.h, atmosphere_ops.h): creation and the
 * dispatch of every question to its kind (riley.c, homogeneous.c; a vacuum answers here).
 * Kinds are a closed, tagged set: a switch is cheaper than a call through a pointer in the
 * renderers' inner loops and keeps every kind's answers side by side. */
#include "atmosphere/atmosphere_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Riley et al. 2004, Table 3: sea-level scattering coefficients, m^-1. */
static const double table3_nm[3] = {680.0, 550.0, 440.0};
static const double table3_beta[3] = {5.8e-6, 1.35e-5, 3.31e-5};

void atmos_atmosphere_defaults(atmos_atmosphere_desc *d)
{
    memset(d, 0, sizeof *d);
    d->beta_sl_550 = ATMOS_SKY_BETA_SL_550;
    d->scale_height_m = 8000.0;
    d->ground_albedo = 0.1;
    d->sun_diameter_deg = 0.5;
    d->sun_scale = 1.0;
    d->kind = ATMOS_ATMOSPHERE_RILEY;
    d->thickness_m = 8000.0;
}

/* Zero means default for every field except ground_albedo (and the vacuum's radiance). */
static void resolve(const atmos_atmosphere_desc *in, atmos_atmosphere_desc *d)
{
    atmos_atmosphere_defaults(d);
    if (!in) return;
    *d = *in;
    if (d->beta_sl_550 == 0) d->beta_sl_550 = ATMOS_SKY_BETA_SL_550;
    if (d->scale_height_m == 0) d->scale_height_m = 8000.0;
    if (d->sun_diameter_deg == 0) d->sun_diameter_deg = 0.5;
    if (d->sun_scale == 0) d->sun_scale = 1.0;
    if (d->thickness_m == 0) d->thickness_m = 8000.0;
}

static atmos_status check(atmos_context *ctx, const atmos_atmosphere_desc *d, const atmos_wavelengths *wl)
{
    if (d->kind != ATMOS_ATMOSPHERE_RILEY && d->kind != ATMOS_ATMOSPHERE_VACUUM && d->kind != ATMOS_ATMOSPHERE_HOMOGENEOUS)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/kind: unknown kind %d", (int)d->kind);
    if (!(d->beta_sl_550 > 0 && d->beta_sl_550 <= 0.01))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/beta_sl_550_per_m: must be in (0, 0.01], got %g",
                            d->beta_sl_550);
    if (!(d->scale_height_m >= 100 && d->scale_height_m <= 100000))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/scale_height_m: must be in [100, 100000], got %g",
                            d->scale_height_m);
    if (!(d->ground_albedo >= 0 && d->ground_albedo <= 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/ground_albedo: must be in [0, 1], got %g",
                            d->ground_albedo);
    if (!(d->sun_diameter_deg > 0 && d->sun_diameter_deg <= 20))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/sun_diameter_deg: must be in (0, 20], got %g",
                            d->sun_diameter_deg);
    if (!(d->sun_scale >= 0 && d->sun_scale <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/sun_scale: must be in [0, 1e6], got %g", d->sun_scale);
    if (!(d->background_radiance >= 0 && d->background_radiance <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/background_radiance: must be in [0, 1e6], got %g",
                            d->background_radiance);
    if (!(d->thickness_m >= 1 && d->thickness_m <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/thickness_m: must be in [1, 1e6], got %g",
                            d->thickness_m);
    if (wl->count < 1 || wl->count > ATMOS_MAX_WAVELENGTHS)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere: wavelength set has %d samples (allowed 1..%d)",
                            wl->count, ATMOS_MAX_WAVELENGTHS);
    return ATMOS_OK;
}

atmos_status atmos_atmosphere_create(atmos_context *ctx, const atmos_atmosphere_desc *desc,
                                     const atmos_wavelengths *wl, atmos_atmosphere **out)
{
    if (!out || !wl) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere: missing argument");
    *out = NULL;
    atmos_atmosphere_desc d;
    resolve(desc, &d);
    atmos_status st = check(ctx, &d, wl);
    if (st != ATMOS_OK) return st;
    atmos_atmosphere *a = calloc(1, sizeof *a);
    if (!a) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory");
    a->desc = d;
    a->wl = *wl;
    a->gamma = 1.0 / d.scale_height_m;
    const double scale = d.beta_sl_550 / ATMOS_SKY_BETA_SL_550;
    for (int i = 0; i < wl->count; i++) {
        double b = ATMOS_SKY_BETA_SL_550 * pow(550.0 / wl->nm[i], 4.0);
        if (wl->mode == ATMOS_WAVELENGTHS_RGB) {
            /* The paper's own channel values where the wavelength is one of Table 3's. */
            for (int k = 0; k < 3; k++)
                if (fabs(wl->nm[i] - table3_nm[k]) < 1e-9) b = table3_beta[k];
        }
        a->beta_sl[i] = d.kind == ATMOS_ATMOSPHERE_VACUUM ? 0.0 : b * scale;
        a->sun_e[i] = wl->sun_irradiance[i] * d.sun_scale;
    }
    const double r = 0.5 * d.sun_diameter_deg * ATMOS_DEG2RAD;
    a->cos_sun_radius = cos(r);
    a->sun_solid_angle = 2.0 * ATMOS_PI * (1.0 - cos(r));
    *out = a;
    return ATMOS_OK;
}

void atmos_atmosphere_destroy(atmos_atmosphere *atm) { free(atm); }
atmos_atmosphere_kind atmos_atmosphere_get_kind(const atmos_atmosphere *atm) { return atm->desc.kind; }
const atmos_wavelengths *atmos_atmosphere_wavelengths(const atmos_atmosphere *atm) { return &atm->wl; }
const atmos_atmosphere_desc *atmos_atmosphere_get_desc(const atmos_atmosphere *atm) { return &atm->desc; }
double atmos_atmosphere_sun_solid_angle(const atmos_atmosphere *atm) { return atm->sun_solid_angle; }
const double *atmos__atm_sun_irradiance(const atmos_atmosphere *a) { return a->sun_e; }
double atmos__atm_cos_sun_radius(const atmos_atmosphere *a) { return a->cos_sun_radius; }

double atmos__atm_background(const atmos_atmosphere *a)
{
    return a->desc.kind == ATMOS_ATMOSPHERE_VACUUM ? a->desc.background_radiance : 0.0;
}

double atmos_atmosphere_ground_albedo(const atmos_atmosphere *atm)
{
    return atm->desc.kind == ATMOS_ATMOSPHERE_VACUUM ? 0.0 : atm->desc.ground_albedo;
}

/* The ground is the plane y = 0 of a flat earth; a point on or below it looking down is on it. */
double atmos_atmosphere_ground_distance(const atmos_atmosphere *atm, const double p[3], const double dir[3])
{
    if (atm->desc.kind == ATMOS_ATMOSPHERE_VACUUM) return INFINITY;
    const double y = p[1];
    if (y <= 0) return dir[1] < 0 ? 0.0 : (y < 0 ? 0.0 : INFINITY);
    if (dir[1] >= 0) return INFINITY;
    return y / -dir[1];
}

void atmos__atm_ground_hit(const atmos_atmosphere *a, double p[3], double n[3])
{
    (void)a; /* every kind here has the flat ground y = 0 */
    p[1] = 0;
    n[0] = 0, n[1] = 1, n[2] = 0;
}

int atmos_atmosphere_sun_disk_visible(const atmos_atmosphere *atm, const double sun_dir[3])
{
    return atm->desc.kind != ATMOS_ATMOSPHERE_VACUUM && !atm->desc.hide_sun_disk && sun_dir[1] > 0;
}

/* ------------------------------------------------------------------ the questions, by kind */

/* Points below the ground answer as on it. */
static double altitude(const double p[3]) { return p[1] > 0 ? p[1] : 0.0; }

void atmos__atm_transmittance_sub(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                                  int m, const int *k, double *out)
{
    switch (a->desc.kind) {
    case ATMOS_ATMOSPHERE_RILEY: atmos__riley_transmittance(a, altitude(p), d, dist, m, k, out); return;
    case ATMOS_ATMOSPHERE_HOMOGENEOUS: atmos__homog_transmittance(a, altitude(p), d, dist, m, k, out); return;
    default:
        for (int i = 0; i < m; i++) out[i] = 1.0;
    }
}

void atmos__atm_sunlight_sub(const atmos_atmosphere *a, const double p[3], const double sun[3], int m, const int *k,
                             double *out)
{
    switch (a->desc.kind) {
    case ATMOS_ATMOSPHERE_RILEY: atmos__riley_sunlight(a, altitude(p), sun, m, k, out); return;
    case ATMOS_ATMOSPHERE_HOMOGENEOUS: atmos__homog_sunlight(a, altitude(p), sun, m, k, out); return;
    default:
        for (int i = 0; i < m; i++) out[i] = a->sun_e[ATMOS__WL(k, i)];
    }
}

int atmos__atm_inscatter_sub(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                             const double sun[3], int m, const int *k, double *out)
{
    switch (a->desc.kind) {
    case ATMOS_ATMOSPHERE_RILEY: return atmos__riley_inscatter(a, altitude(p), d, dist, sun, m, k, out);
    case ATMOS_ATMOSPHERE_HOMOGENEOUS: return atmos__homog_inscatter(a, altitude(p), d, dist, sun, m, k, out);
    default:
        for (int i = 0; i < m; i++) out[i] = 0.0;
        return 0;
    }
}

int atmos__atm_scatter_point(const atmos_atmosphere *a, const double p[3], const double d[3], double dist, int m,
                             const int *k, const double *w, atmos__stream *rng, double *t, double *ratio)
{
    switch (a->desc.kind) {
    case ATMOS_ATMOSPHERE_RILEY: return atmos__riley_scatter_point(a, altitude(p), d, dist, m, k, w, rng, t, ratio);
    case ATMOS_ATMOSPHERE_HOMOGENEOUS:
        return atmos__homog_scatter_point(a, altitude(p), d, dist, m, k, w, rng, t, ratio);
    default: return 0;
    }
}

void atmos_atmosphere_transmittance(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                                    double distance, double *out)
{
    atmos__atm_transmittance_sub(atm, p, dir, distance, atm->wl.count, NULL, out);
}

void atmos_atmosphere_sunlight(const atmos_atmosphere *atm, const double p[3], const double sun_dir[3], double *out)
{
    atmos__atm_sunlight_sub(atm, p, sun_dir, atm->wl.count, NULL, out);
}

void atmos_atmosphere_inscatter(const atmos_atmosphere *atm, const double p[3], const double dir[3], double distance,
                                const double sun_dir[3], double *out)
{
    atmos__atm_inscatter_sub(atm, p, dir, distance, sun_dir, atm->wl.count, NULL, out);
}

void atmos_atmosphere_sun_radiance(const atmos_atmosphere *atm, const double p[3], const double sun_dir[3],
                                   double *out)
{
    atmos_atmosphere_sunlight(atm, p, sun_dir, out);
    for (int i = 0; i < atm->wl.count; i++) out[i] /= atm->sun_solid_angle;
}

void atmos_atmosphere_scattering(const atmos_atmosphere *atm, const double p[3], double *scattering,
                                 double *extinction)
{
    const double y = altitude(p);
    double f = 0.0;
    if (atm->desc.kind == ATMOS_ATMOSPHERE_RILEY) f = exp(-atm->gamma * y);
    else if (atm->desc.kind == ATMOS_ATMOSPHERE_HOMOGENEOUS) f = y <= atm->desc.thickness_m ? 1.0 : 0.0;
    for (int i = 0; i < atm->wl.count; i++) {
        if (scattering) scattering[i] = atm->beta_sl[i] * f; /* albedo 1: extinction = scattering */
        if (extinction) extinction[i] = atm->beta_sl[i] * f;
    }
}

double atmos_atmosphere_phase(const atmos_atmosphere *atm, const double p[3], double cos_theta)
{
    (void)atm, (void)p;
    return atmos_phase_rayleigh(cos_theta);
}

/* What a view ray sees; the sun's disk only with disk. */
static void radiance(const atmos_atmosphere *atm, const double p[3], const double dir[3], const double sun_dir[3],
                     int disk, double *out, atmos_atmosphere_hit *info)
{
    const int n = atm->wl.count;
    const double K = atmos_atmosphere_ground_distance(atm, p, dir);
    const int ground = !isinf(K);
    atmos_atmosphere_inscatter(atm, p, dir, K, sun_dir, out);
    double tmp[ATMOS_MAX_WAVELENGTHS], sun[ATMOS_MAX_WAVELENGTHS];
    int in_disk = 0;
    if (ground) {
        /* Lambertian ground lit by the attenuated sun, seen through the air between it and
         * the eye. */
        const double ly = sun_dir[1], albedo = atmos_atmosphere_ground_albedo(atm);
        if (ly > 0 && albedo > 0) {
            const double g[3] = {p[0] + K * dir[0], 0.0, p[2] + K * dir[2]};
            atmos_atmosphere_sunlight(atm, g, sun_dir, sun);
            atmos_atmosphere_transmittance(atm, p, dir, K, tmp);
            for (int i = 0; i < n; i++) out[i] += albedo / ATMOS_PI * ly * sun[i] * tmp[i];
        }
    } else if (atm->desc.kind == ATMOS_ATMOSPHERE_VACUUM) {
        for (int i = 0; i < n; i++) out[i] += atm->desc.background_radiance;
    } else if (disk && !atm->desc.hide_sun_disk) {
        const double mu = dir[0] * sun_dir[0] + dir[1] * sun_dir[1] + dir[2] * sun_dir[2];
        if (mu >= atm->cos_sun_radius) {
            in_disk = 1;
            atmos_atmosphere_sun_radiance(atm, p, sun_dir, sun);
            for (int i = 0; i < n; i++) out[i] += sun[i];
        }
    }
    if (info) {
        info->distance_m = K;
        info->hits_ground = ground;
        info->in_sun_disk = in_disk;
    }
}

void atmos_atmosphere_radiance(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                               const double sun_dir[3], double *out, atmos_atmosphere_hit *info)
{
    radiance(atm, p, dir, sun_dir, 1, out, info);
}

/* ------------------------------------------------------------------ many view rays at once */

void atmos__atm_batch_init(atmos__atm_batch *b, const atmos_atmosphere *a, const double eye[3], const double sun[3])
{
    memset(b, 0, sizeof *b);
    b->atm = a;
    b->kind = a->desc.kind;
    memcpy(b->eye, eye, sizeof b->eye);
    memcpy(b->sun, sun, sizeof b->sun);
    b->background = (float)atmos__atm_background(a);
    if (a->desc.kind == ATMOS_ATMOSPHERE_RILEY) atmos__sky_batch_init(&b->riley, a, eye[1], sun);
}

/* Any kind: the double-precision radiance of each ray without the sun's disk. */
static void batch_generic(const atmos__atm_batch *b, int count, const float *dx, const float *dy, const float *dz,
                          const float *weight, float *out)
{
    const atmos_atmosphere *a = b->atm;
    const int n = a->wl.count;
    for (int i = 0; i < count; i++) {
        if (weight[i] == 0.0f) continue;
        const double d[3] = {dx[i], dy[i], dz[i]};
        double L[ATMOS_MAX_WAVELENGTHS];
        radiance(a, b->eye, d, b->sun, 0, L, NULL);
        for (int k = 0; k < n; k++) out[(size_t)k * count + i] += weight[i] * (float)L[k];
    }
}

void atmos__atm_batch_eval(const atmos__atm_batch *b, int count, const float *dx, const float *dy, const float *dz,
                           const float *weight, float *out, float *scratch)
{
    switch (b->kind) {
    case ATMOS_ATMOSPHERE_RILEY: atmos__sky_batch_eval(&b->riley, count, dx, dy, dz, weight, out, scratch); return;
    case ATMOS_ATMOSPHERE_VACUUM: {
        const int n = b->atm->wl.count;
        for (int k = 0; k < n; k++)
            for (int i = 0; i < count; i++) out[(size_t)k * count + i] += weight[i] * b->background;
        return;
    }
    default: batch_generic(b, count, dx, dy, dz, weight, out);
    }
}
