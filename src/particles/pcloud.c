/* The particle container (pcloud.h). */
#include "particles/pcloud.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int grow(atmos__pcloud *pc)
{
    const int cap = pc->cap ? 2 * pc->cap : 1024;
    float **arr[5] = {&pc->x, &pc->y, &pc->z, &pc->s, &pc->n0};
    for (int a = 0; a < 5; a++) {
        float *p = realloc(*arr[a], sizeof(float) * (size_t)cap);
        if (!p) return 0;
        *arr[a] = p;
    }
    uint8_t *f = realloc(pc->field, (size_t)cap);
    if (!f) return 0;
    pc->field = f;
    pc->cap = cap;
    return 1;
}

atmos_status atmos__pcloud_add(atmos__pcloud *pc, double x, double y, double z, double s, double n0, int field)
{
    if (pc->n == pc->cap && !grow(pc)) return ATMOS_E_NOMEM;
    const int i = pc->n++;
    pc->x[i] = (float)x, pc->y[i] = (float)y, pc->z[i] = (float)z;
    pc->s[i] = (float)s, pc->n0[i] = (float)n0, pc->field[i] = (uint8_t)field;
    return ATMOS_OK;
}

void atmos__pcloud_free(atmos__pcloud *pc)
{
    free(pc->x), free(pc->y), free(pc->z), free(pc->s), free(pc->n0), free(pc->field);
    memset(pc, 0, sizeof *pc);
}

void atmos__pcloud_bounds(const atmos__pcloud *pc, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) lo[a] = INFINITY, hi[a] = -INFINITY;
    for (int i = 0; i < pc->n; i++) {
        const double c[3] = {pc->x[i], pc->y[i], pc->z[i]}, r = ATMOS__PCLOUD_CUT * pc->s[i];
        for (int a = 0; a < 3; a++) lo[a] = fmin(lo[a], c[a] - r), hi[a] = fmax(hi[a], c[a] + r);
    }
}
