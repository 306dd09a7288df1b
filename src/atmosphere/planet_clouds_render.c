/* A view ray of a spherical kind through the cloud spheres (planet_clouds.h; Dobashi et al.
 * 2002 §5.4): the air before, between and behind the spheres from the solver's in-scatter
 * and transmittance, each sphere's crossing as a thin layer, the ground under them.
 *
 * A crossing of sphere i at x with shell optical depth tau (planet_clouds.c) lets through
 * t = exp(-tau) of the light behind it and adds (1 - t) J, J the source of the shell:
 *   J = E(x) [ G_i(x) P_HG(cos) + mu_s (1 - G_i(x) exp(-tau_i / (2 mu_s))) / pi ]
 * E(x) the sunlight the solver gives at x (the air's attenuation and the planet's shadow),
 * G_i the attenuation texture (the spheres above i), cos = d . sun the cosine of the
 * scattering angle, mu_s the sun's cosine to the vertical at x. The second term is the
 * diffuse light (the clouds' multiple scattering, which Dobashi's single scattering leaves
 * out): the sunlight taken from the direct beam above the middle of the shell becomes
 * isotropic light of radiance mu_s E / pi per unit lost (a thick cloud's top looks like a
 * white Lambertian surface); single_scattering leaves it out. The air under a cloud is lit
 * as if the cloud were not there (its shadow in the air is not drawn); the ground's
 * sunlight is multiplied by G of all spheres. */
#include "atmosphere/planet_clouds.h"

#include "core/fastmath.h"
#include "core/vec.h"

#define MAX_CROSSINGS (2 * ATMOS__CLOUDS_MAX)
/* stop walking once the clouds pass less than this */
#define OPAQUE 1e-4

typedef struct {
    double t;
    int sphere;
} crossing;

/* The crossings of the spheres with the ray in (0, tmax), nearest first. */
static int find_crossings(const atmos__planet *pl, const double p[3], const double d[3], double tmax,
                          crossing *c)
{
    const atmos__clouds *cl = pl->clouds;
    const double o[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double b = atmos__dot3(o, d), oo = atmos__dot3(o, o);
    int n = 0;
    for (int i = 0; i < cl->m; i++) {
        const double disc = b * b - (oo - cl->r[i] * cl->r[i]);
        if (disc <= 0) continue;
        const double s = sqrt(disc), ts[2] = {-b - s, -b + s};
        for (int j = 0; j < 2; j++) {
            if (!(ts[j] > 0 && ts[j] < tmax)) continue;
            int k = n++;
            while (k > 0 && c[k - 1].t > ts[j]) c[k] = c[k - 1], k--;
            c[k].t = ts[j], c[k].sphere = i;
        }
    }
    return n;
}

/* From an eye above the top sphere, a ray that meets the ground at K enters every sphere,
 * the top one first, and leaves none before K: the entries as find_crossings computes them,
 * without its sorting. 0 (c undefined) when they are not m in (0, K), nearest first. */
static int entries(const atmos__planet *pl, const double p[3], const double d[3], double K, crossing *c)
{
    const atmos__clouds *cl = pl->clouds;
    const double o[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double b = atmos__dot3(o, d), oo = atmos__dot3(o, o);
    const int m = cl->m;
    if (!(oo > cl->r[m - 1] * cl->r[m - 1])) return 0;
    double t_prev = 0.0;
    for (int j = 0; j < m; j++) {
        const int i = m - 1 - j;
        const double disc = b * b - (oo - cl->r[i] * cl->r[i]);
        if (disc <= 0) return 0;
        const double t = -b - sqrt(disc);
        if (!(t > t_prev && t < K)) return 0;
        c[j].t = t_prev = t, c[j].sphere = i;
    }
    return 1;
}

static double hg(double g, double cos_theta)
{
    const double q = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * ATMOS_PI * q * sqrt(q));
}

/* The sunlight E at x of radius index j (sphere j, or the ground for j = m) whose sun's cosine
 * is mus, n wavelengths: from the table e when given (linear in mus), else the solver's.
 * Inline in its callers (the compiler left it a call: a few per cent of the frame). */
static inline __attribute__((always_inline)) void sunlight_at(const atmos_atmosphere *a, int n,
                                                              const atmos__sunlight_table *e, int j,
                                                              const double x[3], const double sun[3],
                                                              double mus, double *E)
{
    if (!e) {
        a->solver->sunlight(a, x, sun, n, NULL, E);
        return;
    }
    const double mc = mus > -1.0 ? (mus < 1.0 ? mus : 1.0) : -1.0; /* selects, not library calls */
    const double u = (mc + 1.0) * 0.5 * (e->ne - 1);
    int i = (int)u;
    i = i > e->ne - 2 ? e->ne - 2 : i;
    const float f = (float)(u - i);
    const float *v = e->e + (size_t)j * n * e->ne + i;
    for (int k = 0; k < n; k++, v += e->ne) E[k] = v[0] + f * (v[1] - v[0]);
}

/* Adds the light of a crossing of sphere i at x (latitude and longitude lat, lon) to out
 * (times the transmittance w in front of it): t the crossing's transmittance, mus the sun's
 * cosine to the vertical there, eo = exp(-own / 2) with own the whole shell's optical depth
 * along the sun (used when mus > 0). G from gs's textures, or evaluated here when gs is NULL;
 * ph the phase function of the ray's scattering angle, e the sunlight's table or NULL; n the
 * wavelengths (inline, so that a constant n unrolls its loops). */
static inline __attribute__((always_inline)) void
crossing_shade(const atmos_atmosphere *a, int n, const double x[3], const double sun[3], double lat, double lon, int i,
               double t, double mus, double eo, double ph, const double *w, double through, atmos__clouds_sun *gs,
               const atmos__sunlight_table *e, double *out)
{
    const atmos__planet *pl = a->planet;
    double E[ATMOS_MAX_WAVELENGTHS];
    sunlight_at(a, n, e, i, x, sun, mus, E);
    int lit = 0;
    for (int k = 0; k < n; k++) lit |= E[k] > 0;
    if (!lit) return;
    const double G = gs ? atmos__clouds_sun_lookup_through(gs, x, i, lat, lon, through)
                       : atmos__clouds_sun_attenuation(pl, x, sun, i);
    double J = G * ph;
    if (!pl->clouds->single && mus > 0) J += mus * (1.0 - G * eo) * (1.0 / ATMOS_PI);
    for (int k = 0; k < n; k++) out[k] += w[k] * (1.0 - t) * J * E[k];
}

/* The ground at distance K: lit by the sunlight through the air and the clouds, and its
 * lights; times w. */
static void ground_light(const atmos_atmosphere *a, const double p[3], const double d[3], double K,
                         const double sun[3], const double *w, double through, atmos__clouds_sun *gs,
                         const atmos__sunlight_table *e, double *out)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count;
    double g[3] = {p[0] + K * d[0], p[1] + K * d[1], p[2] + K * d[2]}, nrm[3];
    atmos__planet_ground_point(pl, g, nrm);
    const double cn = atmos__dot3(nrm, sun), cs = cn > 0.0 ? cn : 0.0;
    double E[ATMOS_MAX_WAVELENGTHS];
    double G = 0.0;
    if (cs > 0) {
        sunlight_at(a, n, e, pl->clouds->m, g, sun, cs, E);
        if (gs) {
            double lat, lon;
            atmos__planet_latlon_fast(pl, g, &lat, &lon);
            G = atmos__clouds_sun_lookup_through(gs, g, -1, lat, lon, through);
        } else G = atmos__clouds_sun_attenuation(pl, g, sun, -1);
    }
    for (int k = 0; k < n; k++) {
        const double lit = cs > 0 ? atmos__planet_ground_albedo(pl, g, k) / ATMOS_PI * cs * E[k] * G : 0.0;
        out[k] += w[k] * (lit + atmos__planet_ground_lights(pl, g, sun, k));
    }
}

/* The air of the segment x + t d, t in [0, seg], seen through w: its light added to out, w
 * times its transmittance (when anything lies behind it: last, the segment into space, has
 * nothing); from air when given, else the solver's. */
static void air_segment(const atmos_atmosphere *a, const atmos__clouds_air *air, const double x[3], const double d[3],
                        double seg, int between, int last, const double sun[3], double *w, double *out)
{
    const int n = a->wl.count;
    double S[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    if (air) {
        air->segment(air->ctx, x, d, seg, between, S, T);
        for (int k = 0; k < n; k++) out[k] += w[k] * S[k];
        if (!last)
            for (int k = 0; k < n; k++) w[k] *= T[k];
        return;
    }
    if (a->solver->inscatter(a, x, d, seg, sun, n, NULL, S))
        for (int k = 0; k < n; k++) out[k] += w[k] * S[k];
    if (!last) {
        a->solver->transmittance(a, x, d, seg, n, NULL, T);
        for (int k = 0; k < n; k++) w[k] *= T[k];
    }
}

static void radiance_clouds(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                            const atmos__clouds_air *air, double *out, atmos_atmosphere_hit *info)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count;
    const double K = atmos__planet_ground_distance(pl, p, d);
    crossing c[MAX_CROSSINGS];
    const int nc = find_crossings(pl, p, d, K, c);
    double w[ATMOS_MAX_WAVELENGTHS];
    for (int k = 0; k < n; k++) out[k] = 0.0, w[k] = 1.0;
    double x[3] = {p[0], p[1], p[2]}, t_prev = 0.0, clouds = 1.0;
    const double ph = hg(pl->clouds->g, atmos__dot3(d, sun));
    int opaque = 0;
    for (int j = 0; j <= nc && !opaque; j++) {
        const double t_end = j < nc ? c[j].t : K, seg = t_end - t_prev;
        /* the air of the segment, seen through everything in front of it */
        if (seg > 0) air_segment(a, air, x, d, seg, j > 0 && j < nc, !(j < nc || K < INFINITY), sun, w, out);
        if (j == nc) {
            if (K < INFINITY) ground_light(a, p, d, K, sun, w, 1.0, NULL, NULL, out);
            break;
        }
        for (int i = 0; i < 3; i++) x[i] = p[i] + t_end * d[i];
        double lat, lon;
        atmos__planet_latlon_fast(pl, x, &lat, &lon);
        const double col = atmos__clouds_column_tau(pl->clouds, lat, lon);
        double tc = 1.0;
        if (col > 0) {
            const atmos__clouds *cl = pl->clouds;
            const int i = c[j].sphere;
            const double xc[3] = {x[0], x[1] + pl->r_ground, x[2]}; /* x is on sphere i */
            const double mus = atmos__dot3(xc, sun) * cl->inv_r[i];
            tc = atmos__expf_fast((float)-atmos__clouds_shell_tau(cl, i, col, atmos__dot3(xc, d) * cl->inv_r[i]));
            const double eo = atmos__expf_fast((float)(-0.5 * atmos__clouds_shell_tau(cl, i, col, mus)));
            crossing_shade(a, n, x, sun, lat, lon, i, tc, mus, eo, ph, w, 1.0, NULL, NULL, out);
        }
        clouds *= tc;
        for (int k = 0; k < n; k++) w[k] *= tc;
        opaque = clouds < OPAQUE;
        t_prev = t_end;
    }
    if (info) {
        info->distance_m = K;
        info->hits_ground = K < INFINITY;
        info->in_sun_disk = 0;
    }
}

void atmos__planet_radiance_clouds(const atmos_atmosphere *a, const double p[3], const double d[3],
                                   const double sun[3], double *out, atmos_atmosphere_hit *info)
{
    radiance_clouds(a, p, d, sun, NULL, out, info);
}

void atmos__planet_radiance_clouds_air(const atmos_atmosphere *a, const double p[3], const double d[3],
                                       const double sun[3], const atmos__clouds_air *air, double *out)
{
    radiance_clouds(a, p, d, sun, air, out, NULL);
}

/* The fields of the m crossings c at x whose columns' optical depths are col, as arrays:
 * the sun's cosine to the vertical mus[j], the crossing's transmittance ex[j] = exp(-tau)
 * and ex[m + j] = exp(-own / 2), own the whole shell's optical depth along the sun. */
static void crossing_fields(const atmos__planet *pl, const double d[3], const double sun[3], int m,
                            const crossing *c, const double x[][3], const double *col, double *mus, float *ex)
{
    const atmos__clouds *cl = pl->clouds;
    for (int j = 0; j < m; j++) { /* x[j] is on sphere c[j].sphere: its vertical is (x + centre) / r */
        const int i = c[j].sphere;
        const double xc[3] = {x[j][0], x[j][1] + pl->r_ground, x[j][2]};
        mus[j] = atmos__dot3(xc, sun) * cl->inv_r[i];
        ex[j] = (float)-atmos__clouds_shell_tau(cl, i, col[j], atmos__dot3(xc, d) * cl->inv_r[i]);
        ex[m + j] = (float)(-0.5 * atmos__clouds_shell_tau(cl, i, col[j], mus[j]));
    }
    atmos__expf_fast_array(ex, 2 * m);
}

/* The compositing of a ray's m crossings (their fields prepared by atmos__clouds_radiance_stops)
 * on the air's stops Lc, Tc, front to back, and the ground behind them; n the wavelengths
 * (inline: a constant n unrolls the loops over them). */
static inline __attribute__((always_inline)) void
composite(const atmos_atmosphere *a, int n, const double p[3], const double d[3], const double sun[3], double K,
          const double *Lc, const double *Tc, atmos__clouds_sun *gs, const atmos__sunlight_table *e, int m,
          const crossing *c, const double x[][3], const double *lat, const double *lon, const double *col,
          const double *mus, const float *ex, double ph, double *out)
{
    double w[ATMOS_MAX_WAVELENGTHS], clouds = 1.0;
    for (int k = 0; k < n; k++) out[k] = 0.0;
    for (int j = 0; j <= m; j++) {
        /* the air between stop j - 1 and stop j as the eye sees it, through the clouds */
        for (int k = 0; k < n; k++) { /* a select, not the library's fmax */
            const double dl = Lc[(size_t)j * n + k] - (j ? Lc[(size_t)(j - 1) * n + k] : 0.0);
            out[k] += clouds * (dl > 0.0 ? dl : 0.0);
        }
        for (int k = 0; k < n; k++) w[k] = clouds * Tc[(size_t)j * n + k];
        if (j == m) {
            ground_light(a, p, d, K, sun, w, clouds, gs, e, out);
            break;
        }
        if (col[j] <= 0) continue;
        const double t = ex[j];
        crossing_shade(a, n, x[j], sun, lat[j], lon[j], c[j].sphere, t, mus[j], ex[m + j], ph, w, clouds, gs, e, out);
        clouds *= t;
        if (clouds < OPAQUE) break;
    }
}

int atmos__clouds_radiance_stops(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                                 const double *Lc, const double *Tc, atmos__clouds_sun *gs,
                                 const atmos__sunlight_table *e, double *out)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count, m = pl->clouds->m;
    const double K = atmos__planet_ground_distance(pl, p, d);
    crossing c[MAX_CROSSINGS];
    if (!(K < INFINITY) || !entries(pl, p, d, K, c)) return 0;
    /* the crossings' points, coordinates and columns first: independent of each other, so
     * their divisions and memory reads overlap instead of waiting on the compositing */
    double x[MAX_CROSSINGS][3], lat[MAX_CROSSINGS], lon[MAX_CROSSINGS], col[MAX_CROSSINGS];
    for (int j = 0; j < m; j++) { /* arithmetic only: the compiler may do the crossings side by side */
        for (int i = 0; i < 3; i++) x[j][i] = p[i] + c[j].t * d[i];
        atmos__planet_latlon_fast(pl, x[j], &lat[j], &lon[j]);
    }
    for (int j = 0; j < m; j++) col[j] = atmos__clouds_column_tau(pl->clouds, lat[j], lon[j]);
    double mus[MAX_CROSSINGS];
    float ex[2 * MAX_CROSSINGS];
    crossing_fields(pl, d, sun, m, c, x, col, mus, ex);
    const double ph = hg(pl->clouds->g, atmos__dot3(d, sun));
    if (n == 3) /* rgb: the compositing's loops over the wavelengths unrolled */
        composite(a, 3, p, d, sun, K, Lc, Tc, gs, e, m, c, x, lat, lon, col, mus, ex, ph, out);
    else
        composite(a, n, p, d, sun, K, Lc, Tc, gs, e, m, c, x, lat, lon, col, mus, ex, ph, out);
    return 1;
}

void atmos__clouds_sunlight_fill(const atmos_atmosphere *a, int ne, float *out)
{
    const atmos__planet *pl = a->planet;
    const atmos__clouds *cl = pl->clouds;
    const int n = a->wl.count;
    for (int j = 0; j <= cl->m; j++) {
        const double x[3] = {0.0, (j < cl->m ? cl->r[j] : pl->r_ground) - pl->r_ground, 0.0};
        for (int i = 0; i < ne; i++) {
            const double mu = -1.0 + 2.0 * i / (ne - 1), sun[3] = {sqrt(fmax(0.0, 1.0 - mu * mu)), mu, 0.0};
            double E[ATMOS_MAX_WAVELENGTHS];
            a->solver->sunlight(a, x, sun, n, NULL, E);
            for (int k = 0; k < n; k++) out[((size_t)j * n + k) * ne + i] = (float)E[k];
        }
    }
}

void atmos__clouds_attenuation_texture(const atmos__planet *pl, int i, const double sun[3], int w, int h,
                                       float *out)
{
    for (int y = 0; y < h; y++)
        for (int xx = 0; xx < w; xx++) {
            double x[3];
            const double lat = 90.0 - (y + 0.5) * 180.0 / h, lon = -180.0 + (xx + 0.5) * 360.0 / w;
            atmos__clouds_geo_point(pl, pl->clouds->r[i], lat, lon, x);
            out[(size_t)y * (size_t)w + (size_t)xx] = (float)atmos__clouds_sun_attenuation(pl, x, sun, i);
        }
}

double atmos__clouds_view_transmittance(const atmos__planet *pl, const double p[3], const double d[3], double dist)
{
    crossing c[MAX_CROSSINGS];
    const int nc = find_crossings(pl, p, d, dist, c);
    double tau = 0.0;
    for (int j = 0; j < nc; j++) {
        const double x[3] = {p[0] + c[j].t * d[0], p[1] + c[j].t * d[1], p[2] + c[j].t * d[2]};
        tau += atmos__clouds_crossing_tau(pl, c[j].sphere, x, d);
    }
    return exp(-tau);
}
