// The OpenVDB shim, built as the module libatmos_openvdb.so (see openvdb_shim.h). OpenVDB does the
// parsing, decompression (zip, blosc) and tree walking; this file only copies what
// atmos needs into plain C structures. Every entry point catches everything: an
// exception escaping into C would be undefined behaviour.
#include "volume/openvdb_shim.h"

// libatmos builds with -fvisibility=hidden, but OpenVDB's headers must see
// default visibility: its registries and type-name singletons live in template
// statics shared with libopenvdb.so, and hidden copies of them in a PIC object
// crash openvdb::initialize() (null registry). Our own entry points stay hidden but one.
#pragma GCC visibility push(default)
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#pragma GCC visibility pop

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <mutex>
#include <new>
#include <string>
#include <vector>

struct atmos__vdb {
    openvdb::io::File *file = nullptr;
    std::vector<std::string> names;
    std::vector<std::string> types;
    std::vector<openvdb::FloatGrid::Ptr> grids; // loaded on demand
};

namespace {

void set_msg(char *msg, size_t cap, const std::string &s)
{
    if (msg && cap) std::snprintf(msg, cap, "%s", s.c_str());
}

// openvdb::initialize() registers the grid and map types; it is idempotent but not
// documented as thread-safe, hence the once flag.
void init_once()
{
    static std::once_flag flag;
    std::call_once(flag, [] { openvdb::initialize(); });
}

// Exceptions thrown by the library become return codes; which code depends on the
// exception's class (an IoError is a file problem, everything else a format one).
int from_exception(char *msg, size_t cap, const char *what_doing)
{
    try {
        throw;
    } catch (const openvdb::IoError &e) {
        set_msg(msg, cap, std::string(what_doing) + ": " + e.what());
        return ATMOS__VDB_E_FORMAT;
    } catch (const std::bad_alloc &) {
        set_msg(msg, cap, std::string(what_doing) + ": out of memory");
        return ATMOS__VDB_E_NOMEM;
    } catch (const std::exception &e) {
        set_msg(msg, cap, std::string(what_doing) + ": " + e.what());
        return ATMOS__VDB_E_FORMAT;
    } catch (...) {
        set_msg(msg, cap, std::string(what_doing) + ": unknown error");
        return ATMOS__VDB_E_FORMAT;
    }
}

// Compares the loaded tree with the file_voxel_count and file_bbox_min/max metadata the
// library wrote with the grid (absent in files from other writers: nothing to compare).
const char *stats_disagree(const openvdb::GridBase &grid, const atmos__vdb_grid_stats &st)
{
    static thread_local char why[160];
    auto count = grid.getMetadata<openvdb::Int64Metadata>("file_voxel_count");
    if (count && (uint64_t)count->value() != st.active_voxels) {
        std::snprintf(why, sizeof why, "%llu active voxels, the file's own count says %lld",
                      (unsigned long long)st.active_voxels, (long long)count->value());
        return why;
    }
    auto lo = grid.getMetadata<openvdb::Vec3IMetadata>("file_bbox_min");
    auto hi = grid.getMetadata<openvdb::Vec3IMetadata>("file_bbox_max");
    if (lo && hi && !st.empty) {
        for (int a = 0; a < 3; a++)
            if (lo->value()[a] != st.bbox_min[a] || hi->value()[a] != st.bbox_max[a]) {
                std::snprintf(why, sizeof why, "active voxels span [%d %d %d]..[%d %d %d], the file's own box is "
                              "[%d %d %d]..[%d %d %d]", st.bbox_min[0], st.bbox_min[1], st.bbox_min[2],
                              st.bbox_max[0], st.bbox_max[1], st.bbox_max[2], lo->value()[0], lo->value()[1],
                              lo->value()[2], hi->value()[0], hi->value()[1], hi->value()[2]);
                return why;
            }
    }
    return nullptr;
}

} // namespace

static void shim_close(atmos__vdb *f);

static int shim_open(const char *path, atmos__vdb **out, char *msg, size_t cap)
{
    *out = nullptr;
    atmos__vdb *f = nullptr;
    try {
        init_once();
        // Check readability ourselves: OpenVDB reports a missing file and a corrupt
        // one with the same exception class.
        std::FILE *probe = std::fopen(path, "rb");
        if (!probe) {
            set_msg(msg, cap, std::string("cannot open: ") + std::strerror(errno));
            return ATMOS__VDB_E_IO;
        }
        std::fclose(probe);
        f = new atmos__vdb;
        f->file = new openvdb::io::File(path);
        // Read through a stream rather than a memory map: a truncated file then
        // fails with an exception instead of a SIGBUS.
        f->file->open(false);
        for (auto it = f->file->beginName(); it != f->file->endName(); ++it) {
            f->names.push_back(it.gridName());
        }
        // Grid types come from the metadata only, so listing does not read voxels.
        openvdb::GridPtrVecPtr metas = f->file->readAllGridMetadata();
        // Both lists follow the file's descriptor map, so they match by position (grids
        // with the same name have unique names like "cloud[1]" but the same getName()).
        f->types.assign(f->names.size(), std::string());
        for (size_t i = 0; i < f->names.size() && i < metas->size(); i++) f->types[i] = (*metas)[i]->valueType();
        f->grids.resize(f->names.size());
        *out = f;
        return ATMOS__VDB_OK;
    } catch (...) {
        int rc = from_exception(msg, cap, "OpenVDB");
        shim_close(f);
        return rc;
    }
}

static void shim_close(atmos__vdb *f)
{
    if (!f) return;
    try {
        f->grids.clear();
        if (f->file) {
            if (f->file->isOpen()) f->file->close();
            delete f->file;
        }
        delete f;
    } catch (...) {
        // Closing cannot usefully fail; never let it throw into C.
    }
}

static int shim_grid_count(const atmos__vdb *f) { return f ? (int)f->names.size() : 0; }

static int shim_get_grid_info(const atmos__vdb *f, int index, atmos__vdb_grid_info *info)
{
    std::memset(info, 0, sizeof *info);
    if (!f || index < 0 || (size_t)index >= f->names.size()) return ATMOS__VDB_E_FORMAT;
    std::snprintf(info->name, sizeof info->name, "%s", f->names[index].c_str());
    std::snprintf(info->value_type, sizeof info->value_type, "%s", f->types[index].c_str());
    info->is_float = f->types[index] == openvdb::typeNameAsString<float>();
    return ATMOS__VDB_OK;
}

static int shim_load_grid(atmos__vdb *f, int index, atmos__vdb_grid_stats *st, char *msg, size_t cap)
{
    std::memset(st, 0, sizeof *st);
    if (!f || index < 0 || (size_t)index >= f->names.size()) {
        set_msg(msg, cap, "no such grid");
        return ATMOS__VDB_E_FORMAT;
    }
    try {
        openvdb::GridBase::Ptr base = f->file->readGrid(f->names[index]);
        openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
        if (!grid) {
            set_msg(msg, cap, "grid '" + f->names[index] + "' is of type " + base->valueType() + ", not float");
            return ATMOS__VDB_E_FORMAT;
        }
        const openvdb::FloatTree &tree = grid->tree();
        st->active_voxels = tree.activeVoxelCount();
        st->leaf_voxels = tree.activeLeafVoxelCount();
        st->active_tiles = tree.activeTileCount();
        openvdb::CoordBBox bbox;
        st->empty = !tree.evalActiveVoxelBoundingBox(bbox);
        for (int a = 0; a < 3; a++) {
            st->bbox_min[a] = st->empty ? 0 : bbox.min()[a];
            st->bbox_max[a] = st->empty ? -1 : bbox.max()[a];
        }
        bool first = true;
        for (auto it = tree.cbeginValueOn(); it; ++it) {
            const float v = *it;
            if (!std::isfinite(v) || v < 0.0f) {
                if (st->bad_values++ == 0) {
                    const openvdb::Coord c = it.getCoord();
                    for (int a = 0; a < 3; a++) st->bad_ijk[a] = c[a];
                    st->bad_value = v;
                }
                continue;
            }
            if (first || v < st->min) st->min = v;
            if (first || v > st->max) st->max = v;
            first = false;
        }
        const openvdb::math::Transform &xf = grid->transform();
        st->linear = xf.isLinear();
        std::snprintf(st->map_type, sizeof st->map_type, "%s", xf.mapType().c_str());
        if (st->linear) {
            const openvdb::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
            for (int r = 0; r < 4; r++)
                for (int c = 0; c < 4; c++) st->mat[r][c] = m(r, c);
        }
        // OpenVDB records how each grid was stored in the file as metadata.
        openvdb::Metadata::ConstPtr comp = grid->operator[]("file_compression");
        if (comp) {
            const std::string s = comp->str();
            st->compressed = s.find("zip") != std::string::npos || s.find("blosc") != std::string::npos;
        }
        // OpenVDB records each grid's active voxel count and bounding box as metadata when it
        // writes the file: a tree that disagrees was damaged (a flipped mask bit, say).
        if (const char *why = stats_disagree(*grid, *st)) {
            set_msg(msg, cap, "grid '" + f->names[index] + "': " + why + ": damaged file");
            return ATMOS__VDB_E_FORMAT;
        }
        f->grids[index] = grid;
        return ATMOS__VDB_OK;
    } catch (...) {
        return from_exception(msg, cap, ("OpenVDB: grid '" + f->names[index] + "'").c_str());
    }
}

static int shim_visit(atmos__vdb *f, int index, atmos__vdb_block_fn fn, void *user, char *msg, size_t cap)
{
    if (!f || index < 0 || (size_t)index >= f->grids.size() || !f->grids[index]) {
        set_msg(msg, cap, "grid not loaded");
        return ATMOS__VDB_E_FORMAT;
    }
    try {
        const openvdb::FloatTree &tree = f->grids[index]->tree();
        using Leaf = openvdb::FloatTree::LeafNodeType;
        const int D = Leaf::DIM; // 8
        std::vector<float> block((size_t)D * D * D);
        for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
            // OpenVDB stores a leaf z fastest (offset = x*64 + y*8 + z); atmos wants
            // x fastest, so transpose while zeroing the inactive voxels (whose
            // values are the background or garbage, not data).
            for (int x = 0; x < D; x++)
                for (int y = 0; y < D; y++)
                    for (int z = 0; z < D; z++) {
                        const openvdb::Index n = (openvdb::Index)((x * D + y) * D + z);
                        block[(size_t)x + (size_t)D * ((size_t)y + (size_t)D * z)] =
                            leaf->isValueOn(n) ? leaf->getValue(n) : 0.0f;
                    }
            const openvdb::Coord o = leaf->origin();
            const int origin[3] = {o.x(), o.y(), o.z()}, size[3] = {D, D, D};
            if (fn(user, origin, size, block.data(), 0.0f)) return ATMOS__VDB_E_STOPPED;
        }
        // Active tiles only: stop the value iterator above the leaf level.
        auto it = tree.cbeginValueOn();
        it.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
        for (; it; ++it) {
            if (!it.isTileValue()) continue;
            openvdb::CoordBBox b;
            it.getBoundingBox(b);
            const int origin[3] = {b.min().x(), b.min().y(), b.min().z()};
            const int size[3] = {b.dim().x(), b.dim().y(), b.dim().z()};
            if (fn(user, origin, size, nullptr, *it)) return ATMOS__VDB_E_STOPPED;
        }
        return ATMOS__VDB_OK;
    } catch (...) {
        return from_exception(msg, cap, ("OpenVDB: grid '" + f->names[index] + "'").c_str());
    }
}

// The module's one export (openvdb_shim.h): the table of the entry points above.
extern "C" __attribute__((visibility("default"))) const atmos__vdb_api *atmos_openvdb_module_v1(void)
{
    static const atmos__vdb_api api = {shim_open, shim_close, shim_grid_count, shim_get_grid_info,
                                       shim_load_grid, shim_visit};
    return &api;
}

// What it was built for (core/module.h): the library checks it before calling the entry.
extern "C" __attribute__((visibility("default"))) const atmos__module_stamp atmos_module_stamp;
const atmos__module_stamp atmos_module_stamp = ATMOS__VDB_MODULE_STAMP;
