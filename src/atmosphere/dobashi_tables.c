/* Dobashi et al. 2002 Appendix A: the look-up tables g_l (A.1-A.4) and dI_r, dI_m, dg_v
 * (A.5-A.6) of the sampling planes (§5.2) and the sample spheres (§5.3), built over the
 * planet description (planet.h) with its extinction (air, aerosols and ozone: the paper has
 * no ozone; it is included in every optical length so that all solvers describe the same
 * atmosphere). Grids: dobashi.h. */
#include "atmosphere/dobashi.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Midpoint steps of one sub-segment's integrals: a vertical sub-segment of the default 11 km
 * is cut into 170 m steps, 1/7 of the aerosols' scale height (midpoint error ~1e-3). */
#define SEG_N 64

/* The scattering integrals (A.5) and optical length (A.6) of the segment of length len
 * from height h in the direction of zenith cosine mu, stopped at the ground. */
static void seg_integrals(const atmos__planet *pl, double h, double mu, double len, double *ir, double *im,
                          double *tau)
{
    const int n = pl->n;
    const double r = pl->r_ground + h;
    double L = fmin(len, atmos__planet_dist_ground(pl, r, mu));
    for (int k = 0; k < n; k++) ir[k] = im[k] = tau[k] = 0.0;
    if (!(L > 0)) return;
    const double step = L / SEG_N;
    for (int j = 0; j < SEG_N; j++) {
        const double t = (j + 0.5) * step;
        const double hh = sqrt(fmax(r * r + t * t + 2.0 * r * mu * t, 0.0)) - pl->r_ground;
        if (hh > pl->r_top - pl->r_ground) continue;
        const double rr = atmos__planet_rho_rayleigh(pl, hh), rm = atmos__planet_rho_mie(pl, hh);
        for (int k = 0; k < n; k++) {
            const double e = atmos__planet_extinction(pl, hh, k) * step;
            const double T = exp(-(tau[k] + 0.5 * e));
            ir[k] += pl->rayleigh[k] * rr * T * step;
            im[k] += pl->mie_sca[k] * rm * T * step;
            tau[k] += e;
        }
    }
}

static double row_height(double top, int i)
{
    const double x = (double)i / (ATMOS__DOB_NH - 1);
    return top * x * x;
}

static double horizon_mu(const atmos__planet *pl, double h)
{
    const double r = pl->r_ground + h;
    return -sqrt(fmax(r * r - pl->r_ground * pl->r_ground, 0.0)) / r;
}

/* g_l (A.4) stored as its optical length tau_l = -ln g_l (interpolated linearly, tau_l is
 * smooth where g_l falls steeply near the horizon: 5e-3 instead of 2e-2 worst error). */
static void build_gl(atmos__dobashi *m, const atmos__planet *pl)
{
    const int n = m->n;
    double tau[ATMOS_MAX_WAVELENGTHS];
    for (int i = 0; i < ATMOS__DOB_NH; i++) {
        const double h = row_height(m->top, i), mh = horizon_mu(pl, h);
        for (int j = 0; j < ATMOS__DOB_NS; j++) {
            const double x = (double)j / (ATMOS__DOB_NS - 1);
            /* the first column grazes the ground: nudged off the tangent point */
            const double mu = fmin(mh + (1.0 - mh) * x * x + 1e-9, 1.0);
            const double p[3] = {0, h, 0}, d[3] = {sqrt(fmax(1.0 - mu * mu, 0.0)), mu, 0};
            atmos__planet_optical_depth(pl, p, d, INFINITY, n, NULL, tau);
            float *g = m->gl + ((size_t)i * ATMOS__DOB_NS + j) * n;
            for (int k = 0; k < n; k++) g[k] = (float)tau[k];
        }
    }
}

static void store3(float *dst, int n, const double *ir, const double *im, const double *tau)
{
    for (int k = 0; k < n; k++) {
        dst[3 * k] = (float)ir[k];
        dst[3 * k + 1] = (float)im[k];
        dst[3 * k + 2] = (float)exp(-tau[k]);
    }
}

/* The sampling planes' tables: one sub-segment of length dt. */
static void build_planes(atmos__dobashi *m, const atmos__planet *pl)
{
    const int n = m->n;
    double ir[ATMOS_MAX_WAVELENGTHS], im[ATMOS_MAX_WAVELENGTHS], tau[ATMOS_MAX_WAVELENGTHS];
    for (int i = 0; i < ATMOS__DOB_NH; i++) {
        const double h = row_height(m->top, i);
        for (int j = 0; j < ATMOS__DOB_NV; j++) {
            const double y = 2.0 * j / (ATMOS__DOB_NV - 1) - 1.0, mu = (y < 0 ? -1 : 1) * y * y;
            seg_integrals(pl, h, mu, m->dt, ir, im, tau);
            store3(m->plane + ((size_t)i * ATMOS__DOB_NV + j) * 3 * n, n, ir, im, tau);
        }
    }
}

/* The sample spheres' tables: from sphere s along mu to the next sphere crossed. */
static void build_spheres(atmos__dobashi *m, const atmos__planet *pl)
{
    const int n = m->n, S = m->spheres;
    double ir[ATMOS_MAX_WAVELENGTHS], im[ATMOS_MAX_WAVELENGTHS], tau[ATMOS_MAX_WAVELENGTHS];
    for (int s = 0; s < S; s++) {
        const double r = pl->r_ground + m->h_sphere[s];
        const double ru = s + 1 < S ? pl->r_ground + m->h_sphere[s + 1] : 0.0;
        const double rd = s > 0 ? pl->r_ground + m->h_sphere[s - 1] : 0.0;
        const double mt = m->mu_split[s];
        for (int range = 0; range < 3; range++)
            for (int j = 0; j < ATMOS__DOB_NSV; j++) {
                const double x = (double)j / (ATMOS__DOB_NSV - 1);
                double mu, L = 0.0;
                if (range == 0) { /* up, to sphere s + 1 */
                    mu = x * x;
                    if (s + 1 < S) L = -r * mu + sqrt(fmax(r * r * (mu * mu - 1.0) + ru * ru, 0.0));
                } else if (range == 1) { /* down, past the tangent point back to sphere s */
                    mu = mt * x;
                    if (s > 0) L = -2.0 * r * mu;
                } else { /* down, to sphere s - 1 */
                    mu = mt - (1.0 + mt) * x * x;
                    if (s > 0) L = -r * mu - sqrt(fmax(r * r * (mu * mu - 1.0) + rd * rd, 0.0));
                }
                seg_integrals(pl, m->h_sphere[s], mu, L, ir, im, tau);
                store3(m->sphere + ((((size_t)s * 3 + range) * ATMOS__DOB_NSV) + j) * 3 * n, n, ir, im, tau);
            }
    }
}

/* The aerosols' phase per sin(alpha / 2) (uniform in it: fine near the forward peak, a
 * square root instead of an arc cosine per lookup). */
static void build_mie(atmos__dobashi *m, const atmos__planet *pl)
{
    for (int k = 0; k < m->n; k++)
        for (int j = 0; j < ATMOS__DOB_PHASE_N; j++) {
            const double u = (double)j / (ATMOS__DOB_PHASE_N - 1);
            m->mie[(size_t)k * ATMOS__DOB_PHASE_N + j] = (float)atmos__planet_mie_phase(pl, k, 1.0 - 2.0 * u * u);
        }
}

atmos__dobashi *atmos__dobashi_build(const atmos__planet *pl, double dt, int nspheres)
{
    const clock_t c0 = clock();
    atmos__dobashi *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    const int n = pl->n, S = ATMOS__DOB_SPHERES;
    m->n = n;
    m->top = pl->r_top - pl->r_ground;
    /* §4.2.1/§5.2: a constant spacing; the paper's sky (Fig. 10(a), Table 1) uses 100 planes,
     * here over the longest sight line from the ground to the top (1131 km for a 100 km top) */
    m->dt = dt > 0 ? dt : sqrt(pl->r_top * pl->r_top - pl->r_ground * pl->r_ground) / ATMOS__DOB_PLANES;
    /* spheres on rows of the height grid: all, or fewer spread over it */
    const int every = nspheres > 1 && nspheres < S ? (S - 1) / (nspheres - 1) : 1;
    m->spheres = (S - 1) / every + 1;
    for (int s = 0; s < m->spheres; s++) {
        m->sphere_row[s] = s * every * ((ATMOS__DOB_NH - 1) / (S - 1));
        m->h_sphere[s] = row_height(m->top, m->sphere_row[s]);
        m->sphere_mh[s] = horizon_mu(pl, m->h_sphere[s]);
    }
    for (int s = 0; s < m->spheres; s++) {
        const double r = pl->r_ground + m->h_sphere[s], rd = s > 0 ? pl->r_ground + m->h_sphere[s - 1] : r;
        m->mu_split[s] = -sqrt(fmax(1.0 - (rd / r) * (rd / r), 0.0));
    }
    m->gl = malloc(sizeof(float) * ATMOS__DOB_NH * ATMOS__DOB_NS * n);
    m->plane = malloc(sizeof(float) * ATMOS__DOB_NH * ATMOS__DOB_NV * 3 * n);
    m->sphere = malloc(sizeof(float) * S * 3 * ATMOS__DOB_NSV * 3 * n);
    m->mie = malloc(sizeof(float) * ATMOS__DOB_PHASE_N * n);
    if (!m->gl || !m->plane || !m->sphere || !m->mie) {
        atmos__dobashi_free(m);
        return NULL;
    }
    build_gl(m, pl);
    build_planes(m, pl);
    build_spheres(m, pl);
    build_mie(m, pl);
    m->build_seconds = (double)(clock() - c0) / CLOCKS_PER_SEC;
    return m;
}

void atmos__dobashi_free(void *model)
{
    atmos__dobashi *m = model;
    if (!m) return;
    free(m->gl);
    free(m->plane);
    free(m->sphere);
    free(m->mie);
    free(m);
}
