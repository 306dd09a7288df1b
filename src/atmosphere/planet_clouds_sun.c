/* The attenuation textures G_i of the cloud spheres for one sun (planet_clouds.h; Dobashi
 * et al. 2002 §5.4, their per-frame texture): G_i at the texel centres of a latitude/longitude
 * grid over the cloud image (FINER texels a pixel along each axis, at most MAX_W texels
 * around the globe; a regional image's box grown by MARGIN degrees, where the sunlight's
 * slant path through the layer can still meet its clouds), one layer per sphere below the
 * top one and one for the ground, looked up bilinearly, built downward (fill_tile). The
 * texels are filled tile by tile when a look-up first needs them (the sunlit part of what
 * the eye sees), by whichever thread gets there first while the others wait for it: a
 * texel's value does not depend on who fills it, so the image does not depend on the
 * threads. A look-up whose four texels differ by more than SPREAD takes one step down from
 * the sphere above at the point itself instead of interpolating across the sharp edge that
 * runs between them (step_down); a point seen through clouds that pass c of its light allows
 * SPREAD / c, and so do its steps down (atmos__clouds_sun_lookup_through). Points outside
 * the box get atmos__clouds_sun_attenuation itself. */
#include "atmosphere/planet_clouds.h"

#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define TILE 16       /* texels a side */
#define MAX_W 2048    /* texels around the globe at most (0.18 degree) */
#define MARGIN 3.0    /* degrees around a regional image */
#define FINER 4       /* texels per image pixel along each axis */
#define SPREAD 0.05f  /* a look-up whose four texels differ by more steps G down itself */

struct atmos__clouds_sun {
    const atmos__planet *pl;
    double sun[3];
    int layers;                    /* m: spheres 0 .. m - 2, then the ground */
    int w, h, tw, th, wrap;        /* texels, tiles; wrap: the grid spans 360 degrees */
    double lat_n, lon_w, dlat, dlon, inv_dlat, inv_dlon;
    float *g;                      /* [h][w][layers]: a texel's layers side by side, so that the
                                      look-ups of a ray's crossings (nearly one point seen from
                                      above) and of the step down share cache lines */
    atomic_int *state;             /* [layers][th][tw]: 0 empty, 1 being filled, 2 ready */
};

atmos__clouds_sun *atmos__clouds_sun_create(const atmos__planet *pl, const double sun[3])
{
    const atmos__clouds *cl = pl->clouds;
    if (!cl) return NULL;
    atmos__clouds_sun *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->pl = pl;
    memcpy(s->sun, sun, sizeof s->sun);
    s->layers = cl->m;
    const double pitch = fmax((cl->lon_e - cl->lon_w) / cl->w / FINER, 360.0 / MAX_W);
    double lat_s = cl->lat_s, lat_n = cl->lat_n, lon_w = cl->lon_w, lon_e = cl->lon_e;
    if (!cl->global) {
        lat_s = fmax(lat_s - MARGIN, -90.0), lat_n = fmin(lat_n + MARGIN, 90.0);
        const double c = cos(fmax(fabs(lat_s), fabs(lat_n)) * ATMOS_DEG2RAD);
        const double mlon = c > 0.05 ? MARGIN / c : 180.0;
        lon_w -= mlon, lon_e += mlon;
    }
    s->wrap = cl->global || lon_e - lon_w >= 360.0;
    if (s->wrap) lon_e = lon_w + 360.0;
    s->w = (int)ceil((lon_e - lon_w) / pitch), s->h = (int)ceil((lat_n - lat_s) / pitch);
    s->w = s->w < 2 ? 2 : s->w, s->h = s->h < 2 ? 2 : s->h;
    s->lat_n = lat_n, s->lon_w = lon_w;
    s->dlat = (lat_n - lat_s) / s->h, s->dlon = (lon_e - lon_w) / s->w;
    s->inv_dlat = s->h / (lat_n - lat_s), s->inv_dlon = s->w / (lon_e - lon_w);
    s->tw = (s->w + TILE - 1) / TILE, s->th = (s->h + TILE - 1) / TILE;
    const size_t tiles = (size_t)s->layers * s->tw * s->th;
    s->g = malloc(sizeof(float) * (size_t)s->layers * s->w * s->h);
    s->state = malloc(sizeof(atomic_int) * tiles);
    if (!s->g || !s->state) {
        atmos__clouds_sun_destroy(s);
        return NULL;
    }
    for (size_t i = 0; i < tiles; i++) atomic_init(&s->state[i], 0);
    return s;
}

void atmos__clouds_sun_destroy(atmos__clouds_sun *s)
{
    if (s) free(s->g), free(s->state);
    free(s);
}

int atmos__clouds_sun_same(const atmos__clouds_sun *s, const double sun[3])
{
    return s && s->sun[0] == sun[0] && s->sun[1] == sun[1] && s->sun[2] == sun[2];
}

/* A point at radius r (from the planet's centre) over latitude and longitude (degrees), in
 * the world frame. */
void atmos__clouds_geo_point(const atmos__planet *pl, double r, double lat_deg, double lon_deg, double x[3])
{
    const double lat = lat_deg * ATMOS_DEG2RAD, lon = lon_deg * ATMOS_DEG2RAD;
    const double q[3] = {cos(lat) * cos(lon), cos(lat) * sin(lon), sin(lat)};
    double e = 0, u = 0, no = 0; /* the Earth-centred direction in (east, up, north) */
    for (int c = 0; c < 3; c++) e += q[c] * pl->geo_east[c], u += q[c] * pl->geo_up[c], no += q[c] * pl->geo_north[c];
    x[0] = r * e, x[1] = r * u - pl->r_ground, x[2] = -r * no;
}

/* G at p (on the sphere below sphere `above`, or the ground) from the sphere above: G there
 * at the point y where p's ray to the sun crosses it (looked up, interpolating over a spread
 * of up to tol) times that crossing's transmittance. */
static double lookup_tol(atmos__clouds_sun *s, const double x[3], int below, double lat, double lon, float tol);
static double step_down(atmos__clouds_sun *s, const double p[3], int above, float tol)
{
    const atmos__planet *pl = s->pl;
    const atmos__clouds *cl = pl->clouds;
    const double t = atmos__planet_sphere_hit(pl, p, s->sun, cl->r[above]);
    if (!(t < INFINITY)) return 1.0;
    const double q[3] = {p[0] + t * s->sun[0], p[1] + t * s->sun[1], p[2] + t * s->sun[2]};
    double la, lo;
    atmos__planet_latlon_fast(pl, q, &la, &lo);
    const double col = atmos__clouds_column_tau(cl, la, lo);
    const double G = lookup_tol(s, q, above, la, lo, tol);
    /* q is on sphere `above`: its vertical is (q + centre) / r, without a square root */
    const double mu = (q[0] * s->sun[0] + (q[1] + pl->r_ground) * s->sun[1] + q[2] * s->sun[2]) * cl->inv_r[above];
    return col > 0 ? G * atmos__expf_fast((float)-atmos__clouds_shell_tau(cl, above, col, mu)) : G;
}

/* G at the texel centres of a tile, sphere by sphere downward as Dobashi et al. build their
 * textures: the sunlight at a point of sphere i (or the ground) is what reaches the point y
 * where its ray to the sun crosses sphere i + 1 (sphere 0) times that crossing's
 * transmittance, G_i(x) = G_{i+1}(y) exp(-tau_{i+1}(y)), G_{i+1}(y) looked up in the layer
 * above. */
static void fill_tile(atmos__clouds_sun *s, int layer, int tx, int ty)
{
    const atmos__planet *pl = s->pl;
    const atmos__clouds *cl = pl->clouds;
    const int below = layer < s->layers - 1 ? layer : -1, above = below + 1;
    const double r = below >= 0 ? cl->r[below] : pl->r_ground;
    const size_t L = (size_t)s->layers;
    float *g = s->g + layer;
    const int x0 = tx * TILE, x1 = x0 + TILE < s->w ? x0 + TILE : s->w;
    /* per column, cos lat times (cos lon, sin lon, 0) on the axes east, up, north; the
     * axes' third components take sin lat */
    double ce[TILE], cu[TILE], cn[TILE];
    const double se = pl->geo_east[2], su = pl->geo_up[2], sn = pl->geo_north[2];
    for (int x = x0; x < x1; x++) {
        const double lon = (s->lon_w + (x + 0.5) * s->dlon) * ATMOS_DEG2RAD, c = cos(lon), sl = sin(lon);
        const int k = x - x0;
        ce[k] = c * pl->geo_east[0] + sl * pl->geo_east[1];
        cu[k] = c * pl->geo_up[0] + sl * pl->geo_up[1];
        cn[k] = c * pl->geo_north[0] + sl * pl->geo_north[1];
    }
    for (int y = ty * TILE; y < (ty + 1) * TILE && y < s->h; y++) {
        const double lat = (s->lat_n - (y + 0.5) * s->dlat) * ATMOS_DEG2RAD, cl_ = cos(lat), sl_ = sin(lat);
        for (int x = x0; x < x1; x++) {
            const int k = x - x0;
            /* the Earth-centred direction (cos lat cos lon, cos lat sin lon, sin lat) on the
             * world's axes (east, up, -north), atmos__clouds_geo_point's */
            const double p[3] = {r * (cl_ * ce[k] + sl_ * se), r * (cl_ * cu[k] + sl_ * su) - pl->r_ground,
                                 -r * (cl_ * cn[k] + sl_ * sn)};
            g[((size_t)y * s->w + x) * L] = (float)step_down(s, p, above, SPREAD);
        }
    }
}

/* Makes sure the tile holding texel (x, y) of the layer is filled. */
static void need(atmos__clouds_sun *s, int layer, int x, int y)
{
    const int tx = x / TILE, ty = y / TILE;
    atomic_int *st = s->state + ((size_t)layer * s->th + ty) * s->tw + tx;
    if (atomic_load_explicit(st, memory_order_acquire) == 2) return;
    int empty = 0;
    if (atomic_compare_exchange_strong_explicit(st, &empty, 1, memory_order_acq_rel, memory_order_acquire)) {
        fill_tile(s, layer, tx, ty);
        atomic_store_explicit(st, 2, memory_order_release);
        return;
    }
    /* another thread fills it: give up the core meanwhile (on a busy machine the filler may be
     * waiting for one) */
    while (atomic_load_explicit(st, memory_order_acquire) != 2) sched_yield();
}

static double lookup_tol(atmos__clouds_sun *s, const double x[3], int below, double lat, double lon, float tol)
{
    const int layer = below >= 0 ? below : s->layers - 1;
    if (below >= s->layers - 1) return 1.0; /* the top sphere: nothing above it */
    lon = lon < s->lon_w ? lon + 360.0 : lon;
    double u = (lon - s->lon_w) * s->inv_dlon - 0.5, v = (s->lat_n - lat) * s->inv_dlat - 0.5;
    if (!s->wrap && (u < -0.5 || u > s->w - 0.5)) return atmos__clouds_sun_attenuation(s->pl, x, s->sun, below);
    if (!(v >= -0.5 && v <= s->h - 0.5)) return atmos__clouds_sun_attenuation(s->pl, x, s->sun, below);
    /* selects rather than fmin / fmax and floor, which are library calls here */
    v = v > 0.0 ? v : 0.0, v = v < s->h - 1.0 ? v : s->h - 1.0;
    int y0 = (int)v, y1 = y0 + 1 < s->h ? y0 + 1 : y0, x0, x1;
    if (s->wrap) { /* u in [-0.5, w - 0.5] (lon within one turn east of lon_w) */
        const int f = (int)(u + 1.0) - 1; /* floor(u) for u >= -1 */
        u -= f;
        x0 = f < 0 ? f + s->w : (f >= s->w ? f - s->w : f);
        x1 = x0 + 1 < s->w ? x0 + 1 : 0;
    } else {
        u = u > 0.0 ? u : 0.0, u = u < s->w - 1.0 ? u : s->w - 1.0;
        x0 = (int)u, x1 = x0 + 1 < s->w ? x0 + 1 : x0, u -= x0;
    }
    const double av = v - y0;
    /* the tiles of the four texels: mostly one */
    const int sx = x0 / TILE != x1 / TILE, sy = y0 / TILE != y1 / TILE;
    need(s, layer, x0, y0);
    if (sx) need(s, layer, x1, y0);
    if (sy) need(s, layer, x0, y1);
    if (sx && sy) need(s, layer, x1, y1);
    const float *g = s->g + layer;
    const size_t W = (size_t)s->w, L = (size_t)s->layers;
    const float g00 = g[(y0 * W + x0) * L], g01 = g[(y0 * W + x1) * L], g10 = g[(y1 * W + x0) * L],
                g11 = g[(y1 * W + x1) * L];
    const float l0 = g00 < g01 ? g00 : g01, l1 = g10 < g11 ? g10 : g11, lo = l0 < l1 ? l0 : l1;
    const float h0 = g00 > g01 ? g00 : g01, h1 = g10 > g11 ? g10 : g11, hi = h0 > h1 ? h0 : h1;
    if (hi - lo > tol) return step_down(s, x, below + 1, tol);
    return (1 - av) * ((1 - u) * g00 + u * g01) + av * ((1 - u) * g10 + u * g11);
}

double atmos__clouds_sun_lookup(atmos__clouds_sun *s, const double x[3], int below, double lat, double lon)
{
    return lookup_tol(s, x, below, lat, lon, SPREAD);
}

double atmos__clouds_sun_lookup_through(atmos__clouds_sun *s, const double x[3], int below, double lat, double lon,
                                        double through)
{
    return lookup_tol(s, x, below, lat, lon, through > SPREAD ? (float)(SPREAD / through) : 1.0f);
}
