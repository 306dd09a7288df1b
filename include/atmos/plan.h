/* Plans and frames: build once, render many (as FFTW's plan/execute split).
 *
 * A plan holds everything that depends only on a scene, its volume and their optics: the
 * atmosphere, the volume's placement, its resampled grids and majorants, the phase and Ams
 * tables, the renderer's buffers. A frame is what may change between two images of an
 * interactive session: the camera and image size, the sun's direction, the exposure, the
 * sample budget, the slicing quality. atmos_plan_render renders a frame and redoes only
 * what the change touches:
 *
 *   - nothing changed: the last image is returned (the path tracer goes on adding samples
 *     while the frame's budget is above what it has);
 *   - the camera moved: the per-pixel set-up, the sky and the passes;
 *   - the sun moved: also what depends on the sun alone (the slice renderer's light frame
 *     and the sunlight entering it, the path tracer's sky-light table);
 *   - never the volume's grids or the optics tables.
 *
 * In half-angle slicing (Riley et al. 2004 §5) the light buffer advances slice by slice in
 * step with the eye buffer along the half vector between the view and the light, so its
 * pass is part of every frame whose camera or sun moved.
 *
 *   atmos_plan *p;
 *   atmos_plan_create(ctx, &scene, NULL, NULL, &p);         // loads and places the volume
 *   atmos_frame f;
 *   atmos_frame_from_scene(ctx, &scene, &f);
 *   atmos_image *img;
 *   atmos_plan_image_create(p, &f, &img);
 *   for (int i = 0; i < 36; i++) {
 *       atmos_frame_orbit(&f, p, 10.0);                     // 10 degrees around the volume
 *       atmos_plan_render(p, &f, NULL, img, NULL);
 *   }
 *
 * Thread safety: one render at a time per plan (a plan keeps its buffers and caches); any
 * number of plans may share a volume and optics. Results do not depend on the thread count.
 * The context given at creation must outlive the plan; errors and progress go through it.
 */
#ifndef ATMOS_PLAN_H
#define ATMOS_PLAN_H

#include "atmos/base.h"
#include "atmos/slice.h"
#include "atmos/path.h"
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct atmos_plan atmos_plan;

/* Settings of a plan beyond its scene; zero means default for every field. */
typedef struct atmos_plan_desc {
    const atmos_volume_optics *optics; /* borrowed; NULL = built from the scene (atmos_volume_optics_build) */
    int offset_given;      /* nonzero: the volume moves by offset_m; zero: the scene's placement
                              (atmos_scene_volume_offset) */
    double offset_m[3];
    int reference;         /* slice: the plain scalar passes with libm's exp and the air in front
                              of the volume asked per pixel (for checks; slow) */
} atmos_plan_desc;

/* A frame: what may change between two images of one plan. */
typedef struct atmos_frame {
    atmos_camera_desc camera;
    int width, height;          /* pixels, 1..ATMOS_SCENE_MAX_DIM */
    double sun_dir[3];          /* unit vector toward the sun, world frame */
    int samples_per_pixel;      /* sky and slice renderers: stratified samples of the sky, 1..256, 0 = the scene's */
    int spp;                    /* path tracer: samples per pixel to reach (progressive), 1..ATMOS_PATH_MAX_SPP,
                                   0 = the scene's */
    int slices;                 /* slice renderer: sampling planes, 0 = the scene's */
    double eye_scale;           /* slice renderer: eye buffer scale in (0, 1] or 2, 0 = the scene's */
    int light_size;             /* slice renderer: the light buffer's side in texels for this frame, at most
                                   the scene's "light_size" (a larger one is the scene's), 0 = the scene's:
                                   the viewer's preview while the sun moves */
    int sky_step;               /* the sky behind the volume evaluated every sky_step pixels, 1..16, and read
                                   bilinearly where it is smooth (pinhole cameras, one sample a pixel;
                                   docs/viewer.md): the viewer's frames; 0 or 1 = every pixel */
    int sky_table;              /* 1: the sky behind the volume read bilinearly from a table over view directions
                                   (azimuth from the sun x elevation, crowded at the horizon; Hillaire 2020 §5.3)
                                   made for the eye's height and the sun, kept while they stay: at sky_step's
                                   grid nodes and the pixels it evaluates (within about one level of 255 of
                                   every pixel's; flat kinds, pinhole cameras, one sample a pixel; the viewer's
                                   frames: docs/viewer.md); 0 = the atmosphere evaluated */
    int no_air_shadows;         /* slice renderer: 1 leaves out the volume's shadow on the air and the ground
                                   (the scene's "air_shadows") for this frame: the viewer's moving preview; 0 */
    int warm_field;             /* slice renderer: 1 starts the diffuse field after a sun move from the last
                                   sun's (2-3 times faster, but the image then depends on the frames before it
                                   to the solver's tolerance: the viewer); 0 builds it afresh, so that a frame
                                   is the same however it was reached (renders, animations, MPI ranks; a
                                   field solved warm is solved again at the same sun for such a frame: the
                                   viewer's save). The Nishita renderer's discrete-ordinates field ("do") and
                                   Harris's diffuse field the same way */
    int hold_field;             /* slice renderer: 1 keeps the diffuse (or "do") field of the last sun solved for
                                   when the sun moved (no solve this frame; solved when the plan has none):
                                   the viewer's preview while the sun moves. The next frame without it
                                   solves the field for its sun (warm_field decides how), so that frame is
                                   the one it would have been without the held frames before it. Harris's
                                   renderer the same with its diffuse field (none solved yet: its forward
                                   shading alone until a frame without it); 0 */
    int impostor_budget;        /* Harris's renderer: at most this many impostors made again this frame, the
                                   most out of date first, the others drawn as they are until a later frame
                                   (the viewer's frames: the updates spread over frames); impostors never
                                   made come first, those beyond the budget made at a quarter of their
                                   resolution (cheap stand-ins, refined by later frames); a split cloud's
                                   parts always made; 0 = every stale one */
    double screen_layer_px;     /* Harris's renderer, a cloud holding the eye (drawn as a screen-sized impostor
                                   at 1/4 of the frame's resolution): > 0 splats its nearer particles into up
                                   to three coarser depth layers (1/8, 1/16, 1/32), a particle at the
                                   coarsest whose splat is still this many of its pixels in radius, laid over
                                   the 1/4 one bilinearly (the viewer's frames; docs/viewer.md); 0 = every
                                   particle at 1/4, as atmos render draws; else in [1, 1000] */
    int no_keep;                /* 1: the plan does not keep this frame's pixels for the next call (which copies
                                   them when nothing changed): a frame of a view that moves every frame (the
                                   viewer's scripted flights and previews; docs/viewer.md) saves the copy; the
                                   next frame of the same view is then rendered, and kept; 0 keeps it */
    atmos_tonemap_desc tonemap; /* the exposure: used where the image is displayed, not by the renderers */
    int no_check;               /* with no_keep: 1 leaves the check for NaN and infinities to the caller, who
                                   makes the frame's display values with atmos_image_display_checked (the
                                   viewer: one pass over the frame instead of two); 0: atmos_plan_render
                                   refuses such a frame itself (a kept frame is always checked there) */
} atmos_frame;

/* A rectangle of pixels [x0, x1) x [y0, y1). */
typedef struct atmos_region {
    int x0, y0, x1, y1;
} atmos_region;

/* Builds a plan for a scene: validates it, creates its atmosphere, loads or generates its
 * volume when volume is NULL and the scene names one (else uses volume, borrowed: it must
 * outlive the plan), places it, builds or borrows the optics. desc may be NULL. */
ATMOS_API atmos_status atmos_plan_create(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                         const atmos_plan_desc *desc, atmos_plan **out);
ATMOS_API void atmos_plan_destroy(atmos_plan *plan);

ATMOS_API atmos_renderer_kind atmos_plan_renderer(const atmos_plan *plan);
ATMOS_API const atmos_wavelengths *atmos_plan_wavelengths(const atmos_plan *plan);
ATMOS_API const atmos_atmosphere *atmos_plan_atmosphere(const atmos_plan *plan);
/* The optics of the plan's volume (NULL without one). */
ATMOS_API const atmos_volume_optics *atmos_plan_optics(const atmos_plan *plan);
/* The volume the plan renders (NULL if none) and the shift that places it. */
ATMOS_API const atmos_volume *atmos_plan_volume(const atmos_plan *plan, double offset_m[3]);

/* The scene's frame: its camera, image size, sun (computed from the time and place when the
 * scene gives them), samples, slicing and exposure. */
ATMOS_API atmos_status atmos_frame_from_scene(atmos_context *ctx, const atmos_scene *scene, atmos_frame *out);
/* Moves the camera by degrees around the vertical axis through the point it looks at (or,
 * for a plan with a volume, through the volume's centre at the look-at point's height). */
ATMOS_API void atmos_frame_orbit(atmos_frame *frame, const atmos_plan *plan, double degrees);

/* An image for the plan's frames: width x height, the plan's wavelength count + 1 channels. */
ATMOS_API atmos_status atmos_plan_image_create(const atmos_plan *plan, const atmos_frame *frame, atmos_image **out);

/* Renders a frame into out (created by atmos_plan_image_create for this frame's size):
 * spectral radiance per wavelength (W m^-2 sr^-1 nm^-1), then coverage alpha. With a region,
 * only its pixels are written (the rest of out is left as it was). The path tracer renders
 * frame->spp samples per pixel, reusing the samples it already has when only the budget
 * changed; the image is the same whether reached in one call or several. Reports progress
 * and honours cancellation through the plan's context. info may be NULL. A frame whose
 * image would hold a NaN or an infinity (a renderer bug: no valid scene may give one) fails
 * with ATMOS_E_UNSUPPORTED and a message counting them, rather than being returned. */
ATMOS_API atmos_status atmos_plan_render(atmos_plan *plan, const atmos_frame *frame, const atmos_region *region,
                                         atmos_image *out, atmos_render_info *info);

/* Work done by the last render. */
typedef struct atmos_plan_stats {
    int reused;                 /* 1: nothing changed, the last image was returned */
    int sun_changed, camera_changed;
    atmos_slice_timing slice;   /* slice renderer */
    atmos_path_stats path;      /* path tracer */
    int impostor_updates;       /* Harris's renderer: impostors made again this frame (one made over several
                                   frames counted in its first) */
    int impostors_held;         /* Harris's renderer: out-of-date impostors the frame's budget left as they
                                   were, and one drawn as it was while its new one is made over frames (the
                                   same frame rendered again makes them; not reused meanwhile) */
    int impostors_coarse;       /* Harris's renderer: impostors never made before that the frame's budget made
                                   at a quarter of their resolution (made in full by a later frame; not
                                   counted in impostor_updates) */
} atmos_plan_stats;
ATMOS_API void atmos_plan_get_stats(const atmos_plan *plan, atmos_plan_stats *out);

/* Path tracer: the per-pixel variance of the mean of the last render (per wavelength, then the
 * luminance's in the place of alpha), and the luminance-weighted mean number of volume
 * scattering events (1 channel); see atmos_path_settings. New images owned by the caller. */
ATMOS_API atmos_status atmos_plan_path_variance(const atmos_plan *plan, atmos_image **out);
ATMOS_API atmos_status atmos_plan_path_order(const atmos_plan *plan, atmos_image **out);

/* Renders a scene as `atmos render` does: the scene's renderer and settings, its volume
 * (loaded and placed from the scene when volume is NULL), the density scale, the atmosphere;
 * *out as atmos_plan_render's. The CLI and a C program (and, through this call, any binding)
 * give the same bytes for the same scene. One image: the scene's own sun; the frames of an
 * animation are atmos_scene_animation_frame's scenes, or frames of one plan. */
ATMOS_API atmos_status atmos_render_scene(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                          atmos_image **out, atmos_render_info *info);

#ifdef __cplusplus
}
#endif
#endif
