/* The production sky's per-eye table (spherical.h): Hillaire's sky-view look-up table, the
 * sky renderer's inner loop. For an eye inside the air, batch_init marches a grid of view
 * directions (the one-ray path's march with ATMOS__SPH_STEPS_SKYVIEW steps, so the table
 * equals it at its nodes) and keeps, per wavelength, the logarithms of the Rayleigh and Mie
 * single scattering without their phase functions and of the rest (higher orders, the lit
 * ground seen through the air); batch_eval interpolates the logarithms (the light's
 * exponential fall-offs toward the twilight and the horizon stay smooth), exponentiates and
 * applies the phase functions of the ray's scattering angle, so the sun's aureole is as
 * sharp as the phase table, not the grid.
 *
 * Grid: the view zenith's cosine mu on each side of the horizon mu_h = -sqrt(1 - (R/r)^2)
 * apart (the ground's edge is never blurred), in v = sqrt(x), x = |mu - mu_h| / (1 -+ mu_h):
 * rows crowd at the horizon; the azimuth from the sun's vertical plane over [0, pi] (the
 * sky of a uniform ground is symmetric about it). An eye above the top of the air (where
 * this grid would waste itself on empty space) gets its own table (spherical_space.c).
 *
 * Over a uniform ground (no maps, no cloud spheres) the table depends on the eye's altitude h
 * and the sun's zenith cosine mu_s there alone: it is built for their quantised values (h on
 * h_q = HS (exp(k DH) - 1): steps of 1 m near the ground, 11 m at 100 km; mu_s in steps of
 * 1e-5) and kept while the eye and the sun stay in the same quantum (batch_keep), so an eye
 * flying level reuses it, and a frame's image is the same whatever frames came before it.
 * The horizon's row follows the true altitude. */
#include "atmosphere/spherical.h"

#include "atmosphere/planet_clouds.h"
#include "core/fastmath.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NV ATMOS__SPH_SV_ROWS
#define NA ATMOS__SPH_SV_AZ
#define NPH 1024 /* the Mie phase over x = sqrt((1 - nu) / 2) = sin(theta / 2) */
#define PLANE (2 * NV * NA)
#define TINY 1e-30 /* the values are kept as logarithms, at least log(TINY) */
#define KEEP_HS 10000.0 /* the altitude's quantum: HS DH near the ground (m) */
#define KEEP_DH 1e-4
#define KEEP_DMU 1e-5 /* the sun's zenith cosine's quantum */
/* The look-up's helpers (ATMOS_CLONE_HELPER) are inlined into each clone of eval_table. */

typedef struct sv_state {
    int march, n;
    int keyed;    /* built for the quantised altitude and sun (key) */
    long key[2];
    atmos__sph_space *space; /* the eye above the air; NULL (march per ray) if out of memory */
    atmos__clouds_sun *gs;   /* with cloud spheres from above the air: their attenuation
                                textures for the sun, made on the second frame with the same
                                sun and kept while it stays (NULL: G at each crossing) */
    double up[3], e1[3], e2[3];
    float fup[3], fe1[3], fe2[3], fsun[3];
    float muh;
    float *tab;  /* [2 NV][NA][n][3]: channel 0 Rayleigh, 1 Mie (no phase), 2 the rest; rows
                    0..NV-1 above the horizon, NV..2NV-1 below, row 0 / NV at the horizon;
                    a node's 3n values together, for the look-up's four corners */
    float *mie;  /* [n][NPH] */
} sv_state;

static double node_mu(double muh, int row)
{
    const int lower = row >= NV;
    const double v = (double)(lower ? row - NV : row) / (NV - 1);
    const double x = fmax(v * v, 1e-7);
    return lower ? muh - x * (1.0 + muh) : muh + x * (1.0 - muh);
}

static void node_dir(const sv_state *s, int row, int col, double d[3])
{
    const double mu = node_mu(s->muh, row), sn = sqrt(fmax(0.0, 1.0 - mu * mu));
    const double phi = ATMOS_PI * col / (NA - 1), c = cos(phi), si = sin(phi);
    for (int i = 0; i < 3; i++) d[i] = mu * s->up[i] + sn * (c * s->e1[i] + si * s->e2[i]);
}

static void frame(sv_state *s, const atmos__planet *pl, const double eye[3], const double sun[3])
{
    const double q[3] = {eye[0], eye[1] + pl->r_ground, eye[2]};
    atmos__planet_sun_frame(q, sun, s->up, s->e1, s->e2);
    const double r = sqrt(atmos__dot3(q, q));
    for (int i = 0; i < 3; i++) {
        s->fup[i] = (float)s->up[i], s->fe1[i] = (float)s->e1[i], s->fe2[i] = (float)s->e2[i];
        s->fsun[i] = (float)sun[i];
    }
    const double rr = pl->r_ground / fmax(r, pl->r_ground);
    s->muh = (float)-sqrt(fmax(0.0, 1.0 - rr * rr));
}

static void fill_node(const atmos_atmosphere *a, sv_state *s, const double eye[3], const double sun[3], int row,
                      int col)
{
    const atmos__planet *pl = a->planet;
    const int n = s->n;
    double d[3];
    node_dir(s, row, col, d);
    const double K = atmos__planet_ground_distance(pl, eye, d);
    const double q[3] = {eye[0], eye[1] + pl->r_ground, eye[2]};
    double t0, t1, G[ATMOS_MAX_WAVELENGTHS] = {0};
    atmos__sph_sums sm;
    if (atmos__planet_clip(pl, eye, d, K, &t0, &t1))
        atmos__sph_march(pl, a->model, q, d, t0, t1, sun, ATMOS__SPH_STEPS_SKYVIEW, 1, n, NULL, &sm);
    else {
        memset(&sm, 0, sizeof sm);
        for (int k = 0; k < n; k++) sm.t[k] = 1.0;
    }
    if (K < INFINITY) {
        const double g[3] = {q[0] + K * d[0], q[1] + K * d[1], q[2] + K * d[2]};
        atmos__sph_ground(pl, a->model, g, sun, a->sun_e, n, NULL, G);
    }
    float *t = s->tab + ((size_t)row * NA + col) * 3 * n;
    for (int k = 0; k < n; k++) {
        t[3 * k] = (float)log(fmax(sm.sr[k] * a->sun_e[k], TINY));
        t[3 * k + 1] = (float)log(fmax(sm.sm[k] * a->sun_e[k], TINY));
        t[3 * k + 2] = (float)log(fmax(sm.ms[k] * a->sun_e[k] + sm.t[k] * G[k], TINY));
    }
}

/* The quantised altitude and sun's zenith cosine of an eye (key) and an eye and a sun with
 * those values (eye_q, sun_q); 0 when the table depends on more (the ground's maps, cloud
 * spheres) or the quantised eye would leave the air. */
static int sv_key(const atmos__planet *pl, const double eye[3], const double sun[3], long key[2], double eye_q[3],
                  double sun_q[3])
{
    const double q[3] = {eye[0], eye[1] + pl->r_ground, eye[2]};
    const double r = sqrt(atmos__dot3(q, q));
    if (pl->surface || pl->clouds || !(r > 0)) return 0;
    const double mu = atmos__clampd(atmos__dot3(q, sun) / r, -1.0, 1.0);
    key[0] = lround(log1p(fmax(r - pl->r_ground, 0.0) / KEEP_HS) / KEEP_DH);
    key[1] = lround(mu / KEEP_DMU);
    const double hq = KEEP_HS * expm1((double)key[0] * KEEP_DH);
    const double mq = atmos__clampd((double)key[1] * KEEP_DMU, -1.0, 1.0);
    if (hq >= pl->r_top - pl->r_ground) return 0;
    eye_q[0] = 0.0, eye_q[1] = hq, eye_q[2] = 0.0;
    sun_q[0] = sqrt(fmax(0.0, 1.0 - mq * mq)), sun_q[1] = mq, sun_q[2] = 0.0;
    return 1;
}

int atmos__sph_batch_keep(atmos__atm_batch *b, const double eye[3], const double sun[3])
{
    sv_state *s = b->state;
    long key[2];
    double eq[3], sq[3];
    if (s && s->space) { /* above the air */
        const atmos__planet *pl = b->atm->planet;
        /* with cloud spheres, the second frame in a row with the same sun (the eye moved)
         * makes their attenuation textures, the later ones keep them; a single frame, drawn
         * in one call or in parts, does without */
        const int same = sun[0] == b->sun[0] && sun[1] == b->sun[1] && sun[2] == b->sun[2];
        const int moved = eye[0] != b->eye[0] || eye[1] != b->eye[1] || eye[2] != b->eye[2];
        if (pl->clouds && !same) return 0;
        if (pl->clouds && moved && !s->gs) s->gs = atmos__clouds_sun_create(pl, sun);
        if (atmos__sph_space_keep(s->space, pl, eye, sun, s->gs)) return 1;
        if (!pl->clouds || atmos__planet_altitude(pl, eye) < pl->r_top - pl->r_ground) return 0;
        atmos__sph_space_destroy(s->space); /* the eye's table again, the sun's textures kept */
        s->space = atmos__sph_space_create(b->atm, eye, sun, s->gs);
        return 1;
    }
    if (!s || !s->tab || !s->keyed || !sv_key(b->atm->planet, eye, sun, key, eq, sq)) return 0;
    if (key[0] != s->key[0] || key[1] != s->key[1]) return 0;
    frame(s, b->atm->planet, eye, sun);
    return 1;
}

void atmos__sph_batch_init(atmos__atm_batch *b)
{
    const atmos_atmosphere *a = b->atm;
    const atmos__planet *pl = a->planet;
    sv_state *s = calloc(1, sizeof *s);
    if (!s) return; /* batch_eval falls back on the march */
    s->n = a->wl.count;
    s->march = atmos__planet_altitude(pl, b->eye) >= pl->r_top - pl->r_ground;
    b->state = s;
    if (s->march) { /* the eye above the air, with or without cloud spheres */
        s->space = atmos__sph_space_create(a, b->eye, b->sun, NULL);
        return;
    }
    if (pl->clouds) return; /* rays through cloud spheres from inside the air: one by one */
    double eye[3], sun[3];
    s->keyed = sv_key(pl, b->eye, b->sun, s->key, eye, sun);
    if (!s->keyed) memcpy(eye, b->eye, sizeof eye), memcpy(sun, b->sun, sizeof sun);
    frame(s, pl, eye, sun);
    s->tab = malloc(sizeof(float) * ((size_t)s->n * 3 * PLANE + (size_t)s->n * NPH));
    if (!s->tab) {
        s->march = 1;
        return;
    }
    s->mie = s->tab + (size_t)s->n * 3 * PLANE;
    atmos__planet_mie_phase_table(pl, s->n, NPH, s->mie);
#pragma omp parallel for schedule(dynamic) num_threads(b->threads > 0 ? b->threads : 1)
    for (int e = 0; e < 2 * NV * NA; e++) fill_node(a, s, eye, sun, e / NA, e % NA);
    frame(s, pl, b->eye, b->sun);
}

void atmos__sph_batch_release(atmos__atm_batch *b)
{
    sv_state *s = b->state;
    if (s) {
        free(s->tab);
        atmos__sph_space_destroy(s->space);
        atmos__clouds_sun_destroy(s->gs);
    }
    free(s);
    b->state = NULL;
}

/* The azimuth in [0, pi] of (x, y) with y >= 0. */
ATMOS_CLONE_HELPER float azimuth(float x, float y)
{
    const float ax = fabsf(x);
    const int swap = y > ax;
    const float num = swap ? ax : y, den = swap ? y : ax;
    float a = den > 0 ? atmos__atan_unitf(num / den) : 0.0f;
    a = swap ? 1.57079632679f - a : a;
    return x < 0 ? 3.14159265359f - a : a;
}

/* Ray by ray, each ray's radiance by the march of the production model's solver, or through
 * the cloud spheres when clouds is set. */
static void eval_rays(const atmos__atm_batch *b, int count, const float *dx, const float *dy, const float *dz,
                      const float *weight, float *out, int clouds)
{
    const int n = b->atm->wl.count;
    for (int i = 0; i < count; i++) {
        if (weight[i] == 0.0f) continue;
        double d[3] = {dx[i], dy[i], dz[i]}, L[ATMOS_MAX_WAVELENGTHS];
        const double l = sqrt(atmos__dot3(d, d));
        for (int c = 0; c < 3; c++) d[c] /= l;
        if (clouds)
            atmos__planet_radiance_clouds(b->atm, b->eye, d, b->sun, L, NULL);
        else
            atmos__sph_radiance(b->atm, b->eye, d, b->sun, ATMOS__SPH_STEPS, L, NULL);
        for (int k = 0; k < n; k++) out[(size_t)k * count + i] += weight[i] * (float)L[k];
    }
}

/* Rays i0 .. i0 + m - 1 (m <= BLK) in four loops: the table coordinates and the phase
 * table's of every ray (vectorises), the look-ups of the table's logarithms, their
 * exponentials (vectorises), the phase functions applied. */
#define BLK 16
ATMOS_CLONE_HELPER void eval_block(const sv_state *s, const float *ra, const float *rb, int i0, int m, int count,
                                   const float *dx, const float *dy, const float *dz, const float *weight, float *out)
{
    const int n = s->n, S = 3 * n;
    const float muh = s->muh, kr = 3.0f / (16.0f * 3.14159265359f);
    float lv[BLK * 3 * ATMOS_MAX_WAVELENGTHS], fy[BLK], fx[BLK], fp[BLK], nu2[BLK];
    int low[BLK];
    for (int p = 0; p < BLK; p++) {
        const int i = i0 + (p < m ? p : 0);
        const float x = dx[i], y = dy[i], z = dz[i];
        const float mu = x * s->fup[0] + y * s->fup[1] + z * s->fup[2];
        const float h1 = x * s->fe1[0] + y * s->fe1[1] + z * s->fe1[2];
        const float h2 = fabsf(x * s->fe2[0] + y * s->fe2[1] + z * s->fe2[2]);
        const float nu = x * s->fsun[0] + y * s->fsun[1] + z * s->fsun[2];
        low[p] = mu < muh;
        float xv = low[p] ? (muh - mu) / (1.0f + muh) : (mu - muh) / (1.0f - muh);
        xv = xv < 0 ? 0 : (xv > 1 ? 1 : xv);
        fy[p] = sqrtf(xv) * (NV - 1), fx[p] = azimuth(h1, h2) * ((NA - 1) / 3.14159265359f);
        const float c = 0.5f * (1.0f - nu);
        fp[p] = sqrtf(c > 0 ? c : 0) * (NPH - 1), nu2[p] = nu * nu;
    }
    for (int p = 0; p < m; p++) {
        int iy = (int)fy[p], ix = (int)fx[p];
        iy = iy > NV - 2 ? NV - 2 : iy;
        ix = ix > NA - 2 ? NA - 2 : ix;
        const float ay = fy[p] - iy, ax = fx[p] - ix;
        const float *t00 = s->tab + ((size_t)(iy + (low[p] ? NV : 0)) * NA + ix) * S;
        const float *t01 = t00 + S, *t10 = t00 + (size_t)NA * S, *t11 = t10 + S;
        const float w00 = (1 - ay) * (1 - ax), w01 = (1 - ay) * ax, w10 = ay * (1 - ax), w11 = ay * ax;
        float *l = lv + p * S;
        for (int j = 0; j < S; j++) l[j] = w00 * t00[j] + w01 * t01[j] + w10 * t10[j] + w11 * t11[j];
    }
    for (int j = 0; j < m * S; j++) lv[j] = atmos__expf_fast(lv[j]);
    for (int p = 0; p < m; p++) {
        const float *v = lv + p * S;
        int ip = (int)fp[p];
        ip = ip > NPH - 2 ? NPH - 2 : ip;
        const float ap = fp[p] - ip;
        for (int k = 0; k < n; k++) {
            const float *mp = s->mie + k * NPH + ip;
            const float pm = mp[0] + ap * (mp[1] - mp[0]);
            const float L = kr * (ra[k] + rb[k] * nu2[p]) * v[3 * k] + pm * v[3 * k + 1] + v[3 * k + 2];
            out[(size_t)k * count + i0 + p] += weight[i0 + p] * L;
        }
    }
}

/* The table's rays, block by block; built for AVX2 as well as the baseline (the loader picks
 * the best at run time; without FMA both give the same bits). */
ATMOS_CLONES
static void eval_table(const sv_state *s, const float *ra, const float *rb, int count, const float *dx,
                       const float *dy, const float *dz, const float *weight, float *out)
{
    for (int i0 = 0; i0 < count; i0 += BLK)
        eval_block(s, ra, rb, i0, count - i0 < BLK ? count - i0 : BLK, count, dx, dy, dz, weight, out);
}

void atmos__sph_batch_eval(const atmos__atm_batch *b, int count, const float *dx, const float *dy, const float *dz,
                           const float *weight, float *out, float *scratch)
{
    (void)scratch;
    const sv_state *s = b->state;
    if (s && s->space) {
        atmos__sph_space_eval(s->space, b->atm, b->sun, count, dx, dy, dz, weight, out);
        return;
    }
    if (b->atm->planet->clouds) { /* without the table: ray by ray through the cloud spheres */
        eval_rays(b, count, dx, dy, dz, weight, out, 1);
        return;
    }
    if (!s || s->march) {
        eval_rays(b, count, dx, dy, dz, weight, out, 0);
        return;
    }
    /* the air's depolarized Rayleigh phase function (planet.h): kr (ra + rb nu^2) */
    float ra[ATMOS_MAX_WAVELENGTHS], rb[ATMOS_MAX_WAVELENGTHS];
    for (int k = 0; k < s->n; k++) atmos__planet_rayleigh_ab(b->atm->planet, k, &ra[k], &rb[k]);
    eval_table(s, ra, rb, count, dx, dy, dz, weight, out);
}
