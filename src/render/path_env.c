/* The sky as a light for the path tracer: a direction distribution for next-event
 * estimation toward the sky (path_internal.h). Cells of equal solid angle over
 * (mu = d_y in [-1, 1], phi = atan2(d_z, d_x) in [-pi, pi)), each weighted by the luminance
 * of the atmosphere's single scattering seen at its centre from the point ref,
 * to the ground or to space, mixed with a uniform distribution over the sphere. */
#include "render/path_internal.h"

#include <string.h>

#define NCELL (PATH_ENV_NMU * PATH_ENV_NPHI)
#define DMU (2.0 / PATH_ENV_NMU)
#define DPHI (2.0 * ATMOS_PI / PATH_ENV_NPHI)

/* Share of the uniform distribution: keeps the density of dark directions (the ground
 * seen from above, the sky opposite the sun) from falling far below the phase function's. */
#define UNIFORM_SHARE 0.15

int atmos__path_env_build(const atmos_atmosphere *atm, const double sun[3], const double ref[3], const double *Y,
                          path_env *e)
{
    memset(e, 0, sizeof *e);
    /* (a flat earth's sky is dark once the sun has set; a round one's is not: the cells say) */
    const int n = atmos_atmosphere_wavelengths(atm)->count;
    const double eye[3] = {ref[0], ref[1] > 0 ? ref[1] : 0, ref[2]};
    double v[ATMOS_MAX_WAVELENGTHS], total = 0;
    for (int i = 0; i < PATH_ENV_NMU; i++) {
        const double mu = -1.0 + (i + 0.5) * DMU, st = sqrt(fmax(0.0, 1.0 - mu * mu));
        for (int j = 0; j < PATH_ENV_NPHI; j++) {
            const double phi = -ATMOS_PI + (j + 0.5) * DPHI;
            const double d[3] = {st * cos(phi), mu, st * sin(phi)};
            atmos_atmosphere_inscatter(atm, eye, d, atmos_atmosphere_ground_distance(atm, eye, d), sun, v);
            double s = 0;
            for (int k = 0; k < n; k++) s += Y[k] * (v[k] > 0 ? v[k] : 0);
            e->pdf_cell[i * PATH_ENV_NPHI + j] = s;
            total += s;
        }
    }
    if (!(total > 0) || !isfinite(total)) return 0;
    e->uniform = UNIFORM_SHARE;
    double acc = 0;
    e->cdf[0] = 0;
    for (int c = 0; c < NCELL; c++) {
        acc += e->pdf_cell[c] / total;
        e->cdf[c + 1] = acc;
        /* density over the cell's solid angle DMU * DPHI */
        e->pdf_cell[c] = (1.0 - UNIFORM_SHARE) * e->pdf_cell[c] / total / (DMU * DPHI);
    }
    e->cdf[NCELL] = 1.0;
    return 1;
}

static int cell_of(const double d[3])
{
    int i = (int)((d[1] + 1.0) / DMU);
    if (i < 0) i = 0;
    if (i >= PATH_ENV_NMU) i = PATH_ENV_NMU - 1;
    int j = (int)((atan2(d[2], d[0]) + ATMOS_PI) / DPHI);
    if (j < 0) j = 0;
    if (j >= PATH_ENV_NPHI) j = PATH_ENV_NPHI - 1;
    return i * PATH_ENV_NPHI + j;
}

double atmos__path_env_pdf(const path_env *e, const double d[3])
{
    return e->uniform / (4.0 * ATMOS_PI) + e->pdf_cell[cell_of(d)];
}

double atmos__path_env_sample(const path_env *e, double u0, double u1, double u2, double d[3])
{
    double mu, phi;
    if (u0 < e->uniform) {
        mu = -1.0 + 2.0 * u1;
        phi = -ATMOS_PI + 2.0 * ATMOS_PI * u2;
    } else {
        /* the cell: first c with cdf[c + 1] > u */
        const double u = (u0 - e->uniform) / (1.0 - e->uniform);
        int lo = 0, hi = NCELL - 1;
        while (lo < hi) {
            int mid = (lo + hi) / 2;
            if (e->cdf[mid + 1] > u) hi = mid;
            else lo = mid + 1;
        }
        while (lo < NCELL - 1 && !(e->pdf_cell[lo] > 0)) lo++; /* never a cell of density 0 */
        const int i = lo / PATH_ENV_NPHI, j = lo % PATH_ENV_NPHI;
        mu = -1.0 + (i + u1) * DMU;
        phi = -ATMOS_PI + (j + u2) * DPHI;
    }
    if (mu > 1) mu = 1;
    if (mu < -1) mu = -1;
    const double st = sqrt(fmax(0.0, 1.0 - mu * mu));
    d[0] = st * cos(phi), d[1] = mu, d[2] = st * sin(phi);
    return atmos__path_env_pdf(e, d);
}
