/* What the spherical kinds answer alike (planet_solver.h): the radiance of a view ray from
 * a solver's in-scatter, transmittance and sunlight when it has no faster way. */
#include "atmosphere/planet_solver.h"

#include "core/vec.h"

#include <string.h>

const char *const *atmos_atmosphere_kind_table_names(atmos_atmosphere_kind kind)
{
    static const char *const none[] = {NULL};
    const atmos__planet_solver *s = kind == ATMOS_ATMOSPHERE_DOBASHI     ? &atmos__dobashi_solver
                                    : kind == ATMOS_ATMOSPHERE_SPHERICAL ? &atmos__spherical_solver
                                                                         : NULL;
    return s && s->table_names ? s->table_names : none;
}

const char *const *atmos_atmosphere_table_names(const atmos_atmosphere *atm)
{
    static const char *const none[] = {NULL};
    return atm && atm->solver && atm->solver->table_names ? atm->solver->table_names : none;
}

atmos_status atmos_atmosphere_table(atmos_context *ctx, const atmos_atmosphere *atm, const char *name,
                                    atmos_image **out)
{
    if (!atm || !name || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere table: missing argument");
    *out = NULL;
    const char *const *names = atmos_atmosphere_table_names(atm);
    char known[256] = "";
    for (int i = 0; names[i]; i++) {
        if (!strcmp(names[i], name)) return atm->solver->table(ctx, atm, i, out);
        if (strlen(known) + strlen(names[i]) + 3 < sizeof known) {
            if (i) strcat(known, ", ");
            strcat(known, names[i]);
        }
    }
    return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmosphere table '%s' unknown; this model's tables: %s", name,
                        known[0] ? known : "none (only the spherical models keep tables)");
}

atmos_status atmos__planet_table_image(atmos_context *ctx, const float *src, int w, int h, int n, size_t xs,
                                       size_t ys, size_t ks, int neg_exp, const char *name, const char *axes,
                                       const char *units, atmos_image **out)
{
    atmos_status st = atmos_image_create(ctx, w, h, n, out);
    if (st != ATMOS_OK) return st;
    atmos_image *img = *out;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = 0; k < n; k++) {
                const float v = src[(size_t)k * ks + (size_t)y * ys + (size_t)x * xs];
                img->pixels[((size_t)y * w + x) * n + k] = neg_exp ? expf(-v) : v;
            }
    if ((st = atmos_image_set_meta(img, "atmos:table", name)) == ATMOS_OK)
        st = atmos_image_set_meta(img, "atmos:axes", axes);
    if (st == ATMOS_OK) st = atmos_image_set_meta(img, "atmos:units", units);
    if (st != ATMOS_OK) {
        atmos_image_destroy(img);
        *out = NULL;
    }
    return st;
}

void atmos__planet_ground_sunlit(const atmos_atmosphere *a, const double p[3], const double d[3], double K,
                                 const double sun[3], int lights, double *out)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count;
    double g[3] = {p[0] + K * d[0], p[1] + K * d[1], p[2] + K * d[2]}, nrm[3];
    atmos__planet_ground_point(pl, g, nrm);
    const double cs = fmax(atmos__dot3(nrm, sun), 0.0);
    double E[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    a->solver->transmittance(a, p, d, K, n, NULL, T);
    if (cs > 0) a->solver->sunlight(a, g, sun, n, NULL, E);
    for (int i = 0; i < n; i++) {
        const double lit = cs > 0 ? atmos__planet_ground_albedo(pl, g, i) / ATMOS_PI * cs * E[i] : 0.0;
        out[i] = (lit + (lights ? atmos__planet_ground_lights(pl, g, sun, i) : 0.0)) * T[i];
    }
}

void atmos__planet_radiance_generic(const atmos_atmosphere *a, const double p[3], const double d[3],
                                    const double sun[3], double *out, atmos_atmosphere_hit *info)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count;
    const double K = atmos__planet_ground_distance(pl, p, d);
    const int ground = K < INFINITY;
    if (!a->solver->inscatter(a, p, d, K, sun, n, NULL, out))
        for (int i = 0; i < n; i++) out[i] = 0.0;
    if (ground) {
        double G[ATMOS_MAX_WAVELENGTHS];
        atmos__planet_ground_sunlit(a, p, d, K, sun, 1, G);
        for (int i = 0; i < n; i++) out[i] += G[i];
    }
    if (info) {
        info->distance_m = K;
        info->hits_ground = ground;
        info->in_sun_disk = 0;
    }
}
