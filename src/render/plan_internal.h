/* The plan (plan.c) and the renderers' parts of it. Data flows one way: a scene makes a plan
 * (plan.c: the atmosphere, the placed volume, the optics; each renderer's tables and
 * buffers), a frame makes a view (view.h), and a renderer renders the view from its plan.
 * Not part of the API. */
#ifndef ATMOS_RENDER_PLAN_INTERNAL_H
#define ATMOS_RENDER_PLAN_INTERNAL_H

#include "render/view.h"

typedef struct atmos__slice_plan atmos__slice_plan;
typedef struct atmos__path_plan atmos__path_plan;
typedef struct atmos__nishita_plan atmos__nishita_plan;
typedef struct atmos__harris_plan atmos__harris_plan;
typedef struct atmos__beams_plan atmos__beams_plan;

struct atmos_plan {
    atmos_context *ctx;
    atmos_renderer_kind renderer;
    atmos_scene scene;                  /* validated; the renderers read their settings here */
    atmos_wavelengths wl;
    atmos_atmosphere *atm;
    const atmos_volume *volume;         /* NULL: none */
    atmos_volume *own_volume;           /* loaded by the plan */
    double offset[3];                   /* the volume's placement */
    const atmos_volume_optics *optics;  /* NULL without a volume */
    atmos_volume_optics own_optics;
    int reference;
    /* The last frame rendered and its pixels (sky and slice renderers: returned again when
     * nothing changed). */
    int have_last;                       /* last_view is the last frame rendered */
    int have_pixels;                     /* and last_pixels its pixels over last_rect */
    atmos__view last_view;
    atmos__rect last_rect;
    float *last_pixels;
    size_t last_cap;
    atmos_plan_stats stats;
    atmos__sky_keep *sky_keep;          /* the sky's per-eye tables (sky and slice renderers) */
    atmos__slice_plan *slice;
    atmos__path_plan *path;
    atmos__nishita_plan *nishita;
    atmos__harris_plan *harris;
    atmos__beams_plan *beams;
};

/* The slice renderer's part (slice_plan.c): the render grid, the optics tables, the buffers
 * kept between frames, the per-sun light cache. */
atmos_status atmos__slice_plan_create(atmos_plan *p, atmos__slice_plan **out);
void atmos__slice_plan_destroy(atmos__slice_plan *s);
/* Renders the view into out over r: the sky, the volume by half-angle slicing, the §5
 * composite; fills timing. */
atmos_status atmos__slice_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out,
                                 atmos_slice_timing *timing);
/* The image metadata line of the slice settings used. */
void atmos__slice_describe(const atmos_plan *p, const atmos__view *v, char *buf, size_t cap);

/* The path tracer's part (path_plan.c): the medium, the phase tables, the sky-light table of
 * the last sun, the accumulator of the last view. */
atmos_status atmos__path_plan_create(atmos_plan *p, atmos__path_plan **out);
void atmos__path_plan_destroy(atmos__path_plan *s);
/* Adds samples until every pixel of r has v->spp (starting again when the view changed),
 * then writes the means into out; fills stats. */
atmos_status atmos__path_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out,
                                atmos_path_stats *stats);
atmos_status atmos__path_variance(const atmos_plan *p, atmos_image **out);
atmos_status atmos__path_order(const atmos_plan *p, atmos_image **out);
void atmos__path_describe(const atmos_plan *p, char *buf, size_t cap);

/* The Nishita renderer's part (nishita_plan.c): the render grid, the optics, the sunlight's
 * attenuation per voxel and the light field, each kept until the sun (or the eye's direction)
 * changes. */
atmos_status atmos__nishita_plan_create(atmos_plan *p, atmos__nishita_plan **out);
void atmos__nishita_plan_destroy(atmos__nishita_plan *s);
/* The sky, then the volume by eye rays over it, over the pixels of r (nishita_render.c). */
atmos_status atmos__nishita_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out);
void atmos__nishita_describe(const atmos_plan *p, char *buf, size_t cap);

/* Harris's particle renderer (harris_render.c): the volume's particles, their light from the
 * sun and the sky lights (kept until the sun moves). */
atmos_status atmos__harris_plan_create(atmos_plan *p, atmos__harris_plan **out);
void atmos__harris_plan_destroy(atmos__harris_plan *h);
/* The sky, then the particles splatted over it, over the pixels of r. */
atmos_status atmos__harris_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out);
void atmos__harris_describe(const atmos_plan *p, char *buf, size_t cap);

/* The beam renderer (beams_plan.c, beams_render.c; Dobashi et al. 2002 §4): the scene's
 * objects, lights with their shadow maps, the fog's scattering table. */
atmos_status atmos__beams_plan_create(atmos_plan *p, atmos__beams_plan **out);
/* The beam renderer's memory for a width x height image of that many wavelengths, in bytes
 * (beams_memory.c); the check refuses (ATMOS_E_LIMIT) an image needing more than the machine's
 * physical memory, with the estimate and what lowers it, and warns above half of it. */
double atmos__beams_memory_estimate(int width, int height, int wavelengths);
atmos_status atmos__beams_memory_check(atmos_context *ctx, int width, int height, int wavelengths);
void atmos__beams_plan_destroy(atmos__beams_plan *b);
/* The sky, then the objects and the light the fog scatters, over the pixels of r. */
atmos_status atmos__beams_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out);
void atmos__beams_describe(const atmos_plan *p, char *buf, size_t cap);
/* atmos__beams_render with the frame's samples per pixel N as n x n rays a pixel, n =
 * round(sqrt(N)) (beams_antialias.c); N = 1 (the default): one ray through each centre. */
atmos_status atmos__beams_render_spp(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out);
int atmos__beams_rays_per_side(int samples_per_pixel);

#endif
