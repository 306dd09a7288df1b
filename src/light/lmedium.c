/* The medium on a light field's grid (lfield.h, atmos__lmedium). */
#include "light/lfield.h"

#include <stdlib.h>
#include <string.h>

size_t atmos__lmedium_cells(const atmos__lmedium *m) { return (size_t)m->c[0] * m->c[1] * m->c[2]; }

int atmos__lmedium_alloc(atmos__lmedium *m, int cx, int cy, int cz, int n, double h)
{
    memset(m, 0, sizeof *m);
    m->c[0] = cx, m->c[1] = cy, m->c[2] = cz, m->n = n, m->h = h;
    const size_t cnt = atmos__lmedium_cells(m) * (size_t)n;
    m->sig_t = calloc(cnt, sizeof(float));
    m->sig_s = calloc(cnt, sizeof(float));
    m->g = calloc(cnt, sizeof(float));
    if (!m->sig_t || !m->sig_s || !m->g) {
        atmos__lmedium_free(m);
        return 0;
    }
    return 1;
}

void atmos__lmedium_free(atmos__lmedium *m)
{
    free(m->sig_t), free(m->sig_s), free(m->g), free(m->jin);
    memset(m, 0, sizeof *m);
}
