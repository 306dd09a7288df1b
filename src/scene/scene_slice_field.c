/* The slice renderer's field of the light scattered more than once ("field", scene.h
 * atmos_slice_field): which one a scene's settings select, and the settings that contradict
 * the one chosen. The old keys stay: "do": true is field do, "diffuse": false is field none
 * (a file's "do": false without "field" is field p1: scene_json.c); with field auto (the
 * default) a setting of Riley's path (xi, update, low_albedo) selects that path. So a scene file
 * written before do was the default renders as it did when it set one of these; one that set
 * none of them renders with the do field. */
#include "scene/scene_internal.h"

#include <stdio.h>
#include <string.h>

/* indexed by atmos_slice_field; the names: atmos_slice_field_name (the settings table's) */
static const char *const field_flag[] = {"", "--slice-do", "--slice-p1", "--no-diffuse"};

/* xi's default (the settings table's). */
static double xi_default(void)
{
    int n;
    const atmos_setting *t = atmos_renderer_settings(ATMOS_RENDERER_SLICE, &n);
    for (int i = 0; i < n; i++)
        if (!strcmp(t[i].key, "xi")) return t[i].def;
    return 0;
}

atmos_slice_field atmos_scene_slice_field(const atmos_scene_slice *s)
{
    if (s->field > ATMOS_SLICE_FIELD_AUTO && s->field <= ATMOS_SLICE_FIELD_NONE) return (atmos_slice_field)s->field;
    if (s->do_field) return ATMOS_SLICE_FIELD_DO;
    if (!s->diffuse || s->low_albedo) return ATMOS_SLICE_FIELD_NONE;
    return s->xi != xi_default() || s->eq24 ? ATMOS_SLICE_FIELD_P1 : ATMOS_SLICE_FIELD_DO;
}

/* With the do field these settings would do nothing: set away from their default (xi also 0,
 * which is what the field does) they are refused, naming the key and the flag. */
static atmos_status do_unused(atmos_context *ctx, const char *source, const atmos_scene *s)
{
    static const struct {
        const char *key, *why;
    } unused[] = {
        {"xi", "the field holds the multiple scattering that Riley's xi term stands in for"},
        {"update", "its light pass is the delta-M direct beam, without Eq. 24/25's update"},
        {"low_albedo", "low albedo is single scattering alone: it and the field exclude each other"},
        {"diffuse", "the field takes the place of the diffuse light field: there is none to leave out"},
    };
    int n;
    const atmos_setting *t = atmos_renderer_settings(ATMOS_RENDERER_SLICE, &n);
    for (int i = 0; i < n; i++)
        for (size_t k = 0; k < sizeof unused / sizeof unused[0]; k++) {
            const double v = atmos_scene_setting_get(s, &t[i]);
            if (strcmp(t[i].key, unused[k].key) || v == t[i].def || (!strcmp(t[i].key, "xi") && v == 0)) continue;
            char path[64];
            snprintf(path, sizeof path, "/slice/%s", t[i].key);
            return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, path,
                                     "(--%s) does nothing with the do field (\"field\": \"do\", --slice-do): %s; "
                                     "leave it out, or choose \"field\": \"p1\" (--slice-p1) or \"none\"",
                                     t[i].flag, unused[k].why);
        }
    return ATMOS_OK;
}

/* The field's settings against each other, when the slice renderer is the scene's (another
 * renderer reads none of them; the viewer switched to slice leaves the unused ones unused). */
atmos_status atmos__slice_field_check(atmos_context *ctx, const char *source, const atmos_scene *s)
{
    const atmos_scene_slice *ss = &s->slice;
    if (s->renderer != ATMOS_RENDERER_SLICE) return ATMOS_OK;
    const int f = ss->field;
    if (ss->do_field && (f == ATMOS_SLICE_FIELD_P1 || f == ATMOS_SLICE_FIELD_NONE))
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/slice/do",
                                 "(--slice-do) contradicts \"field\": \"%s\" (%s): leave one out",
                                 atmos_slice_field_name((atmos_slice_field)f),
                                 field_flag[f]);
    if (!ss->diffuse && f == ATMOS_SLICE_FIELD_P1)
        return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, "/slice/diffuse",
                                 "(--no-diffuse) contradicts \"field\": \"p1\" (--slice-p1), the diffuse field it "
                                 "turns off: leave one out (false is \"field\": \"none\")");
    return atmos_scene_slice_field(ss) == ATMOS_SLICE_FIELD_DO ? do_unused(ctx, source, s) : ATMOS_OK;
}
