/* Flights (view.h): keyframes of the camera and the sun read from a JSON file with cJSON,
 * played on the viewer's clock; without a script, an orbit about the target (view_state's). */
#include "view.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int vec3(const cJSON *o, const char *name, double v[3])
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, name);
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != 3) return 0;
    for (int i = 0; i < 3; i++) {
        const cJSON *x = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(x) || !isfinite(x->valuedouble)) return 0;
        v[i] = x->valuedouble;
    }
    return 1;
}

/* One keyframe; returns NULL or what is wrong with it. */
static const char *key_frame(const cJSON *o, double t_prev, view_key_frame *k)
{
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "t");
    if (!cJSON_IsNumber(t) || !(t->valuedouble >= t_prev)) return "\"t\" must be a number of seconds, not decreasing";
    k->t = t->valuedouble;
    if (!vec3(o, "position_m", k->pos) || !vec3(o, "look_at_m", k->look_at))
        return "\"position_m\" and \"look_at_m\" must be arrays of 3 numbers";
    const cJSON *sun = cJSON_GetObjectItemCaseSensitive(o, "sun");
    if (sun) {
        const cJSON *e = cJSON_GetObjectItemCaseSensitive(sun, "elevation_deg");
        const cJSON *a = cJSON_GetObjectItemCaseSensitive(sun, "azimuth_deg");
        if (!cJSON_IsNumber(e) || !cJSON_IsNumber(a) || fabs(e->valuedouble) > 90)
            return "\"sun\" needs \"elevation_deg\" in [-90, 90] and \"azimuth_deg\"";
        k->has_sun = 1, k->sun_el = e->valuedouble, k->sun_az = a->valuedouble;
    }
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(o, "press");
    if (p) {
        if (!cJSON_IsString(p) || (k->press = view_action_named(p->valuestring)) == VA_NONE)
            return "\"press\" must name a key's action (atmos view --help lists them)";
    }
    return NULL;
}

int view_script_load(const char *path, view_script *out)
{
    memset(out, 0, sizeof *out);
    out->fps = 24;
    char *text = cli_read_text(path, CLI_TEXT_MAX);
    if (!text) {
        fprintf(stderr, "atmos view: --script %s: cannot read it\n", path);
        return CLI_EXIT_RUNTIME;
    }
    cJSON *root = cJSON_Parse(text);
    free(text);
    const cJSON *keys = root ? cJSON_GetObjectItemCaseSensitive(root, "keys") : NULL;
    const char *err = !root ? "not valid JSON" : (!cJSON_IsArray(keys) || !cJSON_GetArraySize(keys)) ? "needs a non-empty \"keys\" array" : NULL;
    const cJSON *fps = root ? cJSON_GetObjectItemCaseSensitive(root, "fps") : NULL;
    if (!err && fps && (!cJSON_IsNumber(fps) || !(fps->valuedouble >= 1 && fps->valuedouble <= 1000)))
        err = "\"fps\" must be in [1, 1000]";
    if (!err) {
        if (fps) out->fps = fps->valuedouble;
        out->n = cJSON_GetArraySize(keys);
        out->k = calloc((size_t)out->n, sizeof *out->k);
        if (!out->k) err = "out of memory";
        for (int i = 0; i < out->n && !err; i++) {
            if ((err = key_frame(cJSON_GetArrayItem(keys, i), i ? out->k[i - 1].t : -INFINITY, &out->k[i]))) {
                fprintf(stderr, "atmos view: --script %s: keys[%d]: %s\n", path, i, err);
                cJSON_Delete(root);
                view_script_free(out);
                return CLI_EXIT_USAGE;
            }
        }
    }
    cJSON_Delete(root);
    if (err) {
        fprintf(stderr, "atmos view: --script %s: %s\n", path, err);
        view_script_free(out);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

void view_script_free(view_script *s)
{
    free(s->k);
    memset(s, 0, sizeof *s);
}

/* The camera at pos looking at look_at. */
static void place(view_state *st, const double pos[3], const double look_at[3])
{
    double d[3];
    for (int i = 0; i < 3; i++) st->pos[i] = pos[i], d[i] = look_at[i] - pos[i];
    double yaw;
    atmos_direction_to_angles(d, &st->pitch_deg, &yaw);
    if (d[0] != 0 || d[2] != 0) st->yaw_deg = yaw; /* straight up or down: the heading kept */
    const double limit = view_state_pitch_limit(st);
    if (st->pitch_deg > limit) st->pitch_deg = limit;
    if (st->pitch_deg < -limit) st->pitch_deg = -limit;
    st->changes |= VIEW_CHANGED_CAMERA;
}

/* A frame's step of a full turn of the scene's camera about the vertical through the target
 * (the volume's centre, or without a volume the point the scene's camera looks at): its
 * position and heading turn together, its pitch is kept, so frame 0 is the scene's own view
 * (atmos render's) and each frame sees the target as the first one did. */
static void orbit(view_state *st, int frame, int frames)
{
    st->changes |= VIEW_CHANGED_CAMERA;
    if (frame == 0) return;
    const double step = 360.0 / (frames > 0 ? frames : 1);
    double d[3] = {st->pos[0] - st->target[0], 0.0, st->pos[2] - st->target[2]}, el, az;
    const double r = sqrt(d[0] * d[0] + d[2] * d[2]);
    if (r > 0) {
        atmos_direction_to_angles(d, &el, &az);
        atmos_direction_from_angles(0.0, fmod(az + step, 360.0), d);
        st->pos[0] = st->target[0] + r * d[0], st->pos[2] = st->target[2] + r * d[2];
    }
    st->yaw_deg = fmod(st->yaw_deg + step, 360.0);
}

void view_script_step(const view_script *s, view_state *st, double t_prev, double t, int frame, int frames)
{
    if (!s || s->n == 0) {
        orbit(st, frame, frames);
        return;
    }
    for (int i = 0; i < s->n; i++)
        if (s->k[i].press != VA_NONE && s->k[i].t > t_prev && s->k[i].t <= t) view_state_apply(st, s->k[i].press, 0, 0, 0);
    int i = 0;
    while (i + 1 < s->n && s->k[i + 1].t <= t) i++;
    const view_key_frame *a = &s->k[i], *b = &s->k[i + 1 < s->n ? i + 1 : i];
    const double f = b->t > a->t ? fmin(fmax((t - a->t) / (b->t - a->t), 0.0), 1.0) : 0.0;
    double pos[3], look[3];
    for (int c = 0; c < 3; c++) {
        pos[c] = a->pos[c] + f * (b->pos[c] - a->pos[c]);
        look[c] = a->look_at[c] + f * (b->look_at[c] - a->look_at[c]);
    }
    place(st, pos, look);
    if (a->has_sun) {
        const double el = b->has_sun ? a->sun_el + f * (b->sun_el - a->sun_el) : a->sun_el;
        double daz = b->has_sun ? fmod(b->sun_az - a->sun_az + 540.0, 360.0) - 180.0 : 0.0; /* the shorter arc */
        st->sun_el = el, st->sun_az = fmod(a->sun_az + f * daz + 360.0, 360.0), st->sun_from_time = 0;
        st->changes |= VIEW_CHANGED_SUN;
    }
}
