/* Scene keys set from outside the file (atmos render -D PATH=VALUE, as Mitsuba's -D): each
 * override sets one value in the parsed JSON tree before the tree is read, so the value
 * meets the same rules and messages as one written in the file. */
#include "scene/scene_internal.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define OV_TOKEN_MAX 128

/* The next path token from *p (JSON pointer: up to '/', "~1" = '/', "~0" = '~'; dotted: up
 * to '.'), copied to tok. Returns 0 at the end, -1 for a token too long or empty. */
static int next_token(const char **p, int pointer, char *tok)
{
    const char *s = *p;
    if (!*s) return 0;
    size_t n = 0;
    while (*s && *s != (pointer ? '/' : '.')) {
        char c = *s++;
        if (pointer && c == '~' && (*s == '0' || *s == '1')) c = *s++ == '0' ? '~' : '/';
        if (n + 1 >= OV_TOKEN_MAX) return -1;
        tok[n++] = c;
    }
    tok[n] = '\0';
    if (*s) s++;
    *p = s;
    return n ? 1 : -1;
}

/* An array index token: digits only, at most the array's size (the size appends). */
static int array_index(const char *tok, int size)
{
    if (!*tok) return -1;
    long v = 0;
    for (const char *c = tok; *c; c++) {
        if (*c < '0' || *c > '9' || v > 100000) return -1;
        v = v * 10 + (*c - '0');
    }
    return v <= size ? (int)v : -1;
}

/* Puts value (owned: consumed on success and on failure) at key or index tok of node. */
static int put(cJSON *node, const char *tok, cJSON *value)
{
    int done = 0;
    if (cJSON_IsObject(node)) {
        if (cJSON_GetObjectItemCaseSensitive(node, tok)) done = cJSON_ReplaceItemInObjectCaseSensitive(node, tok, value);
        else done = cJSON_AddItemToObject(node, tok, value);
    } else {
        const int n = cJSON_GetArraySize(node), i = array_index(tok, n);
        if (i == n) done = cJSON_AddItemToArray(node, value);
        else if (i >= 0) done = cJSON_ReplaceItemInArray(node, i, value);
    }
    if (!done) cJSON_Delete(value);
    return done;
}

/* The child of node at tok, created as an object if node is an object without it. */
static cJSON *child(cJSON *node, const char *tok)
{
    if (cJSON_IsObject(node)) {
        cJSON *c = cJSON_GetObjectItemCaseSensitive(node, tok);
        if (!c) {
            c = cJSON_CreateObject();
            if (c && !cJSON_AddItemToObject(node, tok, c)) cJSON_Delete(c), c = NULL;
        }
        return c;
    }
    int i = array_index(tok, cJSON_GetArraySize(node) - 1);
    return i < 0 ? NULL : cJSON_GetArrayItem(node, i);
}

/* The volume's sources, one bit each in the order given (file 1, generate 2, simulate 4). */
static const char *const sources[] = {"file", "generate", "simulate"};

/* The volume's source is one of "file", "generate" and "simulate": one set by an override
 * replaces the others the file had (as --volume replaces the scene's volume), with the keys
 * only the old kind takes (scene_json.c refuses them with the new one) and "particle" (a
 * file's one field's type is not a generated cloud's droplets); overrides after it may set
 * them again. */
static void drop_other_sources(cJSON *root, const cJSON *node, const char *tok)
{
    static const char *const file_only[] = {"grids", "time_index", "density_unit", "subgrid_detail", "particle", NULL},
                             *const gen_only[] = {"seed", "particle", NULL},
                             *const sim_bad[] = {"grids", "time_index", "density_unit", "subgrid_detail", "seed",
                                                 "voxel_size_m", "scale", "particle", NULL};
    cJSON *vol = cJSON_GetObjectItemCaseSensitive(root, "volume");
    int kind = -1;
    for (int i = 0; i < 3; i++)
        if (!strcmp(tok, sources[i])) kind = i;
    if (!vol || node != vol || kind < 0) return;
    int had = -1;
    for (int i = 0; i < 3; i++)
        if (i != kind && cJSON_GetObjectItemCaseSensitive(vol, sources[i])) had = i;
    if (had < 0) return;
    for (int i = 0; i < 3; i++)
        if (i != kind) cJSON_DeleteItemFromObjectCaseSensitive(vol, sources[i]);
    const char *const *drop = kind == 0 ? gen_only : kind == 1 ? file_only : sim_bad;
    for (int i = 0; drop[i]; i++) cJSON_DeleteItemFromObjectCaseSensitive(vol, drop[i]);
}

/* The fog's density is one of "extinction_per_m" and "visibility_m": one set by an override
 * replaces the other the file had (-D fog.visibility_m=500 on a scene that gives the
 * extinction). */
static void drop_other_density(cJSON *root, const cJSON *node, const char *tok)
{
    cJSON *fog = cJSON_GetObjectItemCaseSensitive(root, "fog");
    if (!fog || node != fog) return;
    if (!strcmp(tok, "visibility_m")) cJSON_DeleteItemFromObjectCaseSensitive(fog, "extinction_per_m");
    else if (!strcmp(tok, "extinction_per_m")) cJSON_DeleteItemFromObjectCaseSensitive(fog, "visibility_m");
}

/* An override's VALUE as JSON when the whole of it is JSON (white space after it allowed), as a
 * scene file's text is read; NULL otherwise. cJSON_Parse alone stops after the first value and
 * ignores the rest, so 30abc read as 30 and 2026-06-21T12:00:00Z as the number 2026. */
static cJSON *whole_json(const char *text) { return cJSON_ParseWithOpts(text, NULL, 1); }

static atmos_status apply_one(atmos_context *ctx, const char *source, cJSON *root, const char *ov)
{
    const char *eq = strchr(ov, '=');
    if (!eq || eq == ov)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: override '%.200s': expected PATH=VALUE", source, ov);
    size_t plen = (size_t)(eq - ov);
    char path[1024], tok[OV_TOKEN_MAX];
    if (plen >= sizeof path)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: override '%.60s...': the path is too long", source, ov);
    memcpy(path, ov, plen);
    path[plen] = '\0';
    /* The value: JSON text, or a bare word (not JSON, in whole) taken as a string. */
    cJSON *value = whole_json(eq + 1);
    if (!value) value = cJSON_CreateString(eq + 1);
    if (!value) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", source);
    const int pointer = path[0] == '/';
    const char *p = pointer ? path + 1 : path;
    cJSON *node = root;
    int r;
    while ((r = next_token(&p, pointer, tok)) > 0) {
        if (!cJSON_IsObject(node) && !cJSON_IsArray(node)) break;
        if (!*p) {
            if (!put(node, tok, value))
                return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: override '%s': cannot set '%s' there", source, path,
                                    tok);
            drop_other_sources(root, node, tok);
            drop_other_density(root, node, tok);
            return ATMOS_OK;
        }
        node = child(node, tok);
        if (!node) break;
    }
    cJSON_Delete(value);
    return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                        "%s: override '%s': not a path into the scene (JSON pointer /a/b/0 or dotted a.b.0, "
                        "through objects and arrays)",
                        source, path);
}

/* The volume sources an override names, a bit each (file 1, generate 2, simulate 4): its
 * path is /volume/file, .generate or .simulate, or the whole "volume" holding them. */
static unsigned override_sources(const char *ov)
{
    const char *eq = strchr(ov, '=');
    if (!eq) return 0;
    const char *p = ov + (ov[0] == '/');
    const size_t n = (size_t)(eq - p);
    if (n < 6 || strncmp(p, "volume", 6)) return 0;
    unsigned bits = 0;
    if (n == 6) { /* the whole volume: the sources its object holds */
        cJSON *v = whole_json(eq + 1);
        for (int i = 0; i < 3; i++)
            bits |= cJSON_IsObject(v) && cJSON_GetObjectItemCaseSensitive(v, sources[i]) ? 1u << i : 0;
        cJSON_Delete(v);
        return bits;
    }
    if (p[6] != (ov[0] == '/' ? '/' : '.')) return 0;
    for (int i = 0; i < 3; i++)
        if (n == 7 + strlen(sources[i]) && !strncmp(p + 7, sources[i], strlen(sources[i]))) bits |= 1u << i;
    return bits;
}

/* Two overrides naming volume sources of two kinds (-D volume.file=x -D volume.generate=y)
 * are refused, as the two keys in a scene file are; one replacing the file's source is not. */
static atmos_status two_sources(atmos_context *ctx, const char *const *overrides, int count)
{
    unsigned seen = 0;
    int first = -1;
    for (int i = 0; i < count; i++) {
        const unsigned b = override_sources(overrides[i]);
        if (!b) continue;
        const unsigned u = seen | b;
        if (seen && (u & (u - 1))) { /* two kinds: name the first two */
            int a = 0, c;
            while (!(u >> a & 1u)) a++;
            for (c = a + 1; c < 3 && !(u >> c & 1u); c++) {}
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "-D %.300s and -D %.300s: /volume: \"%s\" and \"%s\" exclude each other (as in a "
                                "scene file): give one",
                                overrides[first], overrides[i], sources[a], sources[c < 3 ? c : a]);
        }
        seen |= b;
        first = i;
    }
    return ATMOS_OK;
}

atmos_status atmos__scene_apply_overrides(atmos_context *ctx, const char *source, struct cJSON *root,
                                          const char *const *overrides, int count)
{
    for (int i = 0; i < count; i++)
        if (!overrides || !overrides[i]) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: override %d is NULL", source, i);
    atmos_status st = two_sources(ctx, overrides, count);
    for (int i = 0; st == ATMOS_OK && i < count; i++) st = apply_one(ctx, source, root, overrides[i]);
    return st;
}

/* Whether the override ov (PATH=VALUE, dotted or a JSON pointer) sets key (a JSON pointer,
 * "/a/b/0") or an object or array that holds it; or, for one naming the volume's source
 * (which replaces the file's), whether key is "/volume" (what the new source does not take). */
static int override_sets(const char *ov, const char *key)
{
    const char *eq = strchr(ov, '=');
    if (!eq || eq == ov) return 0;
    char ptr[1024];
    size_t n = 0;
    const char *p = ov;
    if (*p != '/') ptr[n++] = '/';
    for (; p < eq && n + 1 < sizeof ptr; p++) ptr[n++] = *p == '.' && ov[0] != '/' ? '/' : *p;
    ptr[n] = '\0';
    if (!strcmp(key, "/volume") && override_sources(ov)) return 1;
    return !strncmp(key, ptr, n) && (key[n] == '\0' || key[n] == '/');
}

void atmos__scene_override_blame(char *buf, size_t cap, const char *key, const char *source,
                                  const char *const *overrides, int count)
{
    buf[0] = '\0';
    for (int i = count - 1; overrides && i >= 0; i--) /* the last override of a key is the one that holds */
        if (overrides[i] && override_sets(overrides[i], key)) {
            if (!strcmp(source, "-D")) snprintf(buf, cap, "-D %.300s", overrides[i]);
            else snprintf(buf, cap, "-D %.300s (on %.300s)", overrides[i], source);
            return;
        }
}

atmos_status atmos__scene_blame_override(atmos_context *ctx, atmos_status st, const char *source,
                                         const char *const *overrides, int count)
{
    const char *msg = atmos_context_error(ctx);
    const size_t sl = strlen(source);
    if (st != ATMOS_E_INVALID_ARG || !overrides || strncmp(msg, source, sl) || strncmp(msg + sl, ": /", 3)) return st;
    char key[512];
    const char *k = msg + sl + 2, *end = strstr(k, ": ");
    if (!end || (size_t)(end - k) >= sizeof key) return st;
    memcpy(key, k, (size_t)(end - k));
    key[end - k] = '\0';
    char who[700], rest[1024];
    atmos__scene_override_blame(who, sizeof who, key, source, overrides, count); /* "-D" alone: atmos render's */
    if (!who[0]) return st;                                                       /* scene of overrides alone */
    snprintf(rest, sizeof rest, "%s", k);
    return atmos__error(ctx, st, "%s: %s", who, rest);
}
