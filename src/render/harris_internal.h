/* Harris's particle renderer's part of a plan (harris_plan.c: the particles, their clouds,
 * the light passes; harris_frame.c: a frame). Internal to src/render/. */
#ifndef ATMOS_RENDER_HARRIS_INTERNAL_H
#define ATMOS_RENDER_HARRIS_INTERNAL_H

#include "atmosphere/atmosphere_ops.h"
#include "particles/pcloud.h"
#include "render/dfield.h"
#include "render/plan_internal.h"

#define ATMOS__HARRIS_MAX_LIGHTS 17

/* The scene's objects in Harris's renderer (harris_objects.c). */
typedef struct atmos__harris_objects {
    int n;                               /* meshes */
    atmos_mesh **mesh;
    double (*albedo)[ATMOS_MAX_WAVELENGTHS];
    int nv;                              /* vertices of all meshes: the light passes' probes */
    float *xyz;                          /* [3 nv] */
    int *first;                          /* [n + 1]: mesh m's vertices are first[m] .. */
    float *light[ATMOS__HARRIS_MAX_LIGHTS]; /* [nv nw]: the share of light j the clouds leave at each vertex */
    double centre[3], radius;            /* the sphere about all of them: the split is at its centre */
    /* the last frame's layer over box [x0, x1) x [y0, y1): per pixel the nearest distance to a
     * surface (INFINITY: none), the share of the pixel covered (2 x 2 rays) and the radiance
     * seen through the air, premultiplied by the coverage */
    float *depth, *cover, *col;
    size_t cap;
    int box[4];
} atmos__harris_objects;

atmos_status atmos__harris_objects_create(atmos_plan *p, atmos__harris_objects **out);
void atmos__harris_objects_destroy(atmos__harris_objects *ob);
/* The objects' layer of view v within rect (ap: the frame's aerial-perspective volume or NULL),
 * the light passes done (h->light's probes in ob->light). */
atmos_status atmos__harris_objects_frame(const atmos_plan *p, const atmos__harris_plan *h, atmos__harris_objects *ob,
                                         const atmos__view *v, const atmos__aerial *ap, const int rect[4]);
/* Lays the layer over img: pixel (1 - coverage) + colour (the surfaces are opaque). */
void atmos__harris_objects_over(atmos_context *ctx, const atmos__harris_objects *ob, int nw, const atmos_camera *cam,
                                atmos_image *img);

/* The most frames a large impostor's make is spread over. */
#define ATMOS__HARRIS_SPREAD_MAX 8

struct atmos__harris_plan {
    atmos__pcloud pc;
    atmos__poptics o;
    atmos__pclusters clouds;             /* the particles' clouds (the impostors') */
    atmos__pimpostor *imp;               /* [clouds.n] */
    atmos__harris_objects *obj;          /* NULL: the scene has no objects */
    atmos__pimpostor *split;             /* [2 clouds.n] with objects: each cloud's far and near impostors */
    int *part;                           /* [pc.n] this frame's split clouds' particles, far ones first */
    int *nfar;                           /* [clouds.n] how many of those are far */
    double *offset;                      /* [clouds.n] the split distance less the cloud centre's, this frame */
    double *smin;                        /* [clouds.n] each cloud's narrowest particle width (impostor texels, split) */
    int splits;                          /* clouds split this frame */
    double split_m;                      /* this frame's split distance (INFINITY: none) */
    int nlights;                         /* the sun, then the sky lights */
    double dir[ATMOS__HARRIS_MAX_LIGHTS][3];           /* toward each light */
    double e[ATMOS__HARRIS_MAX_LIGHTS][ATMOS_MAX_WAVELENGTHS]; /* its irradiance outside the cloud */
    float *light[ATMOS__HARRIS_MAX_LIGHTS], *order[ATMOS__HARRIS_MAX_LIGHTS];
    float *air_t, *air_l;                /* the air from the eye to each particle, this frame */
    atmos__aerial aerial;
    /* a large impostor made over frames (harris_frame.c): while spreading, cloud spread_k's
     * whole impostor made into spread from the eye of its first frame, piece spread_at of
     * spread_pieces (rows [spread_cut[j], spread_cut[j + 1])) a frame, its old one drawn until
     * it is done */
    atmos__pimpostor spread;
    int spreading, spread_k, spread_res, spread_at, spread_pieces, spread_cut[ATMOS__HARRIS_SPREAD_MAX + 1];
    double spread_eye[3];
    double sun[3];
    int have_sun, drawn, updates, direct, held, coarse;
    double shade_s;
    /* "diffuse" (harris_diffuse.c): the diffuse light field on the volume's grid, and per particle
     * what it scatters toward this frame's eye ([p * nw + k]; the splats' atmos__plights.diffuse) */
    int diffuse;
    int field_ok;                        /* the field is drawn this frame (0: Harris's forward shading alone) */
    int eye_done;                        /* the field turned toward this frame's eye (0 at a frame's start) */
    double field_sun[3];                 /* the sun the field was solved for (field_ok) */
    sgrid g;
    stables tab;
    atmos__vol_xform x;
    atmos__dfield df;
    float *dview;
};

/* Impostor splitting (harris_split.c): where each cloud goes this frame. */
enum { ATMOS__HARRIS_NEAR = 0, ATMOS__HARRIS_FAR = 1, ATMOS__HARRIS_SPLIT = 2 };
/* The split of view v (the objects' layer made): h->split_m the distance from the eye to the
 * objects' centre (INFINITY: no objects in view), side[k] each cloud's (how[k]: 0 for a cloud out
 * of view): NEAR drawn whole after the objects, FAR whole before them, SPLIT its far particles
 * before and its near ones after (h->part, h->nfar, h->offset). */
void atmos__harris_split(atmos__harris_plan *h, const atmos__view *v, const int rect[4], const int *how, int *side);
/* What cloud k (drawn by how, on side) shows in pass 0 (before the objects) or 1 (after): its
 * impostor *im (whole or the part's) and its particles idx[0..n) of the part; returns how, or 0
 * when it shows nothing in that pass. */
int atmos__harris_piece(const atmos__harris_plan *h, int k, int pass, int how, int side, const atmos__pimpostor **im,
                        const int **idx, int *n);

/* The light passes of the sun sun and the sky lights (harris_plan.c); the impostors become
 * stale. */
atmos_status atmos__harris_lights(atmos_plan *p, atmos__harris_plan *h, const double sun[3]);

/* The diffuse light field (harris_diffuse.c): its grid and medium once per plan (nothing
 * unless the scene's "diffuse"), the field per sun direction (view v's sun, warm-started with
 * v->warm_field; with v->hold_field the last sun's field kept, or none drawn before the first
 * solve; the impostors made stale when the field drawn changes); per frame, only when particles
 * are splatted, the field turned toward the eye eye_w once (_eye: 0 when no field is drawn) and
 * its light toward it at each particle splatted (_at: h->dview[i]). */
atmos_status atmos__harris_diffuse_prepare(atmos_plan *p, atmos__harris_plan *h);
void atmos__harris_diffuse_free(atmos__harris_plan *h);
atmos_status atmos__harris_diffuse_sun(atmos_plan *p, atmos__harris_plan *h, const atmos__view *v);
int atmos__harris_diffuse_eye(const atmos_plan *p, atmos__harris_plan *h, const double eye_w[3]);
void atmos__harris_diffuse_at(atmos__harris_plan *h, int i);

/* The bytes a particle type's phase table (particles/pphase.h) may take in a plan:
 * ATMOS__PPHASE_MAX_BYTES; a test lowers it to see the exact look-up past the cap. */
extern size_t atmos__harris_pphase_max_bytes;

#endif
