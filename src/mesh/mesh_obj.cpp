// The Wavefront OBJ reader behind mesh_obj.h: tinyobjloader parses, this file counts the
// triangles first (so an oversized file is refused before it is read into memory), then
// copies vertices and triangle indices into malloc'd arrays and checks every index.
#include "mesh/mesh_obj.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <new>
#include <sstream>
#include <string>

namespace {

void say(char *msg, size_t cap, const char *text)
{
    if (cap) std::snprintf(msg, cap, "%s", text);
}

// The pass before the reader: the triangles the faces will give (every "f" line of n
// vertices gives n - 2; stops counting past stop_after), and the first vertex line whose
// coordinates are not finite numbers (the reader would take "nan" or "inf" as they are or
// as zero). -1 if the file cannot be opened.
long scan(const char *path, long stop_after, long *bad_line)
{
    std::ifstream f(path, std::ios::binary);
    if (!f) return -1;
    long tris = 0, line_no = 0;
    *bad_line = 0;
    std::string line;
    while (std::getline(f, line) && tris <= stop_after) {
        line_no++;
        if (line.size() < 2 || (line[1] != ' ' && line[1] != '\t')) continue;
        if (line[0] == 'f') {
            std::istringstream in(line.substr(2));
            std::string tok;
            long n = 0;
            while (in >> tok) n++;
            if (n > 2) tris += n - 2;
        } else if (line[0] == 'v' && !*bad_line) {
            const char *p = line.c_str() + 2;
            for (int k = 0; k < 3; k++) {
                char *end = nullptr;
                const double x = std::strtod(p, &end);
                if (end == p || !std::isfinite(x)) {
                    *bad_line = line_no;
                    break;
                }
                p = end;
            }
        }
    }
    return tris;
}

int read_obj(const char *path, long max_triangles, float **positions, long *nv, uint32_t **indices, long *nt,
             char *msg, size_t cap)
{
    long bad_line = 0;
    const long counted = scan(path, max_triangles, &bad_line);
    if (counted < 0) return say(msg, cap, "cannot open the file"), ATMOS__OBJ_E_IO;
    if (counted > max_triangles) {
        if (cap) std::snprintf(msg, cap, "more than %ld triangles (the bound)", max_triangles);
        return ATMOS__OBJ_E_LIMIT;
    }
    if (bad_line) {
        if (cap) std::snprintf(msg, cap, "line %ld: a vertex needs three finite numbers", bad_line);
        return ATMOS__OBJ_E_FORMAT;
    }
    tinyobj::ObjReaderConfig config;
    config.triangulate = false; // fanned here, so that the count matches the one above
    config.vertex_color = false;
    config.mtl_search_path = "";
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config)) {
        std::string e = reader.Error();
        while (!e.empty() && (e.back() == '\n' || e.back() == '\r')) e.pop_back();
        if (cap) std::snprintf(msg, cap, "not a valid OBJ file: %s", e.empty() ? "the reader failed" : e.c_str());
        return ATMOS__OBJ_E_FORMAT;
    }
    const std::vector<tinyobj::real_t> &v = reader.GetAttrib().vertices;
    const long vcount = (long)(v.size() / 3);
    long tris = 0;
    for (const tinyobj::shape_t &s : reader.GetShapes())
        for (const auto n : s.mesh.num_face_vertices) tris += n >= 3 ? (long)n - 2 : 0;
    if (tris > max_triangles) {
        if (cap) std::snprintf(msg, cap, "more than %ld triangles (the bound)", max_triangles);
        return ATMOS__OBJ_E_LIMIT;
    }
    float *pos = (float *)std::malloc(sizeof(float) * 3 * (size_t)(vcount ? vcount : 1));
    uint32_t *idx = (uint32_t *)std::malloc(sizeof(uint32_t) * 3 * (size_t)(tris ? tris : 1));
    if (!pos || !idx) {
        std::free(pos), std::free(idx);
        return say(msg, cap, "out of memory"), ATMOS__OBJ_E_NOMEM;
    }
    for (long i = 0; i < 3 * vcount; i++) pos[i] = v[(size_t)i];
    long t = 0;
    for (const tinyobj::shape_t &s : reader.GetShapes()) {
        size_t at = 0;
        for (const auto fn : s.mesh.num_face_vertices) {
            const int n = (int)fn;
            for (int k = 0; k < n; k++) {
                const int vi = s.mesh.indices[at + (size_t)k].vertex_index;
                if (vi < 0 || vi >= vcount) {
                    if (cap) std::snprintf(msg, cap, "a face refers to vertex %d, the file has %ld", vi + 1, vcount);
                    std::free(pos), std::free(idx);
                    return ATMOS__OBJ_E_FORMAT;
                }
            }
            for (int k = 1; k + 1 < n; k++, t++) {
                idx[3 * t] = (uint32_t)s.mesh.indices[at].vertex_index;
                idx[3 * t + 1] = (uint32_t)s.mesh.indices[at + (size_t)k].vertex_index;
                idx[3 * t + 2] = (uint32_t)s.mesh.indices[at + (size_t)k + 1].vertex_index;
            }
            at += n;
        }
    }
    *positions = pos, *nv = vcount, *indices = idx, *nt = t;
    return ATMOS__OBJ_OK;
}

} // namespace

extern "C" int atmos__obj_read(const char *path, long max_triangles, float **positions, long *vertex_count,
                               uint32_t **indices, long *triangle_count, char *msg, size_t cap)
{
    *positions = nullptr, *indices = nullptr, *vertex_count = 0, *triangle_count = 0;
    if (cap) msg[0] = '\0';
    try {
        return read_obj(path, max_triangles, positions, vertex_count, indices, triangle_count, msg, cap);
    } catch (const std::bad_alloc &) {
        say(msg, cap, "out of memory");
        return ATMOS__OBJ_E_NOMEM;
    } catch (const std::exception &e) {
        if (cap) std::snprintf(msg, cap, "the reader failed: %s", e.what());
        return ATMOS__OBJ_E_FORMAT;
    } catch (...) {
        say(msg, cap, "the reader failed");
        return ATMOS__OBJ_E_FORMAT;
    }
}
