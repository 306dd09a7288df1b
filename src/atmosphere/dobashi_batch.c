/* Many view rays from one eye (the sky renderer's inner loop) for Dobashi's tables. The
 * paper evaluates Eq. 12 at the vertices of its sampling planes' and sample spheres' meshes
 * and lets the hardware interpolate ("the intensity of the scattered light is very smooth",
 * §5.3); here Eq. 12 is evaluated once per eye (dobashi_eval.c) on a grid of view
 * directions and interpolated per pixel:
 *  - rows: the view's zenith cosine mu at the eye in two blocks split at the horizon (or
 *    the planet's limb from space), each mu = mu_h -+ span x^2 (dense at the split), the sky
 *    block ending at the top of the air's limb from space;
 *  - columns: the cosine of the azimuth from the sun's vertical plane (the sky is symmetric
 *    about it).
 * Stored per direction and wavelength: S_r, S_m (Eq. 12's sums without the phase functions,
 * which are applied per pixel so that the aerosols' forward peak stays sharp) and the view
 * transmittance T. Eq. 12's ground term I_sun r g_l(0, theta_g) cos theta_g T / pi is
 * evaluated per pixel at the ray's ground point (the terminator is sharp; the albedo and
 * the emission are read there). Where the table is not smooth enough (mark_rough: the
 * terminator on the ground and in the air, the shadowed limb) the pixel's ray is marched
 * exactly instead (dobashi_eval.c). */
#include "atmosphere/dobashi.h"

#include "core/vec.h"

#include <stdlib.h>
#include <string.h>

#define NM 64   /* rows per block */
#define NPHI 17 /* azimuth cosines */
#define ROUGH 3.0f /* largest ratio of a cell's corners interpolated */
#define TOL 0.02f  /* largest relative error at a cell's centre */

typedef struct {
    int n, outside;
    double q[3], qq;       /* the eye from the planet's centre, |q|^2 */
    double up[3], e1[3], e2[3];
    double mu_s;           /* the sun's zenith cosine at the eye */
    double mu_h, mu_hi;    /* the split between the blocks, the sky block's upper end */
    double r_ground;
    float *tab;            /* [2][NM][NPHI][n][3] */
    unsigned char *exact;  /* [2][NM][NPHI]: the cell from this corner is marched exactly */
} dob_eye;

static void frame(dob_eye *e, const double sun[3])
{
    e->mu_s = atmos__planet_sun_frame(e->q, sun, e->up, e->e1, e->e2);
}

static double row_mu(const dob_eye *e, int block, int i)
{
    const double x = (double)i / (NM - 1);
    if (block == 0) return e->mu_h - (e->mu_h + 1.0) * x * x - 1e-9;
    return e->mu_h + (e->mu_hi - e->mu_h) * x * x + 1e-9;
}

/* One direction's entry: Eq. 12 along the ray (dobashi_eval.c). */
static void entry(const atmos_atmosphere *a, const double eye[3], const double sun[3], const double d[3], float *o)
{
    const atmos__planet *pl = a->planet;
    const int n = a->wl.count;
    double sr[ATMOS_MAX_WAVELENGTHS], sm[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    const double K = atmos__planet_ground_distance(pl, eye, d);
    atmos__dobashi_march(a->model, pl, eye, d, K, sun, sr, sm, T);
    for (int k = 0; k < n; k++) {
        o[3 * k] = (float)sr[k];
        o[3 * k + 1] = (float)sm[k];
        o[3 * k + 2] = (float)T[k];
    }
}

/* The direction of zenith cosine mu and azimuth cosine c. */
static void direction(const dob_eye *e, double mu, double c, double d[3])
{
    const double st = sqrt(fmax(1.0 - mu * mu, 0.0)), s = sqrt(fmax(1.0 - c * c, 0.0));
    for (int k = 0; k < 3; k++) d[k] = mu * e->up[k] + st * (c * e->e1[k] + s * e->e2[k]);
}

/* Marks the cells that bilinear interpolation misses: the ray through the cell's centre,
 * marched exactly, differs from the corners' mean by more than TOL (of the table's largest
 * value / 1000 at least) at some wavelength, or the corners differ by more than a factor
 * ROUGH (a terminator or a shadow's edge inside the cell). */
static void mark_rough(dob_eye *e, const atmos_atmosphere *a, const double eye[3], const double sun[3], int threads)
{
    const int n = e->n, n3 = 3 * n;
    float top[ATMOS_MAX_WAVELENGTHS] = {0};
    for (size_t c = 0; c < (size_t)2 * NM * NPHI; c++)
        for (int k = 0; k < n; k++) top[k] = fmaxf(top[k], e->tab[c * n3 + 3 * k] + e->tab[c * n3 + 3 * k + 1]);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int bi = 0; bi < 2 * NM; bi++)
        for (int j = 0; j < NPHI; j++) {
            unsigned char x = 0;
            if (bi % NM < NM - 1 && j < NPHI - 1) {
                const float *c[4];
                c[0] = e->tab + ((size_t)bi * NPHI + j) * n3, c[1] = c[0] + n3;
                c[2] = c[0] + (size_t)NPHI * n3, c[3] = c[2] + n3;
                float mean[ATMOS_MAX_WAVELENGTHS], mid[3 * ATMOS_MAX_WAVELENGTHS];
                for (int k = 0; k < n && !x; k++) {
                    float lo = INFINITY, hi = 0;
                    mean[k] = 0;
                    for (int q = 0; q < 4; q++) {
                        const float v = c[q][3 * k] + c[q][3 * k + 1];
                        lo = fminf(lo, v), hi = fmaxf(hi, v), mean[k] += 0.25f * v;
                    }
                    x = hi > ROUGH * lo && hi > 1e-3f * top[k];
                }
                if (!x) {
                    const int block = bi / NM, i = bi % NM;
                    const double xr = (i + 0.5) / (NM - 1), mu = block == 0 ? e->mu_h - (e->mu_h + 1.0) * xr * xr
                                                                           : e->mu_h + (e->mu_hi - e->mu_h) * xr * xr;
                    double d[3];
                    direction(e, mu, -1.0 + 2.0 * (j + 0.5) / (NPHI - 1), d);
                    entry(a, eye, sun, d, mid);
                    for (int k = 0; k < n && !x; k++) {
                        const float v = mid[3 * k] + mid[3 * k + 1];
                        x = fabsf(v - mean[k]) > TOL * fmaxf(v, 1e-3f * top[k]);
                    }
                }
            }
            e->exact[(size_t)bi * NPHI + j] = x;
        }
}

void atmos__dobashi_batch_init(atmos__atm_batch *b)
{
    const atmos_atmosphere *a = b->atm;
    const atmos__planet *pl = a->planet;
    dob_eye *e = calloc(1, sizeof *e);
    if (!e) return;
    e->n = a->wl.count;
    e->r_ground = pl->r_ground;
    e->q[0] = b->eye[0], e->q[1] = b->eye[1] + pl->r_ground, e->q[2] = b->eye[2];
    e->qq = atmos__dot3(e->q, e->q);
    frame(e, b->sun);
    const double r = sqrt(e->qq);
    e->outside = r > pl->r_top;
    e->mu_h = -sqrt(fmax(1.0 - pl->r_ground * pl->r_ground / e->qq, 0.0));
    e->mu_hi = e->outside ? -sqrt(fmax(1.0 - pl->r_top * pl->r_top / e->qq, 0.0)) : 1.0;
    const size_t row = (size_t)NPHI * 3 * e->n;
    e->tab = malloc(sizeof(float) * 2 * NM * row);
    e->exact = malloc((size_t)2 * NM * NPHI);
    if (!e->tab || !e->exact) {
        free(e->tab);
        free(e->exact);
        free(e);
        return;
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(b->threads > 0 ? b->threads : 1)
    for (int bi = 0; bi < 2 * NM; bi++) {
        const int block = bi / NM, i = bi % NM;
        const double mu = row_mu(e, block, i);
        for (int j = 0; j < NPHI; j++) {
            double d[3];
            direction(e, mu, -1.0 + 2.0 * j / (NPHI - 1), d);
            entry(a, b->eye, b->sun, d, e->tab + (size_t)bi * row + (size_t)j * 3 * e->n);
        }
    }
    mark_rough(e, a, b->eye, b->sun, b->threads > 0 ? b->threads : 1);
    b->state = e;
}

void atmos__dobashi_batch_release(atmos__atm_batch *b)
{
    dob_eye *e = b->state;
    if (!e) return;
    free(e->tab);
    free(e->exact);
    free(e);
    b->state = NULL;
}

/* The table's entries for direction (mu, c = cos azimuth) interpolated into v[3 n];
 * returns 1 for a ray to the ground, 2 for the sky, -1 where the ray must be marched. */
static int lookup(const dob_eye *e, double mu, double c, float *v)
{
    const int n4 = 3 * e->n;
    int block;
    double x;
    if (mu >= e->mu_h) block = 1, x = (mu - e->mu_h) / (e->mu_hi - e->mu_h);
    else block = 0, x = (e->mu_h - mu) / (e->mu_h + 1.0);
    c = c < -1.0 ? -1.0 : (c > 1.0 ? 1.0 : c);
    const double xr = sqrt(x < 1.0 ? x : 1.0) * (NM - 1), xc = 0.5 * (c + 1.0) * (NPHI - 1);
    int i = (int)xr, j = (int)xc;
    if (i > NM - 2) i = NM - 2;
    if (j > NPHI - 2) j = NPHI - 2;
    if (e->exact[(size_t)(block * NM + i) * NPHI + j]) return -1;
    const float fr = (float)(xr - i), fc = (float)(xc - j);
    const float w00 = (1 - fr) * (1 - fc), w01 = (1 - fr) * fc, w10 = fr * (1 - fc), w11 = fr * fc;
    const float *p = e->tab + ((size_t)(block * NM + i) * NPHI + j) * n4, *q = p + (size_t)NPHI * n4;
    for (int k = 0; k < n4; k++) v[k] = w00 * p[k] + w01 * p[n4 + k] + w10 * q[k] + w11 * q[n4 + k];
    return block == 0 ? 1 : 2;
}

void atmos__dobashi_batch_eval(const atmos__atm_batch *b, int count, const float *dx, const float *dy,
                               const float *dz, const float *weight, float *out, float *scratch)
{
    (void)scratch;
    const dob_eye *e = b->state;
    const atmos_atmosphere *a = b->atm;
    const atmos__dobashi *m = a->model;
    const int n = e->n;
    const double *sun = b->sun, mus = e->mu_s, ss = 1.0 - mus * mus;
    float v[3 * ATMOS_MAX_WAVELENGTHS];
    double gl[ATMOS_MAX_WAVELENGTHS];
    for (int i = 0; i < count; i++) {
        if (weight[i] == 0.0f) continue;
        const double d[3] = {dx[i], dy[i], dz[i]};
        const double mu = atmos__dot3(d, e->up);
        if (e->outside && mu > e->mu_hi) continue; /* misses the air */
        const double nu = atmos__dot3(d, sun), den = (1.0 - mu * mu) * ss;
        const double c = den > 1e-18 ? (nu - mu * mus) / sqrt(den) : 1.0;
        const int got = lookup(e, mu, c, v), ground = got == 1;
        if (got < 0) {
            double L[ATMOS_MAX_WAVELENGTHS];
            atmos__dobashi_radiance(a, b->eye, d, sun, L, NULL);
            for (int k = 0; k < n; k++) out[(size_t)k * count + i] += weight[i] * (float)L[k];
            continue;
        }
        /* the aerosols' phase table (dobashi_tables.c) at sin(alpha / 2) */
        const double hu = 0.5 * (1.0 - nu), u = sqrt(hu < 0 ? 0 : (hu > 1 ? 1 : hu)) * (ATMOS__DOB_PHASE_N - 1);
        int ju = (int)u;
        if (ju > ATMOS__DOB_PHASE_N - 2) ju = ATMOS__DOB_PHASE_N - 2;
        const float fu = (float)(u - ju);
        double g[3] = {0, 0, 0}, cs = 0;
        if (ground) { /* the ground point, its sun cosine and g_l(0, theta_g) */
            const double bq = atmos__dot3(e->q, d);
            const double K = -bq - sqrt(fmax(bq * bq - (e->qq - e->r_ground * e->r_ground), 0.0));
            for (int k = 0; k < 3; k++) g[k] = b->eye[k] + K * d[k];
            cs = (atmos__dot3(e->q, sun) + K * nu) / e->r_ground;
            if (cs > 0) atmos__dobashi_gl(m, a->planet, g, sun, n, NULL, gl);
        }
        for (int k = 0; k < n; k++) {
            const float *w = v + 3 * k;
            const float *ph = m->mie + (size_t)k * ATMOS__DOB_PHASE_N + ju;
            double L = a->sun_e[k] * (atmos__planet_rayleigh_phase(a->planet, k, nu) * w[0] + (ph[0] + fu * (ph[1] - ph[0])) * w[1] +
                                      m->ambient * (1.0 - w[2]));
            if (ground) {
                const double lit = cs > 0 ? atmos__planet_ground_albedo(a->planet, g, k) / ATMOS_PI * cs * gl[k] : 0;
                L += (lit * a->sun_e[k] + atmos__planet_ground_lights(a->planet, g, sun, k)) * w[2];
            }
            out[(size_t)k * count + i] += weight[i] * (float)L;
        }
    }
}
