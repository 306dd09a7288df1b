/* The atmosphere interface's questions (include/atmos/atmosphere.h, atmosphere_ops.h), each
 * passed to its kind (riley.c, homogeneous.c; a vacuum answers here). Kinds are a closed,
 * tagged set: a switch is cheaper than a call through a pointer in the renderers' inner
 * loops and keeps every kind's answers side by side. */
#include "atmosphere/atmosphere_check.h"
#include "atmosphere/atmosphere_internal.h"
#include "atmosphere/planet_clouds.h"
#include "atmosphere/planet_solver.h"

#include <math.h>
#include <string.h>

/* Points below the ground answer as on it. */
static double altitude(const double p[3]) { return p[1] > 0 ? p[1] : 0.0; }

void atmos__atm_transmittance_sub(const atmos_atmosphere *a, const double p[3], const double d[3], double dist,
                                  int m, const int *k, double *out)
{
    if (a->solver) {
        a->solver->transmittance(a, p, d, dist, m, k, out);
        return;
    }
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
    if (a->solver) {
        a->solver->sunlight(a, p, sun, m, k, out);
        return;
    }
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
    if (a->solver) return a->solver->inscatter(a, p, d, dist, sun, m, k, out);
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
    if (a->solver) return 0; /* the spherical kinds: no shadow estimate in the air yet */
    switch (a->desc.kind) {
    case ATMOS_ATMOSPHERE_RILEY: return atmos__riley_scatter_point(a, altitude(p), d, dist, m, k, w, rng, t, ratio);
    case ATMOS_ATMOSPHERE_HOMOGENEOUS:
        return atmos__homog_scatter_point(a, altitude(p), d, dist, m, k, w, rng, t, ratio);
    default: return 0;
    }
}

/* out[0..count-1] = NaN: the answer to a question the public functions refuse
 * (atmosphere_check.c). */
static void refuse(const atmos_atmosphere *atm, double *out)
{
    for (int i = 0; i < atm->wl.count; i++) out[i] = NAN;
}

void atmos_atmosphere_transmittance(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                                    double distance, double *out)
{
    if (atmos__atm_ray_fault(atm, p, dir) || isnan(distance)) refuse(atm, out);
    else atmos__atm_transmittance_sub(atm, p, dir, distance, atm->wl.count, NULL, out);
}

void atmos_atmosphere_sunlight(const atmos_atmosphere *atm, const double p[3], const double sun_dir[3], double *out)
{
    if (atmos__atm_light_fault(p, sun_dir)) refuse(atm, out);
    else atmos__atm_sunlight_sub(atm, p, sun_dir, atm->wl.count, NULL, out);
}

void atmos_atmosphere_inscatter(const atmos_atmosphere *atm, const double p[3], const double dir[3], double distance,
                                const double sun_dir[3], double *out)
{
    if (atmos__atm_ray_fault(atm, p, dir) || atmos__atm_unit_fault(sun_dir) || isnan(distance)) refuse(atm, out);
    else atmos__atm_inscatter_sub(atm, p, dir, distance, sun_dir, atm->wl.count, NULL, out);
}

void atmos_atmosphere_sun_radiance(const atmos_atmosphere *atm, const double p[3], const double sun_dir[3],
                                   double *out)
{
    atmos_atmosphere_sunlight(atm, p, sun_dir, out); /* NaN for what sunlight refuses */
    for (int i = 0; i < atm->wl.count; i++) out[i] /= atm->sun_solid_angle;
}

void atmos_atmosphere_scattering(const atmos_atmosphere *atm, const double p[3], double *scattering,
                                 double *extinction)
{
    if (atm->planet) {
        const atmos__planet *pl = atm->planet;
        const double h = atmos__planet_altitude(pl, p);
        for (int i = 0; i < atm->wl.count; i++) {
            const int on = h <= pl->r_top - pl->r_ground;
            const double s = on ? pl->rayleigh[i] * atmos__planet_rho_rayleigh(pl, h) +
                                      pl->mie_sca[i] * atmos__planet_rho_mie(pl, h)
                                : 0.0;
            if (scattering) scattering[i] = s;
            if (extinction) extinction[i] = atmos__planet_extinction(pl, h, i);
        }
        return;
    }
    const double y = altitude(p);
    double f = 0.0;
    if (atm->desc.kind == ATMOS_ATMOSPHERE_RILEY) f = exp(-atm->gamma * y);
    else if (atm->desc.kind == ATMOS_ATMOSPHERE_HOMOGENEOUS) f = y <= atm->desc.thickness_m ? 1.0 : 0.0;
    for (int i = 0; i < atm->wl.count; i++) {
        if (scattering) scattering[i] = atm->beta_sl[i] * f; /* albedo 1: extinction = scattering */
        if (extinction) extinction[i] = atm->beta_sl[i] * f;
    }
}

/* A spherical kind's mixture is a function of the wavelength; this answer is its first's. */
double atmos_atmosphere_phase(const atmos_atmosphere *atm, const double p[3], double cos_theta)
{
    if (atm->planet) return atmos__planet_phase(atm->planet, atmos__planet_altitude(atm->planet, p), 0, cos_theta);
    return atmos_phase_rayleigh(cos_theta);
}

/* A spherical kind's view ray: its solver's radiance and the sun's disk where the planet
 * does not hide it. */
static void planet_radiance(const atmos_atmosphere *atm, const double p[3], const double dir[3],
                            const double sun_dir[3], int disk, double *out, atmos_atmosphere_hit *info)
{
    atmos_atmosphere_hit h;
    if (atm->planet->clouds) atmos__planet_radiance_clouds(atm, p, dir, sun_dir, out, &h);
    else if (atm->solver->radiance) atm->solver->radiance(atm, p, dir, sun_dir, out, &h);
    else atmos__planet_radiance_generic(atm, p, dir, sun_dir, out, &h);
    h.in_sun_disk = 0;
    if (disk && !h.hits_ground && !atm->desc.hide_sun_disk) {
        const double mu = dir[0] * sun_dir[0] + dir[1] * sun_dir[1] + dir[2] * sun_dir[2];
        if (mu >= atm->cos_sun_radius) {
            double sun[ATMOS_MAX_WAVELENGTHS];
            h.in_sun_disk = 1;
            atmos_atmosphere_sun_radiance(atm, p, sun_dir, sun);
            const double tc =
                atm->planet->clouds ? atmos__clouds_view_transmittance(atm->planet, p, dir, INFINITY) : 1.0;
            for (int i = 0; i < atm->wl.count; i++) out[i] += sun[i] * tc;
        }
    }
    if (info) *info = h;
}

/* The flat ground (y = 0) at distance K along dir from p, Lambertian, lit by the attenuated
 * sun and, with sky, by the sky above it (flat_skylight.c), seen through the air between. */
static void flat_ground(const atmos_atmosphere *atm, const double p[3], const double dir[3], double K,
                        const double sun_dir[3], int sky, double *out)
{
    const int n = atm->wl.count;
    const double ly = sun_dir[1], albedo = atmos_atmosphere_ground_albedo(atm);
    for (int i = 0; i < n; i++) out[i] = 0.0;
    if (!(ly > 0 && albedo > 0)) return;
    const double g[3] = {p[0] + K * dir[0], 0.0, p[2] + K * dir[2]};
    double E[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS], S[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_sunlight(atm, g, sun_dir, E);
    atmos_atmosphere_transmittance(atm, p, dir, K, T);
    atmos__flat_skylight(atm, sky ? ly : 0.0, S);
    for (int i = 0; i < n; i++) out[i] = albedo / ATMOS_PI * (ly * E[i] + S[i]) * T[i];
}

void atmos__atm_ground_sunlit(const atmos_atmosphere *atm, const double p[3], const double dir[3], double K,
                              const double sun_dir[3], double *out)
{
    const int n = atm->wl.count;
    for (int i = 0; i < n; i++) out[i] = 0.0;
    if (!(K < INFINITY)) return;
    if (atm->solver) atmos__planet_ground_sunlit(atm, p, dir, K, sun_dir, 0, out);
    else flat_ground(atm, p, dir, K, sun_dir, 0, out);
}

/* What a view ray sees; the sun's disk only with disk. */
static void radiance(const atmos_atmosphere *atm, const double p[3], const double dir[3], const double sun_dir[3],
                     int disk, double *out, atmos_atmosphere_hit *info)
{
    if (atm->solver) {
        planet_radiance(atm, p, dir, sun_dir, disk, out, info);
        return;
    }
    const int n = atm->wl.count;
    const double K = atmos_atmosphere_ground_distance(atm, p, dir);
    const int ground = !isinf(K);
    atmos_atmosphere_inscatter(atm, p, dir, K, sun_dir, out);
    double tmp[ATMOS_MAX_WAVELENGTHS], sun[ATMOS_MAX_WAVELENGTHS];
    int in_disk = 0;
    if (ground) {
        flat_ground(atm, p, dir, K, sun_dir, 1, tmp);
        for (int i = 0; i < n; i++) out[i] += tmp[i];
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
    if (atmos__atm_ray_fault(atm, p, dir) || atmos__atm_unit_fault(sun_dir)) {
        refuse(atm, out);
        if (info) info->distance_m = NAN, info->hits_ground = 0, info->in_sun_disk = 0;
        return;
    }
    radiance(atm, p, dir, sun_dir, 1, out, info);
}

/* ------------------------------------------------------------------ many view rays at once */

void atmos__atm_batch_init(atmos__atm_batch *b, const atmos_atmosphere *a, const double eye[3], const double sun[3],
                           int threads)
{
    memset(b, 0, sizeof *b);
    b->atm = a;
    b->threads = threads > 0 ? threads : atmos__threads(NULL);
    b->kind = a->desc.kind;
    memcpy(b->eye, eye, sizeof b->eye);
    memcpy(b->sun, sun, sizeof b->sun);
    b->background = (float)atmos__atm_background(a);
    if (a->desc.kind == ATMOS_ATMOSPHERE_RILEY) atmos__sky_batch_init(&b->riley, a, eye[1], sun);
    if (a->solver && a->solver->batch_init) a->solver->batch_init(b);
}

int atmos__atm_batch_update(atmos__atm_batch *b, const atmos_atmosphere *a, const double eye[3], const double sun[3],
                            int threads)
{
    if (b->atm == a && a->solver && a->solver->batch_keep && a->solver->batch_keep(b, eye, sun)) {
        memcpy(b->eye, eye, sizeof b->eye);
        memcpy(b->sun, sun, sizeof b->sun);
        return 1;
    }
    if (b->atm) atmos__atm_batch_release(b);
    atmos__atm_batch_init(b, a, eye, sun, threads);
    return 0;
}

void atmos__atm_batch_release(atmos__atm_batch *b)
{
    if (b->atm && b->atm->solver && b->atm->solver->batch_release) b->atm->solver->batch_release(b);
    b->state = NULL;
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
    case ATMOS_ATMOSPHERE_RILEY:
        /* An eye above ~50 scale heights is outside the float closed form's range. */
        if (b->riley.high) batch_generic(b, count, dx, dy, dz, weight, out);
        else atmos__sky_batch_eval(&b->riley, count, dx, dy, dz, weight, out, scratch);
        return;
    case ATMOS_ATMOSPHERE_VACUUM: {
        const int n = b->atm->wl.count;
        for (int k = 0; k < n; k++)
            for (int i = 0; i < count; i++) out[(size_t)k * count + i] += weight[i] * b->background;
        return;
    }
    default:
        /* clouds: ray by ray through the cloud spheres (planet_clouds_render.c) unless the
         * solver's batch answers them */
        if (b->atm->solver && b->atm->solver->batch_eval && (!b->atm->planet->clouds || b->atm->solver->batch_clouds))
            b->atm->solver->batch_eval(b, count, dx, dy, dz, weight, out, scratch);
        else batch_generic(b, count, dx, dy, dz, weight, out);
    }
}
