/* atmos render's scene: the scene file (or the default), the options applied, validated,
 * and a volume file without a camera framed: the volume loaded here, placed, and the
 * camera pointed at it (atmos_scene_frame_volume). */
#define _XOPEN_SOURCE 700 /* realpath */
#include "render_scene.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int ends_with(const char *s, const char *ext)
{
    size_t n = strlen(s), m = strlen(ext);
    if (n < m) return 0;
    for (size_t i = 0; i < m; i++) {
        char c = s[n - m + i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != ext[i]) return 0;
    }
    return 1;
}

/* A volume file given where a scene goes: by its extension or its first bytes (OpenVDB,
 * NanoVDB, NetCDF classic, HDF5). */
static int looks_like_volume(const char *path)
{
    static const char *const exts[] = {".vdb", ".nvdb", ".nc", ".nc4", ".cdf", ".raw"};
    for (size_t i = 0; i < sizeof exts / sizeof exts[0]; i++)
        if (ends_with(path, exts[i])) return 1;
    unsigned char b[8] = {0};
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    size_t n = fread(b, 1, sizeof b, f);
    fclose(f);
    if (n >= 4 && b[0] == 0x20 && b[1] == 0x42 && b[2] == 0x44 && b[3] == 0x56) return 1;
    if (n >= 7 && !memcmp(b, "NanoVDB", 7)) return 1;
    if (n >= 4 && !memcmp(b, "CDF", 3)) return 1;
    return n >= 8 && !memcmp(b, "\x89HDF\r\n\x1a\n", 8);
}

/* A raw volume's JSON sidecar (the volume file atmos reads): an object with "dims" and "fields". */
static int is_raw_sidecar(const char *text)
{
    cJSON *j = text ? cJSON_Parse(text) : NULL;
    const int yes = cJSON_IsObject(j) && cJSON_GetObjectItemCaseSensitive(j, "dims") &&
                    cJSON_GetObjectItemCaseSensitive(j, "fields");
    cJSON_Delete(j);
    return yes;
}

/* The sidecar of raw file `raw` (atmos volume generate writes STEM.json and STEM.FIELD.raw):
 * STEM.FIELD.json or STEM.json when it exists and is a sidecar. 1 if found (in buf). */
static int raw_sidecar_of(const char *raw, char *buf, size_t cap)
{
    const char *slash = strrchr(raw, '/'), *name = slash ? slash + 1 : raw;
    size_t stem = strlen(raw) - 4; /* without ".raw" */
    for (int k = 0; k < 2; k++) {
        int n = snprintf(buf, cap, "%.*s.json", (int)stem, raw);
        if (n < 0 || (size_t)n >= cap) return 0;
        char *text = cli_read_text(buf, (size_t)1 << 20);
        const int yes = is_raw_sidecar(text);
        free(text);
        if (yes) return 1;
        const char *dot = NULL; /* the stem's last '.', within the file name */
        for (const char *c = name; c < raw + stem; c++)
            if (*c == '.') dot = c;
        if (!dot || dot == name) return 0;
        stem = (size_t)(dot - raw);
    }
    return 0;
}

/* A volume file (or a raw volume's sidecar) given where a scene goes: refused with the command
 * that opens it (a raw file through its sidecar). 1 if refused (message printed). */
static int refuse_volume_file(const render_opts *o)
{
    const char *p = o->scene_path;
    if (!strcmp(p, "-")) return 0;
    const int sidecar = ends_with(p, ".json") && is_raw_sidecar(o->scene_text);
    if (!sidecar && !looks_like_volume(p)) return 0;
    char side[ATMOS_SCENE_PATH_MAX + 8];
    const int raw = ends_with(p, ".raw");
    if (raw && !raw_sidecar_of(p, side, sizeof side)) {
        fprintf(stderr,
                "atmos %s: %s is a raw volume file, not a scene: atmos reads it through its JSON sidecar\n"
                "(a .json file with \"dims\" and \"fields\" naming it): atmos %s --volume SIDECAR.json\n",
                o->cmd, p, o->cmd);
        return 1;
    }
    fprintf(stderr, "atmos %s: %s is a volume file%s, not a scene: open it with\n  atmos %s --volume %s\n", o->cmd, p,
            raw ? " (raw, read through its JSON sidecar)" : sidecar ? " (a raw volume's JSON sidecar)" : "", o->cmd,
            raw ? side : p);
    return 1;
}

/* An image given where a scene goes (known by its first bytes): refused, saying what it is,
 * rather than read as malformed JSON. 1 if refused (message printed). */
static int refuse_image_file(const render_opts *o)
{
    const char *p = o->scene_path;
    const char *kind = strcmp(p, "-") ? atmos_image_file_kind(p) : NULL;
    if (!kind) return 0;
    fprintf(stderr,
            "atmos %s: %s is %s %s image, not a scene: a scene is a JSON file (docs/scene-format.md), which names "
            "the images it uses; atmos compare reads rendered images\n",
            o->cmd, p, kind[0] == 'O' ? "an" : "a", kind);
    return 1;
}

/* Whether the user chose the atmosphere: a scene file, --atmosphere or a -D atmosphere.*. */
static int atmosphere_given(const render_opts *o)
{
    if (o->scene_path || o->air >= 0) return 1;
    for (int i = 0; i < o->ndefines; i++)
        if (!strncmp(o->defines[i], "atmosphere", 10)) return 1;
    return 0;
}

/* The height above which the flat-earth models show an endless plane (the plan warns of it,
 * src/render/plan.c): the Karman line. */
#define FLAT_EARTH_TOP_M 100e3

/* A camera framed above the flat-earth model's range with no atmosphere chosen: the round
 * planet instead, which a user looking down on a domain from orbit expects (the flat
 * model's plane would fill the sky to the horizon). */
static void round_planet_from_orbit(const render_opts *o, atmos_scene *scene)
{
    if (atmosphere_given(o) || scene->atmosphere.kind != ATMOS_ATMOSPHERE_RILEY) return;
    if (!(scene->camera.position[1] > FLAT_EARTH_TOP_M)) return;
    scene->atmosphere.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    /* its height over the round planet (centre (0, -R, 0)), not its y */
    const double R = scene->atmosphere.planet_radius_m > 0 ? scene->atmosphere.planet_radius_m : 6360e3,
                 *p = scene->camera.position, up = hypot(hypot(p[0], p[2]), p[1] + R) - R;
    if (!o->quiet)
        fprintf(stderr,
                "atmos %s: the camera is %.0f km up, above the flat-earth riley model's range: using the spherical "
                "atmosphere model (--atmosphere riley keeps the flat one)\n",
                o->cmd, up / 1000.0);
}

/* A volume file with no camera given: framed as atmos_scene_frame_volume_file frames it, and said.
 * Returns the exit status: a field of view so narrow that the framing camera stands beyond the
 * scene's positions (1e8 m) is a usage error naming --fov, not the position it made. */
static int frame_volume(atmos_context *ctx, const render_opts *o, atmos_scene *scene, atmos_volume **volume)
{
    atmos_status st = atmos_scene_frame_volume_file(ctx, scene, o->view_el, volume);
    if (st != ATMOS_OK) return cli_runtime_error(o->cmd, ctx, st);
    if (!*volume) return CLI_EXIT_OK;
    const double *p = scene->camera.position, *l = scene->camera.look_at;
    const double far = fmax(fabs(p[0]), fmax(fabs(p[1]), fabs(p[2])));
    if (!(far <= 1e8))
        return cli_usage_error(o->cmd, "no camera given: framing the volume in a field of view of %g degrees puts the "
                               "camera %.3g m away, beyond the scene's 1e8 m; give a wider --fov, or the camera's "
                               "--position and --look-at", scene->camera.fov_deg, far);
    if (o->quiet) return round_planet_from_orbit(o, scene), CLI_EXIT_OK;
    double lo[3], hi[3];
    atmos_volume_bounds(*volume, lo, hi);
    fprintf(stderr,
            "atmos %s: no camera given: framing the volume (%.0f x %.0f x %.0f m) from (%.0f, %.0f, %.0f) m "
            "looking at (%.0f, %.0f, %.0f) m\n",
            o->cmd, hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], p[0], p[1], p[2], l[0], l[1], l[2]);
    round_planet_from_orbit(o, scene);
    return CLI_EXIT_OK;
}

/* Writes "KEY=\"VALUE\"" into buf with VALUE's quotes and backslashes escaped for JSON. */
static void quoted_define(char *buf, size_t cap, const char *key, size_t klen, const char *value)
{
    size_t k = (size_t)snprintf(buf, cap, "%.*s=\"", (int)klen, key);
    for (const char *p = value; *p && k + 3 < cap; p++) {
        if (*p == '"' || *p == '\\') buf[k++] = '\\';
        buf[k++] = *p;
    }
    snprintf(buf + k, cap - k, "\"");
}

/* Whether a scene file that failed to load with the user's -D (status st) loads without them: a
 * value one of them gave that another key of the file no longer agrees with (-D
 * fog.extinction_per_m below the file's scattering), or a -D the reader cannot place (-D
 * lights.1.cone_deg in a scene of one light). Then the options made the error, a usage error.
 * Called after the error was printed: the context's message is replaced. */
static int defines_broke_it(atmos_context *ctx, const render_opts *o, atmos_status st)
{
    if (o->ndefines == 0 || st == ATMOS_E_IO || st == ATMOS_E_NOMEM || !strcmp(o->scene_path, "-")) return 0;
    atmos_scene *alone = malloc(sizeof *alone);
    const int ok = alone && atmos_scene_load_with(ctx, o->scene_path, NULL, 0, alone) == ATMOS_OK;
    free(alone);
    atmos_context_clear_error(ctx);
    return ok;
}

static void say_defines(const render_opts *o)
{
    fprintf(stderr, "  (the scene file alone is valid: the -D override%s", o->ndefines > 1 ? "s" : "");
    for (int i = 0; i < o->ndefines; i++) fprintf(stderr, "%s -D %s", i ? "," : "", o->defines[i]);
    fprintf(stderr, " made it so)\n");
}

/* The -D whose key (a.b.0 or /a/b/0) is, or holds, the JSON pointer after the scene file's name
 * in msg ("scene.json: /objects/0/terrain: ..."): the error is the define's, not the file's. */
const char *render_scene_define_in(const render_opts *o, const char *msg)
{
    for (int i = 0; i < o->ndefines; i++) {
        const char *d = o->defines[i], *eq = strchr(d, '=');
        char ptr[256];
        size_t n = 0;
        if (!eq || eq == d) continue;
        if (d[0] != '/') ptr[n++] = '/';
        for (const char *c = d; c < eq && n + 1 < sizeof ptr; c++) ptr[n++] = *c == '.' ? '/' : *c;
        ptr[n] = '\0';
        for (const char *at = strstr(msg, ptr); at; at = strstr(at + 1, ptr))
            if (at - msg >= 2 && at[-2] == ':' && at[-1] == ' ' && (at[n] == ':' || at[n] == '/')) return d;
    }
    return NULL;
}

/* A -D that sets a file (volume.file, a light's image, an object's mesh or terrain, the Earth's
 * maps; or such a key inside an object it sets: -D 'volume={"file": ...}') to a relative path
 * names it from the current folder, as a path typed on the command
 * line does everywhere, not from the scene file's folder: the path is made absolute here
 * (realpath when it exists). Others, "data:", "builtin:", "generate:" and "simulate:" values
 * are kept. Returns def itself or buf. */
static const char *const cwd_keys[] = {"file", "image", "mesh", "terrain", "ground_map", "night_lights", "world_file"};

static int is_path_key(const char *k, size_t n)
{
    for (size_t i = 0; i < sizeof cwd_keys / sizeof cwd_keys[0]; i++)
        if (n == strlen(cwd_keys[i]) && !strncmp(k, cwd_keys[i], n)) return 1;
    return 0;
}

/* value (n bytes) made absolute from the current folder into joined (realpath when it
 * exists); 0 when it is kept: absolute, empty, too long, or "data:", "generate:" ... */
static int cwd_path(const char *v, size_t n, char *joined, size_t cap)
{
    char value[ATMOS_SCENE_PATH_MAX], cwd[ATMOS_SCENE_PATH_MAX];
    if (n == 0 || n >= sizeof value || v[0] == '/' || v[0] == '"' || memchr(v, ':', n)) return 0;
    memcpy(value, v, n);
    value[n] = 0;
    char *abs = realpath(value, NULL);
    if (!abs && getcwd(cwd, sizeof cwd)) snprintf(joined, cap, "%s/%s", cwd, value);
    else snprintf(joined, cap, "%s", abs ? abs : value);
    free(abs);
    return 1;
}

/* The file keys inside a JSON value (-D 'volume={"file": "d.vdb"}', -D 'objects.0={...}'),
 * made absolute as cwd_path does. Returns whether any changed. */
static int cwd_tree(cJSON *node)
{
    int changed = 0;
    for (cJSON *c = node ? node->child : NULL; c; c = c->next) {
        char joined[2 * ATMOS_SCENE_PATH_MAX];
        if (cJSON_IsString(c) && c->string && is_path_key(c->string, strlen(c->string)) &&
            cwd_path(c->valuestring, strlen(c->valuestring), joined, sizeof joined)) {
            changed |= cJSON_SetValuestring(c, joined) != NULL;
        } else if (cJSON_IsObject(c) || cJSON_IsArray(c)) {
            changed |= cwd_tree(c);
        }
    }
    return changed;
}

static const char *cwd_define(const char *def, char *buf, size_t cap)
{
    const char *eq = strchr(def, '=');
    if (!eq) return def;
    const char *last = eq;
    while (last > def && last[-1] != '.' && last[-1] != '/') last--;
    const char *v = eq + 1;
    size_t n = strlen(v);
    if (v[0] == '{' || v[0] == '[') { /* an object or array holding file keys */
        buf[0] = '\0';
        cJSON *tree = cJSON_ParseWithOpts(v, NULL, 1); /* the whole value, as the library reads it */
        char *text = tree && cwd_tree(tree) ? cJSON_PrintUnformatted(tree) : NULL;
        cJSON_Delete(tree);
        if (text && (size_t)(eq - def) + 1 + strlen(text) < cap)
            snprintf(buf, cap, "%.*s=%s", (int)(eq - def), def, text);
        const int done = text && buf[0];
        free(text);
        return done ? buf : def;
    }
    if (n >= 2 && v[0] == '"' && v[n - 1] == '"' && !memchr(v + 1, '\\', n - 2)) v++, n -= 2;
    char joined[2 * ATMOS_SCENE_PATH_MAX];
    if (!is_path_key(last, (size_t)(eq - last)) || !cwd_path(v, n, joined, sizeof joined)) return def;
    quoted_define(buf, cap, def, (size_t)(eq - def), joined);
    return buf;
}

/* -D volume.KEY=VALUE with --volume SOURCE: the scene's "volume" is read from the JSON tree
 * before --volume applies, so without a source there it would be refused ("needs file,
 * generate or simulate") and a source of another kind would make the key wrong. The source
 * goes first as a -D of its own (a file as an absolute path: the scene file's folder does not
 * apply to a command-line path), the user's -D after it (a relative file made absolute,
 * cwd_define, into paths[i]). defs: room for ndefines + 1; buf: the source's define. Returns
 * the count. */
static int volume_defines(const render_opts *o, const char **defs, char *buf, size_t cap,
                          char (*paths)[ATMOS_SCENE_PATH_MAX * 2 + 64])
{
    int touches = 0;
    for (int i = 0; i < o->ndefines; i++)
        touches |= !strncmp(o->defines[i], "volume.", 7) || !strncmp(o->defines[i], "/volume/", 8);
    int n = 0;
    if (o->volume && touches) {
        if (!strncmp(o->volume, "generate:", 9)) {
            snprintf(buf, cap, "volume.generate=\"%s\"", o->volume + 9);
        } else if (!strncmp(o->volume, "simulate:", 9)) {
            snprintf(buf, cap, "volume.simulate={\"preset\": \"%s\"}", o->volume + 9);
        } else {
            char *abs = realpath(o->volume, NULL);
            quoted_define(buf, cap, "volume.file", 11, abs ? abs : o->volume);
            free(abs);
        }
        defs[n++] = buf;
    }
    for (int i = 0; i < o->ndefines; i++) defs[n++] = cwd_define(o->defines[i], paths[i], sizeof paths[i]);
    return n;
}

/* --volume SOURCE names the volume; a -D that names one too (volume.file, .generate, .simulate
 * or the whole "volume") would be overridden by one of them without a word: refused. Returns
 * the offending define or NULL. */
static const char *second_volume_source(const render_opts *o)
{
    static const char *keys[] = {"volume=", "volume.file=", "volume.generate=", "volume.simulate=",
                                 "/volume=", "/volume/file=", "/volume/generate=", "/volume/simulate="};
    for (int i = 0; o->volume && i < o->ndefines; i++)
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++)
            if (!strncmp(o->defines[i], keys[k], strlen(keys[k]))) return o->defines[i];
    return NULL;
}

int render_scene_make(atmos_context *ctx, const render_opts *o, atmos_scene *scene, atmos_volume **volume)
{
    atmos_status st;
    *volume = NULL;
    const char *defs[RENDER_OPTS_MAX_DEFINES + 1];
    char source_def[ATMOS_SCENE_PATH_MAX + 64];
    static char paths[RENDER_OPTS_MAX_DEFINES][ATMOS_SCENE_PATH_MAX * 2 + 64]; /* one command's defines */
    const char *twice = second_volume_source(o);
    if (twice) {
        fprintf(stderr, "atmos %s: --volume %s and -D %s both name the volume: give one of them\n", o->cmd, o->volume,
                twice);
        return CLI_EXIT_USAGE;
    }
    const int ndefs = volume_defines(o, defs, source_def, sizeof source_def, paths);
    if (o->scene_path) {
        if (refuse_volume_file(o) || refuse_image_file(o)) return CLI_EXIT_USAGE;
        if (!strcmp(o->scene_path, "-")) {
            if (!o->scene_text) {
                fprintf(stderr, "atmos %s: standard input: cannot read the scene (larger than 16 MiB, the limit "
                                "for scene files, a NUL byte or a read error)\n", o->cmd);
                return CLI_EXIT_RUNTIME;
            }
            st = atmos_scene_parse_file(ctx, o->scene_text, strlen(o->scene_text), "-", defs, ndefs,
                                        scene);
        } else {
            st = atmos_scene_load_with(ctx, o->scene_path, defs, ndefs, scene);
        }
        if (st != ATMOS_OK) {
            const char *msg = atmos_context_error(ctx);
            const char *def = o->scene_path ? render_scene_define_in(o, msg) : NULL;
            /* a value a -D gave that the scene reader refuses (the message blames the -D): the
             * options alone made it, a usage error as without a scene file; the scene file's
             * own content, or a file that cannot be read, is a runtime error */
            const int named = !strncmp(msg, "-D ", 3);
            const int rc = cli_runtime_error(o->cmd, ctx, st); /* the message printed: the context is free */
            const int by_define = (st == ATMOS_E_INVALID_ARG && named) || (!def && !named && defines_broke_it(ctx, o, st));
            /* the message names the -D already when it starts with it */
            if (def && !named) fprintf(stderr, "  (set by -D %s, not by the scene file)\n", def);
            else if (by_define && !named) say_defines(o);
            return by_define ? CLI_EXIT_USAGE : rc;
        }
    } else if (ndefs) {
        /* the built-in default scene is the parse of an empty one */
        if ((st = atmos_scene_parse_with(ctx, "{}", 2, "-D", defs, ndefs, scene)) != ATMOS_OK) {
            fprintf(stderr, "atmos %s: %s\n", o->cmd, atmos_context_error(ctx));
            return CLI_EXIT_USAGE;
        }
    } else {
        atmos_scene_defaults(scene);
    }
    if (o->volume) scene->volume_by[0] = '\0'; /* --volume's file is the command line's, not a -D's */
    int rc = render_opts_apply(ctx, o, scene);
    if (rc != CLI_EXIT_OK) return rc;
    if ((st = atmos_scene_validate(ctx, scene, o->scene_path ? o->scene_path : "options")) != ATMOS_OK) {
        const char *flag = render_opts_flag_in(atmos_context_error(ctx));
        fprintf(stderr, "atmos %s: %s\n", o->cmd, atmos_context_error(ctx));
        if (flag) fprintf(stderr, "  (the option --%s sets it)\n", flag);
        return CLI_EXIT_USAGE; /* the scene file was valid as read: the options made it invalid */
    }
    return render_opts_camera_given(o) ? CLI_EXIT_OK : frame_volume(ctx, o, scene, volume);
}

const char *render_scene_output_name(const render_opts *o, const atmos_scene *scene, char *buf, size_t cap)
{
    const char *p = o->scene_path;
    if (!p || !strcmp(p, "-")) return scene->name;
    const char *base = strrchr(p, '/') ? strrchr(p, '/') + 1 : p, *dot = strrchr(base, '.');
    size_t n = dot && dot > base ? (size_t)(dot - base) : strlen(base);
    if (n == 0) return scene->name;
    snprintf(buf, cap, "%.*s", (int)(n < cap ? n : cap - 1), base);
    return buf;
}

char *render_scene_text(const char *path)
{
    if (!path) return NULL;
    /* standard input is read here, once: the scene is parsed from this text and the
     * outputs carry it */
    return strcmp(path, "-") ? cli_read_text(path, (size_t)1 << 20) : cli_read_stream(stdin, (size_t)16 << 20);
}
