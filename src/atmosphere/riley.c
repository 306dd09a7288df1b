/* The analytic sky of Riley et al. 2004, §4.1 (Eq. 8-15) and §4.2.4.
 *
 * Flat earth, y = altitude, molecular density eta(h) = eta0 exp(-gamma h) (Eq. 9), so
 * the scattering (= extinction, albedo 1) coefficient is beta(h) = beta_sl exp(-gamma h)
 * (Eq. 10). Along a ray from a point at altitude y in direction p, with
 * beta_eye = beta_sl exp(-gamma y) (Eq. 13) and distance t:
 *
 *   optical depth to the eye  tau_v(t) = beta_eye t g(gamma p_y t),  g(z) = (1 - e^-z)/z
 *   sun's optical depth       tau_s(t) = beta(t) / (gamma l_y)                (Eq. 12)
 *   in-scatter  L = P(theta) E_sun  int_0^K beta(t) exp(-tau_v(t) - tau_s(t)) dt  (Eq. 14)
 *
 * Because d(tau_v + tau_s)/dt = beta(t) (1 - p_y/l_y), the integral is exact:
 *
 *   L = P E_sun tau_v(K) e^{-tau_s(0)} h(D),   D = tau_v(K) (1 - p_y/l_y),  h(D) = (1 - e^-D)/D
 *
 * which equals the paper's Eq. 15 multiplied by exp(-beta_eye / (gamma p_y)): the printed
 * Eq. 15 drops the attenuation between the eye and the start of the segment (see
 * docs/models.md). Written with g and h (both -> 1 at 0, computed with expm1) it has no
 * division by p_y or (p_y - l_y), so horizontal rays and views at the sun's elevation are
 * exact limits rather than 0/0.
 */
#include "core/internal.h"
#include "atmosphere/riley.h"

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
}

double atmos__sky_g(double z)
{
    if (fabs(z) < 1e-6) return 1.0 - 0.5 * z + z * z / 6.0;
    return -expm1(-z) / z;
}

atmos_status atmos_sky_create(atmos_context *ctx, const atmos_atmosphere_desc *desc, const atmos_wavelengths *wl,
                              atmos_sky **out)
{
    if (!out || !wl) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "sky: missing argument");
    *out = NULL;
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    if (desc) {
        d = *desc;
        if (d.beta_sl_550 == 0) d.beta_sl_550 = ATMOS_SKY_BETA_SL_550;
        if (d.scale_height_m == 0) d.scale_height_m = 8000.0;
        if (d.sun_diameter_deg == 0) d.sun_diameter_deg = 0.5;
        if (d.sun_scale == 0) d.sun_scale = 1.0;
    }
    if (!(d.beta_sl_550 > 0 && d.beta_sl_550 <= 0.01))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/beta_sl_550_per_m: must be in (0, 0.01], got %g", d.beta_sl_550);
    if (!(d.scale_height_m >= 100 && d.scale_height_m <= 100000))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/scale_height_m: must be in [100, 100000], got %g", d.scale_height_m);
    if (!(d.ground_albedo >= 0 && d.ground_albedo <= 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/ground_albedo: must be in [0, 1], got %g", d.ground_albedo);
    if (!(d.sun_diameter_deg > 0 && d.sun_diameter_deg <= 20))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/sun_diameter_deg: must be in (0, 20], got %g", d.sun_diameter_deg);
    if (!(d.sun_scale >= 0 && d.sun_scale <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/sun_scale: must be in [0, 1e6], got %g", d.sun_scale);
    if (wl->count < 1 || wl->count > ATMOS_MAX_WAVELENGTHS)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "sky: wavelength set has %d samples (allowed 1..%d)", wl->count, ATMOS_MAX_WAVELENGTHS);

    atmos_sky *sky = calloc(1, sizeof *sky);
    if (!sky) return atmos__error(ctx, ATMOS_E_NOMEM, "sky: out of memory");
    sky->desc = d;
    sky->wl = *wl;
    sky->gamma = 1.0 / d.scale_height_m;
    double scale = d.beta_sl_550 / ATMOS_SKY_BETA_SL_550;
    for (int i = 0; i < wl->count; i++) {
        double b = ATMOS_SKY_BETA_SL_550 * pow(550.0 / wl->nm[i], 4.0);
        if (wl->mode == ATMOS_WAVELENGTHS_RGB) {
            /* The paper's own channel values where the wavelength is one of Table 3's. */
            for (int k = 0; k < 3; k++)
                if (fabs(wl->nm[i] - table3_nm[k]) < 1e-9) b = table3_beta[k];
        }
        sky->beta_sl[i] = b * scale;
        sky->sun_e[i] = wl->sun_irradiance[i] * d.sun_scale;
    }
    double r = 0.5 * d.sun_diameter_deg * ATMOS_DEG2RAD;
    sky->cos_sun_radius = cos(r);
    sky->sun_solid_angle = 2.0 * ATMOS_PI * (1.0 - cos(r));
    *out = sky;
    return ATMOS_OK;
}

void atmos_sky_destroy(atmos_sky *sky) { free(sky); }
const atmos_wavelengths *atmos_sky_wavelengths(const atmos_sky *sky) { return &sky->wl; }
const atmos_atmosphere_desc *atmos_sky_desc(const atmos_sky *sky) { return &sky->desc; }
const double *atmos_sky_beta_sea_level(const atmos_sky *sky) { return sky->beta_sl; }
double atmos_sky_sun_solid_angle(const atmos_sky *sky) { return sky->sun_solid_angle; }

double atmos_sky_ground_distance(double y, const double dir[3])
{
    if (y <= 0) return dir[1] < 0 ? 0.0 : (y < 0 ? 0.0 : INFINITY);
    if (dir[1] >= 0) return INFINITY;
    return y / -dir[1];
}

/* Wavelength-independent part of tau_v(K)/beta_eye: K g(gamma p_y K), INFINITY if unbounded. */
double atmos__sky_view_depth_factor(double gamma, double py, double K)
{
    if (!(K > 0)) return 0.0;
    if (isinf(K)) return py > 0 ? 1.0 / (gamma * py) : INFINITY;
    double z = gamma * py * K;
    if (z < -700.0) return INFINITY; /* exp overflow: beyond any meaningful optical depth */
    return K * atmos__sky_g(z);
}

void atmos_sky_transmittance(const atmos_sky *sky, double y, const double dir[3], double distance, double *out)
{
    double G = atmos__sky_view_depth_factor(sky->gamma, dir[1], distance);
    double ey = exp(-sky->gamma * y);
    for (int i = 0; i < sky->wl.count; i++) out[i] = isinf(G) ? 0.0 : exp(-sky->beta_sl[i] * ey * G);
}

void atmos_sky_sunlight(const atmos_sky *sky, double y, const double sun_dir[3], double *out)
{
    double ly = sun_dir[1];
    double ey = exp(-sky->gamma * y);
    for (int i = 0; i < sky->wl.count; i++)
        out[i] = ly > 0 ? sky->sun_e[i] * exp(-sky->beta_sl[i] * ey / (sky->gamma * ly)) : 0.0;
}

void atmos_sky_sun_radiance(const atmos_sky *sky, double y, const double sun_dir[3], double *out)
{
    atmos_sky_sunlight(sky, y, sun_dir, out);
    for (int i = 0; i < sky->wl.count; i++) out[i] /= sky->sun_solid_angle;
}

static double h_fn(double D) { return atmos__sky_g(D); }

double atmos__sky_inscatter_factor(double gamma, double beta_eye, double G, double ly, double py, double e_end)
{
    /* tau_v(K) e^{-tau_s(0)} h(D) (see the file comment): the in-scattered radiance
     * divided by P(theta) E_sun. G = tau_v(K)/beta_eye (INFINITY for an endless
     * horizontal or downward ray), e_end = exp(-gamma p_y K) = beta(K)/beta_eye. */
    if (!(ly > 0) || !(beta_eye > 0) || !(G > 0)) return 0.0;
    double c = 1.0 - py / ly;
    double ts0 = beta_eye / (gamma * ly);
    if (isinf(G)) {
        /* Endless ray (p_y <= 0 so c >= 1): tau_v -> inf and tau_v h(D) -> 1/c. */
        return exp(-ts0) / c;
    }
    double x = beta_eye * G;
    double D = c * x;
    if (D >= 0) return x * exp(-ts0) * h_fn(D);
    /* D < 0 (view steeper than the sun): e^{-ts0} h(D) = e^{-(ts0 + D)} h(-D), with
     * ts0 + D = tau_v(K) + tau_s(K) >= 0 formed without cancellation. This keeps the
     * sun near the horizon (ts0 huge, e^{-D} huge) from becoming 0 * inf. */
    double tsK = ts0 * e_end;
    return x * exp(-(x + tsK)) * h_fn(-D);
}

void atmos_sky_inscatter(const atmos_sky *sky, const double eye[3], const double dir[3], double distance,
                         const double sun_dir[3], double *out)
{
    double py = dir[1], ly = sun_dir[1];
    double G = atmos__sky_view_depth_factor(sky->gamma, py, distance);
    double e_end = isinf(distance) ? (py > 0 ? 0.0 : INFINITY) : exp(-sky->gamma * py * distance);
    double ey = exp(-sky->gamma * eye[1]);
    double mu = dir[0] * sun_dir[0] + dir[1] * sun_dir[1] + dir[2] * sun_dir[2];
    double P = atmos_phase_rayleigh(mu);
    for (int i = 0; i < sky->wl.count; i++) {
        double f = atmos__sky_inscatter_factor(sky->gamma, sky->beta_sl[i] * ey, G, ly, py, e_end);
        out[i] = P * sky->sun_e[i] * f;
    }
}

void atmos_sky_radiance(const atmos_sky *sky, const double eye[3], const double dir[3], const double sun_dir[3],
                        double *out, atmos_sky_sample *info)
{
    int n = sky->wl.count;
    double K = atmos_sky_ground_distance(eye[1], dir);
    int ground = !isinf(K);
    atmos_sky_inscatter(sky, eye, dir, K, sun_dir, out);
    double tmp[ATMOS_MAX_WAVELENGTHS], sun[ATMOS_MAX_WAVELENGTHS];
    int in_disk = 0;
    if (ground) {
        /* Lambertian ground lit by the attenuated sun (Eq. 12 at y = 0), seen through
         * the air between it and the eye (Eq. 11). */
        double ly = sun_dir[1];
        if (ly > 0 && sky->desc.ground_albedo > 0) {
            atmos_sky_sunlight(sky, 0.0, sun_dir, sun);
            atmos_sky_transmittance(sky, eye[1], dir, K, tmp);
            for (int i = 0; i < n; i++) out[i] += sky->desc.ground_albedo / ATMOS_PI * ly * sun[i] * tmp[i];
        }
    } else if (!sky->desc.hide_sun_disk) {
        double mu = dir[0] * sun_dir[0] + dir[1] * sun_dir[1] + dir[2] * sun_dir[2];
        if (mu >= sky->cos_sun_radius) {
            in_disk = 1;
            atmos_sky_sun_radiance(sky, eye[1], sun_dir, sun);
            for (int i = 0; i < n; i++) out[i] += sun[i];
        }
    }
    if (info) {
        info->distance_m = K;
        info->hits_ground = ground;
        info->in_sun_disk = in_disk;
    }
}
