/* Flights (view.h): keyframes of the camera and the sun read from a JSON file (read and its
 * syntax checked by the scene reader, its keys here as strictly as a scene's), played on the
 * viewer's clock; without a script, an orbit about the target (view_state's). */
#include "view.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* A flight file's mistakes are said as the scene reader says a scene's ("FILE: /keys/1/press:
 * ..."): the JSON pointer of the value and what is wrong with it; exit status 2. */
static int fail(const char *file, const char *ptr, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "atmos view: --script %s: %s: ", file, ptr);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    return CLI_EXIT_USAGE;
}

/* An object's keys all among `allowed` (n of them), none twice; keys starting with "_" are
 * notes, skipped (as in scene files). Returns 0 or an exit status with the message. */
static int known_keys(const char *file, const cJSON *o, const char *ptr, const char *const *allowed, int n)
{
    if (!cJSON_IsObject(o)) return fail(file, ptr[0] ? ptr : "/", "expected an object");
    unsigned seen = 0;
    for (const cJSON *c = o->child; c; c = c->next) {
        const char *key = c->string ? c->string : "";
        if (key[0] == '_') continue;
        int k = 0;
        while (k < n && strcmp(key, allowed[k])) k++;
        if (k < n && !(seen & (1u << k))) {
            seen |= 1u << k;
            continue;
        }
        char list[256] = "", child[128];
        for (int i = 0; i < n; i++) snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", allowed[i]);
        snprintf(child, sizeof child, "%s/%.48s", ptr, key);
        return k < n ? fail(file, child, "duplicate key") : fail(file, child, "unknown key (allowed: %s)", list);
    }
    return CLI_EXIT_OK;
}

static int vec3(const char *file, const cJSON *o, const char *ptr, const char *name, double v[3])
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(o, name);
    if (!a) return fail(file, ptr, "\"%s\" is missing (an array of 3 numbers, metres)", name);
    int ok = cJSON_IsArray(a) && cJSON_GetArraySize(a) == 3;
    for (int i = 0; ok && i < 3; i++) {
        const cJSON *x = cJSON_GetArrayItem(a, i);
        ok = cJSON_IsNumber(x) && isfinite(x->valuedouble);
        if (ok) v[i] = x->valuedouble;
    }
    char sub[96];
    snprintf(sub, sizeof sub, "%s/%s", ptr, name);
    return ok ? CLI_EXIT_OK : fail(file, sub, "expected an array of 3 finite numbers");
}

/* The actions a flight can press: not the camera's (the key frames place the camera every
 * frame, so a move, a turn or the orbit's toggle would be undone at once), nor, when its key
 * frames set the sun, the sun's and the time's (the sun follows the key frames). */
static int flight_presses(view_action a, int sun_keyed)
{
    if ((a >= VA_FORWARD && a <= VA_LOOK_DOWN) || a == VA_ORBIT) return 0;
    return !(sun_keyed && ((a >= VA_SUN_UP && a <= VA_SUN_RIGHT) || a == VA_TIME_BACK || a == VA_TIME_FORWARD));
}

static int press_name(const char *file, const cJSON *p, const char *ptr, int sun_keyed, view_action *out)
{
    *out = cJSON_IsString(p) ? view_action_named(p->valuestring) : VA_NONE;
    if (*out != VA_NONE && flight_presses(*out, sun_keyed)) return CLI_EXIT_OK;
    char list[512] = "";
    for (int a = VA_NONE + 1; a < VA_COUNT; a++)
        if (flight_presses((view_action)a, sun_keyed))
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", list[0] ? ", " : "", view_action_name((view_action)a));
    if (!cJSON_IsString(p)) return fail(file, ptr, "expected a string, one of %s", list);
    if (*out == VA_NONE) return fail(file, ptr, "must be one of %s, got \"%.48s\"", list, p->valuestring);
    return fail(file, ptr, "\"%s\" cannot act in a flight: %s (it can press %s)", p->valuestring,
                sun_keyed && *out != VA_ORBIT && !(*out >= VA_FORWARD && *out <= VA_LOOK_DOWN)
                    ? "its key frames set the sun (\"sun\")"
                    : "the key frames place the camera",
                list);
}

/* Keyframe i (object o) after one at t_prev; sun_keyed: some key frame sets "sun". */
static int key_frame(const char *file, const cJSON *o, int i, double t_prev, int sun_keyed, view_key_frame *k)
{
    static const char *const allowed[] = {"t", "position_m", "look_at_m", "sun", "press"};
    static const char *const sun_keys[] = {"elevation_deg", "azimuth_deg"};
    char ptr[64], sub[80];
    snprintf(ptr, sizeof ptr, "/keys/%d", i);
    int rc = known_keys(file, o, ptr, allowed, 5);
    if (rc) return rc;
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "t");
    snprintf(sub, sizeof sub, "%s/t", ptr);
    if (!cJSON_IsNumber(t) || !isfinite(t->valuedouble) || !(t->valuedouble >= t_prev))
        return fail(file, t ? sub : ptr, "%s must be a number of seconds, not less than the key frame before's",
                    t ? "it" : "\"t\" is missing:");
    if (t->valuedouble < 0) return fail(file, sub, "must be >= 0, got %g", t->valuedouble);
    k->t = t->valuedouble;
    if ((rc = vec3(file, o, ptr, "position_m", k->pos)) || (rc = vec3(file, o, ptr, "look_at_m", k->look_at))) return rc;
    if (k->pos[0] == k->look_at[0] && k->pos[1] == k->look_at[1] && k->pos[2] == k->look_at[2]) {
        snprintf(sub, sizeof sub, "%s/look_at_m", ptr); /* no direction to look in: the scene reader's verdict */
        return fail(file, sub, "must differ from position_m");
    }
    const cJSON *sun = cJSON_GetObjectItemCaseSensitive(o, "sun");
    if (sun) {
        snprintf(sub, sizeof sub, "%s/sun", ptr);
        if ((rc = known_keys(file, sun, sub, sun_keys, 2))) return rc;
        const cJSON *e = cJSON_GetObjectItemCaseSensitive(sun, "elevation_deg");
        const cJSON *a = cJSON_GetObjectItemCaseSensitive(sun, "azimuth_deg");
        if (!cJSON_IsNumber(e) || !cJSON_IsNumber(a) || !(fabs(e->valuedouble) <= 90) || !isfinite(a->valuedouble))
            return fail(file, sub, "needs \"elevation_deg\" in [-90, 90] and \"azimuth_deg\", numbers");
        k->has_sun = 1, k->sun_el = e->valuedouble, k->sun_az = a->valuedouble;
    }
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(o, "press");
    snprintf(sub, sizeof sub, "%s/press", ptr);
    return p ? press_name(file, p, sub, sun_keyed, &k->press) : CLI_EXIT_OK;
}

/* The flight's JSON as the scene reader reads a scene file (atmos_scene_load: the same
 * messages for a file that cannot be read, with the system's reason, and for malformed JSON,
 * with its line and column); only those verdicts are kept, the text not being a scene. Returns
 * the text (NULL with the message said, *rc its exit status). */
static char *flight_text(atmos_context *ctx, const char *file, int *rc)
{
    atmos_scene *scratch = malloc(sizeof *scratch);
    if (!scratch) return *rc = CLI_EXIT_RUNTIME, NULL;
    const atmos_status st = atmos_scene_load(ctx, file, scratch);
    free(scratch);
    if (st == ATMOS_E_IO || st == ATMOS_E_FORMAT || st == ATMOS_E_LIMIT || st == ATMOS_E_NOMEM) {
        fprintf(stderr, "atmos view: --script %s\n", atmos_context_error(ctx));
        *rc = st == ATMOS_E_FORMAT ? CLI_EXIT_USAGE : CLI_EXIT_RUNTIME;
        return NULL;
    }
    char *text = cli_read_text(file, CLI_TEXT_MAX);
    if (!text) fprintf(stderr, "atmos view: --script %s: cannot read it\n", file), *rc = CLI_EXIT_RUNTIME;
    return text;
}

/* The sun at fraction f of the way from key frame a's to b's (the azimuth along the shorter arc). */
static void sun_between(const view_key_frame *a, const view_key_frame *b, double f, double *el, double *az)
{
    const double daz = fmod(b->sun_az - a->sun_az + 540.0, 360.0) - 180.0;
    *el = a->sun_el + f * (b->sun_el - a->sun_el);
    *az = fmod(a->sun_az + f * daz + 360.0, 360.0);
}

/* When some key frames set the sun, each key frame without one is given the sun interpolated
 * in time between the key frames around it that set one (held before the first and after the
 * last): the flight's sun is then linear between the keys that give it, as the camera is. */
static void fill_sun(view_script *s)
{
    int prev = -1;
    for (int i = 0; i < s->n; i++) {
        if (s->k[i].has_sun) {
            prev = i;
            continue;
        }
        int next = i + 1;
        while (next < s->n && !s->k[next].has_sun) next++;
        const view_key_frame *a = &s->k[prev >= 0 ? prev : next], *b = &s->k[next < s->n ? next : prev];
        const double span = b->t - a->t, f = span > 0 ? (s->k[i].t - a->t) / span : 0.0;
        sun_between(a, b, f, &s->k[i].sun_el, &s->k[i].sun_az);
        s->k[i].has_sun = 1;
    }
}

int view_script_load(atmos_context *ctx, const char *path, view_script *out)
{
    static const char *const allowed[] = {"fps", "keys"};
    memset(out, 0, sizeof *out);
    out->fps = 24;
    int rc = CLI_EXIT_OK;
    char *text = flight_text(ctx, path, &rc);
    if (!text) return rc;
    cJSON *root = cJSON_Parse(text);
    free(text);
    const cJSON *keys = cJSON_GetObjectItemCaseSensitive(root, "keys");
    const cJSON *fps = cJSON_GetObjectItemCaseSensitive(root, "fps");
    if (!root) rc = fail(path, "/", "not valid JSON");
    else if ((rc = known_keys(path, root, "", allowed, 2)) != CLI_EXIT_OK) {
    } else if (!cJSON_IsArray(keys) || !cJSON_GetArraySize(keys)) rc = fail(path, "/keys", "expected a non-empty array of key frames");
    else if (fps && (!cJSON_IsNumber(fps) || !(fps->valuedouble >= 1 && fps->valuedouble <= 1000)))
        rc = fail(path, "/fps", "must be a number in [1, 1000]");
    else if (!(out->k = calloc((size_t)cJSON_GetArraySize(keys), sizeof *out->k))) rc = CLI_EXIT_RUNTIME;
    if (rc == CLI_EXIT_OK) {
        if (fps) out->fps = fps->valuedouble;
        out->n = cJSON_GetArraySize(keys);
        int sun_keyed = 0;
        for (const cJSON *k = keys->child; k; k = k->next) sun_keyed |= cJSON_GetObjectItemCaseSensitive(k, "sun") != NULL;
        for (int i = 0; i < out->n && rc == CLI_EXIT_OK; i++)
            rc = key_frame(path, cJSON_GetArrayItem(keys, i), i, i ? out->k[i - 1].t : -INFINITY, sun_keyed, &out->k[i]);
        if (rc == CLI_EXIT_OK && sun_keyed) fill_sun(out);
    }
    cJSON_Delete(root);
    if (rc != CLI_EXIT_OK) view_script_free(out);
    return rc;
}

int view_script_frames(const view_script *s)
{
    if (!s || s->n == 0) return 0;
    /* frame i at t = i / fps: the first frame at or after the last key frame's time */
    const double f = ceil(s->k[s->n - 1].t * s->fps - 1e-9);
    return !(f > 0) ? 1 : f < VIEW_FRAMES_MAX ? (int)f + 1 : VIEW_FRAMES_MAX + 1;
}

int view_script_check(const view_script *s, const view_state *st, const char *path)
{
    for (int i = 0; s && i < s->n; i++)
        if (!st->sun_from_time && (s->k[i].press == VA_TIME_BACK || s->k[i].press == VA_TIME_FORWARD)) {
            char ptr[64];
            snprintf(ptr, sizeof ptr, "/keys/%d/press", i);
            return fail(path, ptr, "\"%s\" needs a scene whose sun follows a date, a time and a place "
                                   "(\"sun\": {\"time\": ...}, or --time with --lat and --lon)",
                        view_action_name(s->k[i].press));
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
        if (s->k[i].press != VA_NONE && s->k[i].t > t_prev && s->k[i].t <= t) view_state_tap(st, s->k[i].press);
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
    if (a->has_sun) { /* every key frame's, or none's (fill_sun) */
        sun_between(a, b, f, &st->sun_el, &st->sun_az);
        st->sun_from_time = 0, st->changes |= VIEW_CHANGED_SUN;
    }
}
