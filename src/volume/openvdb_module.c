/* The OpenVDB shim's calls through its module (openvdb_shim.h): libatmos_openvdb.so is opened
 * the first time a .vdb file is read, not when a program starts (core/module.h). */
#include "volume/openvdb_shim.h"

#include "core/module.h"

#include <pthread.h>
#include <stdio.h>

static const atmos__vdb_api *vdb_api;
static char vdb_why[512];
static pthread_once_t vdb_once = PTHREAD_ONCE_INIT;

static void load_once(void)
{
    const atmos__module_stamp want = ATMOS__VDB_MODULE_STAMP;
    atmos__vdb_module_entry entry;
    *(void **)&entry = atmos__module_symbol(ATMOS__VDB_MODULE, ATMOS__VDB_MODULE_ENTRY, &want, vdb_why, sizeof vdb_why);
    if (entry) vdb_api = entry();
}

int atmos__vdb_module_load(char *msg, size_t cap)
{
    pthread_once(&vdb_once, load_once);
    if (!vdb_api && msg && cap) snprintf(msg, cap, "the OpenVDB reader's module: %s", vdb_why);
    return vdb_api != NULL;
}

int atmos__vdb_open(const char *path, atmos__vdb **out, char *msg, size_t cap)
{
    if (!atmos__vdb_module_load(msg, cap)) return ATMOS__VDB_E_IO;
    return vdb_api->open(path, out, msg, cap);
}

/* The others take a file atmos__vdb_open opened: the module is there. */
void atmos__vdb_close(atmos__vdb *f) { vdb_api->close(f); }
int atmos__vdb_grid_count(const atmos__vdb *f) { return vdb_api->grid_count(f); }
int atmos__vdb_get_grid_info(const atmos__vdb *f, int index, atmos__vdb_grid_info *info)
{
    return vdb_api->get_grid_info(f, index, info);
}
int atmos__vdb_load_grid(atmos__vdb *f, int index, atmos__vdb_grid_stats *stats, char *msg, size_t cap)
{
    return vdb_api->load_grid(f, index, stats, msg, cap);
}
int atmos__vdb_visit(atmos__vdb *f, int index, atmos__vdb_block_fn fn, void *user, char *msg, size_t cap)
{
    return vdb_api->visit(f, index, fn, user, msg, cap);
}
