/* The diffuse light field over a render grid (dfield.c, docs/lightfield.md): the light that
 * Riley et al. 2004's forward model (Eq. 24/25) drops at each scattering, the side- and
 * back-scattered part, taken as the source of a diffuse field of all orders and solved by
 * diffusion on a grid coarser than the render grid (src/light/). Shared by the renderers
 * that add it in their eye passes: the slice renderer (its "diffuse" setting) and the Nishita
 * renderer (nishita "diffuse"). The medium on the field's grid is built once per plan, the
 * field once per sun direction, its view toward the eye once per frame. Not part of the API. */
#ifndef ATMOS_RENDER_DFIELD_H
#define ATMOS_RENDER_DFIELD_H

#include "atmosphere/atmosphere_ops.h"
#include "core/internal.h"
#include "light/lfield.h"
#include "render/slice_grid.h"
#include "render/slice_tables.h"
#include "volume/volume_access.h"

typedef struct {
    /* borrowed from the plan that owns the field (set by atmos__dfield_prepare) */
    const sgrid *g;          /* the render grid */
    const stables *tab;      /* the optics tables: cross-sections, F_n, B_n */
    const atmos__vol_xform *x; /* the volume's placement */
    const char *who;         /* the renderer, for messages ("render slice") */
    int n, nf;
    atmos__lmedium med;      /* the medium on the field's grid */
    float *dens;             /* [cell * nf + f]: each cell's mean density of each field */
    float fg[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* the fields' asymmetry g */
    atmos__lfield field;
    float *fade;             /* the field's weight per cell and wavelength, 0 where the medium is thin */
    int fade_any;            /* 0: every weight is 0 (no solve) */
    float *beam;             /* NULL, or [cell * n + w]: the forward beam's light that has been scattered
                                (Riley's beam less the unscattered sunlight), W m^-2 nm^-1, faded as the
                                field (atmos__dfield_update with want_beam) */
    float *view;             /* per frame: [(cell * nf + f) * vq + c], what a unit density of field f
                                scatters toward the eye, sca_f (L + g_f A) (atmos__dfield_view) */
    int vq;                  /* floats per cell and field in view: 4 for RGB (the fourth 0), else n */
} atmos__dfield;

/* The field's grid and medium from the render grid g and the tables tab (once per plan). */
atmos_status atmos__dfield_prepare(atmos_context *ctx, atmos__dfield *df, const sgrid *g, const stables *tab,
                                   const atmos__vol_xform *x, const atmos_volume_optics *o, const char *who);
void atmos__dfield_free(atmos__dfield *df);

/* The field brought up to date for the sun direction sun_w (world): a solve when the sun
 * moved, warm-started from the last one when warm, else from the coarse grids' cascade as
 * the first; *built: 1 if it solved, 0 if it kept the field. want_beam: also df->beam. */
atmos_status atmos__dfield_update(atmos_context *ctx, atmos__dfield *df, const atmos_atmosphere *atm,
                                  const double sun_w[3], int warm, int want_beam, int *built);

/* The field turned toward the eye at render-voxel coordinate eye: the field's L and A
 * (atmos__lfield_toward) and df->view. */
void atmos__dfield_view(atmos__dfield *df, const double eye[3], int threads);

#endif
