/* The planet's ground (planet.h): a uniform Lambertian reflectance, or one from an
 * equirectangular map of the Earth, and the night side's lights from another; the
 * geographic frame that places the maps (docs/sky.md, "The Earth from space").
 *
 * The maps are kept as their 8-bit sRGB-encoded values (3 bytes a pixel: the 5400 x 2700
 * Blue Marble takes 44 MB) and decoded through the sRGB transfer function (IEC 61966-2-1)
 * when looked up, bilinearly between the four nearest pixel centres. The colour of a
 * wavelength of a spectral set is interpolated linearly between the channels' wavelengths
 * 440 (B), 550 (G) and 680 nm (R), held constant beyond them: a simple, smooth upsampling
 * of RGB that gives back the channels at their own wavelengths (the rgb set). */
#include "atmosphere/planet.h"

#include "atmos/image.h"
#include "core/fastmath.h"

#include <stdlib.h>
#include <string.h>

typedef struct atmos__map {
    int w, h, c;
    unsigned char *px;
} atmos__map;

struct atmos__surface {
    atmos__map ground, night;
    double night_radiance;
    float lut[256];                        /* sRGB code / 255 -> linear */
    double wrgb[ATMOS_MAX_WAVELENGTHS][3]; /* channel weights of each wavelength */
};

/* The weights of R, G, B (channels 0, 1, 2) at nm. */
static void channel_weights(double nm, double w[3])
{
    w[0] = w[1] = w[2] = 0.0;
    if (nm <= 440.0) w[2] = 1.0;
    else if (nm >= 680.0) w[0] = 1.0;
    else if (nm <= 550.0) w[1] = (nm - 440.0) / 110.0, w[2] = 1.0 - w[1];
    else w[0] = (nm - 550.0) / 130.0, w[1] = 1.0 - w[0];
}

static atmos_status map_copy(atmos_context *ctx, const atmos_image *img, const char *field, atmos__map *m)
{
    if (!img) return ATMOS_OK;
    if (!img->pixels || img->width < 2 || img->height < 2 || (img->channels != 1 && img->channels != 3))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "atmosphere/%s: the map needs at least 2 x 2 pixels of 1 or 3 channels", field);
    const size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
    m->px = malloc(n);
    if (!m->px) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere/%s: out of memory", field);
    for (size_t i = 0; i < n; i++) {
        const float v = img->pixels[i];
        m->px[i] = (unsigned char)(v > 0.0f ? (v < 1.0f ? v * 255.0f + 0.5f : 255.0f) : 0.0f);
    }
    m->w = img->width, m->h = img->height, m->c = img->channels;
    return ATMOS_OK;
}

atmos_status atmos__planet_surface_create(atmos_context *ctx, atmos__planet *pl, const atmos_atmosphere_desc *d,
                                          const atmos_wavelengths *wl)
{
    /* Earth-centred axes of the local east, up and north at (lat0, lon0). */
    const double la = d->latitude_deg * ATMOS_DEG2RAD, lo = d->longitude_deg * ATMOS_DEG2RAD;
    const double e[3] = {-sin(lo), cos(lo), 0.0};
    const double u[3] = {cos(la) * cos(lo), cos(la) * sin(lo), sin(la)};
    const double nn[3] = {-sin(la) * cos(lo), -sin(la) * sin(lo), cos(la)};
    memcpy(pl->geo_east, e, sizeof e);
    memcpy(pl->geo_up, u, sizeof u);
    memcpy(pl->geo_north, nn, sizeof nn);
    pl->surface = NULL;
    if (!d->ground_map && !d->night_map) return ATMOS_OK;
    struct atmos__surface *s = calloc(1, sizeof *s);
    if (!s) return atmos__error(ctx, ATMOS_E_NOMEM, "atmosphere: out of memory");
    pl->surface = s;
    atmos_status st = map_copy(ctx, d->ground_map, "ground_map", &s->ground);
    if (st == ATMOS_OK) st = map_copy(ctx, d->night_map, "night_map", &s->night);
    if (st != ATMOS_OK) return st; /* the caller releases */
    s->night_radiance = d->night_radiance > 0 ? d->night_radiance : 5e-6;
    for (int i = 0; i < 256; i++) {
        const double c = i / 255.0;
        s->lut[i] = (float)(c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4));
    }
    for (int k = 0; k < wl->count; k++) {
        if (wl->mode == ATMOS_WAVELENGTHS_RGB && wl->count == 3) {
            s->wrgb[k][0] = s->wrgb[k][1] = s->wrgb[k][2] = 0.0;
            s->wrgb[k][k] = 1.0; /* R, G, B in the set's order */
        } else {
            channel_weights(wl->nm[k], s->wrgb[k]);
        }
    }
    return ATMOS_OK;
}

void atmos__planet_surface_release(atmos__planet *pl)
{
    if (!pl || !pl->surface) return;
    free(pl->surface->ground.px);
    free(pl->surface->night.px);
    free(pl->surface);
    pl->surface = NULL;
}

void atmos__planet_latlon(const atmos__planet *pl, const double x[3], double *lat_deg, double *lon_deg)
{
    const double v[3] = {x[0], x[1] + pl->r_ground, -x[2]}; /* from the centre: east, up, north */
    double q[3];
    for (int i = 0; i < 3; i++) q[i] = v[0] * pl->geo_east[i] + v[1] * pl->geo_up[i] + v[2] * pl->geo_north[i];
    const double r = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    *lat_deg = r > 0 ? asin(fmax(-1.0, fmin(1.0, q[2] / r))) * ATMOS_RAD2DEG : 0.0;
    *lon_deg = atan2(q[1], q[0]) * ATMOS_RAD2DEG;
}

/* The linear value of wavelength k of map m at (lat, lon), bilinear between pixel centres
 * (wrapping in longitude). */
static double map_lookup(const struct atmos__surface *s, const atmos__map *m, double lat, double lon, int k)
{
    double u = (lon + 180.0) / 360.0 * m->w - 0.5, v = (90.0 - lat) / 180.0 * m->h - 0.5;
    v = fmin(fmax(v, 0.0), m->h - 1.0);
    const double fu = floor(u), fv = floor(v);
    const double au = u - fu, av = v - fv;
    int x0 = (int)fu % m->w;
    if (x0 < 0) x0 += m->w;
    const int x1 = (x0 + 1) % m->w, y0 = (int)fv, y1 = y0 + 1 < m->h ? y0 + 1 : y0;
    const int xs[2] = {x0, x1}, ys[2] = {y0, y1};
    const double wx[2] = {1.0 - au, au}, wy[2] = {1.0 - av, av};
    double sum = 0.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            const unsigned char *p = m->px + ((size_t)ys[j] * (size_t)m->w + (size_t)xs[i]) * (size_t)m->c;
            double val;
            if (m->c == 1) val = s->lut[p[0]];
            else val = s->wrgb[k][0] * s->lut[p[0]] + s->wrgb[k][1] * s->lut[p[1]] + s->wrgb[k][2] * s->lut[p[2]];
            sum += wx[i] * wy[j] * val;
        }
    return sum;
}

double atmos__planet_ground_albedo(const atmos__planet *pl, const double g[3], int k)
{
    const struct atmos__surface *s = pl->surface;
    if (!s || !s->ground.px) return pl->albedo;
    double lat, lon;
    atmos__planet_latlon(pl, g, &lat, &lon);
    return map_lookup(s, &s->ground, lat, lon, k);
}

double atmos__planet_ground_emission(const atmos__planet *pl, const double g[3], int k)
{
    const struct atmos__surface *s = pl->surface;
    if (!s || !s->night.px) return 0.0;
    double lat, lon;
    atmos__planet_latlon(pl, g, &lat, &lon);
    return s->night_radiance * map_lookup(s, &s->night, lat, lon, k);
}

double atmos__planet_ground_lights(const atmos__planet *pl, const double g[3], const double sun[3], int k)
{
    if (!pl->surface || !pl->surface->night.px) return 0.0;
    const double n[3] = {g[0], g[1] + pl->r_ground, g[2]};
    const double r = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double sin_el = (n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2]) / r;
    /* 1 below -12 degrees (nautical twilight's end), 0 above the horizon, smoothstep of the
     * elevation between */
    const double el = asin(fmax(-1.0, fmin(1.0, sin_el))) * ATMOS_RAD2DEG;
    const double x = fmin(fmax(-el / 12.0, 0.0), 1.0);
    const double f = x * x * (3.0 - 2.0 * x);
    return f > 0 ? f * atmos__planet_ground_emission(pl, g, k) : 0.0;
}
