/* Finding and opening the library's modules (module.h). */
#define _GNU_SOURCE /* dladdr1 */
#include "core/module.h"

#include <dlfcn.h>
#include <link.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef ATMOS_MODULE_FROM_BIN
#define ATMOS_MODULE_FROM_BIN "../lib"
#endif

/* The folder of the object holding this code: libatmos.so by the path the loader opened it
 * from; a program with libatmos.a linked in (the loader's map names it "") by its own file. */
static int own_folder(char *dir, size_t cap)
{
    Dl_info info;
    struct link_map *map = NULL;
    char exe[4096];
    const char *path = NULL;
    if (dladdr1((void *)own_folder, &info, (void **)&map, RTLD_DL_LINKMAP) && map && map->l_name[0]) {
        path = map->l_name;
    } else {
        const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (n > 0) exe[n] = '\0', path = exe;
    }
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (!slash || (size_t)(slash - path) >= cap) return 0;
    memcpy(dir, path, (size_t)(slash - path));
    dir[slash - path] = '\0';
    return 1;
}

void *atmos__module_open(const char *file, char *msg, size_t cap)
{
    char dir[4096], path[4400];
    const int have_dir = own_folder(dir, sizeof dir);
    const char *env = getenv("ATMOS_MODULE_DIR");
    const char *const base[3] = {env && env[0] ? env : NULL, have_dir ? dir : NULL, have_dir ? dir : NULL};
    const char *const rel[3] = {".", ".", ATMOS_MODULE_FROM_BIN};
    for (int i = 0; i < 3; i++) {
        if (!base[i]) continue;
        snprintf(path, sizeof path, "%s/%s/%s", base[i], rel[i], file);
        if (access(path, F_OK) != 0) continue;
        void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (h) return h;
        if (msg && cap) snprintf(msg, cap, "%s", dlerror());
        return NULL;
    }
    void *h = dlopen(file, RTLD_NOW | RTLD_LOCAL);
    if (!h && msg && cap)
        snprintf(msg, cap, "%s not found (looked in %s%s%s, %s/%s and the loader's folders): %s", file,
                 base[0] ? base[0] : "", base[0] ? " (ATMOS_MODULE_DIR), " : "",
                 have_dir ? dir : "(the library's folder unknown)", have_dir ? dir : "", ATMOS_MODULE_FROM_BIN,
                 dlerror());
    return h;
}

void *atmos__module_symbol(const char *file, const char *sym, const atmos__module_stamp *want, char *why,
                           size_t cap)
{
    void *h = atmos__module_open(file, why, cap);
    if (!h) return NULL;
    const atmos__module_stamp *got = (const atmos__module_stamp *)dlsym(h, ATMOS__MODULE_STAMP);
    if (!got || strncmp(got->version, want->version, sizeof got->version) != 0 || got->abi != want->abi ||
        memcmp(got->sizes, want->sizes, sizeof got->sizes) != 0) {
        snprintf(why, cap, "%s was built for another libatmos (%.24s, interface %u; this one is %s, interface %u)",
                 file, got ? got->version : "no stamp", got ? got->abi : 0u, want->version, want->abi);
        dlclose(h);
        return NULL;
    }
    void *p = dlsym(h, sym);
    if (!p) snprintf(why, cap, "%s: no %s in it", file, sym);
    return p;
}
