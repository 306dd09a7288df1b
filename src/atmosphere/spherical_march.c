/* The production sky's ray march (spherical.h): single scattering with the sunlight's
 * transmittance from the tau table, the higher orders from J_ms (or Psi_ms), the view transmittance
 * accumulated step by step; the lit ground; the radiance of a view ray.
 *
 * Steps: each segment is split at its lowest point (closest to the planet's centre) into
 * monotone pieces; on each, t = t_low +- L s^2 with s at the midpoints of `steps` equal
 * parts of [0, 1], so that samples crowd where the air is densest (a horizontal ray from
 * the ground climbs only h ~ t^2 / 2R). Each sample stands for its step with the source
 * constant over it and the step's own attenuation integrated exactly (Hillaire 2020 §5.3's
 * energy-conserving form), so optically thick steps (grazing blue rays) lose nothing. The
 * higher orders' source (J_ms, Psi_ms) is read once per pair of steps, at the pair's middle:
 * it changes over the table's cells, far more slowly than the steps (halving its look-ups
 * moved the sky by < 0.07 %). */
#include "atmosphere/spherical.h"

#include "core/vec.h"

#include <math.h>
#include <string.h>

/* The higher orders' source at q + t d (the march reads it once per pair of steps, at the
 * pair's middle: it varies over J_ms's cells, far slower than the steps): J_ms's two parts
 * (mode 2) or Psi_ms in jr (mode 1, while J is being built). */
static void ms_source(const atmos__sph_model *m, const double q[3], const double d[3], double t, const double sun[3],
                      const atmos__sph_jg *jg, int mode, int cnt, const int *k, double *jr, double *jm)
{
    const double x[3] = {q[0] + t * d[0], q[1] + t * d[1], q[2] + t * d[2]};
    const double r = sqrt(atmos__dot3(x, x)), mus = atmos__dot3(x, sun) / r;
    if (mode == 2) atmos__sph_j(m, r, atmos__dot3(x, d) / r, mus, jg, cnt, k, jr, jm);
    else atmos__sph_psi(m, r, mus, cnt, k, jr);
}

static void sample_point(const atmos__planet *pl, const atmos__sph_model *m, const double q[3], const double d[3],
                         double t, double w, const double sun[3], int mode, const double *jr, const double *jm,
                         int cnt, const int *k, double *tr, atmos__sph_sums *s)
{
    const double x[3] = {q[0] + t * d[0], q[1] + t * d[1], q[2] + t * d[2]};
    const double r = sqrt(atmos__dot3(x, x)), h = r - pl->r_ground;
    if (h > pl->r_top - pl->r_ground) return;
    const double mus = atmos__dot3(x, sun) / r;
    const double rr = atmos__planet_rho_rayleigh(pl, h), rm = atmos__planet_rho_mie(pl, h);
    const double ro = atmos__planet_rho_ozone(pl, h);
    double ts[ATMOS_MAX_WAVELENGTHS];
    atmos__sph_sun_t(m, r, mus, cnt, k, ts);
    for (int i = 0; i < cnt; i++) {
        const int kk = ATMOS__WL(k, i);
        const double sr = pl->rayleigh[kk] * rr, sm = pl->mie_sca[kk] * rm;
        const double st = (pl->rayleigh[kk] * rr + pl->mie_ext[kk] * rm + pl->ozone[kk] * ro) * w;
        /* the step's own attenuation integrated exactly: int_0^w e^{-sigma_t t} dt */
        const double es = exp(-st), Tw = tr[i] * (st > 1e-7 ? (1.0 - es) / st : 1.0 - 0.5 * st) * w;
        s->sr[i] += sr * Tw * ts[i];
        s->sm[i] += sm * Tw * ts[i];
        s->f[i] += (sr + sm) * Tw;
        if (mode == 2) s->ms[i] += (sr * jr[i] + sm * jm[i]) * Tw;
        else if (mode == 1) s->ms[i] += (sr + sm) * Tw * jr[i];
        tr[i] *= es;
    }
}

/* What the march reads the higher orders from: 0 none, 1 Psi_ms, 2 J_ms (with the ray's
 * angle to the sun in jg). */
static int ms_mode(const atmos__sph_model *m, const double d[3], const double sun[3], int use_ms, atmos__sph_jg *jg)
{
    *jg = (atmos__sph_jg){0, 0.0, 1.0, 0.0};
    if (!use_ms) return 0;
    if (!m->use_j) return 1;
    atmos__sph_j_gamma(atmos__dot3(d, sun), jg);
    return 2;
}

/* One monotone piece of `steps` steps at t = tc + sg L u^2, u = v or 1 - v (down: toward
 * the lowest point), v at the steps' midpoints; the source of the higher orders once per
 * pair of steps, at the pair's middle. */
static void march_piece(const atmos__planet *pl, const atmos__sph_model *m, const double q[3], const double d[3],
                        double tc, double L, int down, int steps, const double sun[3], const atmos__sph_jg *jg,
                        int mode, int cnt, const int *k, double *tr, atmos__sph_sums *s)
{
    const double sg = down ? -1.0 : 1.0;
    double jr[ATMOS_MAX_WAVELENGTHS], jm[ATMOS_MAX_WAVELENGTHS];
    for (int j = 0; j < steps; j += 2) {
        const int last = j + 1 < steps ? j + 1 : j;
        if (mode) {
            const double v = (j + last + 1) * 0.5 / steps, u = down ? 1.0 - v : v;
            ms_source(m, q, d, tc + sg * L * u * u, sun, jg, mode, cnt, k, jr, jm);
        }
        for (int i = j; i <= last; i++) {
            const double v = (i + 0.5) / steps, u = down ? 1.0 - v : v;
            sample_point(pl, m, q, d, tc + sg * L * u * u, 2.0 * L * u / steps, sun, mode, jr, jm, cnt, k, tr, s);
        }
    }
}

void atmos__sph_march(const atmos__planet *pl, const atmos__sph_model *m, const double q[3], const double d[3],
                      double t0, double t1, const double sun[3], int steps, int use_ms, int cnt, const int *k,
                      atmos__sph_sums *s)
{
    double tr[ATMOS_MAX_WAVELENGTHS];
    memset(s, 0, sizeof *s);
    for (int i = 0; i < cnt; i++) tr[i] = 1.0;
    if (t1 > t0) {
        atmos__sph_jg jg;
        const int mode = ms_mode(m, d, sun, use_ms, &jg);
        double tc = -atmos__dot3(q, d);
        tc = tc < t0 ? t0 : (tc > t1 ? t1 : tc);
        const double la = tc - t0, lb = t1 - tc;
        if (la > 0) march_piece(pl, m, q, d, tc, la, 1, steps, sun, &jg, mode, cnt, k, tr, s);
        if (lb > 0) march_piece(pl, m, q, d, tc, lb, 0, steps, sun, &jg, mode, cnt, k, tr, s);
    }
    for (int i = 0; i < cnt; i++) s->t[i] = tr[i];
}

void atmos__sph_ground_irradiance(const atmos__planet *pl, const atmos__sph_model *m, double cs, int cnt,
                                  const int *k, double *out)
{
    double ts[ATMOS_MAX_WAVELENGTHS];
    atmos__sph_sun_t(m, pl->r_ground, cs, cnt, k, ts);
    atmos__sph_esky(m, cs, cnt, k, out);
    for (int i = 0; i < cnt; i++) out[i] += cs > 0 ? cs * ts[i] : 0.0;
}

void atmos__sph_ground(const atmos__planet *pl, const atmos__sph_model *m, const double g[3], const double sun[3],
                       const double *sun_e, int cnt, const int *k, double *out)
{
    const double r = sqrt(atmos__dot3(g, g));
    const double n[3] = {g[0] / r, g[1] / r, g[2] / r};
    const double gw[3] = {n[0] * pl->r_ground, n[1] * pl->r_ground - pl->r_ground, n[2] * pl->r_ground};
    double e[ATMOS_MAX_WAVELENGTHS];
    atmos__sph_ground_irradiance(pl, m, atmos__dot3(n, sun), cnt, k, e);
    for (int i = 0; i < cnt; i++) {
        const int kk = ATMOS__WL(k, i);
        out[i] = atmos__planet_ground_albedo(pl, gw, kk) / ATMOS_PI * e[i] * sun_e[kk] +
                 atmos__planet_ground_lights(pl, gw, sun, kk);
    }
}

void atmos__sph_radiance(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                         int steps, double *out, atmos_atmosphere_hit *info)
{
    const atmos__planet *pl = a->planet;
    const atmos__sph_model *m = a->model;
    const int n = a->wl.count;
    const double K = atmos__planet_ground_distance(pl, p, d);
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    double t0, t1;
    atmos__sph_sums s;
    if (atmos__planet_clip(pl, p, d, K, &t0, &t1)) {
        atmos__sph_march(pl, m, q, d, t0, t1, sun, steps, 1, n, NULL, &s);
        const double nu = atmos__dot3(d, sun);
        for (int i = 0; i < n; i++)
            out[i] = (atmos__planet_rayleigh_phase(pl, i, nu) * s.sr[i] + atmos__planet_mie_phase(pl, i, nu) * s.sm[i] + s.ms[i]) * a->sun_e[i];
    } else {
        for (int i = 0; i < n; i++) out[i] = 0.0, s.t[i] = 1.0;
    }
    if (K < INFINITY) {
        const double g[3] = {q[0] + K * d[0], q[1] + K * d[1], q[2] + K * d[2]};
        double G[ATMOS_MAX_WAVELENGTHS];
        atmos__sph_ground(pl, m, g, sun, a->sun_e, n, NULL, G);
        for (int i = 0; i < n; i++) out[i] += s.t[i] * G[i];
    }
    if (info) {
        info->distance_m = K;
        info->hits_ground = K < INFINITY;
        info->in_sun_disk = 0;
    }
}

/* The cumulative march's steps: at most this change of height per step (the aerosols' scale
 * height is 1200 m). */
#define SPH_CUMULATIVE_CLIMB_M 150.0

void atmos__sph_march_cumulative(const atmos__planet *pl, const atmos__sph_model *m, const double q[3],
                                 const double d[3], double t0, double t1, int nd, const double *tj,
                                 const double sun[3], int steps, int use_ms, int cnt, const int *k, double *out)
{
    double tr[ATMOS_MAX_WAVELENGTHS];
    atmos__sph_sums s;
    memset(&s, 0, sizeof s);
    for (int i = 0; i < cnt; i++) tr[i] = 1.0;
    atmos__sph_jg jg;
    const int mode = ms_mode(m, d, sun, use_ms, &jg);
    double jr[ATMOS_MAX_WAVELENGTHS], jm[ATMOS_MAX_WAVELENGTHS];
    double a = t0;
    const double tc = -atmos__dot3(q, d); /* the ray's lowest point */
    for (int j = 0; j < nd; j++) {
        const double b = tj[j] < t1 ? tj[j] : t1;
        if (b > a) { /* the slice's part in the air, in equal steps at their midpoints */
            double ra = 0, rb = 0, rc = 0;
            for (int c = 0; c < 3; c++) {
                const double xa = q[c] + a * d[c], xb = q[c] + b * d[c], xc = q[c] + tc * d[c];
                ra += xa * xa, rb += xb * xb, rc += xc * xc;
            }
            ra = sqrt(ra), rb = sqrt(rb), rc = tc > a && tc < b ? sqrt(rc) : fmin(ra, rb);
            const double climb = fmax(ra, rb) - rc; /* the most the height changes over the slice */
            const int n = steps > (int)ceil(climb / SPH_CUMULATIVE_CLIMB_M) ? steps : (int)ceil(climb / SPH_CUMULATIVE_CLIMB_M);
            const double w = (b - a) / n;
            for (int st = 0; st < n; st++) { /* the higher orders' source once per pair of steps */
                if (mode && st % 2 == 0) ms_source(m, q, d, a + (st + (st + 1 < n ? 1.0 : 0.5)) * w, sun, &jg, mode, cnt, k, jr, jm);
                sample_point(pl, m, q, d, a + (st + 0.5) * w, w, sun, mode, jr, jm, cnt, k, tr, &s);
            }
            a = b;
        }
        double *o = out + (size_t)j * cnt * 4;
        for (int i = 0; i < cnt; i++) o[4 * i] = s.sr[i], o[4 * i + 1] = s.sm[i], o[4 * i + 2] = s.ms[i], o[4 * i + 3] = tr[i];
    }
}
