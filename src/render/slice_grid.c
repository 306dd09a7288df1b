/* The slice renderer's render grid (slice_grid.h): the volume box-filtered onto a dense
 * grid with an occupancy grid for empty-space skipping. The volume is read through the
 * accessor (volume/volume_access.h): its occupied-brick box, "for each occupied brick"
 * and its transform's voxel size. */
#include "render/slice_internal.h"
#include "volume/volume_access.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

void atmos__sgrid_free(sgrid *g)
{
    free(g->v);
    free(g->occ);
    memset(g, 0, sizeof *g);
}

#define SLICE_MAX_GRID_BYTES ((uint64_t)2 << 30)

atmos_status atmos__sgrid_build(atmos_context *ctx, const atmos_volume *vol, double scale, int cap, sgrid *g)
{
    memset(g, 0, sizeof *g);
    const int nf = vol->nfields;
    g->nf = nf;
    int blo[3], bhi[3];
    if (!atmos__vol_occupied_box(vol, blo, bhi)) return ATMOS_OK; /* empty volume: g->v stays NULL */
    int lo[3], ext[3], emax = 1;
    for (int a = 0; a < 3; a++) {
        lo[a] = blo[a] * VOL_BRICK;
        int hi = (bhi[a] + 1) * VOL_BRICK;
        if (hi > vol->desc.dims[a]) hi = vol->desc.dims[a];
        ext[a] = hi - lo[a];
        if (ext[a] > emax) emax = ext[a];
    }
    int fac = (emax + (cap - 2) - 1) / (cap - 2);
    if (fac < 1) fac = 1;
    uint64_t nvox = 1;
    for (int a = 0; a < 3; a++) {
        g->c[a] = (ext[a] + fac - 1) / fac + 2;
        nvox *= (uint64_t)g->c[a];
    }
    if (nvox * (uint64_t)nf * sizeof(float) > SLICE_MAX_GRID_BYTES)
        return atmos__error(ctx, ATMOS_E_LIMIT, "slice: render grid %dx%dx%d x %d fields exceeds %llu bytes", g->c[0],
                            g->c[1], g->c[2], nf, (unsigned long long)SLICE_MAX_GRID_BYTES);
    g->v = atmos__big_alloc(nvox * (uint64_t)nf * sizeof(float));
    if (g->v) memset(g->v, 0, nvox * (uint64_t)nf * sizeof(float));
    for (int a = 0; a < 3; a++) g->ob[a] = (g->c[a] - 2) / SLICE_OCC_B + 1;
    g->occ = calloc((size_t)g->ob[0] * g->ob[1] * g->ob[2], sizeof *g->occ);
    if (!g->v || !g->occ) {
        atmos__sgrid_free(g);
        return atmos__error(ctx, ATMOS_E_NOMEM, "slice: out of memory for the render grid");
    }
    /* Box filter: every native voxel of every occupied brick adds to its render voxel. */
    for (int f = 0; f < nf; f++) {
        atmos__vol_brick_it it = {0};
        while (atmos__vol_next_brick(vol, f, &it)) {
            const float *br = it.data;
            const int bx = it.o[0], by = it.o[1], bz = it.o[2];
            for (int k = 0; k < VOL_BRICK; k++)
                for (int j = 0; j < VOL_BRICK; j++)
                    for (int i = 0; i < VOL_BRICK; i++) {
                        float val = br[(k * VOL_BRICK + j) * VOL_BRICK + i];
                        if (val == 0.0f) continue;
                        int ci = (bx + i - lo[0]) / fac + 1, cj = (by + j - lo[1]) / fac + 1,
                            ck = (bz + k - lo[2]) / fac + 1;
                        if (ci >= g->c[0] - 1 || cj >= g->c[1] - 1 || ck >= g->c[2] - 1) continue;
                        g->v[(((size_t)ck * g->c[1] + cj) * g->c[0] + ci) * nf + f] += val;
                    }
        }
    }
    const float norm = (float)(scale / ((double)fac * fac * fac));
    for (uint64_t p = 0; p < nvox; p++) {
        int any = 0;
        for (int f = 0; f < nf; f++) {
            g->v[p * nf + f] *= norm;
            any |= g->v[p * nf + f] > 0.0f;
        }
        if (!any) continue;
        int ci = (int)(p % (uint64_t)g->c[0]), cj = (int)((p / (uint64_t)g->c[0]) % (uint64_t)g->c[1]),
            ck = (int)(p / ((uint64_t)g->c[0] * g->c[1]));
        /* A sample whose lower corner is i0 reads voxels i0 and i0+1: mark i0 = c-1, c. */
        for (int dk = -1; dk <= 0; dk++)
            for (int dj = -1; dj <= 0; dj++)
                for (int di = -1; di <= 0; di++) {
                    int a = ci + di, bq = cj + dj, cq = ck + dk;
                    if (a < 0 || bq < 0 || cq < 0 || a > g->c[0] - 2 || bq > g->c[1] - 2 || cq > g->c[2] - 2) continue;
                    g->occ[((size_t)(cq / SLICE_OCC_B) * g->ob[1] + bq / SLICE_OCC_B) * g->ob[0] + a / SLICE_OCC_B] = 1;
                }
    }
    /* Render voxel c covers native [lo + (c-1) fac, lo + c fac); its centre is u = c. */
    const double vs = atmos__vol_xform_of(vol)->vs;
    g->sc = (float)(1.0 / (vs * fac));
    for (int a = 0; a < 3; a++) {
        g->off[a] = (float)(0.5 - (double)lo[a] / fac);
        /* u = (q - lo)/fac + 0.5 with q = g/vs; nonzero for u in (0, c-1). */
        g->box_lo[a] = ((double)lo[a] - 0.5 * fac) * vs;
        g->box_hi[a] = ((double)lo[a] + (g->c[a] - 1.5) * fac) * vs;
    }
    return ATMOS_OK;
}
