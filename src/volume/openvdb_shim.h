/* A thin C interface to the OpenVDB library (src/volume/openvdb_shim.cpp, built as the module
 * libatmos_openvdb.so). It is compiled only when CMake finds OpenVDB (ATMOS_HAVE_OPENVDB).
 *
 * Every function catches all C++ exceptions and turns them into a nonzero return
 * code plus a message in msg (cap bytes, always NUL-terminated), so no exception
 * ever crosses into C. The shim knows nothing of atmos volumes: it hands the grid's
 * contents to a callback in blocks and leaves placement and policy to vdb_reader.c.
 */
#ifndef ATMOS_OPENVDB_SHIM_H
#define ATMOS_OPENVDB_SHIM_H

#include "core/module.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Return codes of the shim (mapped to atmos_status by the caller). */
enum {
    ATMOS__VDB_OK = 0,
    ATMOS__VDB_E_IO = 1,      /* cannot open or read the file */
    ATMOS__VDB_E_FORMAT = 2,  /* not a VDB file, or a corrupt one */
    ATMOS__VDB_E_NOMEM = 3,
    ATMOS__VDB_E_STOPPED = 4  /* the block callback asked to stop */
};

typedef struct atmos__vdb atmos__vdb;

typedef struct atmos__vdb_grid_info {
    char name[128];
    char value_type[32];       /* "float", "vec3s", ... as OpenVDB names them */
    int is_float;              /* a FloatGrid: the only kind atmos reads */
} atmos__vdb_grid_info;

/* Filled by atmos__vdb_load_grid() for a float grid. */
typedef struct atmos__vdb_grid_stats {
    uint64_t active_voxels;    /* OpenVDB's count: active tiles count as the voxels they cover */
    uint64_t leaf_voxels;      /* active voxels stored in leaves */
    uint64_t active_tiles;     /* active tiles at any level */
    int empty;                 /* no active values at all */
    int bbox_min[3], bbox_max[3]; /* inclusive index bounding box of the active values */
    double min, max;           /* over active values */
    uint64_t bad_values;       /* active values that are NaN, Inf or negative */
    int bad_ijk[3];            /* index of the first bad value */
    double bad_value;
    int linear;                /* the transform is an affine map (not a frustum) */
    char map_type[48];         /* OpenVDB's map type name, for messages */
    double mat[4][4];          /* index -> world as OpenVDB stores it: row vectors,
                                  world = [i j k 1] * mat (translation in row 3) */
    int compressed;            /* the file marks this grid as zip or blosc compressed */
} atmos__vdb_grid_stats;

/* One block of a grid in index space: size[0]*size[1]*size[2] values, x fastest,
 * at index origin[]. For a constant active tile, values is NULL and every voxel
 * of the block equals constant. Return nonzero to stop the walk. */
typedef int (*atmos__vdb_block_fn)(void *user, const int origin[3], const int size[3], const float *values,
                                   float constant);

/* The shim's entry points. They live in the module libatmos_openvdb.so, opened on the first
 * use (volume/openvdb_module.c, core/module.h), so that only a program reading a .vdb file
 * loads OpenVDB and its libraries; the module's exports are its stamp (ATMOS__VDB_MODULE_STAMP,
 * core/module.h) and ATMOS__VDB_MODULE_ENTRY, a function returning this table. */
typedef struct atmos__vdb_api {
    int (*open)(const char *path, atmos__vdb **out, char *msg, size_t cap);
    void (*close)(atmos__vdb *f);
    int (*grid_count)(const atmos__vdb *f);
    int (*get_grid_info)(const atmos__vdb *f, int index, atmos__vdb_grid_info *info);
    /* Reads grid `index` (a float grid) from the file and measures it. */
    int (*load_grid)(atmos__vdb *f, int index, atmos__vdb_grid_stats *stats, char *msg, size_t cap);
    /* Walks the loaded grid `index`: every leaf as an 8^3 block (inactive voxels 0) and
     * every active tile as a constant block. */
    int (*visit)(atmos__vdb *f, int index, atmos__vdb_block_fn fn, void *user, char *msg, size_t cap);
} atmos__vdb_api;

#define ATMOS__VDB_MODULE "libatmos_openvdb.so"
#define ATMOS__VDB_MODULE_ENTRY "atmos_openvdb_module_v1"
#define ATMOS__VDB_MODULE_STAMP                                                                                     \
    {ATMOS_VERSION_STRING,                                                                                          \
     ATMOS__MODULE_ABI,                                                                                             \
     {sizeof(atmos__vdb_api), sizeof(atmos__vdb_grid_info), sizeof(atmos__vdb_grid_stats)}}
typedef const atmos__vdb_api *(*atmos__vdb_module_entry)(void);

/* The library's side (openvdb_module.c). atmos__vdb_module_load opens the module once per
 * process (thread-safe): 0 and why in msg when it cannot. The calls below go to the
 * module's table; atmos__vdb_open answers ATMOS__VDB_E_IO with that message without it. */
int atmos__vdb_module_load(char *msg, size_t cap);
int atmos__vdb_open(const char *path, atmos__vdb **out, char *msg, size_t cap);
void atmos__vdb_close(atmos__vdb *f);
int atmos__vdb_grid_count(const atmos__vdb *f);
int atmos__vdb_get_grid_info(const atmos__vdb *f, int index, atmos__vdb_grid_info *info);
int atmos__vdb_load_grid(atmos__vdb *f, int index, atmos__vdb_grid_stats *stats, char *msg, size_t cap);
int atmos__vdb_visit(atmos__vdb *f, int index, atmos__vdb_block_fn fn, void *user, char *msg, size_t cap);

#ifdef __cplusplus
}
#endif
#endif
