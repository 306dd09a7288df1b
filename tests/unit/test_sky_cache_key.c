/* The production sky's tables are cached under a key of the air's description alone
 * (docs/sky.md, "Tables"): an atmosphere with a ground map and cloud spheres finds the tables
 * a plain one stored (the maps do not enter them), and a second atmosphere with maps made while
 * the first is alive (so its maps lie elsewhere in memory) stores nothing new. Until
 * 2026-12-06 the key summed the maps' pointers, so each run of an Earth scene built the
 * tables again and left another 3.9 MB file in the cache. */
#include "atmos/atmos.h"
#include "atmos/cache.h"
#include "test.h"

#include <dirent.h>
#include <string.h>

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        const size_t l = strlen(e->d_name);
        n += l > 11 && strcmp(e->d_name + l - 11, ".atmoscache") == 0;
    }
    if (d) closedir(d);
    return n;
}

static atmos_image *grey(int w, int h, float v)
{
    atmos_image *img = NULL;
    CHECK_OK(atmos_image_create(NULL, w, h, 3, &img));
    for (size_t i = 0; img && i < (size_t)w * h * 3; i++) img->pixels[i] = v;
    return img;
}

static atmos_atmosphere *make(atmos_context *ctx, const atmos_image *ground, const atmos_image *clouds)
{
    atmos_atmosphere_desc d;
    atmos_atmosphere_defaults(&d);
    d.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    d.ground_map = ground;
    d.clouds.image = clouds;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_MSG(atmos_atmosphere_create(ctx, &d, &wl, &a) == ATMOS_OK, "create: %s", atmos_context_error(ctx));
    return a;
}

int main(void)
{
    char dir[1024];
    test_tmp_path(dir, sizeof dir, "sky_cache_key");
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.cache_dir = dir;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    if (!ctx) return test_summary("test_sky_cache_key");
    CHECK_OK(atmos_cache_clear(ctx, NULL));
    atmos_image *g1 = grey(64, 32, 0.3f), *c1 = grey(64, 32, 0.6f), *g2 = grey(64, 32, 0.3f), *c2 = grey(64, 32, 0.6f);
    atmos_atmosphere *plain = make(ctx, NULL, NULL);
    const int n0 = count_entries(dir);
    atmos_atmosphere *a1 = make(ctx, g1, c1);
    const int n1 = count_entries(dir);
    atmos_atmosphere *a2 = make(ctx, g2, c2);
    const int n2 = count_entries(dir);
    printf("cache entries: %d plain, %d with maps, %d with other maps\n", n0, n1, n2);
    CHECK(n0 >= 1);
    CHECK_MSG(n1 == n0 && n2 == n0, "the maps changed the tables' key: %d, %d, %d entries", n0, n1, n2);
    atmos_atmosphere_destroy(a2);
    atmos_atmosphere_destroy(a1);
    atmos_atmosphere_destroy(plain);
    atmos_image_destroy(g1), atmos_image_destroy(c1), atmos_image_destroy(g2), atmos_image_destroy(c2);
    atmos_cache_clear(ctx, NULL);
    atmos_context_destroy(ctx);
    return test_summary("test_sky_cache_key");
}
