/* The fractal outline a field's particle cloud is cut to (pcloud.h, atmos__pfootprint_make): the
 * volume generators' outline (atmos__gen_fractal_phi, generate_footprint.c: a smooth ellipse plus
 * fractional Brownian noise in units of the cloud's width, down to half the particles' spacing)
 * read on the cloud's lattice columns, fixed on the ground, and only the columns joined to the
 * core kept (4-connected: a flood from the kept column nearest the centre), so that a cloud stays
 * one cluster of particles (the renderer's impostors draw clusters). */
#include "particles/pcloud.h"
#include "volume/generator.h"

#include <math.h>
#include <stdlib.h>

/* The outline's noise as the cumulus field's (atmos__gen_fractal_phi's rough = 1) */
#define ROUGH 1.0

atmos_status atmos__pfootprint_make(const atmos__pfootprint_desc *d, atmos__pfootprint *out)
{
    out->nx = d->nx, out->nz = d->nz;
    const size_t n = (size_t)d->nx * (size_t)d->nz;
    out->phi = malloc(sizeof(float) * (n ? n : 1));
    int *stack = malloc(sizeof(int) * (n ? n : 1));
    unsigned char *in = calloc(n ? n : 1, 1);
    if (!out->phi || !stack || !in) {
        free(out->phi), free(stack), free(in);
        out->phi = NULL;
        return ATMOS_E_NOMEM;
    }
    const int oct = atmos__gen_fractal_octaves(d->w, d->h);
    int start = -1;
    double best = INFINITY;
    for (int k = 0; k < d->nz; k++)
        for (int i = 0; i < d->nx; i++) {
            const double x = d->x0 + i * d->h - d->cx, z = d->z0 + k * d->h - d->cz;
            const double u = x / d->a, v = z / d->b, bu = x / d->reach_a, bv = z / d->reach_b;
            const double phi = atmos__gen_fractal_phi(d->seed, x / d->w, z / d->w, 1 - u * u - v * v, oct, ROUGH);
            const size_t q = (size_t)k * d->nx + i;
            const int core = 1 - u * u - v * v >= d->core; /* the core is never cut */
            out->phi[q] = (float)(core ? fmax(phi, 0.0) : phi);
            in[q] = (core || phi >= 0) && bu * bu + bv * bv < 1; /* inside the outline and its reach */
            if (in[q] && x * x + z * z < best) best = x * x + z * z, start = (int)q;
        }
    /* the flood: in[] 2 for the columns reached from the start */
    int top = 0;
    if (start >= 0) stack[top++] = start, in[start] = 2;
    while (top > 0) {
        const int q = stack[--top], i = q % d->nx, k = q / d->nx;
        const int nb[4] = {i > 0 ? q - 1 : -1, i + 1 < d->nx ? q + 1 : -1, k > 0 ? q - d->nx : -1,
                           k + 1 < d->nz ? q + d->nx : -1};
        for (int m = 0; m < 4; m++)
            if (nb[m] >= 0 && in[nb[m]] == 1) in[nb[m]] = 2, stack[top++] = nb[m];
    }
    for (size_t q = 0; q < n; q++)
        if (in[q] != 2) out->phi[q] = -1.0f;
    free(stack), free(in);
    return ATMOS_OK;
}

void atmos__pfootprint_free(atmos__pfootprint *f)
{
    free(f->phi);
    f->phi = NULL;
}
