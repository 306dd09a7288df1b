// The Wavefront OBJ reader behind mesh_obj.h: tinyobjloader parses, this file counts the
// triangles first (so an oversized file is refused before it is read into memory), then
// copies vertices and triangle indices into malloc'd arrays and checks every index. A comment
// ('#' to the end of the line) may follow a line's content ("f 1 2 3 # tri"): the first pass
// reads lines without their comments, and tinyobjloader, which takes a face's '#' for a vertex
// index, is handed such a file's text without them.
#include "mesh/mesh_obj.h"

#include <tiny_obj_loader.h>

#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <algorithm>
#include <new>
#include <sstream>
#include <string>

namespace {

void say(char *msg, size_t cap, const char *text)
{
    if (cap) std::snprintf(msg, cap, "%s", text);
}

// One face vertex as written ("7", "-2", "7/1/3", "7//3"): its vertex index in *out.
// 0 when the text before the first '/' is not an integer.
int face_index(const std::string &tok, long *out)
{
    const std::string head = tok.substr(0, tok.find('/'));
    const char *p = head.c_str();
    char *end = nullptr;
    errno = 0;
    const long v = std::strtol(p, &end, 10);
    if (end == p || *end || errno) return 0;
    *out = v;
    return 1;
}

// A face line's vertices checked as written: integers, not 0, a negative one within the
// vertices before the line (OBJ counts it back from there), a positive one noted in
// *max_pos (checked against the file's count at the end). Empty, or what is wrong.
std::string check_face(const std::string &rest, long line_no, long vertices, long *max_pos, long *max_line)
{
    std::istringstream in(rest);
    std::string tok;
    char buf[256];
    while (in >> tok) {
        long v = 0;
        if (!face_index(tok, &v)) {
            std::snprintf(buf, sizeof buf, "line %ld: a face's vertex '%.40s' is not a number (a vertex index, "
                          "counted from 1)", line_no, tok.c_str());
            return buf;
        }
        if (v == 0) {
            std::snprintf(buf, sizeof buf, "line %ld: a face refers to vertex 0 (indices count from 1)", line_no);
            return buf;
        }
        if (v < 0 && -v > vertices) {
            std::snprintf(buf, sizeof buf, "line %ld: a face refers to vertex %ld, %ld back, with %ld vertices before "
                          "the line", line_no, v, -v, vertices);
            return buf;
        }
        if (v > *max_pos) *max_pos = v, *max_line = line_no;
    }
    return std::string();
}

// A line's statement checked before its content: empty, or what is wrong. The first word must
// be an OBJ statement (the reader skips any other line without a word, so a damaged or wrong
// file would pass as a mesh of fewer faces); bytes no text holds mean another kind of file. The
// message is made only for a wrong line (this runs on every line of the file).
std::string check_statement(const std::string &line, long line_no)
{
    static const char *const known[] = {"v", "vt", "vn", "vp", "vw", "f", "l", "p", "g", "o", "s", "t",
                                        "usemtl", "mtllib", "cstype", "deg", "bmat", "step", "curv", "curv2",
                                        "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "mg",
                                        "bevel", "c_interp", "d_interp", "lod", "maplib", "usemap",
                                        "shadow_obj", "trace_obj", "ctech", "stech", "call", "csh"};
    static const char *const space = " \t\n\v\f\r";
    char buf[160];
    if (line_no == 1 && !line.compare(0, 3, "\xEF\xBB\xBF")) { // the reader would drop the line's statement
        if (line.find_first_not_of(" \t\r", 3) == std::string::npos) return std::string(); // a comment's line
        return "line 1 starts with a UTF-8 byte-order mark, which the OBJ reader takes for a word: save the file "
               "without it";
    }
    bool binary = false;
    for (const unsigned char c : line)
        if ((c < 0x20 && c != '\t' && c != '\r' && c != '\v' && c != '\f') || c == 0x7f) binary = true;
    const size_t b = line.find_first_not_of(space);
    if (!binary && b == std::string::npos) return std::string();
    const size_t n = binary ? 0 : std::min(line.find_first_of(space, b), line.size()) - b;
    for (const char *k : known)
        if (!binary && !line.compare(b, n, k)) return std::string();
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)line[b + i] >= 0x80) binary = true;
    if (binary)
        std::snprintf(buf, sizeof buf, "not an OBJ file (line %ld holds binary data%s)", line_no,
                      line.compare(0, 4, "\x89PNG") ? "" : ": a PNG image");
    else
        std::snprintf(buf, sizeof buf, "line %ld: '%.40s' is not an OBJ statement (v, vt, vn, f, l, p, g, o, s, "
                      "usemtl, mtllib, ...)", line_no, line.substr(b, n).c_str());
    return buf;
}

// The pass before the reader: the triangles the faces will give (every "f" line of n
// vertices gives n - 2; stops counting past stop_after), and the first line that is wrong:
// a vertex whose coordinates are not finite numbers (the reader would take "nan" or "inf"
// as they are or as zero) or a face vertex that is not a vertex of the file (the reader's
// own message for those names neither the index nor the line). -1 if the file cannot be
// opened (why says why). *trailing: whether a comment follows a line's content.
long scan(const char *path, long stop_after, std::string *why, bool *trailing)
{
    struct stat sb;
    if (stat(path, &sb) != 0) return *why = std::strerror(errno), -1;
    if (S_ISDIR(sb.st_mode)) return *why = "it is a folder, not a file", -1;
    std::ifstream f(path, std::ios::binary);
    if (!f) return *why = std::strerror(errno ? errno : EIO), -1;
    long tris = 0, line_no = 0, vertices = 0, max_pos = 0, max_line = 0;
    std::string line;
    while (std::getline(f, line) && tris <= stop_after && why->empty()) {
        line_no++;
        const size_t hash = line.find('#');
        if (hash != std::string::npos) {
            *trailing = *trailing || line.find_first_not_of(" \t") < hash;
            line.erase(hash);
        }
        if (!line.empty() && line.back() == '\x1a' && f.peek() == EOF) line.pop_back(); // a DOS end of file
        const size_t cr = line.find('\r');
        if (cr != std::string::npos && cr + 1 < line.size()) { // the reader would split it where this pass cannot
            char buf[160];
            std::snprintf(buf, sizeof buf, "line %ld: a carriage return without a line feed (old Mac line endings): "
                          "save the file with LF or CRLF line endings", line_no);
            *why = buf;
            break;
        }
        line.erase(0, line.find_first_not_of(" \t")); // an indented statement is one
        if (!(*why = check_statement(line, line_no)).empty()) break;
        if (line.size() < 1 || (line.size() > 1 && line[1] != ' ' && line[1] != '\t' && line[1] != '\r')) continue;
        if (line[0] == 'f') {
            std::istringstream in(line.substr(1));
            std::string tok;
            long n = 0;
            while (in >> tok) n++;
            if (n > 2) tris += n - 2;
            *why = check_face(line.substr(1), line_no, vertices, &max_pos, &max_line);
            if (why->empty() && n < 3) {
                char buf[128];
                std::snprintf(buf, sizeof buf, "line %ld: a face needs 3 or more vertices, this one has %ld (a "
                              "truncated file?)", line_no, n);
                *why = buf;
            }
        } else if (line[0] == 'v') {
            vertices++;
            const char *p = line.c_str() + 1;
            for (int k = 0; k < 3; k++) {
                char *end = nullptr;
                const double x = std::strtod(p, &end);
                bool hex = false; // strtod reads 0x10 as 16, the reader as 0
                for (const char *c = p; c < end; c++) hex = hex || *c == 'x' || *c == 'X';
                if (end == p || !std::isfinite(x) || hex) {
                    char buf[112];
                    std::snprintf(buf, sizeof buf, "line %ld: a vertex needs three finite decimal numbers", line_no);
                    *why = buf;
                    break;
                }
                p = end;
            }
        }
    }
    if (why->empty() && max_pos > vertices && tris <= stop_after) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "line %ld: a face refers to vertex %ld, the file has %ld", max_line, max_pos,
                      vertices);
        *why = buf;
    }
    return tris;
}

// The file's text without its comments, line for line (false if it cannot be read again).
bool uncommented(const char *path, std::string *text)
{
    std::ifstream f(path, std::ios::binary);
    std::string line;
    while (f && std::getline(f, line)) text->append(line, 0, line.find('#')).push_back('\n');
    return f.eof();
}

int read_obj(const char *path, long max_triangles, float **positions, long *nv, uint32_t **indices, long *nt,
             char *msg, size_t cap)
{
    std::string why;
    bool trailing = false;
    const long counted = scan(path, max_triangles, &why, &trailing);
    if (counted < 0) {
        if (cap) std::snprintf(msg, cap, "cannot open: %s", why.c_str());
        return ATMOS__OBJ_E_IO;
    }
    if (counted > max_triangles) {
        if (cap) std::snprintf(msg, cap, "more than %ld triangles (the bound)", max_triangles);
        return ATMOS__OBJ_E_LIMIT;
    }
    if (!why.empty()) return say(msg, cap, why.c_str()), ATMOS__OBJ_E_FORMAT;
    tinyobj::ObjReaderConfig config;
    config.triangulate = false; // fanned here, so that the count matches the one above
    config.vertex_color = false;
    config.mtl_search_path = "";
    tinyobj::ObjReader reader;
    // A file with a comment after a line's content is parsed from its text without comments
    // (two copies of the text at the peak, this one and the reader's stream's; no material
    // file read, only the geometry is used); any other from the file itself.
    std::string text;
    if (trailing && !uncommented(path, &text)) {
        if (cap) std::snprintf(msg, cap, "cannot read the file a second time (it changed or went away while read)");
        return ATMOS__OBJ_E_IO;
    }
    if (!(trailing ? reader.ParseFromString(text, std::string(), config) : reader.ParseFromFile(path, config))) {
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
