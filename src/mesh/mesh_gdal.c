/* Height map files through the GDAL module (terrain_gdal.c, libatmos_gdal.so), opened on the
 * first one (core/module.h): a program that reads none does not load GDAL. */
#include "mesh/mesh_internal.h"

#include "core/module.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#ifdef ATMOS_HAVE_GDAL

static atmos__gdal_module_entry gdal_read;
static char gdal_why[512];
static pthread_once_t gdal_once = PTHREAD_ONCE_INIT;

static void load_once(void)
{
    const atmos__module_stamp want = ATMOS__GDAL_MODULE_STAMP;
    *(void **)&gdal_read =
        atmos__module_symbol(ATMOS__GDAL_MODULE, ATMOS__GDAL_MODULE_ENTRY, &want, gdal_why, sizeof gdal_why);
}

atmos_status atmos__terrain_read(atmos_context *ctx, const char *path, int stride, long max_triangles,
                                 atmos__heights *out)
{
    memset(out, 0, sizeof *out);
    struct stat sb; /* GDAL's own messages for a missing file or a folder are vaguer */
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return atmos__error(ctx, ATMOS_E_IO, "terrain %s: cannot open: it is a folder, not a file", path);
    FILE *f = fopen(path, "rb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "terrain %s: cannot open: %s", path, strerror(errno));
    fclose(f);
    if (stat(path, &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size == 0) /* GDAL: "unknown format" */
        return atmos__error(ctx, ATMOS_E_FORMAT, "terrain %s: empty file (0 bytes)", path);
    pthread_once(&gdal_once, load_once);
    if (!gdal_read)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED, "terrain %s: the GDAL module: %s (install it next to libatmos)",
                            path, gdal_why);
    char msg[1024] = "";
    const atmos_status st = gdal_read(path, stride, max_triangles, out, msg, sizeof msg);
    return st == ATMOS_OK ? ATMOS_OK : atmos__error(ctx, st, "%s", msg);
}

#else

atmos_status atmos__terrain_read(atmos_context *ctx, const char *path, int stride, long max_triangles,
                                 atmos__heights *out)
{
    (void)stride, (void)max_triangles;
    memset(out, 0, sizeof *out);
    return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                        "terrain %s: height map files need GDAL: install libgdal-dev and build atmos again", path);
}

#endif
