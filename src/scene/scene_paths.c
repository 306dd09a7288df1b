/* A scene's file paths (volume, maps, light images, meshes, terrain) made usable wherever the
 * scene is rendered from: a relative path is relative to the scene file's folder, and a path
 * "data:REST" names REST in the data folder ($ATMOS_DATA, else the folder the build was told,
 * ATMOS_DATA_DIR: the real data atmos does not ship, docs/scene-format.md). Generated sources
 * ("builtin:", "generate:", "simulate:") are left as they are. */
#define _POSIX_C_SOURCE 200809L
#include "scene/scene_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef ATMOS_DATA_DEFAULT
#define ATMOS_DATA_DEFAULT "data"
#endif

const char *atmos__scene_data_dir(void)
{
    const char *d = getenv("ATMOS_DATA");
    return d && d[0] ? d : ATMOS_DATA_DEFAULT;
}

static int generated(const char *p)
{
    return !strncmp(p, "builtin:", 8) || !strncmp(p, "generate:", 9) || !strncmp(p, "simulate:", 9);
}

atmos_status atmos__scene_join_path(atmos_context *ctx, const char *scene, size_t dir, char *p, size_t cap,
                                    const char *key)
{
    if (!p[0] || p[0] == '/' || generated(p)) return ATMOS_OK;
    char joined[ATMOS_SCENE_PATH_MAX * 2];
    int n;
    const int data = !strncmp(p, "data:", 5);
    if (data) n = snprintf(joined, sizeof joined, "%s/%s", atmos__scene_data_dir(), p + 5);
    else if (dir > 0) n = snprintf(joined, sizeof joined, "%.*s%s", (int)dir, scene, p);
    else return ATMOS_OK; /* from standard input: the current folder */
    if (n < 0 || (size_t)n >= cap)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: /%s: the path is too long once joined to %s", scene, key,
                            data ? "the data folder" : "the scene's folder");
    if (data && access(joined, R_OK) != 0)
        return atmos__error(ctx, ATMOS_E_IO,
                            "%s: /%s: cannot read %s (from %s): %s; data: paths are read from the folder in "
                            "ATMOS_DATA (else %s): set ATMOS_DATA to the folder that holds the real data",
                            scene, key, joined, p, strerror(errno), ATMOS_DATA_DEFAULT);
    memcpy(p, joined, (size_t)n + 1);
    return ATMOS_OK;
}

atmos_status atmos__scene_file_error(atmos_context *ctx, atmos_status st, const atmos_scene *s, const char *path,
                                    const char *key, int where)
{
    char why[1024], note[2 * ATMOS_SCENE_PATH_MAX + 80];
    snprintf(why, sizeof why, "%s", atmos_context_error(ctx));
    const char *file = s && s->file[0] ? s->file : NULL;
    const char *who = s && !strcmp(key, "/volume/file") && s->volume_by[0] ? s->volume_by
                      : file                                               ? file
                      : s && s->origin[0]                                  ? s->origin
                                                                           : NULL;
    note[0] = '\0';
    if (where && path[0] && path[0] != '/' && !generated(path)) {
        const char *slash = file ? strrchr(file, '/') : NULL;
        const size_t dir = slash ? (size_t)(slash - file) + 1 : 0;
        if (slash && !strncmp(path, file, dir)) /* the joined path: the folder, then what the scene wrote */
            snprintf(note, sizeof note, " (resolved against the scene's folder %.*s; the scene wrote %s)", (int)dir,
                     file, path + dir);
        else if (slash) snprintf(note, sizeof note, " (resolved against the scene's folder %.*s)", (int)dir, file);
        else if (file) snprintf(note, sizeof note, " (a relative path: from the scene's folder, the current folder)");
        else snprintf(note, sizeof note, " (a relative path: from the current folder)");
    }
    return atmos__error(ctx, st, "%s%s%s: %s%s", who ? who : "", who ? ": " : "", key, why, note);
}
