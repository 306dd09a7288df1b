/* The library's optional parts kept in shared objects of their own (modules), opened with
 * dlopen on their first use, so that a program pays for loading their dependencies only
 * when it uses them (docs/architecture.md, "Each atmos process's start"): the OpenVDB
 * reader (libatmos_openvdb.so, volume/openvdb_module.c) drags in OpenVDB, TBB and Imath,
 * whose symbol bindings were more than half of every `atmos` process's start; the height map
 * reader (libatmos_gdal.so, mesh/mesh_gdal.c) drags in GDAL and its hundred libraries. */
#ifndef ATMOS_CORE_MODULE_H
#define ATMOS_CORE_MODULE_H

#include <stddef.h>

/* dlopen's handle of the module `file` (a file name, no directory), looked for in order:
 *  0. in the folder ATMOS_MODULE_DIR names, when it is set (the sanitizer tests: under
 *     AddressSanitizer dlopen is called from its interceptor, whose RUNPATH is not the program's);
 *  1. next to the object holding the library's code (libatmos.so where it is installed or
 *     built; a program linked with libatmos.a: the program's folder);
 *  2. ATMOS_MODULE_FROM_BIN relative to that folder (an installed program in bin/, the
 *     modules in the library folder beside it);
 *  3. by the dynamic loader's own search (the program's RUNPATH, LD_LIBRARY_PATH, the
 *     system's folders).
 * NULL when none opens, with the places tried and the loader's last message in msg. */
void *atmos__module_open(const char *file, char *msg, size_t cap);

/* What a module was built for, its export ATMOS__MODULE_STAMP: the library's version, the
 * interface's revision (bump ATMOS__MODULE_ABI when a structure crossing it changes without
 * changing size) and the sizes of the structures crossing it (0 for the unused). A module of
 * another build (an older install, a second atmos on the system) is refused, not called. */
#define ATMOS__MODULE_ABI 1u
#define ATMOS__MODULE_STAMP "atmos_module_stamp"
typedef struct atmos__module_stamp {
    char version[24];
    unsigned abi;
    size_t sizes[3];
} atmos__module_stamp;

/* The symbol `sym` of the module `file` (atmos__module_open), once its stamp matches `want`
 * (version and abi: the library's own; sizes: the caller's). NULL with why (cap bytes) when
 * the module is missing, stale ("built for another libatmos") or lacks the symbol. */
void *atmos__module_symbol(const char *file, const char *sym, const atmos__module_stamp *want, char *why,
                           size_t cap);

#endif
