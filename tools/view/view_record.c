/* Recording a flight and saving a view (view.h). A saved view is the frame's linear EXR,
 * the PNG as shown, and a scene file that renders the same image offline: the scene file
 * the viewer opened, edited with cJSON to hold the viewer's camera, sun, size, renderer and
 * exposure (and the absolute paths of the volume, meshes, terrains, lights' images and Earth
 * maps, and the volume's placement), so every other setting stays as written. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "outputs.h"
#include "view.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The first file of an earlier recording in DIR (frames.csv or a frame_*.png) into NAME, or 0:
 * a new recording into it would leave the earlier run's later frames among its own. */
static int earlier_recording(const char *dir, char *name, size_t size)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    int found = 0;
    for (struct dirent *e; !found && (e = readdir(d));) {
        const size_t n = strlen(e->d_name);
        found = !strcmp(e->d_name, "frames.csv") ||
                (!strncmp(e->d_name, "frame_", 6) && n > 10 && !strcmp(e->d_name + n - 4, ".png"));
        if (found) snprintf(name, size, "%s", e->d_name);
    }
    closedir(d);
    return found;
}

int view_record_open(view_recorder *r, const char *dir)
{
    memset(r, 0, sizeof *r);
    if (!dir) return CLI_EXIT_OK;
    r->dir = dir;
    struct stat st;
    char csv[CLI_OUTPUT_PATH_MAX];
    /* room for the longest name written into it (frame_NNNNN.png, its frame number any int):
     * a longer path would be cut, and another folder than DIR made */
    if (strlen(dir) + sizeof "/frame_2147483647.png" > sizeof csv) {
        fprintf(stderr, "atmos view: --record %.40s...: the path is too long\n", dir);
        return CLI_EXIT_USAGE;
    }
    snprintf(csv, sizeof csv, "%s/frames.csv", dir);
    /* the folder made with its missing parents, as atmos render's outputs' (a file of that
     * name: said below) */
    if (stat(dir, &st) != 0 && cli_output_folder("view", "--record", csv)) return CLI_EXIT_RUNTIME;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "atmos view: --record %s: not a folder (--record takes the folder to record into)\n", dir);
        return CLI_EXIT_USAGE;
    }
    char name[256];
    if (earlier_recording(dir, name, sizeof name)) {
        fprintf(stderr,
                "atmos view: --record %s: the folder holds an earlier recording (%s): a new one would mix its\n"
                "frames with the earlier ones; remove them (frames.csv, frame_*.png) or record into another folder\n",
                dir, name);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* frames.csv and its header, with the first frame (a session that never renders one leaves
 * no header-only file behind). */
static int open_csv(view_recorder *r)
{
    char path[CLI_OUTPUT_PATH_MAX];
    snprintf(path, sizeof path, "%s/frames.csv", r->dir);
    if (!(r->csv = fopen(path, "w"))) {
        fprintf(stderr, "atmos view: --record: cannot write %s: %s\n", path, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    fprintf(r->csv, "frame,ms,renderer,impostor_updates,x_m,y_m,z_m,yaw_deg,pitch_deg,sun_elevation_deg,sun_azimuth_deg,preview,"
                     "impostors_coarse\n");
    return CLI_EXIT_OK;
}

int view_record_frame(view_recorder *r, atmos_context *ctx, const atmos_image *disp, double ms, const char *renderer,
                      int impostor_updates, int impostors_coarse, int preview, int sunless, const view_state *s)
{
    if (!r->dir) return CLI_EXIT_OK;
    if (!r->csv && open_csv(r) != CLI_EXIT_OK) return CLI_EXIT_RUNTIME;
    char path[CLI_OUTPUT_PATH_MAX];
    snprintf(path, sizeof path, "%s/frame_%05d.png", r->dir, r->frames);
    char sun[64] = ""; /* empty without a sun (lit by lamps only) */
    if (!sunless) snprintf(sun, sizeof sun, "%.4f,%.4f", s->sun_el, s->sun_az);
    else snprintf(sun, sizeof sun, ",");
    /* the frame's PNG and its csv line, flushed, both or neither: a signal meanwhile (Ctrl-C)
     * acts after them, and the recording ends with whole frames and whole lines */
    cli_outputs_defer_signals(1);
    /* zlib's fastest level: at the default, writing a 1280 x 720 frame took more CPU than
     * rendering it */
    atmos_status st = atmos_write_png_level(ctx, disp, path, 8, 1);
    int ok = st == ATMOS_OK;
    if (ok) {
        fprintf(r->csv, "%d,%.3f,%s,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%s,%d,%d\n", r->frames, ms, renderer, impostor_updates,
                s->pos[0], s->pos[1], s->pos[2], s->yaw_deg, s->pitch_deg, sun, preview, impostors_coarse);
        ok = fflush(r->csv) == 0;
        if (!ok) unlink(path); /* no line for it: nor its PNG */
    }
    cli_outputs_defer_signals(0);
    if (st != ATMOS_OK) return cli_runtime_error("view", ctx, st);
    if (!ok) {
        fprintf(stderr, "atmos view: --record: writing %s/frames.csv failed: %s\n", r->dir, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    r->frames++;
    return CLI_EXIT_OK;
}

int view_record_close(view_recorder *r)
{
    int rc = CLI_EXIT_OK;
    if (r->csv && fclose(r->csv) != 0) {
        fprintf(stderr, "atmos view: --record: writing frames.csv failed\n");
        rc = CLI_EXIT_RUNTIME;
    }
    r->csv = NULL;
    return rc;
}

static cJSON *object(cJSON *root, const char *name)
{
    cJSON *o = cJSON_GetObjectItemCaseSensitive(root, name);
    if (!cJSON_IsObject(o)) {
        cJSON_DeleteItemFromObjectCaseSensitive(root, name);
        o = cJSON_AddObjectToObject(root, name);
    }
    return o;
}

static void set(cJSON *o, const char *name, cJSON *v)
{
    if (!o || !v) {
        cJSON_Delete(v);
        return;
    }
    if (cJSON_HasObjectItem(o, name)) cJSON_ReplaceItemInObjectCaseSensitive(o, name, v);
    else cJSON_AddItemToObject(o, name, v);
}

static void clear(cJSON *o, const char *const *names, int n)
{
    for (int i = 0; i < n; i++) cJSON_DeleteItemFromObjectCaseSensitive(o, names[i]);
}

/* o's file key made absolute in the saved scene, which lies in another folder than the one its
 * relative paths were relative to: the path the scene reader resolved (joined to the scene's
 * folder) through realpath. Kept as written: absolute paths, "builtin:", "generate:",
 * "simulate:", "data:" (the data folder's), and a value the scene's (resolved) does not end
 * with (a -D replaced it). */
static void absolute_file(cJSON *o, const char *key, const char *resolved)
{
    static const char *const kept[] = {"builtin:", "generate:", "simulate:", "data:"};
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!cJSON_IsString(v) || !v->valuestring[0] || v->valuestring[0] == '/') return;
    const char *p = v->valuestring;
    for (size_t k = 0; k < sizeof kept / sizeof kept[0]; k++)
        if (!strncmp(p, kept[k], strlen(kept[k]))) return;
    const size_t n = strlen(p), m = strlen(resolved);
    if (m < n || strcmp(resolved + m - n, p) || (m > n && resolved[m - n - 1] != '/')) return;
    char *abs = realpath(resolved, NULL);
    if (abs) set(o, key, cJSON_CreateString(abs));
    free(abs);
}

/* The scene's files besides the volume made absolute: the lights' images, the objects' meshes
 * and terrains, the Earth's maps. */
static void files_absolute(cJSON *root, const atmos_scene *sc)
{
    cJSON *lights = cJSON_GetObjectItemCaseSensitive(root, "lights");
    cJSON *objects = cJSON_GetObjectItemCaseSensitive(root, "objects");
    cJSON *atm = cJSON_GetObjectItemCaseSensitive(root, "atmosphere");
    cJSON *clouds = cJSON_GetObjectItemCaseSensitive(atm, "clouds");
    for (int i = 0; cJSON_IsArray(lights) && i < sc->light_count; i++)
        absolute_file(cJSON_GetArrayItem(lights, i), "image", sc->lights[i].image);
    for (int i = 0; cJSON_IsArray(objects) && i < sc->object_count; i++) {
        absolute_file(cJSON_GetArrayItem(objects, i), "mesh", sc->objects[i].mesh);
        absolute_file(cJSON_GetArrayItem(objects, i), "terrain", sc->objects[i].terrain);
    }
    absolute_file(atm, "ground_map", sc->earth.ground_map);
    absolute_file(atm, "night_lights", sc->earth.night_lights);
    absolute_file(clouds, "image", sc->earth.cloud_image);
    absolute_file(clouds, "world_file", sc->earth.cloud_world_file);
}

char *view_scene_json(const char *scene_json, const atmos_scene *sc, const view_state *s)
{
    cJSON *root = cJSON_Parse(scene_json && *scene_json ? scene_json : "{}");
    if (!root || !cJSON_IsObject(root)) {
        cJSON_Delete(root);
        root = cJSON_CreateObject();
    }
    atmos_frame f;
    memset(&f, 0, sizeof f);
    view_state_frame(s, &f);
    cJSON *img = object(root, "image");
    set(img, "width", cJSON_CreateNumber(sc->width));
    set(img, "height", cJSON_CreateNumber(sc->height));
    cJSON *cam = object(root, "camera");
    static const char *const cam_keys[] = {"view", "position_m", "look_at_m", "up", "fov_deg", "type"};
    static const char *const cam_types[] = {"pinhole", "fisheye", "equirect"};
    clear(cam, cam_keys, 6);
    set(cam, "type", cJSON_CreateString(cam_types[f.camera.type]));
    set(cam, "position_m", cJSON_CreateDoubleArray(f.camera.position, 3));
    set(cam, "look_at_m", cJSON_CreateDoubleArray(f.camera.look_at, 3));
    set(cam, "up", cJSON_CreateDoubleArray(f.camera.up, 3));
    if (f.camera.type != ATMOS_CAMERA_EQUIRECT) set(cam, "fov_deg", cJSON_CreateNumber(f.camera.fov_deg));
    cJSON *sun = object(root, "sun");
    static const char *const sun_keys[] = {"elevation_deg", "azimuth_deg", "time", "latitude_deg", "longitude_deg"};
    clear(sun, sun_keys, 5);
    set(sun, "elevation_deg", cJSON_CreateNumber(s->sun_el));
    set(sun, "azimuth_deg", cJSON_CreateNumber(s->sun_az));
    set(root, "renderer", cJSON_CreateString(atmos_renderer_name(s->renderer)));
    cJSON *out = object(root, "output");
    static const char *const out_keys[] = {"exposure", "exposure_compensation_ev"};
    clear(out, out_keys, 2);
    if (s->manual_exposure) set(out, "exposure", cJSON_CreateNumber(s->ev));
    else set(out, "exposure_compensation_ev", cJSON_CreateNumber(s->ev));
    cJSON *wl = object(root, "wavelengths");
    set(wl, "mode", cJSON_CreateString(s->spectral ? "spectral" : "rgb"));
    cJSON_DeleteItemFromObjectCaseSensitive(root, "animation");
    files_absolute(root, sc);
    if (s->renderer == ATMOS_RENDERER_SKY) {
        cJSON_DeleteItemFromObjectCaseSensitive(root, "volume"); /* the sky renderer's frame is without it */
    } else if (sc->volume.source[0]) {
        cJSON *vol = object(root, "volume");
        const int gen = !strncmp(sc->volume.source, "generate:", 9), sim = !strncmp(sc->volume.source, "simulate:", 9);
        static const char *const src_keys[] = {"file", "generate", "simulate"};
        clear(vol, src_keys, 3);
        if (sim) { /* the scene's own simulation settings, as parsed */
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "preset", sc->volume.source + 9);
            if (sc->volume.sim_minutes > 0) cJSON_AddNumberToObject(o, "minutes", sc->volume.sim_minutes);
            if (sc->volume.sim_grid > 0) cJSON_AddNumberToObject(o, "grid", sc->volume.sim_grid);
            cJSON_AddNumberToObject(o, "seed", (double)sc->volume.seed);
            if (sc->volume.sim_refine > 1) cJSON_AddNumberToObject(o, "refine", sc->volume.sim_refine);
            if (sc->volume.sim_detail > 0) cJSON_AddNumberToObject(o, "detail", sc->volume.sim_detail);
            if (sc->volume.sim_ice) cJSON_AddBoolToObject(o, "ice", 1);
            set(vol, "simulate", o);
        } else if (gen) {
            set(vol, "generate", cJSON_CreateString(sc->volume.source + 9));
        } else { /* absolute: the saved scene's own folder is not the one the path was relative to */
            char *abs = realpath(sc->volume.source, NULL);
            set(vol, "file", cJSON_CreateString(abs ? abs : sc->volume.source));
            free(abs);
        }
        if (sc->volume.placed) set(vol, "position_m", cJSON_CreateDoubleArray(sc->volume.position_m, 3));
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}

/* base + ext into buf */
static const char *save_name(char *buf, size_t cap, const char *base, const char *ext)
{
    snprintf(buf, cap, "%s%s", base, ext);
    return buf;
}

/* A saved view: BASE.exr, BASE.png and BASE.json, all three or none (a failure removes the ones
 * written before it). */
int view_save(atmos_context *ctx, const char *base, const char *scene_json, const atmos_scene *sc,
              const view_state *s, const atmos_image *lin, const atmos_image *disp)
{
    char exr[4096], png[4096], json[4096];
    atmos_status st = atmos_write_exr(ctx, lin, save_name(exr, sizeof exr, base, ".exr"), NULL);
    if (st == ATMOS_OK && (st = atmos_write_png(ctx, disp, save_name(png, sizeof png, base, ".png"), 8)) != ATMOS_OK)
        unlink(exr);
    if (st != ATMOS_OK) return cli_runtime_error("view", ctx, st);
    char *text = view_scene_json(scene_json, sc, s);
    FILE *f = text ? fopen(save_name(json, sizeof json, base, ".json"), "w") : NULL;
    const int ok = f && fputs(text, f) >= 0 && fputc('\n', f) != EOF;
    free(text);
    if ((f && fclose(f) != 0) || !ok) {
        fprintf(stderr, "atmos view: cannot write %s.json: the view was not saved\n", base);
        if (f) unlink(json);
        unlink(exr), unlink(png);
        return CLI_EXIT_RUNTIME;
    }
    fprintf(stderr, "atmos view: saved %s.exr, %s.png and %s.json\n", base, base, base);
    return CLI_EXIT_OK;
}
