/* Dobashi et al. 2002 Eq. 12 from the tables (dobashi.h): the view ray cut into
 * sub-segments of length dt by the sampling planes (§5.2) when the eye is in the air, or
 * into the pieces between the sample spheres it crosses (§5.3) when the eye is in space;
 * each adds I_sun g_l(h_k, theta_sun,k) [F_r dI_r + F_m dI_m] times the product of the dg_v
 * in front of it, g_l and the tables read at the piece's start. */
#include "atmosphere/dobashi.h"

#include "core/vec.h"

static double horizon_mu(const atmos__planet *pl, double r)
{
    return -sqrt(fmax(r * r - pl->r_ground * pl->r_ground, 0.0)) / r;
}

/* Row coordinate of height h in the tables (h_i = top (i / (NH - 1))^2). */
static double row_coord(const atmos__dobashi *m, double h, int *i0)
{
    const double x = sqrt(fmin(fmax(h, 0.0), m->top) / m->top) * (ATMOS__DOB_NH - 1);
    int i = (int)x;
    if (i > ATMOS__DOB_NH - 2) i = ATMOS__DOB_NH - 2;
    *i0 = i;
    return x - i;
}

/* g_l between rows i and i + 1 (weight fh) at sun cosine mu_s, the horizon's cosine mh. */
static void gl_rows(const atmos__dobashi *m, int i, double fh, double mh, double mu_s, double *out)
{
    const int n = m->n;
    if (mu_s < mh) {
        for (int k = 0; k < n; k++) out[k] = 0.0;
        return;
    }
    const double y = (mu_s - mh) / (1.0 - mh);
    const double x = sqrt(y < 1.0 ? y : 1.0) * (ATMOS__DOB_NS - 1);
    int j = (int)x;
    if (j > ATMOS__DOB_NS - 2) j = ATMOS__DOB_NS - 2;
    const double fs = x - j;
    const float *a = m->gl + ((size_t)i * ATMOS__DOB_NS + j) * n;
    if (fh == 0) {
        for (int k = 0; k < n; k++) out[k] = exp(-((1 - fs) * a[k] + fs * a[n + k]));
        return;
    }
    const float *b = a + (size_t)ATMOS__DOB_NS * n;
    for (int k = 0; k < n; k++)
        out[k] = exp(-((1 - fh) * ((1 - fs) * a[k] + fs * a[n + k]) + fh * ((1 - fs) * b[k] + fs * b[n + k])));
}

/* g_l at height h (clamped to the air) and sun cosine mu_s, all wavelengths. */
static void gl_at(const atmos__dobashi *m, const atmos__planet *pl, double h, double mu_s, double *out)
{
    h = fmin(fmax(h, 0.0), m->top);
    int i;
    const double fh = row_coord(m, h, &i);
    gl_rows(m, i, fh, horizon_mu(pl, pl->r_ground + h), mu_s, out);
}

void atmos__dobashi_gl(const atmos__dobashi *m, const atmos__planet *pl, const double p[3], const double sun[3],
                       int cnt, const int *k, double *out)
{
    double g[ATMOS_MAX_WAVELENGTHS];
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double r = sqrt(atmos__dot3(q, q)), b = atmos__dot3(q, sun);
    if (r <= pl->r_top) {
        gl_at(m, pl, r - pl->r_ground, r > 0 ? b / r : 1.0, g);
    } else {
        /* from space: the sun's ray crosses the air (entering it at the top with the zenith
         * cosine -sqrt(disc) / r_top) or misses it */
        const double disc = b * b - (r * r - pl->r_top * pl->r_top);
        if (b >= 0 || disc <= 0) {
            for (int i = 0; i < m->n; i++) g[i] = 1.0;
        } else {
            gl_at(m, pl, m->top, -sqrt(disc) / pl->r_top, g);
        }
    }
    for (int i = 0; i < cnt; i++) out[i] = g[ATMOS__WL(k, i)];
}

/* The planes' dI_r, dI_m, dg_v at (h, mu), bilinear; out[3 k + 0..2]. */
static void plane_at(const atmos__dobashi *m, double h, double mu, double *out)
{
    const int n3 = 3 * m->n;
    int i;
    const double fh = row_coord(m, h, &i);
    const double y = (mu < 0 ? -1 : 1) * sqrt(fmin(fabs(mu), 1.0));
    const double x = 0.5 * (y + 1.0) * (ATMOS__DOB_NV - 1);
    int j = (int)x;
    if (j > ATMOS__DOB_NV - 2) j = ATMOS__DOB_NV - 2;
    const double fv = x - j;
    const float *a = m->plane + ((size_t)i * ATMOS__DOB_NV + j) * n3, *b = a + (size_t)ATMOS__DOB_NV * n3;
    for (int c = 0; c < n3; c++)
        out[c] = (1 - fh) * ((1 - fv) * a[c] + fv * a[n3 + c]) + fh * ((1 - fv) * b[c] + fv * b[n3 + c]);
}

/* A sphere's dI_r, dI_m, dg_v at mu in one of its ranges (dobashi_tables.c). */
static void sphere_at(const atmos__dobashi *m, int s, int range, double mu, double *out)
{
    const int n3 = 3 * m->n;
    const double mt = m->mu_split[s];
    double x;
    if (range == 0) x = sqrt(fmax(mu, 0.0));
    else if (range == 1) x = mt < 0 ? mu / mt : 0.0;
    else x = sqrt(fmax((mt - mu) / (1.0 + mt), 0.0));
    x = fmin(fmax(x, 0.0), 1.0) * (ATMOS__DOB_NSV - 1);
    int j = (int)x;
    if (j > ATMOS__DOB_NSV - 2) j = ATMOS__DOB_NSV - 2;
    const double f = x - j;
    const float *a = m->sphere + (((size_t)s * 3 + range) * ATMOS__DOB_NSV + j) * n3;
    for (int c = 0; c < n3; c++) out[c] = (1 - f) * a[c] + f * a[n3 + c];
}

/* One piece of Eq. 12: a fraction f (< 1 only for a segment cut short by the caller) of the
 * piece whose table values are v, lit by g_l = g; a cut piece's attenuation is exp(-tau_cut)
 * (its optical depth by quadrature: the table's Delta g_v to the power f would spread the
 * sub-segment's depth evenly, 36 % off for the first 3 km straight up in hazy air). */
static void add_piece(int n, const double *v, const double *g, double f, const double *tau_cut, double *sr,
                      double *sm, double *T)
{
    for (int k = 0; k < n; k++) {
        const double gT = g[k] * T[k] * f;
        sr[k] += gT * v[3 * k];
        sm[k] += gT * v[3 * k + 1];
        T[k] *= tau_cut ? exp(-tau_cut[k]) : v[3 * k + 2];
    }
}

/* §5.2: sub-segments [t_k, t_k + dt] from the eye (or from where the ray enters the air). */
static int march_planes(const atmos__dobashi *m, const atmos__planet *pl, const double p[3], const double d[3],
                        double dist, const double sun[3], double *sr, double *sm, double *T)
{
    double t0, t1, a0, a1;
    if (!atmos__planet_clip(pl, p, d, dist, &t0, &t1) || !isfinite(t1)) return 0; /* (a NaN ray) */
    /* the ray's own end (the ground, the top) is in the tables; a caller's shorter end is
     * taken as the fraction of the last sub-segment */
    const int cut = atmos__planet_clip(pl, p, d, INFINITY, &a0, &a1) && t1 < a1 * (1 - 1e-12);
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double qq = atmos__dot3(q, q), b = atmos__dot3(q, d), qs = atmos__dot3(q, sun), ds = atmos__dot3(d, sun);
    double v[3 * ATMOS_MAX_WAVELENGTHS], g[ATMOS_MAX_WAVELENGTHS];
    int steps = 0;
    for (double t = t0; t < t1; t += m->dt, steps++) {
        const double r = sqrt(fmax(qq + 2.0 * b * t + t * t, 1.0));
        const double f = cut && t + m->dt > t1 ? (t1 - t) / m->dt : 1.0;
        double tau[ATMOS_MAX_WAVELENGTHS];
        if (f < 1) {
            const double x[3] = {p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]};
            atmos__planet_optical_depth(pl, x, d, t1 - t, m->n, NULL, tau);
        }
        plane_at(m, r - pl->r_ground, (b + t) / r, v);
        gl_at(m, pl, r - pl->r_ground, (qs + t * ds) / r, g);
        add_piece(m->n, v, g, f, f < 1 ? tau : NULL, sr, sm, T);
    }
    return steps;
}

/* §5.3: the pieces between the sample spheres the ray crosses, from an eye above them. */
static int march_spheres(const atmos__dobashi *m, const atmos__planet *pl, const double p[3], const double d[3],
                         double dist, const double sun[3], double *sr, double *sm, double *T)
{
    const int S = m->spheres;
    const double q[3] = {p[0], p[1] + pl->r_ground, p[2]};
    const double qq = atmos__dot3(q, q), b = atmos__dot3(q, d), qs = atmos__dot3(q, sun), ds = atmos__dot3(d, sun);
    double te[2 * ATMOS__DOB_SPHERES], mue[2 * ATMOS__DOB_SPHERES];
    int se[2 * ATMOS__DOB_SPHERES], re[2 * ATMOS__DOB_SPHERES], ne = 0, low = -1;
    for (int s = S - 1; s >= 0; s--) { /* down through the spheres */
        const double r = pl->r_ground + m->h_sphere[s], disc = b * b - (qq - r * r);
        if (disc <= 0 || b >= 0) break;
        const double sq = sqrt(disc);
        te[ne] = -b - sq, mue[ne] = -sq / r, se[ne] = s, re[ne] = 2, ne++;
        low = s;
    }
    if (low < 0) return 0;
    re[ne - 1] = 1; /* the lowest sphere crossed: the ray turns back up inside it */
    if (low > 0)
        for (int s = low; s < S; s++) { /* and up again */
            const double r = pl->r_ground + m->h_sphere[s], sq = sqrt(fmax(b * b - (qq - r * r), 0.0));
            te[ne] = -b + sq, mue[ne] = sq / r, se[ne] = s, re[ne] = 0, ne++;
        }
    double v[3 * ATMOS_MAX_WAVELENGTHS], g[ATMOS_MAX_WAVELENGTHS];
    int e = 0;
    for (; e < ne && te[e] < dist; e++) {
        const int s = se[e];
        const double r = pl->r_ground + m->h_sphere[s];
        const double f = e + 1 < ne && te[e + 1] > dist ? (dist - te[e]) / (te[e + 1] - te[e]) : 1.0;
        double tau[ATMOS_MAX_WAVELENGTHS];
        if (f < 1) {
            const double x[3] = {p[0] + te[e] * d[0], p[1] + te[e] * d[1], p[2] + te[e] * d[2]};
            atmos__planet_optical_depth(pl, x, d, dist - te[e], m->n, NULL, tau);
        }
        sphere_at(m, s, re[e], mue[e], v);
        gl_rows(m, m->sphere_row[s], 0.0, m->sphere_mh[s], (qs + te[e] * ds) / r, g);
        add_piece(m->n, v, g, f, f < 1 ? tau : NULL, sr, sm, T);
    }
    return e;
}

int atmos__dobashi_march(const atmos__dobashi *m, const atmos__planet *pl, const double p[3], const double d[3],
                         double dist, const double sun[3], double *sr, double *sm, double *T)
{
    for (int k = 0; k < m->n; k++) sr[k] = sm[k] = 0.0, T[k] = 1.0;
    if (atmos__planet_radius(pl, p) > pl->r_top) return march_spheres(m, pl, p, d, dist, sun, sr, sm, T);
    return march_planes(m, pl, p, d, dist, sun, sr, sm, T);
}

double atmos__dobashi_mie_phase(const atmos__dobashi *m, int k, double cos_alpha)
{
    const double u = sqrt(fmin(fmax(0.5 * (1.0 - cos_alpha), 0.0), 1.0)) * (ATMOS__DOB_PHASE_N - 1);
    int j = (int)u;
    if (j > ATMOS__DOB_PHASE_N - 2) j = ATMOS__DOB_PHASE_N - 2;
    const float *t = m->mie + (size_t)k * ATMOS__DOB_PHASE_N;
    return t[j] + (u - j) * (t[j + 1] - t[j]);
}

/* Eq. 12's sums to radiance: I_sun (F_r S_r + F_m S_m) plus the ambient term (1 - T) I_a. */
static void to_radiance(const atmos_atmosphere *a, const double d[3], const double sun[3], const double *sr,
                        const double *sm, const double *T, double *out)
{
    const atmos__dobashi *m = a->model;
    const double nu = atmos__dot3(d, sun);
    for (int k = 0; k < m->n; k++)
        out[k] = a->sun_e[k] * (atmos__planet_rayleigh_phase(a->planet, k, nu) * sr[k] + atmos__planet_mie_phase(a->planet, k, nu) * sm[k] +
                                m->ambient * (1.0 - T[k]));
}

void atmos__dobashi_radiance(const atmos_atmosphere *a, const double p[3], const double d[3], const double sun[3],
                             double *out, atmos_atmosphere_hit *info)
{
    const atmos__planet *pl = a->planet;
    const atmos__dobashi *m = a->model;
    double sr[ATMOS_MAX_WAVELENGTHS], sm[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    const double K = atmos__planet_ground_distance(pl, p, d);
    atmos__dobashi_march(m, pl, p, d, K, sun, sr, sm, T);
    to_radiance(a, d, sun, sr, sm, T, out);
    if (K < INFINITY) { /* Eq. 12's first term: I_sun r g_l(0, theta_g) cos theta_g / pi */
        double g[3] = {p[0] + K * d[0], p[1] + K * d[1], p[2] + K * d[2]}, nrm[3], gl[ATMOS_MAX_WAVELENGTHS];
        atmos__planet_ground_point(pl, g, nrm);
        const double cs = atmos__dot3(nrm, sun);
        gl_at(m, pl, 0.0, cs, gl);
        for (int k = 0; k < m->n; k++) {
            const double lit = cs > 0 ? atmos__planet_ground_albedo(pl, g, k) / ATMOS_PI * cs * gl[k] * a->sun_e[k] : 0;
            out[k] += (lit + atmos__planet_ground_lights(pl, g, sun, k)) * T[k];
        }
    }
    if (info) {
        info->distance_m = K;
        info->hits_ground = K < INFINITY;
        info->in_sun_disk = 0;
    }
}
