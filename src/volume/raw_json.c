/* Raw little-endian float32 volumes described by a JSON sidecar (docs/volumes.md):
 *
 *   {"file": "x.raw", "dims": [nx, ny, nz], "voxel_size_m": s, "origin_m": [x, y, z],
 *    "field": "cloud", "particle": "cloud", "scale": 1.0}
 *   {"dims": ..., "voxel_size_m": ..., "origin_m": ..., "rotation": [9 numbers],
 *    "fields": [{"name": "cloud", "particle": "cloud", "file": "c.raw", "scale": 1}, ...]}
 *
 * either with "periodic": true when the grid wraps round along x and z (a simulation's sides).
 *
 * x varies fastest in the raw file; "file" is relative to the sidecar's directory.
 * Validation is strict: unknown or repeated keys, wrong types, dims whose byte
 * count differs from the raw file's size (checked before anything is allocated),
 * NaN/Inf/negative values: ATMOS_E_FORMAT naming the file and the problem. Data is
 * read one z-plane at a time so memory never exceeds the volume's limit plus one
 * plane.
 */
#define _POSIX_C_SOURCE 200809L
#include "volume/volume_access.h"
#include "volume/volume_internal.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#define SIDECAR_MAX_BYTES (1 << 20)
#define PATH_CAP 4096

typedef struct {
    char name[VOL_NAME_MAX];
    char particle[VOL_NAME_MAX];
    char file[PATH_CAP];
    double scale;
} raw_field;

typedef struct {
    atmos_volume_desc vd;
    int nfields;
    raw_field f[ATMOS_VOLUME_MAX_FIELDS];
} raw_sidecar;

static int host_is_le(void)
{
    const uint32_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

static atmos_status read_text(atmos_context *ctx, const char *path, char **out)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));
    char *buf = malloc(SIDECAR_MAX_BYTES + 1);
    if (!buf) {
        fclose(f);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
    }
    size_t n = fread(buf, 1, SIDECAR_MAX_BYTES + 1, f);
    int err = ferror(f);
    fclose(f);
    if (err) {
        free(buf);
        return atmos__error(ctx, ATMOS_E_IO, "%s: read error", path);
    }
    if (n > SIDECAR_MAX_BYTES) {
        free(buf);
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: sidecar larger than %d bytes", path, SIDECAR_MAX_BYTES);
    }
    buf[n] = '\0';
    if (strlen(buf) != n) {
        free(buf);
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: NUL byte in the JSON sidecar", path);
    }
    *out = buf;
    return ATMOS_OK;
}

/* Keys of obj must be in allowed[] and appear once. */
static atmos_status check_keys(atmos_context *ctx, const char *path, const char *where, const cJSON *obj,
                               const char *const *allowed)
{
    for (const cJSON *c = obj->child; c; c = c->next) {
        int ok = 0;
        for (int i = 0; allowed[i]; i++)
            if (c->string && !strcmp(c->string, allowed[i])) ok = 1;
        if (!ok) {
            char list[256] = "";
            for (int i = 0; allowed[i]; i++) {
                strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
                strncat(list, allowed[i], sizeof list - strlen(list) - 1);
            }
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: unknown key '%.64s' (allowed: %s)", path, where,
                                c->string ? c->string : "", list);
        }
        for (const cJSON *d = c->next; d; d = d->next)
            if (d->string && !strcmp(d->string, c->string))
                return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: key '%s' appears twice", path, where, c->string);
    }
    return ATMOS_OK;
}

static atmos_status get_number(atmos_context *ctx, const char *path, const cJSON *obj, const char *key, int required,
                               double lo, double dflt, double *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        if (required) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: missing key '%s'", path, key);
        *out = dflt;
        return ATMOS_OK;
    }
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || v->valuedouble < lo || (lo == 0 && v->valuedouble <= 0 && required))
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: expected a finite number%s", path, key,
                            lo == 0 ? " > 0" : "");
    *out = v->valuedouble;
    return ATMOS_OK;
}

static atmos_status get_string(atmos_context *ctx, const char *path, const char *where, const cJSON *obj,
                               const char *key, int required, char *out, size_t cap)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        if (required) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: missing key '%s'", path, where, key);
        return ATMOS_OK;
    }
    if (!cJSON_IsString(v) || !v->valuestring || !*v->valuestring || strlen(v->valuestring) >= cap)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: %s: expected a non-empty string shorter than %zu bytes", path,
                            where, key, cap);
    for (const char *s = v->valuestring; *s; s++)
        if ((unsigned char)*s < 0x20 || *s == '"' || *s == '\\')
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: %s: control character, quote or backslash in the string",
                                path, where, key);
    snprintf(out, cap, "%s", v->valuestring);
    return ATMOS_OK;
}

static atmos_status get_vec(atmos_context *ctx, const char *path, const cJSON *obj, const char *key, int n,
                            double *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) return ATMOS_OK;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: expected an array of %d numbers", path, key, n);
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, i++) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s[%d]: expected a finite number", path, key, i);
        out[i] = e->valuedouble;
    }
    return ATMOS_OK;
}

static atmos_status get_dims(atmos_context *ctx, const char *path, const cJSON *obj, int dims[3])
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, "dims");
    if (!v) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: missing key 'dims'", path);
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: dims: expected an array of 3 integers", path);
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, i++) {
        double x = cJSON_IsNumber(e) ? e->valuedouble : NAN;
        if (!(x >= 1 && x <= ATMOS_VOLUME_MAX_DIM) || x != floor(x))
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: dims[%d]: expected an integer in 1..%d", path, i,
                                ATMOS_VOLUME_MAX_DIM);
        dims[i] = (int)x;
    }
    return ATMOS_OK;
}

/* Joins the sidecar's directory and a relative file name. */
static atmos_status resolve(atmos_context *ctx, const char *sidecar, const char *file, char *out, size_t cap)
{
    const char *slash = strrchr(sidecar, '/');
    int n;
    if (file[0] == '/' || !slash) n = snprintf(out, cap, "%s", file);
    else n = snprintf(out, cap, "%.*s/%s", (int)(slash - sidecar), sidecar, file);
    if (n < 0 || (size_t)n >= cap) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: file path too long", sidecar);
    return ATMOS_OK;
}

static atmos_status parse_field(atmos_context *ctx, const char *path, const cJSON *obj, const char *where, int single,
                                raw_field *rf)
{
    static const char *const keys[] = {"name", "particle", "file", "scale", NULL};
    atmos_status st;
    if (!single && (st = check_keys(ctx, path, where, obj, keys)) != ATMOS_OK) return st;
    char file[PATH_CAP] = "";
    if ((st = get_string(ctx, path, where, obj, single ? "field" : "name", !single, rf->name, sizeof rf->name)) ||
        (st = get_string(ctx, path, where, obj, "particle", 0, rf->particle, sizeof rf->particle)) ||
        (st = get_string(ctx, path, where, obj, "file", 1, file, sizeof file)))
        return st;
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(obj, "scale");
    rf->scale = 1;
    if (s) {
        if (!cJSON_IsNumber(s) || !isfinite(s->valuedouble) || s->valuedouble < 0)
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: scale: expected a finite number >= 0", path, where);
        rf->scale = s->valuedouble;
    }
    return resolve(ctx, path, file, rf->file, sizeof rf->file);
}

static atmos_status parse_sidecar(atmos_context *ctx, const char *path, const cJSON *root, const char *field_override,
                                  raw_sidecar *sc)
{
    static const char *const single_keys[] = {"file", "dims", "voxel_size_m", "origin_m", "rotation",
                                              "field", "particle", "scale", "periodic", NULL};
    static const char *const multi_keys[] = {"dims", "voxel_size_m", "origin_m", "rotation", "fields", "periodic", NULL};
    if (!cJSON_IsObject(root)) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: top level: expected a JSON object", path);
    const cJSON *fields = cJSON_GetObjectItemCaseSensitive(root, "fields");
    int single = fields == NULL;
    /* a scene file given where a volume is read: said as such, not as a sidecar's unknown key */
    static const char *const scene_keys[] = {"camera", "sun", "image", "renderer", "volume", "atmosphere",
                                             "objects", "lights", "fog", "background", "wavelengths", NULL};
    for (int i = 0; scene_keys[i]; i++)
        if (cJSON_HasObjectItem(root, scene_keys[i]))
            return atmos__error(ctx, ATMOS_E_FORMAT,
                                "%s: a scene file (it has \"%s\"), not a volume's JSON sidecar: a scene renders "
                                "with atmos render SCENE; its volume is the file in its \"volume\"",
                                path, scene_keys[i]);
    atmos_status st = check_keys(ctx, path, "top level", root, single ? single_keys : multi_keys);
    if (st != ATMOS_OK) return st;
    memset(sc, 0, sizeof *sc);
    if ((st = get_dims(ctx, path, root, sc->vd.dims)) ||
        (st = get_number(ctx, path, root, "voxel_size_m", 1, 0, 0, &sc->vd.voxel_size_m)) ||
        (st = get_vec(ctx, path, root, "origin_m", 3, sc->vd.origin_m)) ||
        (st = get_vec(ctx, path, root, "rotation", 9, sc->vd.rotation)))
        return st;
    const cJSON *per = cJSON_GetObjectItemCaseSensitive(root, "periodic");
    if (per && !cJSON_IsBool(per))
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: periodic: expected true or false", path);
    sc->vd.periodic = cJSON_IsTrue(per);
    if (!(sc->vd.voxel_size_m > 0))
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: voxel_size_m: must be > 0", path);
    if (sc->vd.voxel_size_m < ATMOS_VOLUME_MIN_VOXEL_M || sc->vd.voxel_size_m > ATMOS_VOLUME_MAX_VOXEL_M)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: voxel_size_m: voxel size %g m is outside the supported %g..%g m",
                            path, sc->vd.voxel_size_m, ATMOS_VOLUME_MIN_VOXEL_M, ATMOS_VOLUME_MAX_VOXEL_M);
    if (single) {
        sc->nfields = 1;
        if ((st = parse_field(ctx, path, root, "top level", 1, &sc->f[0])) != ATMOS_OK) return st;
        if (field_override) snprintf(sc->f[0].name, sizeof sc->f[0].name, "%s", field_override);
        if (!sc->f[0].name[0]) snprintf(sc->f[0].name, sizeof sc->f[0].name, "cloud");
    } else {
        if (!cJSON_IsArray(fields) || cJSON_GetArraySize(fields) < 1 ||
            cJSON_GetArraySize(fields) > ATMOS_VOLUME_MAX_FIELDS)
            return atmos__error(ctx, ATMOS_E_FORMAT, "%s: fields: expected an array of 1..%d objects", path,
                                ATMOS_VOLUME_MAX_FIELDS);
        for (const cJSON *e = fields->child; e; e = e->next) {
            char where[32];
            snprintf(where, sizeof where, "fields[%d]", sc->nfields);
            if (!cJSON_IsObject(e)) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: expected an object", path, where);
            if ((st = parse_field(ctx, path, e, where, 0, &sc->f[sc->nfields])) != ATMOS_OK) return st;
            for (int g = 0; g < sc->nfields; g++)
                if (!strcmp(sc->f[g].name, sc->f[sc->nfields].name))
                    return atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s: field name '%s' repeated", path, where,
                                        sc->f[g].name);
            sc->nfields++;
        }
    }
    for (int g = 0; g < sc->nfields; g++)
        if (!sc->f[g].particle[0]) memcpy(sc->f[g].particle, sc->f[g].name, sizeof sc->f[g].particle);
    return ATMOS_OK;
}

static atmos_status check_raw_size(atmos_context *ctx, const char *sidecar, const int n[3], const char *file)
{
    uint64_t expect = (uint64_t)n[0] * (uint64_t)n[1] * (uint64_t)n[2] * 4u;
    struct stat sb;
    if (stat(file, &sb) != 0)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: raw file %s: cannot stat: %s", sidecar, file, strerror(errno));
    if (!S_ISREG(sb.st_mode))
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: raw file %s: not a regular file", sidecar, file);
    if ((uint64_t)sb.st_size != expect)
        return atmos__error(ctx, ATMOS_E_FORMAT,
                            "%s: raw file %s has %llu bytes but dims %dx%dx%d of float32 need %llu%s", sidecar, file,
                            (unsigned long long)sb.st_size, n[0], n[1], n[2], (unsigned long long)expect,
                            (uint64_t)sb.st_size < expect ? " (truncated)" : "");
    return ATMOS_OK;
}

/* Errors from the volume API (which does not know the file) get the path in front;
 * invalid descriptions read from a file are format errors. */
static atmos_status prefix_error(atmos_context *ctx, const char *path, atmos_status st)
{
    char msg[512];
    snprintf(msg, sizeof msg, "%s", atmos_context_error(ctx));
    if (!strncmp(msg, path, strlen(path))) return st;
    return atmos__error(ctx, st == ATMOS_E_INVALID_ARG ? ATMOS_E_FORMAT : st, "%s: %s", path, msg);
}

/* Streams one raw file into field `fi`, plane by plane. */
static atmos_status read_raw(atmos_context *ctx, const char *sidecar, atmos_volume *vol, int fi, const raw_field *rf,
                             double extra_scale)
{
    const int *n = atmos_volume_get_desc(vol)->dims;
    uint64_t plane = (uint64_t)n[0] * (uint64_t)n[1];
    uint64_t buf_bytes = plane * 4u;
    if (!atmos__volume_can_alloc(vol, buf_bytes))
        return atmos__error(ctx, ATMOS_E_LIMIT, "%s: a %llu-byte read buffer exceeds the memory limit", sidecar,
                            (unsigned long long)buf_bytes);
    float scale = (float)(rf->scale * extra_scale);
    if (!isfinite(scale)) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: scale overflows float", sidecar);
    FILE *f = fopen(rf->file, "rb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open raw file %s: %s", sidecar, rf->file, strerror(errno));
    float *buf = malloc((size_t)buf_bytes);
    if (!buf) {
        fclose(f);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", sidecar);
    }
    atmos_status st = ATMOS_OK;
    int le = host_is_le();
    for (int k = 0; k < n[2] && st == ATMOS_OK; k++) {
        if (fread(buf, 4, (size_t)plane, f) != (size_t)plane) {
            st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: raw file %s: short read at z-plane %d (truncated?)", sidecar,
                              rf->file, k);
            break;
        }
        for (uint64_t p = 0; p < plane; p++) {
            if (!le) {
                unsigned char *b = (unsigned char *)&buf[p], t;
                t = b[0], b[0] = b[3], b[3] = t;
                t = b[1], b[1] = b[2], b[2] = t;
            }
            float x = buf[p];
            if (!isfinite(x) || x < 0 || !isfinite(x * scale)) {
                st = atmos__error(ctx, ATMOS_E_FORMAT,
                                  "%s: raw file %s: voxel (%d, %d, %d): density must be finite and >= 0, got %g%s",
                                  sidecar, rf->file, (int)(p % (uint64_t)n[0]), (int)(p / (uint64_t)n[0]), k, (double)x,
                                  isfinite(x) && x >= 0 ? " times scale overflows" : "");
                break;
            }
        }
        if (st != ATMOS_OK) break;
        int off[3] = {0, 0, k}, size[3] = {n[0], n[1], 1};
        st = atmos_volume_set_dense(ctx, vol, fi, off, size, buf, scale);
        if (st == ATMOS_OK && atmos__progress(ctx, "volume load", (k + 1.0) / n[2]))
            st = atmos__error(ctx, ATMOS_E_CANCELLED, "%s: cancelled", sidecar);
    }
    free(buf);
    fclose(f);
    return st;
}

atmos_status atmos__volume_load_raw_json(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                         atmos_volume **out)
{
    *out = NULL;
    char *text;
    atmos_status st = read_text(ctx, path, &text);
    if (st != ATMOS_OK) return st;
    cJSON *root = cJSON_Parse(text);
    if (!root) {
        const char *e = cJSON_GetErrorPtr();
        long off = e && e >= text && e <= text + strlen(text) ? (long)(e - text) : -1;
        free(text);
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: JSON syntax error near byte %ld", path, off);
    }
    free(text);
    raw_sidecar sc;
    st = parse_sidecar(ctx, path, root, desc ? desc->field : NULL, &sc);
    cJSON_Delete(root);
    if (st != ATMOS_OK) return st;
    double extra = desc && desc->density_scale != 0 ? desc->density_scale : 1.0;
    if (!isfinite(extra) || extra < 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: density_scale must be finite and >= 0", path);
    /* Every raw file must hold exactly the bytes the dims claim: checked before
     * anything is allocated, so absurd dims never reach an allocation. */
    for (int g = 0; g < sc.nfields; g++)
        if ((st = check_raw_size(ctx, path, sc.vd.dims, sc.f[g].file)) != ATMOS_OK) return st;
    sc.vd.max_memory = desc ? desc->max_memory : 0;
    atmos_volume *vol = NULL;
    if ((st = atmos_volume_create(ctx, &sc.vd, &vol)) != ATMOS_OK) return prefix_error(ctx, path, st);
    for (int g = 0; g < sc.nfields && st == ATMOS_OK; g++) {
        int fi;
        st = atmos_volume_add_field(ctx, vol, sc.f[g].name, sc.f[g].particle, &fi);
        if (st == ATMOS_OK) st = read_raw(ctx, path, vol, fi, &sc.f[g], extra);
    }
    if (st == ATMOS_OK) st = atmos_volume_finalize(ctx, vol);
    if (st != ATMOS_OK) {
        atmos_volume_destroy(vol);
        return prefix_error(ctx, path, st);
    }
    *out = vol;
    return ATMOS_OK;
}

/* ---------------------------------------------------------------- writing */

typedef struct {
    const atmos_volume *vol;
    int field;
    const char *text;
} raw_write_job;

static atmos_status write_field_fn(atmos_context *ctx, const char *tmp, void *user)
{
    const raw_write_job *j = user;
    const atmos_volume *v = j->vol;
    const int *n = atmos_volume_get_desc(v)->dims;
    FILE *f = fopen(tmp, "wb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot create: %s", tmp, strerror(errno));
    float *row = malloc((size_t)n[0] * sizeof(float));
    if (!row) {
        fclose(f);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", tmp);
    }
    int le = host_is_le(), ok = 1;
    for (int k = 0; k < n[2] && ok; k++)
        for (int jj = 0; jj < n[1] && ok; jj++) {
            for (int i = 0; i < n[0]; i++) {
                row[i] = atmos__vol_voxel(v, j->field, i, jj, k);
                if (!le) {
                    unsigned char *b = (unsigned char *)&row[i], t;
                    t = b[0], b[0] = b[3], b[3] = t;
                    t = b[1], b[1] = b[2], b[2] = t;
                }
            }
            ok = fwrite(row, sizeof(float), (size_t)n[0], f) == (size_t)n[0];
        }
    free(row);
    if (fclose(f) != 0) ok = 0;
    return ok ? ATMOS_OK : atmos__error(ctx, ATMOS_E_IO, "%s: write failed: %s", tmp, strerror(errno));
}

/* cJSON prints 15 significant digits when they round-trip within its epsilon
 * comparison, which is not bit-exact: print 17 digits ourselves. */
static cJSON *exact_numbers(const double *v, int n)
{
    char buf[32 * 9 + 8];
    size_t len = 0;
    buf[len++] = '[';
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(buf + len, sizeof buf - len, "%s%.17g", i ? ", " : "", v[i]);
    snprintf(buf + len, sizeof buf - len, "]");
    return cJSON_CreateRaw(buf);
}

static int is_identity(const double r[9])
{
    for (int i = 0; i < 9; i++)
        if (r[i] != (i % 4 == 0 ? 1.0 : 0.0)) return 0;
    return 1;
}

static atmos_status write_text_fn(atmos_context *ctx, const char *tmp, void *user)
{
    const raw_write_job *j = user;
    FILE *f = fopen(tmp, "wb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot create: %s", tmp, strerror(errno));
    size_t len = strlen(j->text);
    int ok = fwrite(j->text, 1, len, f) == len;
    if (fclose(f) != 0) ok = 0;
    return ok ? ATMOS_OK : atmos__error(ctx, ATMOS_E_IO, "%s: write failed: %s", tmp, strerror(errno));
}

/* Field f's raw file: rel, its name next to the sidecar (<stem>.<field>.raw), and full, its
 * path. 0 when a name does not fit. */
static int raw_name(const atmos_volume *vol, int f, const char *json_path, const char *base, size_t stem_len,
                    char rel[PATH_CAP], char full[PATH_CAP])
{
    int n = snprintf(rel, PATH_CAP, "%.*s.%s.raw", (int)stem_len, base, atmos_volume_field_name(vol, f));
    int m = snprintf(full, PATH_CAP, "%.*s%s", (int)(base - json_path), json_path, rel);
    return n >= 0 && m >= 0 && n < PATH_CAP && m < PATH_CAP;
}

/* Removes the raw files of fields 0..n-1 (a write that failed leaves none). */
/* The name a file is written under until the whole set is (full + ".staged"); 0 when too long. */
static int staged_name(const char *full, char out[PATH_CAP])
{
    const int n = snprintf(out, PATH_CAP, "%s.staged", full);
    return n >= 0 && n < PATH_CAP;
}

/* The raw files 0..n-1 of the set: their staged copies removed, or (put != 0) renamed into
 * place; 0 when a rename failed. */
static int finish_raws(const atmos_volume *vol, int n, const char *json_path, const char *base, size_t stem_len, int put)
{
    int ok = 1;
    for (int f = 0; f < n; f++) {
        char rel[PATH_CAP], full[PATH_CAP], staged[PATH_CAP];
        if (!raw_name(vol, f, json_path, base, stem_len, rel, full) || !staged_name(full, staged)) continue;
        if (!put) remove(staged);
        else if (ok && rename(staged, full) != 0) ok = 0;
        else if (!ok) remove(staged);
    }
    return ok;
}

atmos_status atmos_volume_write_raw(atmos_context *ctx, const atmos_volume *vol, const char *json_path)
{
    if (!vol || !json_path || !*json_path)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume write_raw: NULL volume or empty path");
    const int nf = atmos_volume_field_count(vol);
    if (nf == 0) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: the volume has no fields", json_path);
    /* Raw files: <stem>.<field>.raw next to the sidecar, named relative to it. */
    const char *base = strrchr(json_path, '/');
    base = base ? base + 1 : json_path;
    size_t stem_len = strlen(base);
    if (stem_len > 5 && !strcasecmp(base + stem_len - 5, ".json")) stem_len -= 5; /* any case, as the CLI's */
    /* A write killed between staging and renaming (SIGKILL, a power cut) leaves staged files
     * of these names: removed first, so that this one leaves none, failing or not. */
    char stale[PATH_CAP];
    finish_raws(vol, nf, json_path, base, stem_len, 0);
    if (staged_name(json_path, stale)) remove(stale);
    cJSON *root = cJSON_CreateObject(), *arr;
    if (!root) return atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", json_path);
    const atmos_volume_desc *d = atmos_volume_get_desc(vol);
    double dims[3] = {d->dims[0], d->dims[1], d->dims[2]};
    cJSON_AddItemToObject(root, "dims", cJSON_CreateDoubleArray(dims, 3));
    char num[40];
    snprintf(num, sizeof num, "%.17g", d->voxel_size_m);
    cJSON_AddRawToObject(root, "voxel_size_m", num);
    cJSON_AddItemToObject(root, "origin_m", exact_numbers(d->origin_m, 3));
    if (!is_identity(d->rotation)) cJSON_AddItemToObject(root, "rotation", exact_numbers(d->rotation, 9));
    if (d->periodic) cJSON_AddTrueToObject(root, "periodic");
    cJSON_AddItemToObject(root, "fields", arr = cJSON_CreateArray());
    atmos_status st = ATMOS_OK;
    int written = 0; /* the raw files written so far */
    for (int f = 0; f < nf && st == ATMOS_OK; f++) {
        char rel[PATH_CAP], full[PATH_CAP];
        if (!raw_name(vol, f, json_path, base, stem_len, rel, full)) {
            st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: path too long", json_path);
            break;
        }
        char staged[PATH_CAP];
        if (!staged_name(full, staged)) {
            st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: path too long", json_path);
            break;
        }
        raw_write_job job = {vol, f, NULL};
        st = atmos__write_atomic(ctx, staged, write_field_fn, &job);
        written += st == ATMOS_OK;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", atmos_volume_field_name(vol, f));
        cJSON_AddStringToObject(o, "particle", atmos_volume_field_particle(vol, f));
        cJSON_AddStringToObject(o, "file", rel);
        cJSON_AddNumberToObject(o, "scale", 1);
        cJSON_AddItemToArray(arr, o);
    }
    char *text = st == ATMOS_OK ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (st == ATMOS_OK && !text) st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", json_path);
    if (st != ATMOS_OK) return finish_raws(vol, written, json_path, base, stem_len, 0), st;
    size_t len = strlen(text);
    char *t2 = realloc(text, len + 2);
    if (t2) {
        text = t2;
        text[len] = '\n';
        text[len + 1] = '\0';
    }
    raw_write_job job = {vol, 0, text};
    char staged[PATH_CAP];
    st = staged_name(json_path, staged) ? atmos__write_atomic(ctx, staged, write_text_fn, &job)
                                        : atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: path too long", json_path);
    free(text);
    /* All or nothing: every file is staged before any is put in place, so a failure leaves an
     * earlier set of these names whole (only a rename failing part way could mix them). */
    if (st != ATMOS_OK) return finish_raws(vol, nf, json_path, base, stem_len, 0), st;
    if (!finish_raws(vol, nf, json_path, base, stem_len, 1) || rename(staged, json_path) != 0) {
        remove(staged);
        return atmos__error(ctx, ATMOS_E_IO, "%s: cannot put the volume's files in place: %s", json_path, strerror(errno));
    }
    return ATMOS_OK;
}
