/* The particles' Ams_n tabulated on the scattering angle's cosine (pphase.h). */
#include "particles/pphase.h"

#include <stdlib.h>

size_t atmos__pphase_bytes(const atmos_msphase *m, int nw)
{
    return m && nw > 0 ? sizeof(float) * (size_t)(atmos_msphase_max_order(m) + 1) * 2 * (ATMOS__PPHASE_NODES + 1) * nw
                       : 0;
}

atmos__pphase *atmos__pphase_make(const atmos_msphase *m, int nw, size_t max_bytes)
{
    enum { N = ATMOS__PPHASE_NODES, ROW = 2 * (N + 1) };
    if (!m || nw < 1 || nw > ATMOS_MAX_WAVELENGTHS) return NULL; /* k past m's wavelengths: 0, as eval_all */
    if (atmos__pphase_bytes(m, nw) > max_bytes) return NULL;
    atmos__pphase *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    t->nw = nw, t->orders = atmos_msphase_max_order(m) + 1;
    t->v = malloc(sizeof(float) * (size_t)t->orders * ROW * nw);
    if (!t->v) {
        free(t);
        return NULL;
    }
    for (int n = 1; n <= t->orders; n++)
        for (int h = 0; h < 2; h++)
            for (int i = 0; i <= N; i++) {
                /* node i: sqrt(1 - |cos|) = i / N, forward (h = 0) or backward */
                const double s = (double)i / N, c = h ? s * s - 1.0 : 1.0 - s * s;
                float *o = t->v + ((size_t)(n - 1) * ROW + h * (N + 1) + i) * nw;
                for (int k = 0; k < nw; k++) o[k] = (float)atmos_msphase_eval(m, k, n, c);
            }
    return t;
}

void atmos__pphase_free(const atmos__pphase *t)
{
    if (!t) return;
    free(t->v);
    free((void *)t);
}
