/* The production sky's per-eye table for an eye above the top of the air (spherical.h): the
 * Earth from space. Every view ray from such an eye is a straight line that meets the air, if
 * at all, on the planet's side of the eye, and what the air gives along it depends on two
 * coordinates about the axis from the eye to the planet's centre:
 *  - the ray's impact parameter p (its closest distance to the centre), in two blocks split
 *    at the ground's radius R (the disk's edge is never blurred):
 *      the disk, p < R: p = R sin z, z = pi / 2 (1 - (AD v + (1 - AD) v^2)) the zenith angle
 *        where the ray meets the ground, v uniform over the rows: rows crowd at the disk's
 *        edge, where the air's path grows as 1 / cos z, and stay a few degrees of z apart at
 *        its centre;
 *      the limb, R <= p < R_top: p - R = (R_top - R) v^2, rows crowd at the bottom of the
 *        limb, where the air is densest;
 *  - the azimuth of the ray about that axis from the sun's side, over [0, pi] (the planet's
 *    light is symmetric about the plane through the eye, the centre and the sun), the columns
 *    of each row crowded where the sun sets at the row's reference point (the air's light
 *    falls off steeply across the terminator).
 * Per node and wavelength the table keeps the logarithms of the air's light as the march
 * gives it (Rayleigh and Mie single scattering without their phase functions, the higher
 * orders) and of the view transmittance to the ground: interpolated as logarithms, the
 * exponential fall-offs (the limb's brightness with height, the twilight) stay smooth. With
 * cloud spheres the disk's stops are also kept exponentiated, and interpolated as they are
 * between nodes whose logarithms differ little (smooth_nodes).
 * Per pixel: the ray's node coordinates, the phase functions of its own scattering angle, and
 * on the disk the ground at the ray's own ground point (the maps' albedo and night lights,
 * the sun and the sky there: atmos__sph_ground) seen through the interpolated transmittance,
 * so the maps and the terminator on the ground stay as sharp as the per-ray answer. Rays that
 * miss the air cost a dot product. */
#include "atmosphere/spherical.h"

#include "atmosphere/planet_clouds.h"
#include "core/fastmath.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NG ATMOS__SPH_SP_DISK
#define NL ATMOS__SPH_SP_LIMB
#define NA ATMOS__SPH_SP_AZ
#define NC 4 /* channels: Rayleigh, Mie (no phase), the higher orders, the view transmittance */
#define TINY 1e-30 /* the values are kept as logarithms, at least log(TINY) */
#define NPH 1024 /* the Mie phase over sin(theta / 2), as the ground's table */
#define NCS 2048 /* the ground's irradiance over the sun's cosine there, in [-1, 1] */

struct atmos__sph_space {
    int n, ns;                   /* wavelengths; stops per node (1, or m + 1 with m cloud spheres) */
    int keyed;                   /* the table is the key's (else the eye's own) */
    long key[2];                 /* the eye's distance from the centre and the sun's cosine there,
                                    quantised (KEEP_DR, KEEP_DMU) */
    double eye[3];               /* world frame */
    double rc2;                  /* the top cloud sphere's radius squared (0: no clouds) */
    double q[3], qq, r;          /* the eye from the planet's centre, |q|^2, |q| */
    double up[3], e1[3], e2[3];  /* up = q / r, e1 toward the sun's side, e2 = up x e1 */
    double R, Rt;
    float *tab;                  /* [NG + NL][NA][ns][n][NC]: rows 0..NG-1 the disk (row 0 at its
                                    edge), NG..NG+NL-1 the limb (row NG at its bottom); stop
                                    ns - 1 the whole ray, stops j < ns - 1 of the disk's rows
                                    from the eye to the crossing of cloud sphere m - 1 - j */
    double phit[NG + NL];        /* per row: the azimuth where the sun sets at the row's
                                    reference point (its columns crowd there) */
    float *mie;                  /* [n][NPH] */
    float *gi;                   /* [n][NCS]: the ground's irradiance by the sun and the sky
                                    over pi, times the sun's, as atmos__sph_ground has it */
    float ra[ATMOS_MAX_WAVELENGTHS], rb[ATMOS_MAX_WAVELENGTHS]; /* Rayleigh: kr (ra + rb nu^2) */
    atmos__clouds_sun *gs;       /* the cloud spheres' attenuation textures for the sun (not
                                    owned; NULL: G at each crossing) */
    float *ec;                   /* [m + 1][n][NCS]: the sunlight at each cloud sphere's radius
                                    and the ground's over the sun's cosine (clouds only) */
    float *lin;                  /* [NG][NA][ns][n][NC]: the disk's stops exponentiated (clouds
                                    only; smooth_nodes) */
    unsigned char *smooth;       /* [NG][NA]: 1 where lin may be interpolated (smooth_nodes) */
};

#define AD 0.3 /* the disk's rows: the linear share of their mapping (above) */
/* The impact parameter of row `row`. */
static double row_p(const atmos__sph_space *s, int row)
{
    if (row < NG) { /* the zenith angle at the ground z = pi / 2 (1 - g(v)) */
        const double v = (double)row / (NG - 1);
        return s->R * cos(0.5 * ATMOS_PI * fmax(AD * v + (1.0 - AD) * v * v, 1e-6));
    }
    const double v = (double)(row - NG) / (NL - 1);
    return s->R + (s->Rt - s->R) * fmax(v * v, 1e-9);
}

/* The azimuth of the terminator at the row's reference point (where a ray of the disk meets
 * the ground, the bottom of a ray of the limb): that point, at angle beta from the point
 * under the eye, sees the sun at cosine cos(beta) mu_s + sin(beta) sin_s cos(phi). 0 or pi
 * when the sun is up or down at every azimuth. */
static double row_phit(const atmos__sph_space *s, int row, double mu_s)
{
    const double p = row_p(s, row), th = asin(fmin(1.0, p / s->r));
    const double beta = row < NG ? asin(fmin(1.0, p / s->R)) - th : 0.5 * ATMOS_PI - th;
    const double den = sin(beta) * sqrt(fmax(0.0, 1.0 - mu_s * mu_s));
    const double c = den > 1e-12 ? -cos(beta) * mu_s / den : (mu_s > 0 ? -2.0 : 2.0);
    return acos(fmax(-1.0, fmin(1.0, c)));
}

/* Columns: x in [0, 1] (column x (NA - 1)) to the azimuth and back, the nodes crowded at
 * the terminator's azimuth t: on each side the offset from t grows as A s + (1 - A) s^2 of
 * the side's length with s uniform in x (the nodes are 1 / A times denser at t than a
 * uniform grid would put them on that side). */
#define A 0.3
static double col_phi(double t, double x)
{
    const double xt = t / ATMOS_PI;
    if (x < xt || xt >= 1.0) {
        const double s = 1.0 - x / xt;
        return t - t * (A * s + (1.0 - A) * s * s);
    }
    const double s = (x - xt) / (1.0 - xt);
    return t + (ATMOS_PI - t) * (A * s + (1.0 - A) * s * s);
}
static double phi_col(double t, double phi)
{
    const double xt = t / ATMOS_PI, left = phi <= t;
    const double len = left ? t : ATMOS_PI - t;
    if (!(len > 1e-12)) return xt;
    const double y = fabs(phi - t) / len;
    const double s = (-A + sqrt(A * A + 4.0 * (1.0 - A) * y)) * (0.5 / (1.0 - A));
    return left ? xt * (1.0 - s) : xt + (1.0 - xt) * s;
}

static void node_dir(const atmos__sph_space *s, int row, int col, double d[3])
{
    const double st = row_p(s, row) / s->r, ct = sqrt(fmax(0.0, 1.0 - st * st));
    const double phi = col_phi(s->phit[row], (double)col / (NA - 1)), c = cos(phi), sn = sin(phi);
    for (int i = 0; i < 3; i++) d[i] = -ct * s->up[i] + st * (c * s->e1[i] + sn * s->e2[i]);
}

/* The look-ups' frame for an eye and a sun: the eye, q, |q|, the axes; returns the sun's
 * cosine to the eye's vertical. */
static double space_frame(atmos__sph_space *s, const atmos__planet *pl, const double eye[3], const double sun[3])
{
    memcpy(s->eye, eye, sizeof s->eye);
    s->q[0] = eye[0], s->q[1] = eye[1] + pl->r_ground, s->q[2] = eye[2];
    s->qq = atmos__dot3(s->q, s->q), s->r = sqrt(s->qq);
    return atmos__planet_sun_frame(s->q, sun, s->up, s->e1, s->e2);
}

/* The key of the frame's distance r and the sun's cosine mu (quanta KEEP_DR of log r and
 * KEEP_DMU of mu), and an eye eq and a sun sq with the quantised values in a fixed frame
 * (the eye over the origin): the table depends on nothing else (the air is the same all
 * round the planet's centre; the ground's maps and the clouds are looked up per ray). 0 when
 * the eye or the quantised eye is not above the air. */
#define KEEP_DR 1e-6
#define KEEP_DMU 1e-5
static int key_eye(const atmos__sph_space *s, const atmos__planet *pl, double mu, long key[2], double eq[3],
                   double sq[3])
{
    key[0] = lround(log(s->r) / KEEP_DR), key[1] = lround(fmax(-1.0, fmin(1.0, mu)) / KEEP_DMU);
    const double rq = exp((double)key[0] * KEEP_DR), mq = fmax(-1.0, fmin(1.0, (double)key[1] * KEEP_DMU));
    if (!(rq > pl->r_top * (1.0 + 1e-9)) || !(s->r > pl->r_top)) return 0;
    eq[0] = 0.0, eq[1] = rq - pl->r_ground, eq[2] = 0.0;
    sq[0] = sqrt(fmax(0.0, 1.0 - mq * mq)), sq[1] = mq, sq[2] = 0.0;
    return 1;
}

/* Steps of the march per piece of the slices between cloud spheres and below them. */
#define STEPS_CLOUDS 3
/* the same for a limb's ray between its crossings (longer: the ray runs along the layer) */
#define STEPS_LIMB 8

/* A node's stop: the logarithms of the sums times the sun's irradiance. */
static void put_stop(const atmos_atmosphere *a, int n, const atmos__sph_sums *u, float *t)
{
    for (int k = 0; k < n; k++) {
        t[NC * k] = (float)log(fmax(u->sr[k] * a->sun_e[k], TINY));
        t[NC * k + 1] = (float)log(fmax(u->sm[k] * a->sun_e[k], TINY));
        t[NC * k + 2] = (float)log(fmax(u->ms[k] * a->sun_e[k], TINY));
        t[NC * k + 3] = (float)log(fmax(u->t[k], TINY));
    }
}

/* The march's sums from t0 to each stop of a ray of the disk through the cloud spheres (the
 * entries of spheres m - 1 .. 0, then the ground at K) into the node's stops t, chained
 * slice by slice: over [t0, b] = over [t0, a] + T(t0, a) x over [a, b]. */
static void march_stops(const atmos_atmosphere *a, const atmos__sph_space *s, const double d[3], double t0,
                        double K, const double sun[3], float *t)
{
    const atmos__planet *pl = a->planet;
    const atmos__clouds *cl = pl->clouds;
    const int n = s->n, m = cl->m;
    const double b = atmos__dot3(s->q, d);
    double ta = t0;
    atmos__sph_sums acc, seg;
    memset(&acc, 0, sizeof acc);
    for (int k = 0; k < n; k++) acc.t[k] = 1.0;
    for (int j = 0; j <= m; j++) {
        const double rr = j < m ? cl->r[m - 1 - j] : s->R;
        const double tb = j < m ? fmax(-b - sqrt(fmax(0.0, b * b - (s->qq - rr * rr))), ta) : K;
        if (tb > ta) {
            atmos__sph_march(pl, a->model, s->q, d, ta, tb, sun, j ? STEPS_CLOUDS : ATMOS__SPH_STEPS_SPACE, 1, n,
                             NULL, &seg);
            for (int k = 0; k < n; k++) {
                acc.sr[k] += acc.t[k] * seg.sr[k], acc.sm[k] += acc.t[k] * seg.sm[k];
                acc.ms[k] += acc.t[k] * seg.ms[k], acc.t[k] *= seg.t[k];
            }
        }
        put_stop(a, n, &acc, t + (size_t)j * NC * n);
        ta = tb;
    }
}

/* A node: the whole ray in every stop, or with cloud spheres on the disk's rows each stop. */
static void fill_node(const atmos_atmosphere *a, atmos__sph_space *s, const double eye[3], const double sun[3],
                      int row, int col)
{
    const atmos__planet *pl = a->planet;
    const int n = s->n, ns = s->ns;
    double d[3], t0, t1;
    node_dir(s, row, col, d);
    const double K = atmos__planet_ground_distance(pl, eye, d);
    float *t = s->tab + ((size_t)row * NA + col) * ns * NC * n;
    const int inside = atmos__planet_clip(pl, eye, d, K, &t0, &t1);
    if (inside && ns > 1 && row < NG && K < INFINITY) {
        march_stops(a, s, d, t0, K, sun, t);
        return;
    }
    atmos__sph_sums sm;
    if (inside) atmos__sph_march(pl, a->model, s->q, d, t0, t1, sun, ATMOS__SPH_STEPS_SPACE, 1, n, NULL, &sm);
    else {
        memset(&sm, 0, sizeof sm);
        for (int k = 0; k < n; k++) sm.t[k] = 1.0;
    }
    for (int j = 0; j < ns; j++) put_stop(a, n, &sm, t + (size_t)j * NC * n);
}

/* With cloud spheres, the disk's stops also exponentiated (lin), and a disk node marked smooth
 * where none of its logarithms differs by more than DLOG from its neighbours' (the rows and
 * columns either side): between smooth nodes the values themselves are interpolated, without
 * an exponential per value and stop, and differ from the exponential of the interpolated
 * logarithms by at most about DLOG^2 / 8 of the value. Elsewhere (across the terminator,
 * where the air's light falls off by orders of magnitude over a cell, and at the dark side's
 * floor) the logarithms are interpolated as on the limb. 0 when out of memory. */
#define DLOG 0.5f
static int smooth_nodes(atmos__sph_space *s)
{
    const size_t S = (size_t)NC * s->ns * s->n;
    s->lin = malloc(sizeof(float) * NG * NA * S + NG * NA);
    if (!s->lin) return 0;
    s->smooth = (unsigned char *)(s->lin + NG * NA * S);
    for (size_t j = 0; j < NG * NA * S; j++) s->lin[j] = atmos__expf_fast(s->tab[j]);
    for (int row = 0; row < NG; row++)
        for (int col = 0; col < NA; col++) {
            const float *t = s->tab + ((size_t)row * NA + col) * S;
            int ok = 1;
            for (int r = row - 1; r <= row + 1 && ok; r++)
                for (int c = col - 1; c <= col + 1 && ok; c++) {
                    if (r < 0 || r >= NG || c < 0 || c >= NA) continue;
                    const float *u = s->tab + ((size_t)r * NA + c) * S;
                    for (size_t j = 0; j < S && ok; j++) ok = fabsf(u[j] - t[j]) <= DLOG;
                }
            s->smooth[row * NA + col] = (unsigned char)ok;
        }
    return 1;
}

atmos__sph_space *atmos__sph_space_create(const atmos_atmosphere *a, const double eye[3], const double sun[3],
                                          atmos__clouds_sun *gs)
{
    const atmos__planet *pl = a->planet;
    atmos__sph_space *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->gs = gs;
    s->n = a->wl.count;
    s->ns = 1;
    if (pl->clouds) {
        const int m = pl->clouds->m;
        if ((m + 1) * s->n > ATMOS_MAX_WAVELENGTHS) { /* the look-up's buffers; rays one by one */
            free(s);
            return NULL;
        }
        s->ns = m + 1, s->rc2 = pl->clouds->r[m - 1] * pl->clouds->r[m - 1];
    }
    s->R = pl->r_ground, s->Rt = pl->r_top;
    /* the table for the quantised distance and sun (key), in a frame of its own: its values
     * are the same whenever the key is */
    double eq[3], sq[3];
    const int keyed = key_eye(s, pl, space_frame(s, pl, eye, sun), s->key, eq, sq);
    if (!keyed) memcpy(eq, eye, sizeof eq), memcpy(sq, sun, sizeof sq);
    const double mu_s = space_frame(s, pl, eq, sq);
    for (int row = 0; row < NG + NL; row++) s->phit[row] = row_phit(s, row, mu_s);
    const size_t nodes = (size_t)(NG + NL) * NA * NC * s->ns * s->n;
    const size_t nec = s->ns > 1 ? (size_t)s->ns * s->n * NCS : 0;
    s->tab = malloc(sizeof(float) * (nodes + (size_t)s->n * (NPH + NCS) + nec));
    if (!s->tab) {
        free(s);
        return NULL;
    }
    s->mie = s->tab + nodes;
    s->gi = s->mie + (size_t)s->n * NPH;
    s->ec = nec ? s->gi + (size_t)s->n * NCS : NULL;
    if (s->ec) atmos__clouds_sunlight_fill(a, NCS, s->ec);
    for (int j = 0; j < NCS; j++) { /* (cos T_sun + E_sky) E / pi, as atmos__sph_ground */
        const double cs = -1.0 + 2.0 * j / (NCS - 1);
        double e[ATMOS_MAX_WAVELENGTHS];
        atmos__sph_ground_irradiance(pl, a->model, cs, s->n, NULL, e);
        for (int k = 0; k < s->n; k++) s->gi[k * NCS + j] = (float)(e[k] / ATMOS_PI * a->sun_e[k]);
    }
    for (int k = 0; k < s->n; k++) atmos__planet_rayleigh_ab(pl, k, &s->ra[k], &s->rb[k]);
    atmos__planet_mie_phase_table(pl, s->n, NPH, s->mie);
#pragma omp parallel for schedule(dynamic)
    for (int e = 0; e < (NG + NL) * NA; e++) fill_node(a, s, eq, sq, e / NA, e % NA);
    if (s->ns > 1 && !smooth_nodes(s)) {
        atmos__sph_space_destroy(s);
        return NULL;
    }
    s->keyed = keyed;
    space_frame(s, pl, eye, sun); /* the look-ups in the eye's own frame */
    return s;
}

int atmos__sph_space_keep(atmos__sph_space *s, const atmos__planet *pl, const double eye[3], const double sun[3],
                          struct atmos__clouds_sun *gs)
{
    atmos__sph_space t = *s;
    long key[2];
    double eq[3], sq[3];
    if (!s->keyed || !key_eye(&t, pl, space_frame(&t, pl, eye, sun), key, eq, sq) || key[0] != s->key[0] ||
        key[1] != s->key[1])
        return 0;
    space_frame(s, pl, eye, sun);
    s->gs = gs;
    return 1;
}

void atmos__sph_space_destroy(atmos__sph_space *s)
{
    if (s) free(s->tab), free(s->lin);
    free(s);
}

/* The table's row coordinate (fractional, within the block) of a ray of impact parameter
 * squared p2 < R_top^2; *disk: the ray meets the ground. */
static double row_coord(const atmos__sph_space *s, double p2, int *disk)
{
    const double R2 = s->R * s->R;
    *disk = p2 < R2;
    if (*disk) {
        const double y = atmos__atan2_fast(sqrt(R2 - p2), sqrt(p2)) * (2.0 / ATMOS_PI);
        return (-AD + sqrt(AD * AD + 4.0 * (1.0 - AD) * y)) * (0.5 / (1.0 - AD)) * (NG - 1);
    }
    const double h = sqrt(p2) - s->R;
    return sqrt(fmin(1.0, h / (s->Rt - s->R))) * (NL - 1);
}

/* A ray's place in the table: its rows (row, row + 1; ay between them), its columns in each
 * (ix0, ix1; ax0, ax1), whether it meets the ground (disk). */
typedef struct {
    int row, ix0, ix1, disk;
    float ay, ax0, ax1;
} node_at;

/* The node coordinates of one ray (d a unit vector toward the air, p2 its impact parameter
 * squared). */
static void ray_node(const atmos__sph_space *s, const double d[3], double p2, node_at *c)
{
    const double fy = row_coord(s, p2, &c->disk);
    const double phi = atmos__atan2_fast(fabs(atmos__dot3(d, s->e2)), atmos__dot3(d, s->e1));
    const int lim = (c->disk ? NG : NL) - 2;
    int iy = (int)fy;
    iy = iy > lim ? lim : iy;
    const int row = iy + (c->disk ? 0 : NG);
    const double fx0 = phi_col(s->phit[row], phi) * (NA - 1), fx1 = phi_col(s->phit[row + 1], phi) * (NA - 1);
    int ix0 = (int)fx0, ix1 = (int)fx1;
    ix0 = ix0 > NA - 2 ? NA - 2 : ix0;
    ix1 = ix1 > NA - 2 ? NA - 2 : ix1;
    c->row = row, c->ix0 = ix0, c->ix1 = ix1;
    c->ay = (float)(fy - iy), c->ax0 = (float)(fx0 - ix0), c->ax1 = (float)(fx1 - ix1);
}

/* The table's values at a ray's place interpolated into l[NC ns n]: from tab (logarithms)
 * or, on the disk, lin (the values). */
static void node_logs(const atmos__sph_space *s, const float *tab, const node_at *c, float *l)
{
    const int S = NC * s->ns * s->n;
    const float ay = c->ay, ax0 = c->ax0, ax1 = c->ax1;
    const float *t00 = tab + ((size_t)c->row * NA + c->ix0) * S, *t01 = t00 + S;
    const float *t10 = tab + ((size_t)(c->row + 1) * NA + c->ix1) * S, *t11 = t10 + S;
    const float w00 = (1 - ay) * (1 - ax0), w01 = (1 - ay) * ax0, w10 = ay * (1 - ax1), w11 = ay * ax1;
    for (int j = 0; j < S; j++) l[j] = w00 * t00[j] + w01 * t01[j] + w10 * t10[j] + w11 * t11[j];
}

/* The light of the ground where the ray d (b = q . d) meets it: its albedo and night lights
 * there, its irradiance from the table over the sun's cosine (atmos__sph_ground's). */
static void ground(const atmos__sph_space *s, const atmos_atmosphere *a, const double sun[3], const double d[3],
                   double b, float *G)
{
    const atmos__planet *pl = a->planet;
    const double K = -b - sqrt(fmax(0.0, b * b - (s->qq - s->R * s->R)));
    double nr[3] = {s->q[0] + K * d[0], s->q[1] + K * d[1], s->q[2] + K * d[2]};
    const double l = sqrt(atmos__dot3(nr, nr));
    for (int c = 0; c < 3; c++) nr[c] /= l;
    const double gw[3] = {nr[0] * s->R, nr[1] * s->R - s->R, nr[2] * s->R}; /* world frame */
    const double u = (atmos__dot3(nr, sun) + 1.0) * 0.5 * (NCS - 1);
    int j = (int)u;
    j = j < 0 ? 0 : (j > NCS - 2 ? NCS - 2 : j);
    const float f = (float)(u - j);
    for (int k = 0; k < s->n; k++) {
        const float *e = s->gi + k * NCS + j;
        G[k] = (float)atmos__planet_ground_albedo(pl, gw, k) * (e[0] + f * (e[1] - e[0])) +
               (float)atmos__planet_ground_lights(pl, gw, sun, k);
    }
}

/* One ray through the cloud spheres answered alone (planet_clouds_render.c). */
static void cloud_ray(const atmos__sph_space *s, const atmos_atmosphere *a, const double sun[3], const double d[3],
                      float wt, int count, int i, float *out)
{
    double L[ATMOS_MAX_WAVELENGTHS];
    atmos__planet_radiance_clouds(a, s->eye, d, sun, L, NULL);
    for (int k = 0; k < s->n; k++) out[(size_t)k * count + i] += wt * (float)L[k];
}

/* The air of a segment of a limb's ray through the cloud spheres (atmos__clouds_air): one
 * march for its light and transmittance together, as the table's nodes take them, with the
 * ray's own phase functions (pr, pm) and the steps of the table's slices (between crossings)
 * or of its nodes (the segments into and out of the layer). */
typedef struct {
    const atmos_atmosphere *a;
    const double *sun;
    double pr[ATMOS_MAX_WAVELENGTHS], pm[ATMOS_MAX_WAVELENGTHS];
} limb_air;

static void limb_segment(const void *ctx, const double x[3], const double d[3], double len, int between, double *S,
                         double *T)
{
    const limb_air *l = ctx;
    const atmos__planet *pl = l->a->planet;
    const int n = l->a->wl.count;
    double t0, t1;
    if (!atmos__planet_clip(pl, x, d, len, &t0, &t1)) {
        for (int k = 0; k < n; k++) S[k] = 0.0, T[k] = 1.0;
        return;
    }
    const double q[3] = {x[0], x[1] + pl->r_ground, x[2]};
    atmos__sph_sums u;
    atmos__sph_march(pl, l->a->model, q, d, t0, t1, l->sun, between ? STEPS_LIMB : ATMOS__SPH_STEPS_SPACE, 1, n,
                     NULL, &u);
    for (int k = 0; k < n; k++) S[k] = (l->pr[k] * u.sr[k] + l->pm[k] * u.sm[k] + u.ms[k]) * l->a->sun_e[k], T[k] = u.t[k];
}

/* A ray of the limb through the cloud spheres: the one-ray path's crossings with the air's
 * segments marched as above. */
static void cloud_limb(const atmos__sph_space *s, const atmos_atmosphere *a, const double sun[3], const double d[3],
                       float wt, int count, int i, float *out)
{
    limb_air l = {a, sun, {0}, {0}};
    const double nu = atmos__dot3(d, sun);
    for (int k = 0; k < s->n; k++)
        l.pr[k] = atmos__planet_rayleigh_phase(a->planet, k, nu), l.pm[k] = atmos__planet_mie_phase(a->planet, k, nu);
    const atmos__clouds_air air = {limb_segment, &l};
    double L[ATMOS_MAX_WAVELENGTHS];
    atmos__planet_radiance_clouds_air(a, s->eye, d, sun, &air, L);
    for (int k = 0; k < s->n; k++) out[(size_t)k * count + i] += wt * (float)L[k];
}

/* A ray of the disk through the cloud spheres: the air's light and transmittance to each
 * stop from its exponentiated look-up v, composited with the clouds' light. */
static void cloud_disk(const atmos__sph_space *s, const atmos_atmosphere *a, const double sun[3], const double d[3],
                       const float *v, const float *pr, const float *pm, float wt, int count, int i, float *out)
{
    const int n = s->n;
    double Lc[ATMOS_MAX_WAVELENGTHS], Tc[ATMOS_MAX_WAVELENGTHS], L[ATMOS_MAX_WAVELENGTHS];
    for (int j = 0; j < s->ns; j++)
        for (int k = 0; k < n; k++) {
            const float *u = v + ((size_t)j * n + k) * NC;
            Lc[j * n + k] = pr[k] * u[0] + pm[k] * u[1] + u[2], Tc[j * n + k] = u[3];
        }
    const atmos__sunlight_table e = {s->ec, NCS};
    if (!atmos__clouds_radiance_stops(a, s->eye, d, sun, Lc, Tc, s->gs, &e, L)) {
        cloud_ray(s, a, sun, d, wt, count, i, out);
        return;
    }
    for (int k = 0; k < n; k++) out[(size_t)k * count + i] += wt * (float)L[k];
}

/* Rays i0 .. i0 + m - 1 (m <= BLK): which of them meet the air, then their places in the
 * table (a loop of its own, so that the rays' chains of divisions and square roots overlap),
 * the look-ups and their ground, the exponentials in one loop (which vectorises), then the
 * phase functions. With cloud spheres the disk's rays composite the clouds on the table's
 * stops (cloud_disk) and the limb's rays through the cloud layer are answered alone, their
 * air marched piece by piece (cloud_limb). */
#define BLK 16
static void space_block(const atmos__sph_space *s, const atmos_atmosphere *a, const double sun[3], int i0, int m,
                       int count, const float *dx, const float *dy, const float *dz, const float *weight, float *out)
{
    const int n = s->n, S = NC * s->ns * n, last = NC * (s->ns - 1) * n, clouds = s->ns > 1;
    const float kr = 3.0f / (16.0f * 3.14159265359f);
    float lv[BLK * NC * ATMOS_MAX_WAVELENGTHS], G[BLK * ATMOS_MAX_WAVELENGTHS], nu2[BLK], ap[BLK];
    double dd[BLK][3], bb[BLK], pp[BLK];
    node_at nd[BLK];
    int ip[BLK], idx[BLK], lin[BLK], h = 0;
    for (int i = i0; i < i0 + m; i++) {
        if (weight[i] == 0.0f) continue;
        double d[3] = {dx[i], dy[i], dz[i]};
        const double l = sqrt(atmos__dot3(d, d));
        for (int c = 0; c < 3; c++) d[c] /= l;
        const double b = atmos__dot3(s->q, d), p2 = s->qq - b * b;
        if (b >= 0 || p2 >= s->Rt * s->Rt) continue; /* misses the air */
        if (clouds && p2 >= s->R * s->R && p2 < s->rc2) {
            cloud_limb(s, a, sun, d, weight[i], count, i, out);
            continue;
        }
        idx[h] = i, bb[h] = b, pp[h] = p2;
        memcpy(dd[h], d, sizeof d);
        h++;
    }
    for (int r = 0; r < h; r++) {
        ray_node(s, dd[r], pp[r], &nd[r]);
        const float nu = (float)atmos__dot3(dd[r], sun);
        const float fp = sqrtf(fmaxf(0.0f, 0.5f * (1.0f - nu))) * (NPH - 1);
        ip[r] = (int)fp < NPH - 2 ? (int)fp : NPH - 2;
        ap[r] = fp - ip[r], nu2[r] = nu * nu;
    }
    for (int r = 0; r < h; r++) {
        const unsigned char *sm = s->smooth;
        const node_at *c = &nd[r];
        lin[r] = clouds && c->disk && sm[c->row * NA + c->ix0] && sm[c->row * NA + c->ix0 + 1] &&
                 sm[(c->row + 1) * NA + c->ix1] && sm[(c->row + 1) * NA + c->ix1 + 1];
        node_logs(s, lin[r] ? s->lin : s->tab, c, lv + r * S);
        if (c->disk && !clouds) ground(s, a, sun, dd[r], bb[r], G + r * n);
    }
    if (!clouds) atmos__expf_fast_array(lv, h * S); /* the logarithms' exponentials in one loop */
    else
        for (int r = 0; r < h; r++) /* those of the whole ray's stop alone where only it is read */
            if (!lin[r]) atmos__expf_fast_array(lv + r * S + (nd[r].disk ? 0 : last), nd[r].disk ? S : NC * n);
    for (int r = 0; r < h; r++) {
        float pr[ATMOS_MAX_WAVELENGTHS], pm[ATMOS_MAX_WAVELENGTHS];
        for (int k = 0; k < n; k++) {
            const float *mp = s->mie + k * NPH + ip[r];
            pm[k] = mp[0] + ap[r] * (mp[1] - mp[0]), pr[k] = kr * (s->ra[k] + s->rb[k] * nu2[r]);
        }
        const int i = idx[r];
        if (clouds && nd[r].disk) {
            cloud_disk(s, a, sun, dd[r], lv + r * S, pr, pm, weight[i], count, i, out);
            continue;
        }
        for (int k = 0; k < n; k++) {
            const float *v = lv + r * S + last + NC * k;
            const float L = pr[k] * v[0] + pm[k] * v[1] + v[2] + (nd[r].disk ? v[3] * G[r * n + k] : 0.0f);
            out[(size_t)k * count + i] += weight[i] * L;
        }
    }
}

void atmos__sph_space_eval(const atmos__sph_space *s, const atmos_atmosphere *a, const double sun[3], int count,
                           const float *dx, const float *dy, const float *dz, const float *weight, float *out)
{
    for (int i0 = 0; i0 < count; i0 += BLK)
        space_block(s, a, sun, i0, count - i0 < BLK ? count - i0 : BLK, count, dx, dy, dz, weight, out);
}
