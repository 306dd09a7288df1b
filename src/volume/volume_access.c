/* The out-of-line parts of the volume accessor (volume_access.h): the transform's set-up
 * and its inverse direction, the occupied-brick boxes and the occupied-brick iterator. */
#include "volume/volume_access.h"

#include <string.h>

void atmos__vol_xform_init(const atmos_volume *v, const double offset[3], atmos__vol_xform *x)
{
    for (int a = 0; a < 3; a++) x->org[a] = offset ? v->desc.origin_m[a] + offset[a] : v->desc.origin_m[a];
    memcpy(x->R, v->desc.rotation, sizeof x->R);
    x->vs = v->desc.voxel_size_m;
    x->inv_vs = 1.0 / v->desc.voxel_size_m;
}

void atmos__vol_frame_to_point(const atmos__vol_xform *x, const double g[3], double p[3])
{
    const double *r = x->R;
    for (int a = 0; a < 3; a++) p[a] = x->org[a] + r[3 * a] * g[0] + r[3 * a + 1] * g[1] + r[3 * a + 2] * g[2];
}

void atmos__vol_index_to_point(const atmos__vol_xform *x, const double q[3], double p[3])
{
    const double s[3] = {q[0] * x->vs, q[1] * x->vs, q[2] * x->vs};
    atmos__vol_frame_to_point(x, s, p);
}

void atmos__vol_index_to_dir(const atmos__vol_xform *x, const double qd[3], double d[3])
{
    const double *r = x->R;
    const double s[3] = {qd[0] * x->vs, qd[1] * x->vs, qd[2] * x->vs};
    for (int a = 0; a < 3; a++) d[a] = r[3 * a] * s[0] + r[3 * a + 1] * s[1] + r[3 * a + 2] * s[2];
}

static int copy_box(const int blo[3], const int bhi[3], int lo[3], int hi[3])
{
    if (bhi[0] < blo[0]) return 0;
    for (int a = 0; a < 3; a++) {
        lo[a] = blo[a];
        hi[a] = bhi[a];
    }
    return 1;
}

int atmos__vol_occupied_box(const atmos_volume *v, int lo[3], int hi[3]) { return copy_box(v->occ_lo, v->occ_hi, lo, hi); }

int atmos__vol_range_box(const atmos_volume *v, int lo[3], int hi[3]) { return copy_box(v->rng_lo, v->rng_hi, lo, hi); }

int atmos__vol_next_brick(const atmos_volume *v, int field, atmos__vol_brick_it *it)
{
    const vol_field *fl = &v->field[field];
    if (!fl->count) return 0;
    for (uint64_t b = it->next; b < v->nbricks; b++) {
        const uint32_t s = fl->table[b];
        if (!s) continue;
        it->next = b + 1;
        it->o[0] = (int)(b % (uint64_t)v->nb[0]) * VOL_BRICK;
        it->o[1] = (int)((b / (uint64_t)v->nb[0]) % (uint64_t)v->nb[1]) * VOL_BRICK;
        it->o[2] = (int)(b / ((uint64_t)v->nb[0] * (uint64_t)v->nb[1])) * VOL_BRICK;
        it->data = vol_brick_data(v, s);
        return 1;
    }
    it->next = v->nbricks;
    return 0;
}
