/* The Earth's maps and clouds of a scene (atmos_scene_earth): their files' paths, reading
 * them (JPEG or PNG) and the world file that places a geolocated cloud image. */
#define _POSIX_C_SOURCE 200809L
#include "scene/scene_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static atmos_status fix_path(atmos_context *ctx, const char *scene, size_t dir, char *p, size_t cap,
                             const char *key)
{
    if (!p[0]) return ATMOS_OK;
    char field[64];
    snprintf(field, sizeof field, "atmosphere/%s", key);
    atmos_status st = atmos__scene_join_path(ctx, scene, dir, p, cap, field);
    if (st != ATMOS_OK) return st;
    if (access(p, R_OK) != 0)
        return atmos__error(ctx, ATMOS_E_IO, "%s: /atmosphere/%s: cannot read %s: %s", scene, key, p, strerror(errno));
    return ATMOS_OK;
}

atmos_status atmos__scene_earth_paths(atmos_context *ctx, const char *path, size_t dir, atmos_scene_earth *e)
{
    atmos_status st = fix_path(ctx, path, dir, e->ground_map, sizeof e->ground_map, "ground_map");
    if (!st) st = fix_path(ctx, path, dir, e->night_lights, sizeof e->night_lights, "night_lights");
    if (!st) st = fix_path(ctx, path, dir, e->cloud_image, sizeof e->cloud_image, "clouds/image");
    if (!st) st = fix_path(ctx, path, dir, e->cloud_world_file, sizeof e->cloud_world_file, "clouds/world_file");
    return st;
}

/* A JPEG (FF D8 FF) or a PNG (its 8-byte signature) by the file's first bytes; the messages
 * name the file (map_error puts the scene and its key in front). */
static atmos_status read_map(atmos_context *ctx, const char *path, int reduce, atmos_image **out)
{
    unsigned char m[8] = {0};
    FILE *f = fopen(path, "rb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));
    const size_t n = fread(m, 1, sizeof m, f);
    fclose(f);
    const char *kind = atmos_image_kind(m, n);
    const int jpeg = kind && !strcmp(kind, "JPEG"), png = kind && !strcmp(kind, "PNG");
    if (!jpeg && !png)
        return atmos__error(ctx, ATMOS_E_FORMAT,
                            "%s is not an image atmos reads: the Earth's maps are PNG or JPEG files "
                            "(known by their first bytes)",
                            path);
    return jpeg ? atmos_read_jpeg_scaled(ctx, path, reduce ? reduce : 1, out) : atmos_read_png(ctx, path, out);
}

/* A failure st of reading the file at path, named by the scene's key /atmosphere/KEY: said as
 * every file a scene names is (the scene file, the key, the reader's message). */
static atmos_status map_error(atmos_context *ctx, atmos_status st, const atmos_scene *scene, const char *key,
                              const char *path)
{
    if (st == ATMOS_OK) return st;
    char k[64];
    snprintf(k, sizeof k, "/atmosphere/%s", key);
    return atmos__scene_file_error(ctx, st, scene, path, k, 1);
}

/* An ESRI world file (six numbers: x size of a pixel, two rotations, y size, and the
 * centre of the top-left pixel) sets the extent of a w x h image; rotations must be 0. */
static atmos_status world_file(atmos_context *ctx, const char *path, int w, int h, atmos_cloud_desc *c)
{
    double v[6];
    FILE *f = fopen(path, "r");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));
    int n = 0;
    while (n < 6 && fscanf(f, "%lf", &v[n]) == 1) n++;
    fclose(f);
    if (n < 6 || v[0] <= 0 || v[3] >= 0 || v[1] != 0 || v[2] != 0)
        return atmos__error(ctx, ATMOS_E_FORMAT,
                            "%s: a world file needs six numbers, a positive x size, no rotation and a negative y size",
                            path);
    c->lon_west_deg = v[4] - 0.5 * v[0];
    c->lon_east_deg = c->lon_west_deg + w * v[0];
    c->lat_north_deg = v[5] - 0.5 * v[3];
    c->lat_south_deg = c->lat_north_deg + h * v[3];
    if (c->lat_south_deg < -90 || c->lat_north_deg > 90)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: the image would reach beyond the poles", path);
    return ATMOS_OK;
}

atmos_status atmos_scene_atmosphere_create(atmos_context *ctx, const atmos_scene *scene, const atmos_wavelengths *wl,
                                           atmos_atmosphere **out)
{
    if (!scene || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_scene_atmosphere_create: NULL argument");
    const atmos_scene_earth *e = &scene->earth;
    const int spherical = scene->atmosphere.kind == ATMOS_ATMOSPHERE_DOBASHI ||
                          scene->atmosphere.kind == ATMOS_ATMOSPHERE_SPHERICAL;
    atmos_atmosphere_desc d = scene->atmosphere;
    atmos_image *ground = NULL, *night = NULL, *clouds = NULL;
    atmos_status st = ATMOS_OK;
    if (spherical && e->ground_map[0])
        st = map_error(ctx, read_map(ctx, e->ground_map, e->map_reduce, &ground), scene, "ground_map", e->ground_map);
    if (!st && spherical && e->night_lights[0])
        st = map_error(ctx, read_map(ctx, e->night_lights, e->map_reduce, &night), scene, "night_lights",
                       e->night_lights);
    if (!st && spherical && e->cloud_image[0])
        st = map_error(ctx, read_map(ctx, e->cloud_image, 1, &clouds), scene, "clouds/image", e->cloud_image);
    if (!st && clouds && e->cloud_world_file[0])
        st = map_error(ctx, world_file(ctx, e->cloud_world_file, clouds->width, clouds->height, &d.clouds), scene,
                       "clouds/world_file", e->cloud_world_file);
    if (!st) {
        /* the files named in the scene, else the images the scene's desc holds (a scene built
         * in code) */
        if (ground) d.ground_map = ground;
        if (night) d.night_map = night;
        if (clouds) d.clouds.image = clouds;
        st = atmos_atmosphere_create(ctx, &d, wl, out);
    }
    atmos_image_destroy(ground);
    atmos_image_destroy(night);
    atmos_image_destroy(clouds);
    return st;
}
