/* Scenes: the built-in defaults, reading a scene file, checking the text before
 * cJSON sees it, and the sun direction of a scene. The JSON tree walk is in
 * scene_json.c, the value rules in scene_validate.c.
 */
#define _POSIX_C_SOURCE 200809L /* fileno, fstat */
#include "scene/scene_internal.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

void atmos_scene_defaults(atmos_scene *s)
{
    if (!s) return;
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "default");
    s->width = 1280;
    s->height = 720;
    s->samples_per_pixel = 1;

    /* From a 1000 m hill, looking just above the south-south-west horizon: with the
     * afternoon sun in the south-west the view shows the sun's disk, the blue
     * gradient, the horizon brightening and the aerial perspective over the plain. */
    double dir[3];
    atmos_direction_from_angles(1.0, 200.0, dir);
    s->camera.type = ATMOS_CAMERA_PINHOLE;
    s->camera.position[1] = 1000.0;
    for (int i = 0; i < 3; i++) s->camera.look_at[i] = s->camera.position[i] + 1000.0 * dir[i];
    s->camera.up[1] = 1.0;
    s->camera.fov_deg = 60.0;

    s->sun.from_time = 0;
    s->sun.elevation_deg = 22.0;
    s->sun.azimuth_deg = 235.0;
    s->sun.refraction = 1;

    atmos_atmosphere_defaults(&s->atmosphere);
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
    s->spectral_samples = ATMOS_SPECTRAL_DEFAULT;
    s->animation.exposure_limit_ev = ATMOS_SCENE_EXPOSURE_LIMIT_EV;
    s->tonemap.manual_exposure = 0;
    s->tonemap.exposure_ev = 0.0;
    s->tonemap.curve = ATMOS_TONE_FILMIC;
    s->png_bits = 8;
    s->exr_half = 0;

    s->renderer = ATMOS_RENDERER_SKY;
    s->volume.density_scale = 1.0;
    s->volume.seed = 1;
    s->volume.scale = 1.0;
    atmos__settings_defaults(s);
}

/* 1-based line and byte column of offset, for messages an editor can jump to. */
static void line_col(const char *text, size_t offset, size_t *line, size_t *col)
{
    size_t l = 1, c = 1;
    for (size_t i = 0; i < offset; i++) {
        if (text[i] == '\n') {
            l++;
            c = 1;
        } else {
            c++;
        }
    }
    *line = l;
    *col = c;
}

static atmos_status text_error(atmos_context *ctx, atmos_status status, const char *source,
                               const char *text, size_t offset, const char *what)
{
    size_t line, col;
    line_col(text, offset, &line, &col);
    return atmos__error(ctx, status, "%s:%zu:%zu: %s", source, line, col, what);
}

/* Length of the well-formed UTF-8 sequence at s (Unicode Table 3-7: no overlong
 * forms, no surrogates, nothing above U+10FFFF), or 0. */
static size_t utf8_len(const unsigned char *s, size_t n)
{
    unsigned c = s[0];
    size_t len;
    unsigned lo = 0x80, hi = 0xBF;
    if (c >= 0xC2 && c <= 0xDF) len = 2;
    else if (c >= 0xE0 && c <= 0xEF) {
        len = 3;
        if (c == 0xE0) lo = 0xA0;
        if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
        len = 4;
        if (c == 0xF0) lo = 0x90;
        if (c == 0xF4) hi = 0x8F;
    } else {
        return 0;
    }
    if (n < len) return 0;
    if (s[1] < lo || s[1] > hi) return 0;
    for (size_t i = 2; i < len; i++)
        if (s[i] < 0x80 || s[i] > 0xBF) return 0;
    return len;
}

typedef struct scan_result {
    size_t depth;   /* open brackets at the end of the text */
    int in_string;  /* the text ends inside a string... */
    size_t string_start; /* ...that starts here */
} scan_result;

/* One pass over the raw text before cJSON parses it, for what cJSON does not
 * check or checks too late: invalid UTF-8 (RFC 8259 requires UTF-8), raw control
 * characters, NUL bytes and "\u0000" (they would silently truncate C strings),
 * and absurd nesting, which must be refused before cJSON recurses into it. */
static atmos_status scan_text(atmos_context *ctx, const char *source, const char *text, size_t n,
                              scan_result *res)
{
    const unsigned char *s = (const unsigned char *)text;
    int in_string = 0, escape = 0, content = 0;
    size_t depth = 0;
    if (n >= 2 && ((s[0] == 0xFF && s[1] == 0xFE) || (s[0] == 0xFE && s[1] == 0xFF))) /* a UTF-16 byte order mark */
        return text_error(ctx, ATMOS_E_FORMAT, source, text, 0, "malformed JSON: UTF-16: save the scene as UTF-8");
    for (size_t i = 0; i < n; i++) {
        unsigned c = s[i];
        if (c == 0) return text_error(ctx, ATMOS_E_FORMAT, source, text, i, "malformed JSON: NUL byte");
        if (c >= 0x80) {
            size_t len = utf8_len(s + i, n - i);
            if (!len) return text_error(ctx, ATMOS_E_FORMAT, source, text, i, "malformed JSON: invalid UTF-8");
            /* A byte order mark at the very start is allowed (cJSON skips it). */
            if (!(i == 0 && len == 3 && c == 0xEF && s[1] == 0xBB && s[2] == 0xBF)) content = 1;
            i += len - 1;
            escape = 0;
            continue;
        }
        if (in_string) {
            if (escape) {
                escape = 0;
                if (c == 'u' && n - i > 4 && memcmp(s + i + 1, "0000", 4) == 0)
                    return text_error(ctx, ATMOS_E_FORMAT, source, text, i - 1,
                                      "malformed JSON: \\u0000 is not allowed in scene strings");
            } else if (c == '\\') {
                escape = 1;
            } else if (c == '"') {
                in_string = 0;
            } else if (c < 0x20) {
                return text_error(ctx, ATMOS_E_FORMAT, source, text, i,
                                  "malformed JSON: control character in a string (escape it)");
            }
            continue;
        }
        if (c == ' ' || c == '\t' || c == '\n' || c == '\r') continue;
        if (c < 0x20 || c == 0x7F)
            return text_error(ctx, ATMOS_E_FORMAT, source, text, i, "malformed JSON: control character");
        content = 1;
        if (c == '"') {
            in_string = 1;
            res->string_start = i;
        } else if (c == '[' || c == '{') {
            if (++depth > ATMOS__SCENE_MAX_DEPTH) {
                char what[96];
                snprintf(what, sizeof what, "nesting deeper than %d levels", ATMOS__SCENE_MAX_DEPTH);
                return text_error(ctx, ATMOS_E_LIMIT, source, text, i, what);
            }
        } else if ((c == ']' || c == '}') && depth > 0) {
            depth--;
        }
    }
    if (!content) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: empty input (expected a JSON object)", source);
    res->depth = depth;
    res->in_string = in_string;
    return ATMOS_OK;
}

/* cJSON reports where it stopped; quote a little of the text there so the
 * message makes sense without opening the file. */
static atmos_status syntax_error(atmos_context *ctx, const char *source, const char *text, size_t n,
                                 size_t offset, const scan_result *scan)
{
    /* Truncated input: cJSON stops at (or just before) the end, or at the start
     * of a string that never closes. */
    if (scan->in_string && offset >= scan->string_start)
        return text_error(ctx, ATMOS_E_FORMAT, source, text, n,
                          "malformed JSON: unexpected end of input inside a string");
    if (scan->depth > 0 && offset + 1 >= n)
        return text_error(ctx, ATMOS_E_FORMAT, source, text, n,
                          "malformed JSON: unexpected end of input (unclosed { or [)");
    char what[96];
    size_t o = (size_t)snprintf(what, sizeof what, "malformed JSON near '");
    for (size_t i = offset; i < n && i < offset + 24 && text[i] != '\n'; i++) {
        unsigned char c = (unsigned char)text[i];
        what[o++] = c >= 0x20 && c < 0x7F ? (char)c : '?';
    }
    snprintf(what + o, sizeof what - o, "'");
    return text_error(ctx, ATMOS_E_FORMAT, source, text, offset, what);
}

atmos_status atmos_scene_parse(atmos_context *ctx, const char *json, size_t length, const char *source,
                               atmos_scene *out)
{
    return atmos_scene_parse_with(ctx, json, length, source, NULL, 0, out);
}

atmos_status atmos_scene_parse_with(atmos_context *ctx, const char *json, size_t length, const char *source,
                                    const char *const *overrides, int count, atmos_scene *out)
{
    if (!source) source = "scene";
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: atmos_scene_parse: out is NULL", source);
    if (!json && length) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: atmos_scene_parse: json is NULL", source);
    if (length > ATMOS__SCENE_MAX_BYTES)
        return atmos__error(ctx, ATMOS_E_LIMIT, "%s: input is %zu bytes; scene files are limited to 16 MiB",
                            source, length);
    scan_result scan = {0, 0, 0};
    atmos_status st = scan_text(ctx, source, json ? json : "", length, &scan);
    if (st) return st;

    /* cJSON is given a terminated private copy: the caller's buffer need not be
     * terminated, and a reader bug in the (uninstrumented) system cJSON can never
     * run past our allocation. */
    char *copy = malloc(length + 1);
    if (!copy) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", source);
    memcpy(copy, json, length);
    copy[length] = '\0';
    /* return_parse_end instead of cJSON_GetErrorPtr(): the same position, but
     * not a process-wide global another thread may be overwriting. */
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(copy, length, &end, 0);
    if (!root) {
        size_t off = end && end >= copy && end <= copy + length ? (size_t)(end - copy) : 0;
        st = syntax_error(ctx, source, copy, length, off, &scan);
        free(copy);
        return st;
    }
    size_t off = end && end >= copy && end <= copy + length ? (size_t)(end - copy) : length;
    while (off < length && (copy[off] == ' ' || copy[off] == '\t' || copy[off] == '\n' || copy[off] == '\r'))
        off++;
    if (off < length) {
        st = text_error(ctx, ATMOS_E_FORMAT, source, copy, off,
                        "malformed JSON: unexpected text after the end of the scene");
    } else {
        /* Parse into a local so that *out is untouched on failure. */
        atmos_scene s;
        atmos_scene_defaults(&s);
        if (count > 0 && !cJSON_IsObject(root))
            st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: a scene must be a JSON object", source);
        else st = atmos__scene_apply_overrides(ctx, source, root, overrides, count);
        if (st == ATMOS_OK) {
            st = atmos__scene_from_json(ctx, source, root, &s);
            if (st != ATMOS_OK && count > 0) st = atmos__scene_blame_override(ctx, st, source, overrides, count);
        }
        if (st == ATMOS_OK) {
            atmos__scene_override_blame(s.volume_by, sizeof s.volume_by, "/volume/file", source, overrides, count);
            *out = s;
        }
    }
    cJSON_Delete(root);
    free(copy);
    return st;
}

atmos_status atmos_scene_load(atmos_context *ctx, const char *path, atmos_scene *out)
{
    return atmos_scene_load_with(ctx, path, NULL, 0, out);
}

atmos_status atmos_scene_load_with(atmos_context *ctx, const char *path, const char *const *overrides, int count,
                                   atmos_scene *out)
{
    if (!path || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_scene_load: path or out is NULL");
    const int in = !strcmp(path, "-");
    FILE *f = in ? stdin : fopen(path, "rb");
    if (in) path = "standard input";
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));
    /* The size is checked before anything is allocated; the read loop below also
     * stops at the limit, for files that grow or report no size (pipes). */
    struct stat sb;
    size_t cap = 4096;
    if (fstat(fileno(f), &sb) == 0) {
        if (S_ISDIR(sb.st_mode)) {
            if (!in) fclose(f);
            return atmos__error(ctx, ATMOS_E_IO, "%s: cannot read: %s", path, strerror(EISDIR));
        }
        if (S_ISREG(sb.st_mode)) {
            if ((unsigned long long)sb.st_size > ATMOS__SCENE_MAX_BYTES) {
                if (!in) fclose(f);
                return atmos__error(ctx, ATMOS_E_LIMIT, "%s: file is %lld bytes; scene files are limited to 16 MiB",
                                    path, (long long)sb.st_size);
            }
            cap = (size_t)sb.st_size + 1;
        }
    }
    char *buf = malloc(cap);
    size_t len = 0;
    atmos_status st = ATMOS_OK;
    while (buf) {
        len += fread(buf + len, 1, cap - len, f);
        if (ferror(f)) {
            st = atmos__error(ctx, ATMOS_E_IO, "%s: cannot read: %s", path, strerror(errno));
            break;
        }
        if (len > ATMOS__SCENE_MAX_BYTES) {
            st = atmos__error(ctx, ATMOS_E_LIMIT, "%s: file is larger than 16 MiB, the limit for scene files", path);
            break;
        }
        if (feof(f)) break;
        if (len == cap) {
            size_t ncap = cap * 2 > ATMOS__SCENE_MAX_BYTES + 1 ? ATMOS__SCENE_MAX_BYTES + 1 : cap * 2;
            char *nb = realloc(buf, ncap);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb;
            cap = ncap;
        }
    }
    if (!in) fclose(f);
    if (!buf) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
    if (st == ATMOS_OK) st = atmos_scene_parse_file(ctx, buf, len, in ? "-" : path, overrides, count, out);
    free(buf);
    return st;
}

atmos_status atmos_scene_parse_file(atmos_context *ctx, const char *json, size_t length, const char *path,
                                    const char *const *overrides, int count, atmos_scene *out)
{
    if (!json || !path || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_scene_parse_file: an argument is NULL");
    const int in = !strcmp(path, "-");
    if (in) path = "standard input";
    atmos_status st = atmos_scene_parse_with(ctx, json, length, path, overrides, count, out);
    /* Relative files are relative to the scene file's folder, so scenes can be rendered from
     * anywhere; "data:" files are in the data folder (scene_paths.c). */
    const char *slash = in ? NULL : strrchr(path, '/'); /* from standard input: the current folder */
    const size_t dir = slash ? (size_t)(slash - path) + 1 : 0;
    char key[64];
    if (st == ATMOS_OK && in) snprintf(out->origin, sizeof out->origin, "standard input");
    if (st == ATMOS_OK && !in) { /* for messages only: a path too long kept as "..." and its end */
        const size_t len = strlen(path), cap = sizeof out->file;
        if (len < cap) snprintf(out->file, cap, "%s", path);
        else snprintf(out->file, cap, "...%s", path + len - (cap - 4));
    }
    if (st == ATMOS_OK)
        st = atmos__scene_join_path(ctx, path, dir, out->volume.source, sizeof out->volume.source, "volume/file");
    if (st == ATMOS_OK) st = atmos__scene_earth_paths(ctx, path, dir, &out->earth);
    for (int i = 0; st == ATMOS_OK && i < out->light_count; i++) {
        snprintf(key, sizeof key, "lights/%d/image", i);
        st = atmos__scene_join_path(ctx, path, dir, out->lights[i].image, ATMOS_SCENE_PATH_MAX, key);
    }
    for (int i = 0; st == ATMOS_OK && i < 2 * out->object_count; i++) {
        char *m = i % 2 ? out->objects[i / 2].terrain : out->objects[i / 2].mesh; /* both ATMOS_SCENE_PATH_MAX */
        snprintf(key, sizeof key, "objects/%d/%s", i / 2, i % 2 ? "terrain" : "mesh");
        st = atmos__scene_join_path(ctx, path, dir, m, ATMOS_SCENE_PATH_MAX, key);
    }
    return st;
}

atmos_status atmos_scene_wavelengths(atmos_context *ctx, const atmos_scene *scene, atmos_wavelengths *out)
{
    if (scene->wavelengths == ATMOS_WAVELENGTHS_RGB) {
        atmos_wavelengths_rgb(out);
    } else if (atmos_wavelengths_spectral(scene->spectral_samples, out) != ATMOS_OK) {
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "wavelengths/samples: must be in [1, %d], got %d",
                            ATMOS_MAX_WAVELENGTHS, scene->spectral_samples);
    }
    /* A sun given by its irradiance replaces the solar spectrum; the colour
     * conversion stays that of the set (to_srgb/to_xyz are unchanged). */
    if (scene->sun.irradiance_count == 1)
        for (int i = 0; i < out->count; i++) out->sun_irradiance[i] = scene->sun.irradiance[0];
    else if (scene->sun.irradiance_count == 3 && out->count == 3)
        for (int i = 0; i < 3; i++) out->sun_irradiance[i] = scene->sun.irradiance[i];
    return ATMOS_OK;
}

atmos_status atmos_scene_sun_direction(atmos_context *ctx, const atmos_scene *scene, double dir[3],
                                       double *elevation_deg, double *azimuth_deg)
{
    if (!scene || !dir) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_scene_sun_direction: scene or dir is NULL");
    /* A scene built in code may hold anything; never turn a NaN into a direction. */
    atmos_status st = atmos__scene_validate_sun(ctx, "scene", &scene->sun);
    if (st) return st;
    double e = scene->sun.elevation_deg, a = scene->sun.azimuth_deg;
    if (scene->sun.from_time) {
        atmos_sun_position pos;
        st = atmos_sun_position_compute(ctx, &scene->sun.time, scene->sun.latitude_deg,
                                        scene->sun.longitude_deg, scene->sun.refraction, &pos);
        if (st) return st;
        e = pos.elevation_deg;
        a = pos.azimuth_deg;
    }
    atmos_direction_from_angles(e, a, dir);
    if (elevation_deg) *elevation_deg = e;
    if (azimuth_deg) *azimuth_deg = a;
    return ATMOS_OK;
}

atmos_status atmos_scene_animation_frame(atmos_context *ctx, const atmos_scene *scene, int index, atmos_scene *out)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_scene_animation_frame: scene or out is NULL");
    atmos_status st = atmos__scene_validate_animation(ctx, "scene", scene);
    if (st != ATMOS_OK) return st;
    const atmos_scene_animation *a = &scene->animation;
    int n = a->frames > 1 ? a->frames : 1;
    if (index < 0 || index >= n)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "animation frame %d is out of range (the scene has %d frame%s)",
                            index, n, n == 1 ? "" : "s");
    atmos_scene s = *scene;
    if (n > 1) {
        double f = (double)index / (n - 1);
        if (s.sun.from_time && a->time_end_set) {
            double t0 = atmos_utc_time_seconds(&s.sun.time), t1 = atmos_utc_time_seconds(&a->time_end);
            atmos_utc_time_from_seconds(index == n - 1 ? t1 : t0 + f * (t1 - t0), &s.sun.time);
        } else if (!s.sun.from_time) {
            if (a->elevation_end_set)
                s.sun.elevation_deg += f * (a->elevation_end_deg - s.sun.elevation_deg);
            if (a->azimuth_end_set) {
                /* The shorter way round: 350 -> 10 passes north. */
                double d = fmod(a->azimuth_end_deg - s.sun.azimuth_deg + 540.0, 360.0) - 180.0;
                double az = fmod(s.sun.azimuth_deg + f * d + 360.0, 360.0);
                s.sun.azimuth_deg = az >= 360.0 ? 0.0 : az;
            }
        }
    }
    if (n > 1 && a->minutes_end_set) {
        const double m0 = atmos__scene_first_sim_minutes(&s);
        s.volume.sim_minutes = index == n - 1 ? a->minutes_end : m0 + (double)index / (n - 1) * (a->minutes_end - m0);
    }
    memset(&s.animation, 0, sizeof s.animation); /* a frame is a single image, with the animation's limit */
    s.animation.exposure_limit_ev = a->exposure_limit_ev;
    *out = s;
    return ATMOS_OK;
}
