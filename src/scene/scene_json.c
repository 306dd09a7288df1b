/* Walks a parsed JSON scene into an atmos_scene, strictly: unknown keys, wrong
 * types and out-of-range values are errors named by their JSON pointer
 * ("scene.json: /camera/fov_deg: ..."). Keys are handled in document order and
 * the first error stops the walk, so the message points at the first problem a
 * reader meets. Keys starting with "_" are annotations and are skipped.
 */
#include "scene/scene_internal.h"
#include "scene/scene_fog.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#define PATH_CAP 256
/* Unknown keys and bad string values are quoted in messages; keep them short so
 * the path and the reason always fit in the context's message buffer. */
#define QUOTE_MAX 48
/* Distance of the look_at point the parser derives from a direction. */
#define LOOK_DISTANCE_M 1000.0

typedef struct jp {
    atmos_context *ctx;
    const char *source;
} jp;

static const char *type_name(const cJSON *j)
{
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsBool(j)) return "a boolean";
    if (cJSON_IsNumber(j)) return "a number";
    if (cJSON_IsString(j)) return "a string";
    if (cJSON_IsArray(j)) return "an array";
    if (cJSON_IsObject(j)) return "an object";
    return "an unknown value";
}

/* Copies at most max bytes of s, escaping what would garble a one-line message,
 * and never cutting a UTF-8 sequence in half (the input was checked to be valid
 * UTF-8, so continuation bytes are 10xxxxxx). */
static void escape_text(char *out, size_t cap, const char *s, size_t max, int pointer)
{
    size_t o = 0, i = 0, n = strlen(s);
    size_t limit = n <= max ? n : max;
    while (limit < n && ((unsigned char)s[limit] & 0xC0) == 0x80) limit--;
    for (; i < limit && o + 8 < cap; i++) {
        unsigned char c = (unsigned char)s[i];
        if (pointer && c == '~') o += (size_t)snprintf(out + o, cap - o, "~0");
        else if (pointer && c == '/') o += (size_t)snprintf(out + o, cap - o, "~1");
        else if (!pointer && (c == '"' || c == '\\')) o += (size_t)snprintf(out + o, cap - o, "\\%c", c);
        else if (c < 0x20 || c == 0x7F) o += (size_t)snprintf(out + o, cap - o, "\\u%04x", c);
        else out[o++] = (char)c;
    }
    if (i < n && o + 4 < cap) o += (size_t)snprintf(out + o, cap - o, "...");
    out[o < cap ? o : cap - 1] = '\0';
}

/* parent + "/" + key as a JSON pointer (RFC 6901: "~" -> "~0", "/" -> "~1"). */
static void child_path(char *out, size_t cap, const char *parent, const char *key)
{
    char esc[QUOTE_MAX * 6 + 8];
    escape_text(esc, sizeof esc, key, QUOTE_MAX, 1);
    /* Paths are at most three keys deep, so truncation cannot happen in practice;
     * if it did, only a message would be shortened. */
    if (snprintf(out, cap, "%s/%s", parent, esc) >= (int)cap) out[cap - 1] = '\0';
}

static atmos_status type_error(const jp *p, const char *path, const char *expected, const cJSON *j)
{
    return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "expected %s, got %s",
                             expected, type_name(j));
}

/* Numbers: cJSON turns 1e999 into infinity; JSON has no other non-finite spelling. */
static atmos_status get_number(const jp *p, const cJSON *j, const char *path, const atmos__range *r,
                               const char *extra, double *out)
{
    if (!cJSON_IsNumber(j)) return type_error(p, path, "a number", j);
    double v = j->valuedouble;
    if (!isfinite(v))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 "must be a finite number (this one overflows a double)");
    atmos_status st = r ? atmos__scene_check_range(p->ctx, p->source, path, v, r, extra) : ATMOS_OK;
    if (st == ATMOS_OK) *out = v;
    return st;
}

/* Integers are range-checked before the conversion, which would be undefined
 * behaviour for values outside int. */
static atmos_status get_int(const jp *p, const cJSON *j, const char *path, const atmos__range *r, int *out)
{
    if (!cJSON_IsNumber(j)) return type_error(p, path, "an integer", j);
    double v = j->valuedouble;
    if (!isfinite(v))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 "must be a finite number (this one overflows a double)");
    if (v != floor(v)) {
        char got[40];
        atmos__scene_fmt_num(got, sizeof got, v);
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 "expected an integer, got %s", got);
    }
    atmos_status st = atmos__scene_check_range(p->ctx, p->source, path, v, r, NULL);
    if (st == ATMOS_OK) *out = (int)v;
    return st;
}

static atmos_status get_bool(const jp *p, const cJSON *j, const char *path, int *out)
{
    if (!cJSON_IsBool(j)) return type_error(p, path, "true or false", j);
    *out = cJSON_IsTrue(j) ? 1 : 0;
    return ATMOS_OK;
}

static atmos_status get_string(const jp *p, const cJSON *j, const char *path, const char **out)
{
    if (!cJSON_IsString(j) || !j->valuestring) return type_error(p, path, "a string", j);
    *out = j->valuestring;
    return ATMOS_OK;
}

/* One of a fixed list of words; the message lists them. */
static atmos_status get_enum(const jp *p, const cJSON *j, const char *path, const char *const *names,
                             int n, int *out)
{
    const char *s = NULL;
    atmos_status st = get_string(p, j, path, &s);
    if (st) return st;
    for (int i = 0; i < n; i++) {
        if (strcmp(s, names[i]) == 0) {
            *out = i;
            return ATMOS_OK;
        }
    }
    char list[256] = "", got[QUOTE_MAX * 6 + 8];
    for (int i = 0; i < n; i++) {
        strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, names[i], sizeof list - strlen(list) - 1);
    }
    escape_text(got, sizeof got, s, QUOTE_MAX, 0);
    return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "must be one of %s, got \"%s\"",
                             list, got);
}

static atmos_status get_vec3(const jp *p, const cJSON *j, const char *path, const atmos__range *const r[3],
                             double out[3])
{
    if (!cJSON_IsArray(j)) return type_error(p, path, "an array of 3 numbers", j);
    int n = 0;
    for (const cJSON *e = j->child; e && n < 4; e = e->next) n++;
    if (n != 3)
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 "expected an array of 3 numbers, got %s elements",
                                 n < 4 ? (n == 0 ? "0" : n == 1 ? "1" : "2") : "more than 3");
    double v[3];
    const cJSON *e = j->child;
    for (int i = 0; i < 3; i++, e = e->next) {
        char ep[PATH_CAP];
        snprintf(ep, sizeof ep, "%s/%d", path, i);
        atmos_status st = get_number(p, e, ep, r[i], NULL, &v[i]);
        if (st) return st;
    }
    memcpy(out, v, sizeof v);
    return ATMOS_OK;
}

/* Iterates an object's keys in document order, rejecting unknown and duplicate
 * keys and skipping "_" annotations. */
typedef struct obj_iter {
    const cJSON *next;
    const char *path;
    const char *const *keys;
    int nkeys;
    unsigned seen;
} obj_iter;

/* The number of names in a function's own keys[] array; a pointer does not compile (GCC, Clang). */
#if defined(__GNUC__)
#define KEY_COUNT(a)                                                                                             \
    ((int)(sizeof(a) / sizeof *(a)) +                                                                             \
     0 * (int)sizeof(struct {                                                                                     \
         _Static_assert(!__builtin_types_compatible_p(__typeof__(a), __typeof__(&(a)[0])), "keys: an array");     \
         int unused;                                                                                              \
     }))
#else
#define KEY_COUNT(a) ((int)(sizeof(a) / sizeof *(a)))
#endif

static atmos_status iter_begin(const jp *p, const cJSON *obj, const char *path, const char *const *keys,
                               int nkeys, obj_iter *it)
{
    if (!cJSON_IsObject(obj)) return type_error(p, path, "an object", obj);
    it->next = obj->child;
    it->path = path;
    it->keys = keys;
    it->nkeys = nkeys;
    it->seen = 0;
    return ATMOS_OK;
}

/* Sets *idx to the key's index (or -1 at the end), *item and item_path. */
static atmos_status iter_next(const jp *p, obj_iter *it, int *idx, const cJSON **item, char *item_path)
{
    *idx = -1;
    while (it->next) {
        const cJSON *c = it->next;
        it->next = c->next;
        const char *key = c->string ? c->string : "";
        child_path(item_path, PATH_CAP, it->path, key);
        if (key[0] == '_') continue;
        int k = 0;
        while (k < it->nkeys && strcmp(key, it->keys[k]) != 0) k++;
        if (k == it->nkeys) {
            char list[512] = "";
            for (int i = 0; i < it->nkeys; i++) {
                strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
                strncat(list, it->keys[i], sizeof list - strlen(list) - 1);
            }
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, item_path,
                                     "unknown key (allowed: %s)", list);
        }
        /* cJSON keeps both copies of a repeated key; which one would win is not
         * something a scene file should depend on. */
        if (it->seen & (1u << k))
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, item_path, "duplicate key");
        it->seen |= 1u << k;
        *idx = k;
        *item = c;
        return ATMOS_OK;
    }
    return ATMOS_OK;
}

#define TRY(expr)                              \
    do {                                       \
        atmos_status st_ = (expr);             \
        if (st_ != ATMOS_OK) return st_;       \
    } while (0)

static atmos_status parse_image(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"width", "height", "samples_per_pixel"};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) return ATMOS_OK;
        int *field = k == 0 ? &s->width : k == 1 ? &s->height : &s->samples_per_pixel;
        TRY(get_int(p, v, ip, k == 2 ? &atmos__r_spp : &atmos__r_dim, field));
    }
}

static atmos_status parse_view(const jp *p, const cJSON *j, const char *path, double dir[3])
{
    static const char *const keys[] = {"elevation_deg", "azimuth_deg"};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k;
    double angle[2];
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        TRY(get_number(p, v, ip, k == 0 ? &atmos__r_elevation : &atmos__r_azimuth, NULL, &angle[k]));
    }
    /* Both angles: a half-given direction has no obvious meaning. */
    for (k = 0; k < 2; k++) {
        if (!(it.seen & (1u << k)))
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                     "missing key \"%s\"", keys[k]);
    }
    atmos_direction_from_angles(angle[0], angle[1], dir);
    return ATMOS_OK;
}

static atmos_status parse_camera(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"type", "position_m", "look_at_m", "view", "up", "fov_deg"};
    static const char *const types[] = {"pinhole", "fisheye", "equirect"};
    static const atmos__range any = {-HUGE_VAL, HUGE_VAL, 0, 0};
    const atmos__range *pos_r[3] = {&atmos__r_pos, &atmos__r_altitude, &atmos__r_pos};
    const atmos__range *look_r[3] = {&atmos__r_look, &atmos__r_look, &atmos__r_look};
    const atmos__range *any_r[3] = {&any, &any, &any};
    enum { K_TYPE, K_POS, K_LOOK, K_VIEW, K_UP, K_FOV };
    atmos_camera_desc cam = s->camera;
    /* The starting view direction, kept so that moving only the position moves
     * the default look_at with it. */
    double dir[3] = {cam.look_at[0] - cam.position[0], cam.look_at[1] - cam.position[1],
                     cam.look_at[2] - cam.position[2]};
    obj_iter it;
    char ip[PATH_CAP], fov_path[PATH_CAP] = "", look_path[PATH_CAP] = "";
    const cJSON *v;
    int k, type;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        switch (k) {
        case K_TYPE:
            TRY(get_enum(p, v, ip, types, 3, &type));
            cam.type = (atmos_camera_type)type;
            break;
        case K_POS: TRY(get_vec3(p, v, ip, pos_r, cam.position)); break;
        case K_LOOK:
            if (it.seen & (1u << K_VIEW))
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                         "cannot be combined with view (give one of them)");
            TRY(get_vec3(p, v, ip, look_r, cam.look_at));
            snprintf(look_path, sizeof look_path, "%s", ip);
            break;
        case K_VIEW:
            if (it.seen & (1u << K_LOOK))
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                         "cannot be combined with look_at_m (give one of them)");
            TRY(parse_view(p, v, ip, dir));
            break;
        case K_UP:
            TRY(get_vec3(p, v, ip, any_r, cam.up));
            /* In the struct a zero up means "default"; in a file it is a mistake. */
            if (cam.up[0] == 0 && cam.up[1] == 0 && cam.up[2] == 0)
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip, "must be nonzero");
            break;
        case K_FOV:
            /* Its range depends on the type, which may come later in the object. */
            TRY(get_number(p, v, ip, NULL, NULL, &cam.fov_deg));
            snprintf(fov_path, sizeof fov_path, "%s", ip);
            break;
        }
    }
    int have_look = (it.seen >> K_LOOK) & 1, have_view = (it.seen >> K_VIEW) & 1;
    /* A fov of 0 means "the type's default" in the struct, so the validator
     * accepts it; written in a file it is out of range. */
    if ((it.seen & (1u << K_FOV)) && cam.fov_deg == 0 && cam.type != ATMOS_CAMERA_EQUIRECT) {
        int fish = cam.type == ATMOS_CAMERA_FISHEYE;
        TRY(atmos__scene_check_range(p->ctx, p->source, fov_path, 0.0,
                                     fish ? &atmos__r_fov_fisheye : &atmos__r_fov_pinhole,
                                     fish ? " for a fisheye camera" : " for a pinhole camera"));
    }
    /* A look_at of exactly [0, 0, 0] would read as "default" in the struct;
     * store the same direction as another point (1000 m from the origin on the
     * far side), which is never zero. */
    if (have_look && cam.look_at[0] == 0 && cam.look_at[1] == 0 && cam.look_at[2] == 0) {
        double n = atmos__scene_norm3(cam.position);
        if (!(n > 0))
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, look_path,
                                     "must differ from position_m");
        for (int i = 0; i < 3; i++) cam.look_at[i] = -cam.position[i] / n * LOOK_DISTANCE_M;
    }
    if (cam.type == ATMOS_CAMERA_FISHEYE) {
        /* camera.h: a fisheye defaults to a 180° all-sky view of the zenith. */
        if (!(it.seen & (1u << K_FOV))) cam.fov_deg = 180.0;
        if (!have_look && !have_view) {
            dir[0] = 0.0;
            dir[1] = 1.0;
            dir[2] = 0.0;
        }
    }
    if (!have_look) {
        double n = atmos__scene_norm3(dir);
        if (n > 0) {
            for (int i = 0; i < 3; i++) cam.look_at[i] = cam.position[i] + LOOK_DISTANCE_M * dir[i] / n;
        }
    }
    /* Looking straight up or down leaves the default up undefined; north is the
     * conventional top of a zenith image (camera.h). An explicit up is kept and
     * validated as given. */
    if (!(it.seen & (1u << K_UP))) {
        double d[3] = {cam.look_at[0] - cam.position[0], cam.look_at[1] - cam.position[1],
                       cam.look_at[2] - cam.position[2]};
        double y[3] = {0.0, 1.0, 0.0};
        double sa = atmos__scene_sin_angle(d, y);
        if (sa >= 0 && sa < 1e-6) {
            cam.up[0] = 0.0;
            cam.up[1] = 0.0;
            cam.up[2] = -1.0;
        }
    }
    TRY(atmos__scene_validate_camera(p->ctx, p->source, &cam));
    s->camera = cam;
    return ATMOS_OK;
}

/* atmos_parse_utc_time reports through a context; a private one keeps its
 * unprefixed message out of the caller's log so only the JSON-pointer version
 * is reported. */
static atmos_status parse_time(const jp *p, const char *text, const char *path, atmos_utc_time *out)
{
    atmos_context *tmp = NULL;
    if (atmos_context_create(NULL, &tmp) != ATMOS_OK)
        return atmos__scene_fail(p->ctx, ATMOS_E_NOMEM, p->source, path, "out of memory");
    atmos_status st = atmos_parse_utc_time(tmp, text, out);
    if (st != ATMOS_OK) {
        const char *msg = atmos_context_error(tmp);
        st = atmos__scene_fail(p->ctx, st, p->source, path, "%s", *msg ? msg : "not a valid date-time");
    }
    atmos_context_destroy(tmp);
    return st;
}

/* "irradiance": W m^-2 nm^-1 outside the air, one number (every wavelength) or three
 * (the rgb channels, 680, 550, 440 nm). */
static atmos_status parse_irradiance(const jp *p, const cJSON *j, const char *path, atmos_scene_sun *sun)
{
    static const atmos__range r_irr = {0, 1e6, 0, 0};
    if (cJSON_IsNumber(j)) {
        TRY(get_number(p, j, path, &r_irr, NULL, &sun->irradiance[0]));
        sun->irradiance_count = 1;
        return ATMOS_OK;
    }
    if (!cJSON_IsArray(j)) return type_error(p, path, "a number or an array of 3 numbers (W m^-2 nm^-1)", j);
    const atmos__range *r[3] = {&r_irr, &r_irr, &r_irr};
    TRY(get_vec3(p, j, path, r, sun->irradiance));
    sun->irradiance_count = 3;
    return ATMOS_OK;
}

static atmos_status parse_sun(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"elevation_deg", "azimuth_deg", "time", "latitude_deg",
                                       "longitude_deg", "refraction", "irradiance"};
    enum { K_ELEV, K_AZIM, K_TIME, K_LAT, K_LON, K_REFR, K_IRR };
    const unsigned angle_keys = 1u << K_ELEV | 1u << K_AZIM, irr_key = 1u << K_IRR;
    atmos_scene_sun sun = s->sun;
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    const char *text = NULL;
    int k;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        /* Angles and time/place are two ways to say the same thing. */
        unsigned mine = (1u << k) & angle_keys ? angle_keys : ~angle_keys;
        if (k != K_IRR && (it.seen & ~mine & ~irr_key))
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                     "cannot be combined with %s (give elevation_deg/azimuth_deg or "
                                     "time/latitude_deg/longitude_deg, not both)",
                                     mine == angle_keys ? "time/latitude_deg/longitude_deg/refraction"
                                                        : "elevation_deg/azimuth_deg");
        switch (k) {
        case K_ELEV: TRY(get_number(p, v, ip, &atmos__r_elevation, NULL, &sun.elevation_deg)); break;
        case K_AZIM: TRY(get_number(p, v, ip, &atmos__r_azimuth, NULL, &sun.azimuth_deg)); break;
        case K_TIME:
            TRY(get_string(p, v, ip, &text));
            TRY(parse_time(p, text, ip, &sun.time));
            break;
        case K_LAT: TRY(get_number(p, v, ip, &atmos__r_latitude, NULL, &sun.latitude_deg)); break;
        case K_LON: TRY(get_number(p, v, ip, &atmos__r_longitude, NULL, &sun.longitude_deg)); break;
        case K_REFR: TRY(get_bool(p, v, ip, &sun.refraction)); break;
        case K_IRR: TRY(parse_irradiance(p, v, ip, &sun)); break;
        }
    }
    if (it.seen & ~angle_keys & ~irr_key) {
        /* No default place or time: a sun computed for a place the user did not
         * name would be a silent surprise. */
        static const int required[] = {K_TIME, K_LAT, K_LON};
        for (int i = 0; i < 3; i++) {
            if (!(it.seen & (1u << required[i])))
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                         "missing key \"%s\" (time, latitude_deg and longitude_deg "
                                         "go together)", keys[required[i]]);
        }
        sun.from_time = 1;
    } else if (it.seen & angle_keys) {
        sun.from_time = 0;
    }
    TRY(atmos__scene_validate_sun(p->ctx, p->source, &sun));
    s->sun = sun;
    return ATMOS_OK;
}

static atmos_status get_text(const jp *p, const cJSON *j, const char *path, char *out, size_t cap);

/* "clouds" of a spherical atmosphere: the satellite image, where it lies, the layer. */
static atmos_status parse_clouds(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"lon_west_deg", "lon_east_deg", "lat_south_deg", "lat_north_deg", "base_m",
                                       "top_m", "threshold", "max_optical_depth", "g", "image", "world_file",
                                       "spheres", "single_scattering"};
    enum { NUM = 9, K_IMAGE = 9, K_WORLD, K_SPHERES, K_SINGLE, NKEYS };
    static const atmos__range lon = {-360, 360, 0, 0}, lat = {-90, 90, 0, 0}, height = {0, 1e6, 0, 0},
                              unit = {0, 1, 0, 1}, tau = {0, 1e4, 1, 0}, g = {-1, 1, 1, 1}, spheres = {1, 64, 0, 0};
    atmos_cloud_desc *c = &s->atmosphere.clouds;
    double *fields[NUM] = {&c->lon_west_deg, &c->lon_east_deg, &c->lat_south_deg, &c->lat_north_deg, &c->base_m,
                           &c->top_m, &c->threshold, &c->max_optical_depth, &c->g};
    const atmos__range *ranges[NUM] = {&lon, &lon, &lat, &lat, &height, &height, &unit, &tau, &g};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k;
    TRY(iter_begin(p, j, path, keys, NKEYS, &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        if (k < NUM) TRY(get_number(p, v, ip, ranges[k], NULL, fields[k]));
        else if (k == K_IMAGE) TRY(get_text(p, v, ip, s->earth.cloud_image, sizeof s->earth.cloud_image));
        else if (k == K_WORLD) TRY(get_text(p, v, ip, s->earth.cloud_world_file, sizeof s->earth.cloud_world_file));
        else if (k == K_SPHERES) TRY(get_int(p, v, ip, &spheres, &c->spheres));
        else TRY(get_bool(p, v, ip, &c->single_scattering));
    }
    if (!(it.seen & (1u << K_IMAGE)))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "missing key \"image\"");
    return ATMOS_OK;
}

/* The spherical atmosphere's Earth: where the origin is, the maps, the clouds. */
static atmos_status parse_earth_key(const jp *p, int k, const cJSON *v, const char *ip, atmos_scene *s)
{
    static const atmos__range reduce = {1, 8, 0, 0}, night = {0, 1e3, 0, 0};
    atmos_atmosphere_desc *a = &s->atmosphere;
    switch (k) {
    case 0: return get_number(p, v, ip, &atmos__r_latitude, NULL, &a->latitude_deg);
    case 1: return get_number(p, v, ip, &atmos__r_longitude, NULL, &a->longitude_deg);
    case 2: return get_number(p, v, ip, &night, NULL, &a->night_radiance);
    case 3: return get_text(p, v, ip, s->earth.ground_map, sizeof s->earth.ground_map);
    case 4: return get_text(p, v, ip, s->earth.night_lights, sizeof s->earth.night_lights);
    case 5: {
        TRY(get_int(p, v, ip, &reduce, &s->earth.map_reduce));
        if (s->earth.map_reduce & (s->earth.map_reduce - 1))
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip, "must be 1, 2, 4 or 8");
        return ATMOS_OK;
    }
    default: return parse_clouds(p, v, ip, s);
    }
}

/* "model" (or its older name "kind") picks the atmosphere's kind; the spherical models'
 * settings are read for any model and used by those. */
static atmos_status parse_atmosphere(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"beta_sl_550_per_m", "scale_height_m", "ground_albedo", "sun_diameter_deg",
                                       "sun_scale", "thickness_m", "planet_radius_m", "top_m",
                                       "rayleigh_scale_height_m", "aerosol_scale_height_m", "visibility_km",
                                       "turbidity", "ozone_du", "dobashi_ambient", "sun_disk", "ozone", "kind",
                                       "model", "aerosol", "latitude_deg", "longitude_deg", "night_radiance",
                                       "ground_map", "night_lights", "map_reduce", "clouds"};
    enum { NUM = 14, K_DISK = 14, K_OZONE, K_KIND, K_MODEL, K_AEROSOL, K_EARTH, NKEYS = K_EARTH + 7 };
    static const char *const kinds[] = {"riley", "homogeneous", "dobashi", "spherical"};
    static const atmos_atmosphere_kind kind_of[] = {ATMOS_ATMOSPHERE_RILEY, ATMOS_ATMOSPHERE_HOMOGENEOUS,
                                                    ATMOS_ATMOSPHERE_DOBASHI, ATMOS_ATMOSPHERE_SPHERICAL};
    static const char *const aerosols[] = {"continental", "maritime", "urban", "desert", "none"};
    atmos_atmosphere_desc *a = &s->atmosphere;
    double *fields[NUM] = {&a->beta_sl_550, &a->scale_height_m, &a->ground_albedo, &a->sun_diameter_deg,
                           &a->sun_scale, &a->thickness_m, &a->planet_radius_m, &a->top_m,
                           &a->rayleigh_scale_height_m, &a->aerosol_scale_height_m, &a->visibility_km,
                           &a->turbidity, &a->ozone_du, &a->dobashi_ambient};
    const atmos__range *ranges[NUM] = {&atmos__r_beta, &atmos__r_scale_height, &atmos__r_albedo,
                                       &atmos__r_sun_diameter, &atmos__r_sun_scale, &atmos__r_thickness,
                                       &atmos__r_planet_radius, &atmos__r_top, &atmos__r_scale_height,
                                       &atmos__r_scale_height, &atmos__r_visibility, &atmos__r_turbidity,
                                       &atmos__r_ozone, &atmos__r_dobashi_ambient};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k, flag = 1, e = 0;
    TRY(iter_begin(p, j, path, keys, NKEYS, &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) return ATMOS_OK;
        if (k < NUM) {
            TRY(get_number(p, v, ip, ranges[k], NULL, fields[k]));
        } else if (k >= K_EARTH) {
            TRY(parse_earth_key(p, k - K_EARTH, v, ip, s));
        } else if (k == K_DISK || k == K_OZONE) {
            TRY(get_bool(p, v, ip, &flag));
            if (k == K_DISK) a->hide_sun_disk = !flag;
            else a->no_ozone = !flag;
        } else if (k == K_AEROSOL) {
            TRY(get_enum(p, v, ip, aerosols, 5, &e));
            a->aerosol = (atmos_aerosol_type)e;
        } else {
            TRY(get_enum(p, v, ip, kinds, 4, &e));
            /* a vacuum set by "background" stays one */
            if (a->kind != ATMOS_ATMOSPHERE_VACUUM) a->kind = kind_of[e];
        }
    }
}

static atmos_status parse_wavelengths(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"mode", "samples"};
    static const char *const modes[] = {"rgb", "spectral"};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k, mode;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) return ATMOS_OK;
        if (k == 0) {
            TRY(get_enum(p, v, ip, modes, 2, &mode));
            s->wavelengths = mode == 0 ? ATMOS_WAVELENGTHS_RGB : ATMOS_WAVELENGTHS_SPECTRAL;
        } else {
            TRY(get_int(p, v, ip, &atmos__r_samples, &s->spectral_samples));
        }
    }
}

static atmos_status parse_output(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"exposure", "exposure_compensation_ev", "tone_curve", "png_bits",
                                       "exr_pixel"};
    static const char *const curves[] = {"filmic", "reinhard", "clamp"};
    static const char *const pixels[] = {"float", "half"};
    static const atmos__range int_range = {-2147483648.0, 2147483647.0, 0, 0};
    enum { K_EXPOSURE, K_COMP, K_CURVE, K_BITS, K_PIXEL };
    atmos_scene out = *s;
    obj_iter it;
    char ip[PATH_CAP], exposure_path[PATH_CAP] = "", comp_path[PATH_CAP] = "";
    const cJSON *v;
    int k, e, manual = -1;
    double ev = 0.0, comp = 0.0;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        switch (k) {
        case K_EXPOSURE:
            if (cJSON_IsString(v) && v->valuestring && strcmp(v->valuestring, "auto") == 0) {
                manual = 0;
            } else if (cJSON_IsNumber(v)) {
                TRY(get_number(p, v, ip, &atmos__r_manual_ev, NULL, &ev));
                manual = 1;
            } else if (cJSON_IsString(v)) {
                char got[QUOTE_MAX * 6 + 8];
                escape_text(got, sizeof got, v->valuestring ? v->valuestring : "", QUOTE_MAX, 0);
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                         "must be \"auto\" or a number (EV100), got \"%s\"", got);
            } else {
                return type_error(p, ip, "\"auto\" or a number (EV100)", v);
            }
            snprintf(exposure_path, sizeof exposure_path, "%s", ip);
            break;
        case K_COMP:
            TRY(get_number(p, v, ip, &atmos__r_compensation, NULL, &comp));
            snprintf(comp_path, sizeof comp_path, "%s", ip);
            break;
        case K_CURVE:
            TRY(get_enum(p, v, ip, curves, 3, &e));
            out.tonemap.curve = (atmos_tone_curve)e;
            break;
        case K_BITS:
            TRY(get_int(p, v, ip, &int_range, &e));
            if (e != 8 && e != 16)
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                         "must be 8 or 16, got %d", e);
            out.png_bits = e;
            break;
        case K_PIXEL:
            TRY(get_enum(p, v, ip, pixels, 2, &e));
            out.exr_half = e;
            break;
        }
    }
    /* atmos_tonemap_desc has one exposure_ev: a manual EV100, or the compensation
     * added to the automatic choice. Both at once would be ambiguous. */
    if (manual == 1 && comp_path[0])
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, comp_path,
                                 "only applies with automatic exposure (\"exposure\": \"auto\"), "
                                 "but %s is a manual EV", exposure_path);
    if (manual == 1) {
        out.tonemap.manual_exposure = 1;
        out.tonemap.exposure_ev = ev;
    } else if (manual == 0 || comp_path[0]) {
        /* Compensation alone switches to automatic exposure: that is the only
         * mode in which it means anything. */
        out.tonemap.manual_exposure = 0;
        out.tonemap.exposure_ev = comp;
    }
    TRY(atmos__scene_validate_output(p->ctx, p->source, &out));
    *s = out;
    return ATMOS_OK;
}

/* ---- user-defined particle types: "particles": {NAME: {...}, ...} ---- */

static const atmos__range r_radius = {0, 0.005, 1, 0}, r_sigma = {0, 2, 1, 0}, r_alpha = {0, 100, 1, 0},
                          r_gamma = {0, 10, 1, 0}, r_rbound = {0, 0.02, 0, 0},
                          r_aspect = {0.01, 100, 0, 0}, r_distortion = {0, 1, 0, 0}, /* the crystal tables' (crystal.c) */
                          r_rays = {1000, 1e9, 0, 0}, r_g = {-1, 1, 1, 1},
                          r_weight = {0, 1e6, 0, 0}, r_sigma_ext = {0, 1, 0, 0}, r_unit = {0, 1, 0, 0};

static atmos_status parse_size(const jp *p, const cJSON *j, const char *path, atmos_size_distribution *d)
{
    static const char *const keys[] = {"distribution", "radius_m", "sigma", "alpha", "gamma", "r_min_m", "r_max_m"};
    static const char *const kinds[] = {"mono", "lognormal", "gamma"};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k, kind;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        switch (k) {
        case 0: TRY(get_enum(p, v, ip, kinds, 3, &kind)); d->kind = (atmos_size_kind)kind; break;
        case 1: TRY(get_number(p, v, ip, &r_radius, NULL, &d->r_m)); break;
        case 2: TRY(get_number(p, v, ip, &r_sigma, NULL, &d->sigma)); break;
        case 3: TRY(get_number(p, v, ip, &r_alpha, NULL, &d->alpha)); break;
        case 4: TRY(get_number(p, v, ip, &r_gamma, NULL, &d->gamma)); break;
        case 5: TRY(get_number(p, v, ip, &r_rbound, NULL, &d->r_min)); break;
        case 6: TRY(get_number(p, v, ip, &r_rbound, NULL, &d->r_max)); break;
        }
    }
    if (d->r_min > 0 && d->r_max > 0 && !(d->r_max > d->r_min))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "r_max_m must exceed r_min_m");
    return ATMOS_OK;
}

static atmos_status parse_lobes(const jp *p, const cJSON *j, const char *path, atmos_phase_mixture *m)
{
    static const char *const keys[] = {"type", "g", "weight"};
    static const char *const types[] = {"isotropic", "rayleigh", "hg", "cornette_shanks"};
    if (!cJSON_IsArray(j)) return type_error(p, path, "an array of lobes", j);
    memset(m, 0, sizeof *m);
    int n = 0;
    for (const cJSON *e = j->child; e; e = e->next, n++) {
        char ep[PATH_CAP + 16];
        snprintf(ep, sizeof ep, "%s/%d", path, n);
        ep[PATH_CAP - 1] = '\0';
        if (n >= ATMOS_PHASE_MAX_LOBES)
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ep, "at most %d lobes", ATMOS_PHASE_MAX_LOBES);
        obj_iter it;
        char ip[PATH_CAP];
        const cJSON *v;
        int k, type = -1;
        m->weight[n] = 1.0;
        TRY(iter_begin(p, e, ep, keys, KEY_COUNT(keys), &it));
        for (;;) {
            TRY(iter_next(p, &it, &k, &v, ip));
            if (k < 0) break;
            if (k == 0) TRY(get_enum(p, v, ip, types, 4, &type));
            else if (k == 1) TRY(get_number(p, v, ip, &r_g, NULL, &m->g[n]));
            else TRY(get_number(p, v, ip, &r_weight, NULL, &m->weight[n]));
        }
        if (type < 0) return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ep, "missing key \"type\"");
        m->kind[n] = (atmos_phase_kind)type;
    }
    m->count = n;
    double w = 0;
    for (int i = 0; i < n; i++) w += m->weight[i];
    if (!(w > 0))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "needs at least one lobe with weight > 0");
    return ATMOS_OK;
}

static atmos_status parse_particle(const jp *p, const cJSON *j, const char *path, const char *name,
                                   atmos_particle_desc *d)
{
    static const char *const keys[] = {"preset", "kind", "size", "habit", "aspect_ratio", "distortion", "rays",
                                       "lobes", "sigma_ext_m2", "albedo"};
    static const char *const kinds[] = {"air", "water", "ice", "snow", "analytic"};
    static const char *const habits[] = {"column", "plate"};
    enum { K_PRESET, K_KIND, K_SIZE, K_HABIT, K_ASPECT, K_DISTORTION, K_RAYS, K_LOBES, K_SIGMA, K_ALBEDO };
    memset(d, 0, sizeof *d);
    /* A "preset" is the starting point whatever its place in the object. */
    const cJSON *pre = cJSON_GetObjectItemCaseSensitive(j, "preset");
    if (cJSON_IsObject(j) && pre) {
        char pp[PATH_CAP];
        child_path(pp, sizeof pp, path, "preset");
        const char *pname = NULL;
        TRY(get_string(p, pre, pp, &pname));
        if (atmos_particle_preset(NULL, pname, d) != ATMOS_OK) {
            char list[256] = "";
            const char *const *names = atmos_particle_preset_names();
            for (int i = 0; names && names[i]; i++) {
                strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
                strncat(list, names[i], sizeof list - strlen(list) - 1);
            }
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, pp, "unknown preset (known: %s)", list);
        }
    }
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k, e, have_kind = pre != NULL;
    double rays = 0;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        switch (k) {
        case K_PRESET: break;
        case K_KIND: TRY(get_enum(p, v, ip, kinds, 5, &e)); d->kind = (atmos_particle_kind)e; have_kind = 1; break;
        case K_SIZE: TRY(parse_size(p, v, ip, &d->size)); break;
        case K_HABIT: TRY(get_enum(p, v, ip, habits, 2, &e)); d->habit = (atmos_crystal_habit)e; break;
        case K_ASPECT: TRY(get_number(p, v, ip, &r_aspect, NULL, &d->aspect_ratio)); break;
        case K_DISTORTION: TRY(get_number(p, v, ip, &r_distortion, NULL, &d->distortion)); break;
        case K_RAYS:
            TRY(get_number(p, v, ip, &r_rays, NULL, &rays));
            if (rays != floor(rays))
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip, "expected an integer");
            d->rays = (long)rays;
            break;
        case K_LOBES: TRY(parse_lobes(p, v, ip, &d->analytic)); break;
        case K_SIGMA: TRY(get_number(p, v, ip, &r_sigma_ext, NULL, &d->sigma_ext_m2)); break;
        case K_ALBEDO:
            TRY(get_number(p, v, ip, &r_unit, NULL, &d->albedo));
            d->albedo_set = 1;
            break;
        }
    }
    if (!have_kind) return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "needs \"kind\" or \"preset\"");
    if (d->kind == ATMOS_PARTICLE_WATER && !(d->size.r_m > 0))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 "water particles need size.radius_m (the mono radius, lognormal median or gamma mode)");
    if (d->kind == ATMOS_PARTICLE_WATER && d->size.kind == ATMOS_SIZE_LOGNORMAL && !(d->size.sigma > 0))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "a lognormal size needs size.sigma > 0");
    if (d->kind == ATMOS_PARTICLE_WATER && d->size.kind == ATMOS_SIZE_GAMMA && !(d->size.alpha > 0 && d->size.gamma > 0))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "a gamma size needs size.alpha and size.gamma > 0");
    if (d->kind == ATMOS_PARTICLE_ANALYTIC && d->analytic.count < 1)
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "analytic particles need \"lobes\"");
    snprintf(d->name, sizeof d->name, "%s", name);
    return ATMOS_OK;
}

static atmos_status parse_particles(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    if (!cJSON_IsObject(j)) return type_error(p, path, "an object of named particle types", j);
    int n = 0;
    for (const cJSON *c = j->child; c; c = c->next) {
        const char *name = c->string ? c->string : "";
        char ip[PATH_CAP];
        child_path(ip, sizeof ip, path, name);
        if (name[0] == '_') continue;
        size_t len = strlen(name);
        int ok = len >= 1 && len < sizeof s->particles[0].name;
        for (size_t i = 0; ok && i < len; i++) {
            char ch = name[i];
            ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '-';
        }
        if (!ok)
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                     "a particle name is 1..%d letters, digits, '_' or '-'", (int)sizeof s->particles[0].name - 1);
        for (int i = 0; i < n; i++)
            if (!strcmp(s->particles[i].name, name))
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip, "duplicate key");
        if (n >= ATMOS_SCENE_MAX_PARTICLES)
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip, "at most %d particle types",
                                     ATMOS_SCENE_MAX_PARTICLES);
        TRY(parse_particle(p, c, ip, name, &s->particles[n]));
        n++;
    }
    s->particle_count = n;
    return ATMOS_OK;
}

/* ---- renderers, background, volume ---- */

static const atmos__range r_seed = {0, 9007199254740992.0, 0, 0}, r_dscale = {0, 1e30, 1, 0}, r_time_index = {0, 1000000, 0, 0},
                          r_voxel = {0, 1e5, 0, 0}, r_vscale = {0, 100, 1, 0};

static atmos_status get_u64(const jp *p, const cJSON *j, const char *path, const atmos__range *r, uint64_t *out)
{
    double v = 0;
    TRY(get_number(p, j, path, r, NULL, &v));
    if (v != floor(v)) return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "expected an integer");
    *out = (uint64_t)v;
    return ATMOS_OK;
}

/* Copies a string value into a fixed buffer, refusing one that does not fit. */
static atmos_status get_text(const jp *p, const cJSON *j, const char *path, char *out, size_t cap)
{
    const char *t = NULL;
    TRY(get_string(p, j, path, &t));
    if (strlen(t) >= cap)
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "must be at most %d bytes, got %zu",
                                 (int)cap - 1, strlen(t));
    if (!t[0]) return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "must not be empty");
    memcpy(out, t, strlen(t) + 1);
    return ATMOS_OK;
}

/* "background": "sky" | "black" | {"type": "uniform", "radiance": L}: "sky" is the scene's
 * atmosphere (Riley's unless "atmosphere" says otherwise), the others a vacuum. */
static atmos_status parse_background(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    enum { BG_SKY, BG_BLACK, BG_UNIFORM };
    static const char *const types[] = {"sky", "black", "uniform"};
    static const char *const keys[] = {"type", "radiance"};
    int type = -1;
    double radiance = 0;
    if (cJSON_IsString(j)) {
        TRY(get_enum(p, j, path, types, 2, &type));
    } else {
        if (!cJSON_IsObject(j)) return type_error(p, path, "\"sky\", \"black\" or an object", j);
        obj_iter it;
        char ip[PATH_CAP];
        const cJSON *v;
        int k;
        TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
        for (;;) {
            TRY(iter_next(p, &it, &k, &v, ip));
            if (k < 0) break;
            if (k == 0) TRY(get_enum(p, v, ip, types, 3, &type));
            else TRY(get_number(p, v, ip, &atmos__r_radiance, NULL, &radiance));
        }
        if (type < 0) return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "missing key \"type\"");
        if ((it.seen & 2u) && type != BG_UNIFORM)
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                     "\"radiance\" goes with \"type\": \"uniform\" only");
        if (type == BG_UNIFORM && !(it.seen & 2u))
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                     "missing key \"radiance\" (W m^-2 sr^-1 nm^-1)");
    }
    atmos_atmosphere_desc *a = &s->atmosphere;
    if (type == BG_SKY) {
        if (a->kind == ATMOS_ATMOSPHERE_VACUUM) a->kind = ATMOS_ATMOSPHERE_RILEY;
    } else {
        a->kind = ATMOS_ATMOSPHERE_VACUUM;
    }
    a->background_radiance = radiance;
    return ATMOS_OK;
}

/* "simulate": {"preset": NAME, "minutes": M, "grid": N, "seed": S, "refine": R, "detail": A,
 * "ice": B} (atmos/sim.h). */
static atmos_status parse_simulate(const jp *p, const cJSON *j, const char *path, atmos_scene_volume *vol)
{
    static const char *const keys[] = {"preset", "minutes", "grid", "seed", "refine", "detail", "ice"};
    static const atmos__range r_min = {0, ATMOS_SIM_MAX_MINUTES, 1, 0}, r_grid = {ATMOS_SIM_MIN_GRID, ATMOS_SIM_MAX_GRID, 0, 0},
                              r_refine = {1, ATMOS_SIM_MAX_REFINE, 0, 0};
    obj_iter it;
    char ip[PATH_CAP], buf[64];
    const cJSON *v;
    int k;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        switch (k) {
        case 0: {
            TRY(get_text(p, v, ip, buf, sizeof buf));
            if (!atmos_sim_preset_minutes(buf)) {
                char list[256] = "";
                for (const char *const *n = atmos_sim_preset_names(); *n; n++)
                    snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", *n, n[1] ? ", " : "");
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip, "unknown preset (known: %s)", list);
            }
            snprintf(vol->source, sizeof vol->source, "simulate:%s", buf);
            break;
        }
        case 1: TRY(get_number(p, v, ip, &r_min, NULL, &vol->sim_minutes)); break;
        case 2: TRY(get_int(p, v, ip, &r_grid, &vol->sim_grid)); break;
        case 3: TRY(get_u64(p, v, ip, &r_seed, &vol->seed)); break;
        case 4: TRY(get_int(p, v, ip, &r_refine, &vol->sim_refine)); break;
        case 5: TRY(get_number(p, v, ip, &r_unit, NULL, &vol->sim_detail)); break;
        case 6: TRY(get_bool(p, v, ip, &vol->sim_ice)); break;
        }
    }
    if (!(it.seen & 1u)) return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "missing key \"preset\"");
    return ATMOS_OK;
}

static atmos_status parse_volume(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"file",         "generate", "grids", "particle",   "density_scale",
                                       "time_index",   "voxel_size_m", "seed",  "scale",  "position_m",
                                       "density_unit", "subgrid_detail", "simulate"};
    static const char *const units[] = {"auto", "per_m3", "g_m3", "fraction"};
    enum { K_FILE, K_GEN, K_GRIDS, K_PARTICLE, K_DSCALE, K_TIME, K_VOXEL, K_SEED, K_SCALE, K_POS, K_UNIT, K_DETAIL, K_SIM };
    static const atmos__range r_detail = {0, 1, 0, 0};
    const atmos__range *pos_r[3] = {&atmos__r_pos, &atmos__r_pos, &atmos__r_pos};
    atmos_scene_volume vol = s->volume;
    obj_iter it;
    char ip[PATH_CAP], buf[64];
    const cJSON *v;
    int k;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        switch (k) {
        case K_UNIT: {
            int u = 0;
            TRY(get_enum(p, v, ip, units, 4, &u));
            vol.density_unit = (atmos_density_unit)u;
            break;
        }
        case K_SIM: TRY(parse_simulate(p, v, ip, &vol)); break;
        case K_FILE:
        case K_GEN:
            if (it.seen & (k == K_FILE ? 1u << K_GEN : 1u << K_FILE))
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                         "\"file\" and \"generate\" exclude each other");
            if (k == K_FILE) {
                TRY(get_text(p, v, ip, vol.source, sizeof vol.source));
                if (!strncmp(vol.source, "generate:", 9))
                    return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                             "use \"generate\": \"%.40s\" for a generated volume", vol.source + 9);
            } else {
                TRY(get_text(p, v, ip, buf, sizeof buf));
                char list[512];
                if (!atmos_scene_generator_known(buf, list, sizeof list))
                    return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                             "unknown generator (known: %s)", list);
                snprintf(vol.source, sizeof vol.source, "generate:%s", buf);
            }
            break;
        case K_GRIDS:
            if (cJSON_IsArray(v)) {
                vol.grids[0] = '\0';
                int n = 0;
                for (const cJSON *e = v->child; e; e = e->next, n++) {
                    char ep[PATH_CAP + 16];
                    snprintf(ep, sizeof ep, "%s/%d", ip, n);
                    ep[PATH_CAP - 1] = '\0';
                    char g[64];
                    TRY(get_text(p, e, ep, g, sizeof g));
                    if (strchr(g, ','))
                        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ep, "a grid name has no ','");
                    if (strlen(vol.grids) + strlen(g) + 2 > sizeof vol.grids)
                        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip, "too many grid names");
                    if (n) strcat(vol.grids, ",");
                    strcat(vol.grids, g);
                }
                if (n == 0) return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip, "must not be empty");
            } else {
                return type_error(p, ip, "an array of grid names", v);
            }
            break;
        case K_PARTICLE: TRY(get_text(p, v, ip, vol.particle, sizeof vol.particle)); break;
        case K_DSCALE: TRY(get_number(p, v, ip, &r_dscale, NULL, &vol.density_scale)); break;
        case K_DETAIL: TRY(get_number(p, v, ip, &r_detail, NULL, &vol.subgrid_detail)); break;
        case K_TIME: TRY(get_int(p, v, ip, &r_time_index, &vol.time_index)); break;
        case K_VOXEL: TRY(get_number(p, v, ip, &r_voxel, NULL, &vol.voxel_size_m)); break;
        case K_SEED: TRY(get_u64(p, v, ip, &r_seed, &vol.seed)); break;
        case K_SCALE: TRY(get_number(p, v, ip, &r_vscale, NULL, &vol.scale)); break;
        case K_POS:
            TRY(get_vec3(p, v, ip, pos_r, vol.position_m));
            vol.placed = 1;
            break;
        }
    }
    const unsigned sources = it.seen & (1u << K_FILE | 1u << K_GEN | 1u << K_SIM);
    if (!sources)
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 "needs \"file\", \"generate\" or \"simulate\"");
    if (sources & (sources - 1))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 "\"file\", \"generate\" and \"simulate\" exclude each other");
    if (it.seen & (1u << K_SIM)) {
        static const int sim_bad[] = {K_GRIDS, K_TIME, K_UNIT, K_DETAIL, K_SEED, K_VOXEL, K_SCALE, K_PARTICLE};
        for (int i = 0; i < 8; i++)
            if (it.seen & (1u << sim_bad[i]))
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                         "\"%s\" does not apply to a simulated volume (its settings go inside "
                                         "\"simulate\": preset, minutes, grid, seed)",
                                         keys[sim_bad[i]]);
        s->volume = vol;
        return ATMOS_OK;
    }
    /* The keys one kind of volume would ignore are refused with it. */
    /* "particle" applies to both: a file's one field's type, a generated volume's cloud
     * droplets' (its "cloud" fields; a storm's rain and ice keep theirs: scene_optics.c). */
    static const int file_only[] = {K_GRIDS, K_TIME, K_UNIT, K_DETAIL}, gen_only[] = {K_SEED};
    const int is_file = (it.seen & (1u << K_FILE)) != 0;
    const int *bad = is_file ? gen_only : file_only, nbad = is_file ? 1 : 4;
    for (int i = 0; i < nbad; i++)
        if (it.seen & (1u << bad[i]))
            return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                     "\"%s\" applies to %s, not to a %s volume", keys[bad[i]],
                                     is_file ? "generated volumes" : "volume files", is_file ? "file" : "generated");
    s->volume = vol;
    return ATMOS_OK;
}

/* The slice's "do": false in a file, "field" left out: the P1 field, what it meant when the P1 field
 * was the default (before 2026-12-06), unless "diffuse": false or "low_albedo" ask for none
 * (auto's choice then). A file's key only: the scene struct's do_field 0 says nothing. */
static atmos_status old_do_false(const atmos_setting *t, int n, unsigned seen, atmos_scene *s)
{
    for (int i = 0; i < n && i < 32; i++)
        if (t[i].offset == offsetof(atmos_scene, slice.field) && (seen & (1u << i))) return ATMOS_OK;
    if (s->slice.diffuse && !s->slice.low_albedo) s->slice.field = ATMOS_SLICE_FIELD_P1;
    return ATMOS_OK;
}

/* A renderer's section ("slice", "path"): every key is a row of its settings table
 * (atmos_renderer_settings), which gives its type and range. */
static atmos_status parse_settings(const jp *p, const cJSON *j, const char *path, atmos_renderer_kind r, atmos_scene *s)
{
    int n = 0;
    const atmos_setting *t = atmos_renderer_settings(r, &n);
    const char *keys[32];
    for (int i = 0; i < n && i < 32; i++) keys[i] = t[i].key;
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k;
    TRY(iter_begin(p, j, path, keys, n < 32 ? n : 32, &it));
    int do_false = 0; /* the slice's "do": false */
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) return do_false ? old_do_false(t, n, it.seen, s) : ATMOS_OK;
        const atmos_setting *st = &t[k];
        const atmos__range range = {st->min, st->max, st->min_open, st->max_open};
        double value = 0;
        int x = 0, count = 0;
        uint64_t u = 0;
        switch (st->type) {
        case ATMOS_SETTING_INT: TRY(get_int(p, v, ip, &range, &x)); value = x; break;
        case ATMOS_SETTING_REAL: TRY(get_number(p, v, ip, &range, NULL, &value)); break;
        case ATMOS_SETTING_BOOL: TRY(get_bool(p, v, ip, &x)); value = x; break;
        case ATMOS_SETTING_CHOICE:
            while (st->choices[count]) count++;
            TRY(get_enum(p, v, ip, st->choices, count, &x));
            value = x;
            break;
        case ATMOS_SETTING_SEED: TRY(get_u64(p, v, ip, &range, &u)); value = (double)u; break;
        }
        atmos_scene_setting_set(s, st, value);
        do_false |= r == ATMOS_RENDERER_SLICE && st->offset == offsetof(atmos_scene, slice.do_field) && value == 0;
    }
}

/* "animation": {"frames": N, "time_end": T} or {"frames": N, "elevation_end_deg": E,
 * "azimuth_end_deg": A}; whether the end matches the sun is checked once the whole file
 * is read (the sun may come later). */
/* ------------------------------------------------------------------ lights, fog, objects */

static atmos_status parse_light(const jp *p, const cJSON *j, const char *path, atmos_scene_light *L)
{
    static const char *const keys[] = {"type", "position_m", "direction", "cone_deg", "edge_deg", "intensity_w_sr",
                                       "colour_temperature_k", "colour", "range_m", "image"};
    static const char *const types[] = {"point", "spot"};
    const atmos__range *const any[3] = {NULL, NULL, NULL};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k, type;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) {
            const double n = atmos__scene_norm3(L->direction); /* zero: refused by the validator */
            if (n > 0 && isfinite(n))
                for (int a = 0; a < 3; a++) L->direction[a] /= n;
            return ATMOS_OK;
        }
        switch (k) {
        case 0: TRY(get_enum(p, v, ip, types, 2, &type)); L->type = (atmos_light_type)type; break;
        case 1: TRY(get_vec3(p, v, ip, any, L->position_m)); break;
        case 2: TRY(get_vec3(p, v, ip, any, L->direction)); break;
        case 3: TRY(get_number(p, v, ip, NULL, NULL, &L->cone_deg)); break;
        case 4: TRY(get_number(p, v, ip, NULL, NULL, &L->edge_deg)); break;
        case 5: TRY(get_number(p, v, ip, NULL, NULL, &L->intensity_w_sr)); break;
        case 6: TRY(get_number(p, v, ip, NULL, NULL, &L->colour_temperature_k)); break;
        case 7: TRY(get_vec3(p, v, ip, any, L->colour)); break;
        case 8: TRY(get_number(p, v, ip, NULL, NULL, &L->range_m)); break;
        case 9: TRY(get_text(p, v, ip, L->image, sizeof L->image)); break;
        }
    }
}

/* An array of at most max objects, each read by one of the two parsers into slot i. */
static atmos_status parse_array(const jp *p, const cJSON *j, const char *path, int max, int *count,
                                atmos_status (*item)(const jp *, const cJSON *, const char *, atmos_scene *, int),
                                atmos_scene *s)
{
    if (!cJSON_IsArray(j)) return type_error(p, path, "an array of objects", j);
    int n = 0;
    for (const cJSON *e = j->child; e; e = e->next, n++) {
        char ip[PATH_CAP];
        snprintf(ip, sizeof ip, "%s/%d", path, n);
        if (n >= max)
            return atmos__scene_fail(p->ctx, ATMOS_E_LIMIT, p->source, ip, "at most %d are allowed", max);
        TRY(item(p, e, ip, s, n));
    }
    *count = n;
    return ATMOS_OK;
}

static atmos_status light_item(const jp *p, const cJSON *j, const char *path, atmos_scene *s, int i)
{
    atmos__scene_light_defaults(&s->lights[i]);
    return parse_light(p, j, path, &s->lights[i]);
}

/* An object's terrain keys (keys 5-12 of object_item's). */
static atmos_status object_terrain_key(const jp *p, const cJSON *v, const char *ip, int k, atmos_scene_object *o)
{
    static const atmos__range r_count = {0, 1e9, 0, 0};
    switch (k) {
    case 5: return get_text(p, v, ip, o->terrain, sizeof o->terrain);
    case 6: return get_number(p, v, ip, NULL, NULL, &o->size_m);
    case 7: return get_number(p, v, ip, NULL, NULL, &o->height_m);
    case 8: return get_number(p, v, ip, NULL, NULL, &o->height_scale);
    case 9: return get_int(p, v, ip, &r_count, &o->stride);
    case 10: return get_int(p, v, ip, &r_count, &o->samples);
    case 11: return get_int(p, v, ip, &r_count, &o->max_triangles);
    default: return get_u64(p, v, ip, &r_seed, &o->seed);
    }
}

static atmos_status object_item(const jp *p, const cJSON *j, const char *path, atmos_scene *s, int i)
{
    static const char *const keys[] = {"mesh",   "position_m", "scale",   "rotation_deg", "albedo",        "terrain", "size_m",
                                       "height_m", "height_scale", "stride", "samples", "max_triangles", "seed"};
    const atmos__range *const any[3] = {NULL, NULL, NULL};
    atmos_scene_object *o = &s->objects[i];
    atmos__scene_object_defaults(o);
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        double x;
        switch (k) {
        case 0: TRY(get_text(p, v, ip, o->mesh, sizeof o->mesh)); break;
        case 1: TRY(get_vec3(p, v, ip, any, o->position_m)); break;
        case 2: /* one number: the same on every axis */
        case 4:
            if (cJSON_IsNumber(v)) {
                TRY(get_number(p, v, ip, NULL, NULL, &x));
                double *d = k == 2 ? o->scale : o->albedo;
                d[0] = d[1] = d[2] = x;
            } else TRY(get_vec3(p, v, ip, any, k == 2 ? o->scale : o->albedo));
            break;
        case 3: TRY(get_vec3(p, v, ip, any, o->rotation_deg)); break;
        default: TRY(object_terrain_key(p, v, ip, k, o));
        }
    }
    if (!o->mesh[0] && !o->terrain[0])
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "needs \"mesh\" or \"terrain\"");
    return ATMOS_OK;
}

/* "fog": coefficients (extinction_per_m or visibility_m; scattering_per_m, g), or a particle
 * type with its extinction at 550 nm (extinction_per_m or visibility_m) and nothing else of its
 * optics; height_m, base_m with either. */
static atmos_status parse_fog(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"extinction_per_m", "scattering_per_m", "g", "height_m", "base_m",
                                       "visibility_m", "particle"};
    static const atmos__range r_vis = {ATMOS__KOSCHMIEDER / 10, 1e7, 0, 0};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    int k;
    atmos_scene_fog *f = &s->fog;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        if (k == 6) {
            const char *name = NULL;
            TRY(get_string(p, v, ip, &name));
            if (!name[0] || strlen(name) >= sizeof f->particle)
                return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, ip,
                                         "must name a particle type (1-31 characters)");
            strcpy(f->particle, name);
            continue;
        }
        double *const fields[6] = {&f->extinction_per_m, &f->scattering_per_m, &f->g, &f->height_m, &f->base_m,
                                   &f->visibility_m};
        TRY(get_number(p, v, ip, k == 5 ? &r_vis : NULL, k == 5 ? " (metres)" : NULL, fields[k]));
    }
    const unsigned ext = 1u, sca = 2u, g = 4u, vis = 32u, part = 64u;
    if (!!(it.seen & ext) == !!(it.seen & vis))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 (it.seen & ext) ? "give only one of \"extinction_per_m\" and \"visibility_m\" (the same "
                                                   "density two ways)"
                                                 : "needs one of \"extinction_per_m\" and \"visibility_m\"");
    if ((it.seen & part) && (it.seen & (sca | g)))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path,
                                 "a fog of a particle type takes its albedo and phase function from the type: "
                                 "\"scattering_per_m\" and \"g\" go with a fog without \"particle\"");
    if (it.seen & vis) f->extinction_per_m = ATMOS__KOSCHMIEDER / f->visibility_m;
    if (!(it.seen & sca)) f->scattering_per_m = f->extinction_per_m; /* no absorption unless given */
    f->enabled = 1;
    return ATMOS_OK;
}

static atmos_status parse_animation(const jp *p, const cJSON *j, const char *path, atmos_scene *s)
{
    static const char *const keys[] = {"frames",      "time_end", "elevation_end_deg", "azimuth_end_deg",
                                       "minutes_end", "exposure", "exposure_limit_ev"};
    static const char *const exposures[] = {"locked", "per_frame"};
    static const atmos__range r_limit = {-20, 40, 0, 0}; /* as a manual exposure's */
    static const atmos__range r_minutes = {0, ATMOS_SIM_MAX_MINUTES, 1, 0};
    /* 0 and 1: a single image (0 = no animation, include/atmos/scene.h), so -D animation.frames=0
     * turns a scene's animation off */
    static const atmos__range r_frames = {0, ATMOS_SCENE_MAX_FRAMES, 0, 0};
    atmos_scene_animation a;
    memset(&a, 0, sizeof a);
    a.exposure_limit_ev = ATMOS_SCENE_EXPOSURE_LIMIT_EV;
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    const char *text = NULL;
    int k;
    TRY(iter_begin(p, j, path, keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(p, &it, &k, &v, ip));
        if (k < 0) break;
        switch (k) {
        case 0: TRY(get_int(p, v, ip, &r_frames, &a.frames)); break;
        case 5: TRY(get_enum(p, v, ip, exposures, 2, &a.exposure_per_frame)); break;
        case 6: TRY(get_number(p, v, ip, &r_limit, NULL, &a.exposure_limit_ev)); break;
        case 4:
            TRY(get_number(p, v, ip, &r_minutes, NULL, &a.minutes_end));
            a.minutes_end_set = 1;
            break;
        case 1:
            TRY(get_string(p, v, ip, &text));
            TRY(parse_time(p, text, ip, &a.time_end));
            a.time_end_set = 1;
            break;
        case 2:
            TRY(get_number(p, v, ip, &atmos__r_elevation, NULL, &a.elevation_end_deg));
            a.elevation_end_set = 1;
            break;
        case 3:
            TRY(get_number(p, v, ip, &atmos__r_azimuth, NULL, &a.azimuth_end_deg));
            a.azimuth_end_set = 1;
            break;
        }
    }
    if (!(it.seen & 1u))
        return atmos__scene_fail(p->ctx, ATMOS_E_INVALID_ARG, p->source, path, "missing key \"frames\"");
    s->animation = a;
    return ATMOS_OK;
}

atmos_status atmos__scene_from_json(atmos_context *ctx, const char *source, const cJSON *root,
                                    atmos_scene *s)
{
    static const char *const keys[] = {"name", "image", "camera", "sun", "atmosphere", "wavelengths",
                                       "output", "renderer", "particles", "background", "volume", "slice",
                                       "path", "animation", "nishita", "harris", "beams", "lights", "fog",
                                       "objects"};
    static const char *const renderers[] = {"sky", "slice", "path", "nishita", "harris", "beams"};
    enum {
        K_NAME, K_IMAGE, K_CAMERA, K_SUN, K_ATMOSPHERE, K_WAVELENGTHS, K_OUTPUT, K_RENDERER, K_PARTICLES,
        K_BACKGROUND, K_VOLUME, K_SLICE, K_PATH, K_ANIMATION, K_NISHITA, K_HARRIS, K_BEAMS, K_LIGHTS, K_FOG, K_OBJECTS
    };
    jp p = {ctx, source};
    obj_iter it;
    char ip[PATH_CAP];
    const cJSON *v;
    const char *name = NULL;
    int k, renderer;
    if (!cJSON_IsObject(root)) return type_error(&p, "/", "an object", root);
    TRY(iter_begin(&p, root, "", keys, KEY_COUNT(keys), &it));
    for (;;) {
        TRY(iter_next(&p, &it, &k, &v, ip));
        if (k < 0) {
            /* A volume without a renderer named is drawn by the slice renderer. */
            if ((it.seen & (1u << K_VOLUME)) && !(it.seen & (1u << K_RENDERER))) s->renderer = ATMOS_RENDERER_SLICE;
            TRY(atmos__scene_validate_renderer(ctx, source, s));
            return atmos__scene_validate_animation(ctx, source, s);
        }
        switch (k) {
        case K_NAME:
            TRY(get_string(&p, v, ip, &name));
            if (strlen(name) >= sizeof s->name)
                return atmos__scene_fail(ctx, ATMOS_E_INVALID_ARG, source, ip,
                                         "must be at most %d bytes, got %zu", (int)sizeof s->name - 1,
                                         strlen(name));
            memcpy(s->name, name, strlen(name) + 1);
            break;
        case K_IMAGE: TRY(parse_image(&p, v, ip, s)); break;
        case K_CAMERA:
            TRY(parse_camera(&p, v, ip, s));
            s->camera_given = 1;
            break;
        case K_SUN: TRY(parse_sun(&p, v, ip, s)); break;
        case K_ATMOSPHERE: TRY(parse_atmosphere(&p, v, ip, s)); break;
        case K_WAVELENGTHS: TRY(parse_wavelengths(&p, v, ip, s)); break;
        case K_OUTPUT: TRY(parse_output(&p, v, ip, s)); break;
        case K_RENDERER:
            TRY(get_enum(&p, v, ip, renderers, 6, &renderer));
            s->renderer = (atmos_renderer_kind)renderer;
            break;
        case K_PARTICLES: TRY(parse_particles(&p, v, ip, s)); break;
        case K_BACKGROUND: TRY(parse_background(&p, v, ip, s)); break;
        case K_VOLUME: TRY(parse_volume(&p, v, ip, s)); break;
        case K_SLICE: TRY(parse_settings(&p, v, ip, ATMOS_RENDERER_SLICE, s)); break;
        case K_PATH: TRY(parse_settings(&p, v, ip, ATMOS_RENDERER_PATH, s)); break;
        case K_ANIMATION: TRY(parse_animation(&p, v, ip, s)); break;
        case K_NISHITA: TRY(parse_settings(&p, v, ip, ATMOS_RENDERER_NISHITA, s)); break;
        case K_HARRIS: TRY(parse_settings(&p, v, ip, ATMOS_RENDERER_HARRIS, s)); break;
        case K_BEAMS: TRY(parse_settings(&p, v, ip, ATMOS_RENDERER_BEAMS, s)); break;
        case K_LIGHTS: TRY(parse_array(&p, v, ip, ATMOS_SCENE_MAX_LIGHTS, &s->light_count, light_item, s)); break;
        case K_FOG: TRY(parse_fog(&p, v, ip, s)); break;
        case K_OBJECTS: TRY(parse_array(&p, v, ip, ATMOS_SCENE_MAX_OBJECTS, &s->object_count, object_item, s)); break;
        }
    }
}
