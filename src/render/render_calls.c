/* The one-call renderers (atmos_render_scene in plan.h; render.h, slice.h, path.h): a plan made
 * for one frame of the scene and destroyed. A caller rendering many frames keeps the plan. */
#include "render/plan_internal.h"

#include <string.h>

/* A plan for one frame of the scene, rendered into a new image. */
static atmos_status render_once(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                const atmos_plan_desc *desc, atmos_image **out, atmos_render_info *info,
                                atmos_plan **keep)
{
    atmos_plan *p = NULL;
    atmos_frame f;
    atmos_image *img = NULL;
    atmos_status st = atmos_plan_create(ctx, scene, volume, desc, &p);
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, scene, &f);
    if (st == ATMOS_OK) st = atmos_plan_image_create(p, &f, &img);
    if (st == ATMOS_OK) st = atmos_plan_render(p, &f, NULL, img, info);
    if (st != ATMOS_OK) {
        atmos_plan_destroy(p);
        atmos_image_destroy(img);
        return st;
    }
    *out = img;
    if (keep) *keep = p;
    else atmos_plan_destroy(p);
    return ATMOS_OK;
}

atmos_status atmos_render_scene(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                atmos_image **out, atmos_render_info *info)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render scene: missing scene or output");
    *out = NULL;
    return render_once(ctx, scene, volume, NULL, out, info, NULL);
}

atmos_status atmos_render_sky(atmos_context *ctx, const atmos_scene *scene, atmos_image **out, atmos_render_info *info)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render: missing scene or output");
    *out = NULL;
    atmos_scene s = *scene; /* the sky of any scene, whatever renderer it names */
    s.renderer = ATMOS_RENDERER_SKY;
    s.volume.source[0] = '\0';
    return render_once(ctx, &s, NULL, NULL, out, info, NULL);
}

void atmos_slice_defaults(atmos_slice_settings *s) { memset(s, 0, sizeof *s); }

atmos_status atmos_render_slice(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                const atmos_slice_settings *settings, atmos_image **out, atmos_render_info *info)
{
    if (!scene || !volume || !out)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render slice: missing scene, volume or output");
    *out = NULL;
    atmos_slice_settings ss;
    atmos_slice_defaults(&ss);
    if (settings) ss = *settings;
    atmos_scene s = *scene;
    s.renderer = ATMOS_RENDERER_SLICE;
    atmos_plan_desc d = {ss.optics, 1, {ss.offset_m[0], ss.offset_m[1], ss.offset_m[2]}, ss.reference};
    atmos_plan *p = NULL;
    atmos_status st = render_once(ctx, &s, volume, &d, out, info, &p);
    if (st != ATMOS_OK) return st;
    if (ss.timing) *ss.timing = p->stats.slice;
    atmos_plan_destroy(p);
    return ATMOS_OK;
}

void atmos_path_defaults(atmos_path_settings *s) { memset(s, 0, sizeof *s); }

atmos_status atmos_render_path(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                               const atmos_path_settings *settings, atmos_image **out, atmos_render_info *info)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "render path: missing scene or output");
    *out = NULL;
    atmos_path_settings ps;
    atmos_path_defaults(&ps);
    if (settings) ps = *settings;
    if (ps.variance) *ps.variance = NULL;
    if (ps.order) *ps.order = NULL;
    atmos_scene s = *scene;
    s.renderer = ATMOS_RENDERER_PATH;
    if (!volume) s.volume.source[0] = '\0'; /* the atmosphere and the ground alone */
    atmos_plan_desc d = {ps.optics, 1, {ps.offset_m[0], ps.offset_m[1], ps.offset_m[2]}, 0};
    atmos_plan *p = NULL;
    atmos_status st = render_once(ctx, &s, volume, &d, out, info, &p);
    if (st != ATMOS_OK) return st;
    if (ps.stats) *ps.stats = p->stats.path;
    if (ps.variance) st = atmos_plan_path_variance(p, ps.variance);
    if (st == ATMOS_OK && ps.order) st = atmos_plan_path_order(p, ps.order);
    atmos_plan_destroy(p);
    if (st != ATMOS_OK) {
        atmos_image_destroy(*out);
        *out = NULL;
        if (ps.variance) atmos_image_destroy(*ps.variance), *ps.variance = NULL;
    }
    return st;
}
