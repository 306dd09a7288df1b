/* The renderers' settings tables (atmos_renderer_settings) are the one description of every
 * setting: the scene's defaults are the rows' defaults, the parser accepts each row's range
 * and refuses beyond it naming the key, the validator says the same of a scene set in code,
 * and atmos render has each row's option (it sets the value the parser would) and lists it
 * in --help; docs/scene-format.md has a row for each. */
#define _GNU_SOURCE /* memmem */
#include "atmos/atmos.h"
#include "test.h"

#include <stdlib.h>
#include <string.h>

/* A scene file with one setting of a renderer's section set to the text value. */
static atmos_status parse_one(atmos_context *ctx, atmos_renderer_kind r, const char *key, const char *value,
                              atmos_scene *s)
{
    char json[512];
    snprintf(json, sizeof json, "{\"%s\": {\"%s\": %s}}", atmos_renderer_name(r), key, value);
    atmos_scene_defaults(s);
    return atmos_scene_parse(ctx, json, strlen(json), "t.json", s);
}

static void fmt(char *buf, size_t cap, double v) { snprintf(buf, cap, "%.17g", v); }

static void check_row(atmos_context *ctx, atmos_renderer_kind r, const atmos_setting *st)
{
    atmos_scene d, s;
    atmos_scene_defaults(&d);
    char path[96], v[64];
    snprintf(path, sizeof path, "/%s/%s", atmos_renderer_name(r), st->key);
    CHECK_MSG(atmos_scene_setting_get(&d, st) == st->def, "%s: the scene's default %g is not the row's %g", path,
              atmos_scene_setting_get(&d, st), st->def);
    if (st->type == ATMOS_SETTING_BOOL) {
        /* a flag turns its setting on, a --no- flag off (--beams-sun once turned the sun off) */
        if (st->flag)
            CHECK_MSG(st->flag_sets == (strncmp(st->flag, "no-", 3) != 0), "--%s sets %s to %d", st->flag, path,
                      st->flag_sets);
        CHECK_OK(parse_one(ctx, r, st->key, st->def ? "false" : "true", &s));
        CHECK(atmos_scene_setting_get(&s, st) == !st->def);
        CHECK(parse_one(ctx, r, st->key, "1", &s) == ATMOS_E_INVALID_ARG);
        return;
    }
    if (st->type == ATMOS_SETTING_CHOICE) {
        for (int i = 0; st->choices[i]; i++) {
            snprintf(v, sizeof v, "\"%s\"", st->choices[i]);
            CHECK_OK(parse_one(ctx, r, st->key, v, &s));
            CHECK(atmos_scene_setting_get(&s, st) == i);
        }
        CHECK(parse_one(ctx, r, st->key, "\"nope\"", &s) == ATMOS_E_INVALID_ARG);
        return;
    }
    /* the ends of the range (an open end: just inside), then just beyond each */
    const double span = st->max - st->min, eps = st->type == ATMOS_SETTING_REAL ? 1e-6 * span : 1;
    const double ends[2] = {st->min_open ? st->min + eps : st->min, st->max_open ? st->max - eps : st->max};
    for (int e = 0; e < 2; e++) {
        fmt(v, sizeof v, ends[e]);
        CHECK_MSG(parse_one(ctx, r, st->key, v, &s) == ATMOS_OK, "%s = %s refused: %s", path, v, atmos_context_error(ctx));
        CHECK(atmos_scene_setting_get(&s, st) == ends[e]);
        CHECK_OK(atmos_scene_validate(ctx, &s, "code"));
        if (st->type == ATMOS_SETTING_SEED) { /* a uint64_t: only a negative number can be out of range */
            CHECK(parse_one(ctx, r, st->key, "-1", &s) == ATMOS_E_INVALID_ARG && strstr(atmos_context_error(ctx), path));
            continue;
        }
        const double beyond = e ? st->max + eps : st->min - eps;
        fmt(v, sizeof v, st->min_open && !e ? st->min : (st->max_open && e ? st->max : beyond));
        CHECK_MSG(parse_one(ctx, r, st->key, v, &s) == ATMOS_E_INVALID_ARG && strstr(atmos_context_error(ctx), path),
                  "%s = %s accepted or unnamed (%s)", path, v, atmos_context_error(ctx));
        atmos_scene_defaults(&s);
        atmos_scene_setting_set(&s, st, st->min_open && !e ? st->min : (st->max_open && e ? st->max : beyond));
        CHECK_MSG(atmos_scene_validate(ctx, &s, "code") == ATMOS_E_INVALID_ARG && strstr(atmos_context_error(ctx), path),
                  "%s: the validator accepted %s", path, v);
    }
}

/* atmos render's --help names every option of the tables, with its doc. */
static void check_help(void)
{
    const char *cli = getenv("ATMOS_CLI");
    if (!cli || !*cli) return;
    char out[4200], cmd[9000];
    test_tmp_path(out, sizeof out, "render_help.txt");
    snprintf(cmd, sizeof cmd, "'%s' render --help > '%s'", cli, out);
    CHECK(system(cmd) == 0);
    size_t n = 0;
    char *text = (char *)test_slurp(out, &n);
    /* --help wraps the docs at 100 columns: every run of spaces and line breaks read as one space */
    size_t w = 0;
    for (size_t i = 0; text && i < n; i++) {
        const int sp = text[i] == ' ' || text[i] == '\n';
        if (sp && w > 0 && text[w - 1] == ' ') continue;
        text[w++] = sp ? ' ' : text[i];
    }
    n = w;
    if (text) text[n] = 0;
    for (int r = ATMOS_RENDERER_SLICE; text && r <= ATMOS_RENDERER_LAST; r++) {
        int count;
        const atmos_setting *t = atmos_renderer_settings((atmos_renderer_kind)r, &count);
        for (int i = 0; i < count; i++) {
            char opt[80];
            snprintf(opt, sizeof opt, "--%s", t[i].flag);
            CHECK_MSG(t[i].flag && memmem(text, n, opt, strlen(opt)) && memmem(text, n, t[i].doc, strlen(t[i].doc)),
                      "render --help lacks %s or its doc", opt);
        }
    }
    /* the --volume paragraph names every generator and simulation preset the library takes */
    const char *vol = text ? strstr(text, "--volume SOURCE") : NULL, *end = vol ? strstr(vol, "--volume-position") : NULL;
    CHECK_MSG(vol && end, "render --help has no --volume SOURCE paragraph");
    for (int k = 0; vol && end && k < 2; k++)
        for (const char *const *nm = k ? atmos_sim_preset_names() : atmos_scene_generator_names(); *nm; nm++) {
            int found = 0;
            for (const char *at = vol; !found && (at = strstr(at, *nm)) && at < end; at += strlen(*nm)) {
                const char before = at[-1], after = at[strlen(*nm)];
                found = (before == ' ' || before == ':') && (after == ',' || after == ')' || after == ';' || after == ' ');
            }
            CHECK_MSG(found, "render --help's --volume paragraph lacks %s %s", k ? "simulate:" : "generate:", *nm);
        }
    CHECK_MSG(vol && end && memmem(vol, (size_t)(end - vol), "simulate:PRESET", 15), "--volume: simulate:PRESET not named");
    free(text);
}

/* docs/scene-format.md has a row for every setting, in its renderer's section ("## `harris`"
 * up to the next "## "): the page says its tables are these. */
static void check_docs(void)
{
    const char *root = getenv("ATMOS_SOURCE_DIR");
    if (!root || !*root) return;
    char path[1024];
    snprintf(path, sizeof path, "%s/docs/scene-format.md", root);
    size_t n = 0;
    char *text = (char *)test_slurp(path, &n);
    CHECK_MSG(text != NULL, "cannot read %s", path);
    for (int r = ATMOS_RENDERER_SLICE; text && r <= ATMOS_RENDERER_LAST; r++) {
        char head[64], row[96];
        snprintf(head, sizeof head, "\n## `%s`", atmos_renderer_name((atmos_renderer_kind)r));
        const char *sec = memmem(text, n, head, strlen(head));
        const char *end = sec ? memmem(sec + 1, n - (size_t)(sec + 1 - text), "\n## ", 4) : NULL;
        const size_t len = sec ? (size_t)((end ? end : text + n) - sec) : 0;
        CHECK_MSG(sec != NULL, "scene-format.md has no section %s", head + 1);
        int count;
        const atmos_setting *t = atmos_renderer_settings((atmos_renderer_kind)r, &count);
        for (int i = 0; sec && i < count; i++) {
            snprintf(row, sizeof row, "\n| `%s` |", t[i].key);
            CHECK_MSG(memmem(sec, len, row, strlen(row)), "scene-format.md's %s table lacks %s", head + 1, t[i].key);
        }
    }
    free(text);
}

/* The slice renderer's "field": what each scene section selects (atmos_scene_slice_field), and
 * the contradictions the parser refuses naming the key, the flag and the field. */
static void check_slice_field(atmos_context *ctx)
{
    static const struct {
        const char *slice; /* the "slice" section's members */
        int field;         /* the field selected, or -1: refused */
        const char *msg;   /* with -1: in the message */
    } cases[] = {
        {"", ATMOS_SLICE_FIELD_DO, NULL},
        {"\"field\": \"auto\"", ATMOS_SLICE_FIELD_DO, NULL},
        {"\"diffuse\": true", ATMOS_SLICE_FIELD_DO, NULL},
        {"\"do\": true", ATMOS_SLICE_FIELD_DO, NULL},
        /* a file's "do": false without "field": the P1 field, its meaning before the do field was the default */
        {"\"do\": false", ATMOS_SLICE_FIELD_P1, NULL},
        {"\"do\": false, \"diffuse\": false", ATMOS_SLICE_FIELD_NONE, NULL},
        {"\"low_albedo\": true, \"do\": false", ATMOS_SLICE_FIELD_NONE, NULL},
        {"\"do\": false, \"field\": \"auto\"", ATMOS_SLICE_FIELD_DO, NULL},
        {"\"do\": false, \"field\": \"do\"", ATMOS_SLICE_FIELD_DO, NULL},
        {"\"field\": \"p1\"", ATMOS_SLICE_FIELD_P1, NULL},
        {"\"field\": \"none\"", ATMOS_SLICE_FIELD_NONE, NULL},
        {"\"field\": \"none\", \"diffuse\": false", ATMOS_SLICE_FIELD_NONE, NULL},
        {"\"diffuse\": false", ATMOS_SLICE_FIELD_NONE, NULL},
        {"\"low_albedo\": true", ATMOS_SLICE_FIELD_NONE, NULL},
        {"\"xi\": 0.02", ATMOS_SLICE_FIELD_P1, NULL},
        {"\"xi\": 0", ATMOS_SLICE_FIELD_P1, NULL},
        {"\"update\": \"eq24\"", ATMOS_SLICE_FIELD_P1, NULL},
        {"\"xi\": 0.02, \"diffuse\": false", ATMOS_SLICE_FIELD_NONE, NULL},
        {"\"field\": \"do\", \"xi\": 0", ATMOS_SLICE_FIELD_DO, NULL},
        {"\"field\": \"p1\", \"xi\": 0.02, \"update\": \"eq24\"", ATMOS_SLICE_FIELD_P1, NULL},
        {"\"field\": \"none\", \"xi\": 0.02", ATMOS_SLICE_FIELD_NONE, NULL},
        {"\"field\": \"do\", \"xi\": 0.02", -1, "/slice/xi: (--xi) does nothing with the do field"},
        {"\"do\": true, \"update\": \"eq24\"", -1, "/slice/update: (--eq24) does nothing with the do field"},
        {"\"field\": \"do\", \"diffuse\": false", -1, "/slice/diffuse: (--no-diffuse) does nothing with the do"},
        {"\"field\": \"p1\", \"do\": true", -1, "/slice/do: (--slice-do) contradicts \"field\": \"p1\" (--slice-p1)"},
        {"\"field\": \"none\", \"do\": true", -1, "/slice/do: (--slice-do) contradicts \"field\": \"none\""},
        {"\"field\": \"p1\", \"diffuse\": false", -1, "/slice/diffuse: (--no-diffuse) contradicts \"field\": \"p1\""},
        {"\"field\": \"p2\"", -1, "/slice/field: must be one of auto, do, p1, none"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char json[512];
        snprintf(json, sizeof json, "{\"renderer\": \"slice\", \"volume\": {\"generate\": \"storm\"}, \"slice\": {%s}}",
                 cases[i].slice);
        atmos_scene s;
        atmos_scene_defaults(&s);
        const atmos_status st = atmos_scene_parse(ctx, json, strlen(json), "t.json", &s);
        if (cases[i].field < 0)
            CHECK_MSG(st == ATMOS_E_INVALID_ARG && strstr(atmos_context_error(ctx), cases[i].msg),
                      "{%s}: %s (wanted %s)", cases[i].slice, st ? atmos_context_error(ctx) : "accepted", cases[i].msg);
        else
            CHECK_MSG(st == ATMOS_OK && (int)atmos_scene_slice_field(&s.slice) == cases[i].field, "{%s}: %s, field %d",
                      cases[i].slice, st ? atmos_context_error(ctx) : "ok", (int)atmos_scene_slice_field(&s.slice));
    }
    /* another renderer reads none of them: a leftover contradiction is no error there */
    const char *nish = "{\"renderer\": \"nishita\", \"volume\": {\"generate\": \"storm\"}, \"slice\": {\"field\": "
                       "\"p1\", \"do\": true}}";
    atmos_scene s;
    atmos_scene_defaults(&s);
    CHECK_OK(atmos_scene_parse(ctx, nish, strlen(nish), "t.json", &s));
}

int main(void)
{
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(NULL, &ctx));
    int total = 0;
    for (int r = ATMOS_RENDERER_SKY; r <= ATMOS_RENDERER_LAST; r++) {
        int n = -1;
        const atmos_setting *t = atmos_renderer_settings((atmos_renderer_kind)r, &n);
        CHECK(r == ATMOS_RENDERER_SKY ? (!t && n == 0) : (t && n > 0));
        for (int i = 0; i < n; i++) check_row(ctx, (atmos_renderer_kind)r, &t[i]);
        total += n;
    }
    printf("%d settings checked\n", total);
    CHECK(atmos_renderer_name((atmos_renderer_kind)9) == NULL);
    /* the field's names: the "field" row's choices */
    int ns = 0;
    const atmos_setting *sl = atmos_renderer_settings(ATMOS_RENDERER_SLICE, &ns);
    for (int i = 0; i < ns; i++)
        if (!strcmp(sl[i].key, "field"))
            for (int f = 0; f <= ATMOS_SLICE_FIELD_NONE + 1; f++) {
                const char *name = atmos_slice_field_name((atmos_slice_field)f);
                CHECK(f > ATMOS_SLICE_FIELD_NONE ? !name && !sl[i].choices[f] : name && !strcmp(name, sl[i].choices[f]));
            }
    check_help();
    check_docs();
    check_slice_field(ctx);
    atmos_context_destroy(ctx);
    return test_summary("test_settings");
}
