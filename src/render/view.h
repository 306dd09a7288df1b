/* A frame resolved for the renderers (plan.c builds it from an atmos_frame): the camera
 * built for the image, the sun's direction and the frame's budgets with the scene's values
 * filled in. Renderers take this, never a scene. Not part of the API. */
#ifndef ATMOS_RENDER_VIEW_H
#define ATMOS_RENDER_VIEW_H

#include "core/internal.h"

typedef struct atmos__view {
    atmos_camera cam;          /* width x height pixels */
    double sun[3];             /* unit vector toward the sun */
    int samples_per_pixel;     /* stratified samples of the sky, 1..256 */
    int spp;                   /* path tracer: samples per pixel to reach */
    int slices;                /* slice renderer: sampling planes */
    double eye_scale;          /* slice renderer: eye buffer scale, (0, 1] or 2 */
    int light_size;            /* slice renderer: light buffer side, 0 = the scene's (at most the scene's) */
    int sky_step;              /* the sky background every sky_step pixels (1: every pixel) */
    int sky_table;             /* the sky background from a table over view directions (sky_view.h) */
    int no_air_shadows;        /* slice renderer: the volume's shadow on the air left out this frame */
    int warm_field;            /* slice renderer: the diffuse field warm-started from the last sun's */
    int hold_field;            /* slice renderer: the last solved sun's diffuse field kept, not solved */
    int impostor_budget;       /* Harris's renderer: impostors made again this frame at most (0: all stale) */
    double screen_layer_px;    /* Harris's renderer: the screen-sized impostor's coarser layers (0: none) */
} atmos__view;

/* A region clipped to the image: [x0, x1) x [y0, y1), never empty unless the image is. */
typedef struct atmos__rect {
    int x0, y0, x1, y1;
} atmos__rect;

/* What the sky renderer keeps between the frames of one plan: the atmosphere's per-eye
 * tables, built again only when the eye or the sun moved enough to change them. */
typedef struct atmos__sky_keep atmos__sky_keep;
atmos__sky_keep *atmos__sky_keep_create(void);
void atmos__sky_keep_destroy(atmos__sky_keep *k);

/* The sky renderer (sky_render.c): what every view ray sees of the atmosphere, the sun's
 * disk antialiased, over the pixels of r, written into out (width x height x count + 1
 * channels: radiance per wavelength, coverage alpha). Reports progress as "render sky".
 * keep: the plan's (NULL: the per-eye tables are built for this frame alone). */
atmos_status atmos__sky_render(atmos_context *ctx, const atmos_atmosphere *atm, const atmos__view *v,
                               const atmos__rect *r, atmos_image *out, atmos__sky_keep *keep);
/* The same, where hidden (NULL: nowhere) marks the pixels of r (row by row, non-zero: hidden
 * by a caller's surface) whose sky the caller will not show: on the grid of every sky_step
 * pixels those are read bilinearly instead of being evaluated one by one (the grid itself and
 * every other pixel as atmos__sky_render makes them, so the same bits there). */
atmos_status atmos__sky_render_hidden(atmos_context *ctx, const atmos_atmosphere *atm, const atmos__view *v,
                                      const atmos__rect *r, atmos_image *out, atmos__sky_keep *keep,
                                      const unsigned char *hidden);

#endif
