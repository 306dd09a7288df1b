/* The Wavefront OBJ reader (mesh_obj.cpp, through tinyobjloader): a C interface to the only
 * C++ of the mesh module. No exception crosses it: every failure is a return code and a
 * message. It knows nothing of atmos_mesh; mesh.c checks and owns what it returns. */
#ifndef ATMOS_MESH_OBJ_H
#define ATMOS_MESH_OBJ_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
    ATMOS__OBJ_OK = 0,
    ATMOS__OBJ_E_IO = 1,     /* cannot open or read the file */
    ATMOS__OBJ_E_FORMAT = 2, /* the reader refused it, or an index is out of range */
    ATMOS__OBJ_E_NOMEM = 3,
    ATMOS__OBJ_E_LIMIT = 4   /* more triangles than asked for (counted before the file is read) */
};

/* Reads path's vertices and faces (fanned into triangles). On success *positions (3 floats a
 * vertex) and *indices (3 a triangle) are malloc'd for the caller; counts may be 0. msg
 * (cap bytes, NUL-terminated) says what went wrong. */
int atmos__obj_read(const char *path, long max_triangles, float **positions, long *vertex_count, uint32_t **indices,
                    long *triangle_count, char *msg, size_t cap);

#ifdef __cplusplus
}
#endif
#endif
