/* The light-field container (lfield.h): its cells and their values. */
#include "light/lfield.h"

#include <stdlib.h>
#include <string.h>

int atmos__lfield_alloc(atmos__lfield *f, int kind, int cx, int cy, int cz, int n, int s)
{
    memset(f, 0, sizeof *f);
    const size_t cnt = (size_t)cx * cy * cz * n;
    f->L = calloc(cnt, sizeof(float));
    f->phi = calloc(cnt, sizeof(float));
    f->J = calloc(cnt * 3, sizeof(float));
    if (!f->L || !f->phi || !f->J) {
        atmos__lfield_free(f);
        return 0;
    }
    f->kind = kind;
    f->c[0] = cx, f->c[1] = cy, f->c[2] = cz, f->n = n, f->s = s;
    return 1;
}

void atmos__lfield_free(atmos__lfield *f)
{
    free(f->L), free(f->phi), free(f->J);
    memset(f, 0, sizeof *f);
}

