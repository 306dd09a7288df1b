/* The sky's light on the beam renderer's surfaces (beams_sky.h). The irradiance of a surface
 * of normal n from the sky is E(n) = int L(w) max(0, n . w) dw over the upper hemisphere, L the
 * atmosphere's radiance without the sun's disk (the sun is the beam renderer's own light).
 * Directions: BEAMS_SKY_MU rings of equal width in cos(zenith) by BEAMS_SKY_PHI azimuths,
 * cells of equal solid angle 2 pi / (MU PHI), each at its centre. The sky is that of one point
 * (the ground under the eye): what a surface sees below the horizon (the ground's light) and
 * the sky hidden by other objects are left out (docs/beams.md). The scene's fog dims it as it
 * dims the sky the eye sees: a height-dependent fog's layer above the surface by exp(-C / mu)
 * (the table's layers of C); a uniform fog hides it (its caller adds none). */
#include "render/beams_sky.h"
#include "render/sky_inflow.h"
#include "core/clones.h"
#include "core/vec.h"

#include <stdlib.h>
#include <string.h>

#define BEAMS_SKY_MU 24
#define BEAMS_SKY_PHI 48

/* The table's normal at node (iy, ia). */
static void node_normal(int iy, int ia, double n[3])
{
    const double y = -1.0 + 2.0 * iy / (BEAMS_SKY_NY - 1), s = sqrt(fmax(0.0, 1.0 - y * y));
    const double a = 2.0 * ATMOS_PI * ia / BEAMS_SKY_NA;
    n[0] = s * cos(a), n[1] = y, n[2] = s * sin(a);
}

/* The sky's irradiance on a surface of normal n ring by ring of the directions (the rows of L
 * as in atmos__beams_sky_build): R[r * nw + k]. */
ATMOS_CLONES static void ring_irradiance(const double *L, int nw, const double n[3], double *R)
{
    const int nd = BEAMS_SKY_MU * BEAMS_SKY_PHI;
    const double dw = 2.0 * ATMOS_PI / nd;
    for (int q = 0; q < BEAMS_SKY_MU * nw; q++) R[q] = 0;
    for (int i = 0; i < nd; i++) {
        const double *row = L + (size_t)i * (nw + 3), c = atmos__dot3(n, row);
        if (!(c > 0)) continue;
        double *Rr = R + (i / BEAMS_SKY_PHI) * nw;
#pragma omp simd
        for (int k = 0; k < nw; k++) Rr[k] += row[3 + k] * c * dw;
    }
}

/* Each layer's dimming of each ring, exp(-C / mu) at the ring's centre (ic = 0: C = 0,
 * undimmed): T[ic * BEAMS_SKY_MU + r], the same for every normal, so made once a table. */
static void ring_dimming(int nc, double *T)
{
    for (int ic = 0; ic < nc; ic++) {
        const double x = (double)ic / (BEAMS_SKY_NC - 1), C = BEAMS_SKY_CMAX * x * x;
        for (int r = 0; r < BEAMS_SKY_MU; r++) T[ic * BEAMS_SKY_MU + r] = ic ? exp(-C / ((r + 0.5) / BEAMS_SKY_MU)) : 1.0;
    }
}

/* The table's values of normal j: its rings' irradiance R summed, for each layer ic of C, each
 * ring dimmed by T (ring_dimming). */
ATMOS_CLONES static void node_values(const double *R, const double *T, int nw, int j, atmos__beams_sky *s)
{
    const int nn = BEAMS_SKY_NY * BEAMS_SKY_NA;
    for (int ic = 0; ic < s->nc; ic++) {
        double e[ATMOS_MAX_WAVELENGTHS] = {0};
        for (int r = 0; r < BEAMS_SKY_MU; r++) {
            const double t = T[ic * BEAMS_SKY_MU + r];
#pragma omp simd
            for (int k = 0; k < nw; k++) e[k] += t * R[r * nw + k];
        }
        for (int k = 0; k < nw; k++) s->E[((size_t)ic * nn + j) * nw + k] = (float)e[k];
    }
}

atmos_status atmos__beams_sky_build(atmos_context *ctx, const atmos_atmosphere *atm, const double p[3],
                                    const double sun_dir[3], int nw, int layered, atmos__beams_sky *s)
{
    memset(s, 0, sizeof *s);
    if (atmos_atmosphere_get_kind(atm) == ATMOS_ATMOSPHERE_VACUUM) return ATMOS_OK;
    const int nd = BEAMS_SKY_MU * BEAMS_SKY_PHI, nn = BEAMS_SKY_NY * BEAMS_SKY_NA;
    s->nc = layered ? BEAMS_SKY_NC : 1;
    double *L = malloc(sizeof(double) * (size_t)nd * (nw + 3));
    s->E = calloc((size_t)s->nc * nn * nw, sizeof *s->E);
    if (!L || !s->E) {
        free(L), free(s->E), s->E = NULL;
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for the sky's light");
    }
#pragma omp parallel for schedule(dynamic, 8) num_threads(atmos__threads(ctx))
    for (int i = 0; i < nd; i++) {
        const double mu = ((i / BEAMS_SKY_PHI) + 0.5) / BEAMS_SKY_MU, phi = 2.0 * ATMOS_PI * ((i % BEAMS_SKY_PHI) + 0.5) / BEAMS_SKY_PHI;
        const double st = sqrt(fmax(0.0, 1.0 - mu * mu));
        double *row = L + (size_t)i * (nw + 3);
        row[0] = st * cos(phi), row[1] = mu, row[2] = st * sin(phi);
        atmos__sky_seen(atm, p, row, sun_dir, nw, row + 3); /* without the sun's disk */
    }
    double T[BEAMS_SKY_NC * BEAMS_SKY_MU];
    ring_dimming(s->nc, T);
    /* each normal's values on their own (the same bits with any number of threads) */
#pragma omp parallel for schedule(dynamic, 8) num_threads(atmos__threads(ctx))
    for (int j = 0; j < nn; j++) {
        double n[3], R[BEAMS_SKY_MU * ATMOS_MAX_WAVELENGTHS];
        node_normal(j / BEAMS_SKY_NA, j % BEAMS_SKY_NA, n);
        ring_irradiance(L, nw, n, R);
        node_values(R, T, nw, j, s);
    }
    free(L);
    s->nw = nw;
    return ATMOS_OK;
}

/* The wavelengths' blend in one loop, vectorised in the AVX2 clone (the same operations in
 * the same order for each wavelength: the same bits). */
ATMOS_CLONES void atmos__beams_sky_irradiance(const atmos__beams_sky *s, const double n[3], double C, double *E)
{
    const int nw = s->nw;
    if (!nw) return;
    /* the layer: linear in x = sqrt(C / CMAX) between two of the table's values of C */
    double tc = 0;
    size_t c0 = 0, c1 = 0;
    if (s->nc > 1 && C > 0) {
        const double fc = fmin(1.0, sqrt(C / BEAMS_SKY_CMAX)) * (BEAMS_SKY_NC - 1);
        c0 = (size_t)fc < BEAMS_SKY_NC - 1 ? (size_t)fc : BEAMS_SKY_NC - 2;
        c1 = c0 + 1, tc = fc - (double)c0;
    }
    const double fy = (fmin(1.0, fmax(-1.0, n[1])) + 1.0) * 0.5 * (BEAMS_SKY_NY - 1);
    double fa = atan2(n[2], n[0]) / (2.0 * ATMOS_PI) * BEAMS_SKY_NA;
    if (fa < 0) fa += BEAMS_SKY_NA;
    int iy = (int)fy, ia = (int)fa;
    if (iy > BEAMS_SKY_NY - 2) iy = BEAMS_SKY_NY - 2;
    if (ia > BEAMS_SKY_NA - 1) ia = BEAMS_SKY_NA - 1;
    const double ty = fy - iy, ta = fa - ia;
    const int ib = (ia + 1) % BEAMS_SKY_NA;
    const size_t layer = (size_t)BEAMS_SKY_NY * BEAMS_SKY_NA * nw;
    const float *e00 = s->E + c0 * layer + ((size_t)iy * BEAMS_SKY_NA + ia) * nw;
    const float *e01 = s->E + c0 * layer + ((size_t)iy * BEAMS_SKY_NA + ib) * nw;
    const float *e10 = s->E + c0 * layer + ((size_t)(iy + 1) * BEAMS_SKY_NA + ia) * nw;
    const float *e11 = s->E + c0 * layer + ((size_t)(iy + 1) * BEAMS_SKY_NA + ib) * nw;
#pragma omp simd
    for (int k = 0; k < nw; k++)
        E[k] = (1 - ty) * ((1 - ta) * e00[k] + ta * e01[k]) + ty * ((1 - ta) * e10[k] + ta * e11[k]);
    if (c1 == c0) return; /* no layer */
    const size_t dl = (c1 - c0) * layer;
#pragma omp simd
    for (int k = 0; k < nw; k++) {
        const double up = (1 - ty) * ((1 - ta) * e00[dl + k] + ta * e01[dl + k]) + ty * ((1 - ta) * e10[dl + k] + ta * e11[dl + k]);
        E[k] = (1 - tc) * E[k] + tc * up;
    }
}

const double *atmos__beams_sky_irradiance_memo(const atmos__beams_sky *s, const double n[3], double C, double *E,
                                               atmos__beams_sky_memo *memo)
{
    if (!memo) {
        atmos__beams_sky_irradiance(s, n, C, E);
        return E;
    }
    if (!memo->valid || memcmp(memo->n, n, sizeof memo->n) || memcmp(&memo->C, &C, sizeof C)) {
        atmos__beams_sky_irradiance(s, n, C, memo->E);
        memcpy(memo->n, n, sizeof memo->n), memo->C = C, memo->valid = 1;
    }
    return memo->E;
}

void atmos__beams_sky_free(atmos__beams_sky *s)
{
    if (s) free(s->E), memset(s, 0, sizeof *s);
}

void atmos__beams_sky_axes(const double sun_dir[3], double u[2])
{
    const double h = hypot(sun_dir[0], sun_dir[2]);
    u[0] = h > 1e-9 ? sun_dir[0] / h : 1.0, u[1] = h > 1e-9 ? sun_dir[2] / h : 0.0;
}

atmos_status atmos__beams_sky_keep(atmos_context *ctx, const atmos_atmosphere *atm, const double eye[3],
                                   const double sun_dir[3], int nw, int layered, atmos__beams_sky *s)
{
    double u[2]; /* along the sun's azimuth (x, z); across it: (-u[1], u[0]) */
    atmos__beams_sky_axes(sun_dir, u);
    const long key[2] = {lround((eye[0] * u[0] + eye[2] * u[1]) / BEAMS_SKY_KEEP_M),
                         lround((eye[2] * u[0] - eye[0] * u[1]) / BEAMS_SKY_KEEP_ACROSS_M)};
    if (s->built && s->atm == atm && s->nw == nw && s->key[0] == key[0] && s->key[1] == key[1] &&
        s->layered == layered && !memcmp(s->sun, sun_dir, sizeof s->sun))
        return ATMOS_OK;
    const double a = (double)key[0] * BEAMS_SKY_KEEP_M, c = (double)key[1] * BEAMS_SKY_KEEP_ACROSS_M;
    const double under[3] = {a * u[0] - c * u[1] + 0.0, 0, a * u[1] + c * u[0] + 0.0}; /* + 0: no -0 */
    atmos__beams_sky_free(s);
    const atmos_status st = atmos__beams_sky_build(ctx, atm, under, sun_dir, nw, layered, s);
    if (st != ATMOS_OK) return st;
    s->atm = atm, s->key[0] = key[0], s->key[1] = key[1], s->built = 1, s->layered = layered;
    memcpy(s->sun, sun_dir, sizeof s->sun);
    return ATMOS_OK;
}
