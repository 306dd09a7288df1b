/* Cloud spheres of the spherical kinds from a satellite image (Dobashi et al. 2002 §5.4,
 * Fig. 8; docs/sky.md, "The Earth from space"): the image's brightness gives each point's
 * column optical depth; the layer between base_m and top_m holds it at uniform density along
 * the vertical and is drawn as m concentric spheres, sphere i (0 the lowest) at the middle of
 * the i-th of m equal shells, each carrying 1/m of the column (its cloud texture T_i). A ray
 * crossing sphere i with direction cosine mu to the vertical there passes through the shell
 * with optical depth (tau_column / m) / max(|mu|, mu_min); mu_min = sqrt(dh / (2 r_i)) makes a
 * grazing ray's path sqrt(2 r_i dh) long, half the chord of a ray tangent to the shell's
 * bottom, dh = (top - base) / m.
 *
 * Brightness to optical depth: b, the pixel's linear value (sRGB decoded; the mean of R, G
 * and B), is taken as the cloud's reflectance R = (b - b0) / (1 - b0) above the cloud-free
 * level b0 (threshold), and inverted through the two-stream reflectance of a non-absorbing
 * layer, R = (1 - g) tau / (2 + (1 - g) tau) (Bohren 1987, Am. J. Phys. 55, 524), with
 * g = 0.85 (water clouds in the visible): tau = 2 R / ((1 - g)(1 - R)), capped at
 * max_optical_depth. */
#include "atmosphere/planet_clouds.h"

#include "atmos/image.h"

#include <stdlib.h>
#include <string.h>

/* asymmetry of water clouds used to invert the image's reflectance */
#define CLOUD_G_INVERSION 0.85

static double srgb_decode(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

double atmos__clouds_tau_from_brightness(double b, double threshold, double max_tau)
{
    double R = (b - threshold) / (1.0 - threshold);
    if (!(R > 0)) return 0.0;
    R = fmin(R, 0.999);
    return fmin(2.0 * R / ((1.0 - CLOUD_G_INVERSION) * (1.0 - R)), max_tau);
}

static atmos_status check(atmos_context *ctx, const atmos_cloud_desc *c, double top_of_air)
{
    const atmos_image *img = c->image;
    if (!img->pixels || img->width < 2 || img->height < 2 || (img->channels != 1 && img->channels < 3))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/clouds/image: needs at least 2 x 2 pixels");
    if (!(c->base_m >= 0 && c->top_m > c->base_m && c->top_m < top_of_air))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmosphere/clouds: need 0 <= base_m < top_m < the atmosphere's top, got %g and %g",
                            c->base_m, c->top_m);
    if (c->spheres < 1 || c->spheres > ATMOS__CLOUDS_MAX)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere/clouds/spheres: must be in [1, %d], got %d",
                            ATMOS__CLOUDS_MAX, c->spheres);
    if (!(c->lon_west_deg >= -360 && c->lon_east_deg > c->lon_west_deg && c->lon_east_deg <= 360 &&
          c->lat_south_deg >= -90 && c->lat_north_deg > c->lat_south_deg && c->lat_north_deg <= 90))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmosphere/clouds: the image's extent must have west < east and south < north "
                            "(degrees, latitudes in [-90, 90])");
    if (!(c->threshold >= 0 && c->threshold < 1) || !(c->max_optical_depth > 0 && c->max_optical_depth <= 1e4) ||
        !(c->g > -1 && c->g < 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmosphere/clouds: threshold must be in [0, 1), max_optical_depth in (0, 1e4], "
                            "g in (-1, 1)");
    return ATMOS_OK;
}

void atmos__clouds_resolve(atmos_cloud_desc *c)
{
    if (c->lon_west_deg == 0 && c->lon_east_deg == 0 && c->lat_south_deg == 0 && c->lat_north_deg == 0)
        c->lon_west_deg = -180, c->lon_east_deg = 180, c->lat_south_deg = -90, c->lat_north_deg = 90;
    if (c->base_m == 0 && c->top_m == 0) c->base_m = 2000, c->top_m = 8000;
    if (c->spheres == 0) c->spheres = 5;
    if (c->threshold == 0) c->threshold = 0.04;
    if (c->max_optical_depth == 0) c->max_optical_depth = 100;
}

atmos_status atmos__planet_clouds_create(atmos_context *ctx, atmos__planet *pl, const atmos_atmosphere_desc *d)
{
    pl->clouds = NULL;
    if (!d->clouds.image) return ATMOS_OK;
    atmos_cloud_desc c = d->clouds;
    atmos__clouds_resolve(&c);
    atmos_status st = check(ctx, &c, pl->r_top - pl->r_ground);
    if (st != ATMOS_OK) return st;
    const atmos_image *img = c.image;
    atmos__clouds *cl = calloc(1, sizeof *cl);
    if (!cl) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory");
    cl->tau = malloc((size_t)img->width * (size_t)img->height * sizeof *cl->tau);
    if (!cl->tau) {
        free(cl);
        return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere/clouds: out of memory");
    }
    cl->w = img->width, cl->h = img->height;
    cl->lon_w = c.lon_west_deg, cl->lon_e = c.lon_east_deg, cl->lat_s = c.lat_south_deg, cl->lat_n = c.lat_north_deg;
    cl->global = cl->lon_e - cl->lon_w >= 360.0 - 1e-9;
    cl->m = c.spheres;
    cl->inv_m = 1.0 / c.spheres;
    cl->u_per_deg = cl->w / (cl->lon_e - cl->lon_w), cl->v_per_deg = cl->h / (cl->lat_n - cl->lat_s);
    cl->base = c.base_m, cl->top = c.top_m;
    cl->dh = (c.top_m - c.base_m) / c.spheres;
    cl->sigma_per_tau = 1.0 / (c.top_m - c.base_m);
    for (int i = 0; i < cl->m; i++) {
        cl->r[i] = pl->r_ground + c.base_m + (i + 0.5) * cl->dh;
        cl->mu_min[i] = sqrt(cl->dh / (2.0 * cl->r[i]));
        cl->inv_r[i] = 1.0 / cl->r[i];
    }
    cl->g = c.g;
    cl->single = c.single_scattering;
    const int nc = img->channels;
    for (size_t i = 0; i < (size_t)cl->w * (size_t)cl->h; i++) {
        const float *p = img->pixels + i * (size_t)nc;
        const double v = nc == 1 ? p[0] : (p[0] + p[1] + p[2]) / 3.0;
        cl->tau[i] = (float)atmos__clouds_tau_from_brightness(srgb_decode(fmin(fmax(v, 0.0), 1.0)), c.threshold,
                                                              c.max_optical_depth);
    }
    pl->clouds = cl;
    return ATMOS_OK;
}

void atmos__planet_clouds_release(atmos__planet *pl)
{
    if (!pl || !pl->clouds) return;
    free(pl->clouds->tau);
    free(pl->clouds);
    pl->clouds = NULL;
}

/* A regional image's clouds fade out over its outer CLOUD_FADE of the shorter side
 * (smoothstep of the distance to the nearest edge, in pixels): its clouds end where the
 * image ends, and a straight cliff of cloud along the frame is the one thing sure to be
 * wrong. */
#define CLOUD_FADE 0.05
static double edge_fade(const atmos__clouds *cl, double u, double v)
{
    const double d = fmin(fmin(u + 0.5, cl->w - 0.5 - u), fmin(v + 0.5, cl->h - 0.5 - v));
    const double margin = fmax(2.0, CLOUD_FADE * (cl->w < cl->h ? cl->w : cl->h));
    const double x = fmin(fmax(d / margin, 0.0), 1.0);
    return x * x * (3.0 - 2.0 * x);
}

double atmos__clouds_column_tau_edge(const atmos__clouds *cl, double lat, double lon)
{
    if (lon < cl->lon_w) lon += 360.0;
    if (lat < cl->lat_s || lat > cl->lat_n || lon < cl->lon_w || lon > cl->lon_e) return 0.0;
    const double u = (lon - cl->lon_w) * cl->u_per_deg - 0.5, v = (cl->lat_n - lat) * cl->v_per_deg - 0.5;
    const double fade = edge_fade(cl, u, v), tau = atmos__clouds_bilinear(cl, u, v);
    if (fade >= 1.0) return tau;
    /* faded in reflectance, R = k tau / (1 + k tau) as atmos__clouds_tau_from_brightness
     * inverts it, so that a thick cloud thins out over the margin instead of staying opaque
     * to its last pixel */
    const double k = 0.5 * (1.0 - CLOUD_G_INVERSION), R = fade * k * tau / (1.0 + k * tau);
    return R / (k * (1.0 - R));
}

double atmos__clouds_crossing_tau(const atmos__planet *pl, int i, const double x[3], const double d[3])
{
    const atmos__clouds *cl = pl->clouds;
    double lat, lon;
    atmos__planet_latlon_fast(pl, x, &lat, &lon);
    const double tau = atmos__clouds_column_tau(cl, lat, lon);
    if (tau <= 0) return 0.0;
    return atmos__clouds_shell_tau(cl, i, tau, atmos__planet_mu(pl, x, d));
}

double atmos__clouds_sun_attenuation(const atmos__planet *pl, const double x[3], const double sun[3], int below)
{
    const atmos__clouds *cl = pl->clouds;
    double depth = 0.0;
    for (int j = below + 1; j < cl->m; j++) {
        const double t = atmos__planet_sphere_hit(pl, x, sun, cl->r[j]);
        if (!(t < INFINITY)) continue;
        const double y[3] = {x[0] + t * sun[0], x[1] + t * sun[1], x[2] + t * sun[2]};
        depth += atmos__clouds_crossing_tau(pl, j, y, sun);
    }
    return exp(-depth);
}

double atmos_atmosphere_cloud_extinction(const atmos_atmosphere *atm, const double p[3])
{
    const atmos__planet *pl = atm ? atm->planet : NULL;
    if (!pl || !pl->clouds) return 0.0;
    const atmos__clouds *cl = pl->clouds;
    const double h = atmos__planet_altitude(pl, p);
    if (h < cl->base || h > cl->top) return 0.0;
    double lat, lon;
    atmos__planet_latlon(pl, p, &lat, &lon);
    return atmos__clouds_column_tau(cl, lat, lon) * cl->sigma_per_tau;
}
