/* The light-field container (lfield.h): its cells and their values. */
#include "light/lfield.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int atmos__lfield_alloc(atmos__lfield *f, int kind, int cx, int cy, int cz, int n, int s)
{
    memset(f, 0, sizeof *f);
    const size_t cnt = (size_t)cx * cy * cz * n;
    f->L = calloc(cnt, sizeof(float));
    f->phi = calloc(cnt, sizeof(float));
    f->J = calloc(cnt * 3, sizeof(float));
    f->LA = calloc(cnt * 2, sizeof(float));
    if (!f->L || !f->phi || !f->J || !f->LA) {
        atmos__lfield_free(f);
        return 0;
    }
    f->kind = kind;
    f->c[0] = cx, f->c[1] = cy, f->c[2] = cz, f->n = n, f->s = s;
    return 1;
}

void atmos__lfield_free(atmos__lfield *f)
{
    free(f->L), free(f->phi), free(f->J), free(f->LA), free(f->part);
    memset(f, 0, sizeof *f);
}


void atmos__lfield_toward(atmos__lfield *f, const double eye[3], int threads)
{
    const int n = f->n, cx = f->c[0], cy = f->c[1], cz = f->c[2];
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int k = 0; k < cz; k++)
        for (int j = 0; j < cy; j++)
            for (int i = 0; i < cx; i++) {
                const size_t cell = ((size_t)k * cy + j) * cx + i;
                const double h = 0.5 * (f->s - 1);
                double d[3] = {eye[0] - (i * f->s + h), eye[1] - (j * f->s + h), eye[2] - (k * f->s + h)};
                const double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                const double s = r > 0 ? 3.0 / (4.0 * 3.14159265358979323846) / r : 0.0;
                float *o = f->LA + cell * 2 * n;
                for (int w = 0; w < n; w++) {
                    const float *J = f->J + (cell * n + w) * 3;
                    o[w] = f->L[cell * n + w];
                    o[n + w] = (float)(s * (J[0] * d[0] + J[1] * d[1] + J[2] * d[2]));
                }
            }
}

float atmos__lkeep_none(const void *user, size_t cell, int w, float n, float *mu)
{
    (void)user, (void)cell, (void)w, (void)n;
    if (mu) *mu = 0.0f;
    return 0.0f;
}
