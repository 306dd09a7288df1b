/* Nishita et al. 1996's sky elements (nishita.h, §3.5, Fig. 6): the sky and the ground seen
 * from a cell are split into elements around the six axes and the eight diagonals of the
 * grid (the hemi-cube faces and the diagonal directions the paper suggests), plus a cone
 * around the sun, where the sky is brightest. Per cell, the attenuation toward each
 * element's direction (the sun's for the cone) is stored; Eq. 7 sums t_l I_l. */
#include "light/nishita.h"

#include <stdlib.h>

void atmos__nishita_sky_dir(int l, double d[3])
{
    d[0] = d[1] = d[2] = 0;
    if (l < 6) {
        d[l / 2] = l & 1 ? 1.0 : -1.0;
        return;
    }
    const double s = 1.0 / sqrt(3.0);
    for (int a = 0; a < 3; a++) d[a] = ((l - 6) >> a & 1) ? s : -s;
}

int atmos__nishita_sky_element(const double d[3], const double sun[3])
{
    if (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2] >= cos(ATMOS__NISHITA_AUREOLE_DEG * 3.14159265358979323846 / 180))
        return ATMOS__NISHITA_DIRS;
    int best = 0;
    double bc = -2;
    for (int l = 0; l < ATMOS__NISHITA_DIRS; l++) {
        double e[3];
        atmos__nishita_sky_dir(l, e);
        const double c = d[0] * e[0] + d[1] * e[1] + d[2] * e[2];
        if (c > bc) bc = c, best = l;
    }
    return best;
}

int atmos__nishita_sky_attenuation(const atmos__lmedium *m, const double sun[3], float *t, int threads)
{
    const int n = m->n, E = ATMOS__NISHITA_ELEMENTS;
    const size_t cells = atmos__lmedium_cells(m);
    float *Q = malloc(sizeof(float) * cells * n), *I = malloc(sizeof(float) * cells * n);
    double one[ATMOS_MAX_WAVELENGTHS];
    for (int w = 0; w < n; w++) one[w] = 1.0;
    const int ok = Q && I;
    for (int l = 0; ok && l < E; l++) {
        double d[3], lt[3];
        if (l < ATMOS__NISHITA_DIRS) atmos__nishita_sky_dir(l, d);
        else d[0] = sun[0], d[1] = sun[1], d[2] = sun[2];
        for (int a = 0; a < 3; a++) lt[a] = -d[a];
        atmos__lfield_sun_source(m, lt, one, atmos__lkeep_none, NULL, Q, NULL, I, threads);
        for (size_t c = 0; c < cells; c++)
            for (int w = 0; w < n; w++) t[(c * E + l) * n + w] = I[c * n + w];
    }
    free(Q), free(I);
    return ok;
}
