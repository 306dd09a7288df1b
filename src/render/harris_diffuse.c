/* Harris's particle renderer with the diffuse light field (harris "diffuse", docs/particles.md):
 * Harris 2002's light passes keep the light scattered forward (Eq. 5-8, the multiple forward
 * scattering toward the light) and lose the light scattered sideways and back, which in a
 * dense cloud stays and diffuses. The slice renderer's field (dfield.c) holds exactly that
 * light: solved once per sun direction on the volume's grid (the grid the particles were made
 * from, or, for Harris's own generated clouds, the grid they were summed to), it is read at each
 * particle's centre and what it scatters toward the eye, albedo (L + g A) per wavelength (the
 * particle's colour is a source function: its scattered radiance over its extinction), added
 * to the particle's colour. */
#include "render/harris_internal.h"

#include <stdlib.h>
#include <string.h>

#define GRID_CAP 256 /* render voxels per axis at most, as the Nishita renderer's */

atmos_status atmos__harris_diffuse_prepare(atmos_plan *p, atmos__harris_plan *h)
{
    if (!p->scene.harris.diffuse) return ATMOS_OK;
    atmos_context *ctx = p->ctx;
    atmos__vol_xform_init(p->volume, p->offset, &h->x);
    atmos_status st = atmos__sgrid_build(ctx, p->volume, p->scene.volume.density_scale, GRID_CAP, &h->g);
    if (st != ATMOS_OK || !h->g.v) return st; /* an empty volume: nothing to light */
    if ((st = atmos__stables_build(ctx, p->optics, h->o.nw, 2, &h->tab)) != ATMOS_OK) return st;
    if ((st = atmos__dfield_prepare(ctx, &h->df, &h->g, &h->tab, &h->x, p->optics, "render harris")) != ATMOS_OK)
        return st;
    if (!(h->dview = calloc((size_t)(h->pc.n ? h->pc.n : 1) * h->o.nw, sizeof(float))))
        return atmos__error(ctx, ATMOS_E_NOMEM, "render harris: out of memory for the diffuse light field");
    h->diffuse = 1;
    return ATMOS_OK;
}

void atmos__harris_diffuse_free(atmos__harris_plan *h)
{
    atmos__dfield_free(&h->df);
    atmos__stables_free(&h->tab);
    atmos__sgrid_free(&h->g);
    free(h->dview);
}

atmos_status atmos__harris_diffuse_sun(atmos_plan *p, atmos__harris_plan *h, const atmos__view *v)
{
    const int cold_asked = !v->warm_field && h->df.field.warm && !v->hold_field; /* a save after warm starts */
    if (!h->diffuse || (h->field_ok && !memcmp(h->field_sun, v->sun, sizeof h->field_sun) && !cold_asked))
        return ATMOS_OK;
    const int was = h->field_ok;
    if (v->hold_field) { /* the viewer's moving sun: the last sun's field, or the forward shading alone */
        if (h->df.field.valid == was) return ATMOS_OK;
        h->field_ok = h->df.field.valid;
    } else {
        int built; /* warm: from the last sun's field (2-3 times fewer sweeps), the viewer's frames */
        atmos_status st = atmos__dfield_update(p->ctx, &h->df, p->atm, v->sun, v->warm_field, 0, &built);
        if (st != ATMOS_OK) return st;
        memcpy(h->field_sun, v->sun, sizeof h->field_sun);
        h->field_ok = 1;
        if (!built && was) return ATMOS_OK; /* the same field as drawn */
    }
    for (int k = 0; k < h->clouds.n; k++) h->imp[k].valid = 0; /* what the particles show has changed */
    for (int k = 0; h->split && k < 2 * h->clouds.n; k++) h->split[k].valid = 0;
    h->spreading = 0;
    return ATMOS_OK;
}

int atmos__harris_diffuse_eye(const atmos_plan *p, atmos__harris_plan *h, const double eye_w[3])
{
    if (!h->diffuse || !h->field_ok) return 0;
    if (h->eye_done) return 1;
    const sgrid *g = &h->g;
    double rel[3], eg[3], eu[3];
    for (int a = 0; a < 3; a++) rel[a] = eye_w[a] - h->x.org[a];
    atmos__vol_dir_to_frame(&h->x, rel, eg);
    for (int a = 0; a < 3; a++) eu[a] = eg[a] * g->sc + g->off[a];
    atmos__dfield_view(&h->df, eu, atmos__threads(p->ctx)); /* the field's L and A toward the eye */
    h->eye_done = 1;
    return 1;
}

void atmos__harris_diffuse_at(atmos__harris_plan *h, int i)
{
    const int nw = h->o.nw;
    const sgrid *g = &h->g;
    const atmos__lfield *fl = &h->df.field;
    const double d[3] = {h->pc.x[i] - h->x.org[0], h->pc.y[i] - h->x.org[1], h->pc.z[i] - h->x.org[2]};
    double q[3];
    atmos__vol_dir_to_frame(&h->x, d, q);
    float la[2 * ATMOS_MAX_WAVELENGTHS];
    atmos__lfield_sample(fl, fl->LA, 2 * nw, (float)(q[0] * g->sc + g->off[0]), (float)(q[1] * g->sc + g->off[1]),
                         (float)(q[2] * g->sc + g->off[2]), la);
    const int f = h->pc.field[i];
    for (int k = 0; k < nw; k++) {
        const float s = la[k] + h->df.fg[f][k] * la[nw + k];
        h->dview[(size_t)i * nw + k] = s > 0.0f ? (float)(h->o.albedo[f][k] * s) : 0.0f;
    }
}
