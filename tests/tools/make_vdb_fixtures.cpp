// Writes the small OpenVDB and NanoVDB files the reader tests check against
// (tests/unit/test_volume_readers.c). Built only when OpenVDB is found; run by
// ctest as a FIXTURES_SETUP test. Usage: make_vdb_fixtures OUTPUT_DIR
//
// Every value is a formula of its index so the C test can check voxels exactly:
//   density(i, j, k) = 1 + (i + 2) + 10 j + 100 k   for i in -2..1, j in 0..2, k in 0..1
//   plus one active tile at the lower-internal-node level (8^3 voxels) with corner
//   (16, 0, 0) and value 2.5, and one inactive voxel (20, 20, 20) = 7 that must not load.
// Transform of small.vdb: voxel size 0.5, translation (10, 20, 30).
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <openvdb/math/Transform.h>

#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

namespace {

openvdb::FloatGrid::Ptr make_density(openvdb::math::Transform::Ptr xf)
{
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(xf);
    auto acc = grid->getAccessor();
    for (int k = 0; k <= 1; k++)
        for (int j = 0; j <= 2; j++)
            for (int i = -2; i <= 1; i++)
                acc.setValue(openvdb::Coord(i, j, k), float(1 + (i + 2) + 10 * j + 100 * k));
    // Level 1 = a tile of a lower internal node: 8^3 voxels.
    grid->tree().addTile(1, openvdb::Coord(16, 0, 0), 2.5f, true);
    acc.setValueOff(openvdb::Coord(20, 20, 20), 7.0f);
    return grid;
}

void write_vdb(const std::string &path, openvdb::GridPtrVec grids, uint32_t compression)
{
    openvdb::io::File file(path);
    file.setCompression(compression);
    file.write(grids);
    file.close();
}

} // namespace

int main(int argc, char **argv)
{
    if (argc != 2) {
        std::fprintf(stderr, "usage: make_vdb_fixtures OUTPUT_DIR\n");
        return 2;
    }
    const std::string dir = argv[1];
    try {
        openvdb::initialize();
        auto xf = openvdb::math::Transform::createLinearTransform(0.5);
        xf->postTranslate(openvdb::Vec3d(10, 20, 30));
        auto density = make_density(xf);

        auto temperature = openvdb::FloatGrid::create(0.0f);
        temperature->setName("temperature");
        temperature->setTransform(xf);
        temperature->tree().setValue(openvdb::Coord(0, 0, 0), 300.0f);

        auto vel = openvdb::Vec3SGrid::create();
        vel->setName("vel");
        vel->setTransform(xf);
        vel->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 0, 0));

        openvdb::GridPtrVec all{density, temperature, vel};
        write_vdb(dir + "/small.vdb", all, openvdb::io::COMPRESS_NONE);
        write_vdb(dir + "/small_zip.vdb", all, openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK);
        write_vdb(dir + "/small_blosc.vdb", all, openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
        write_vdb(dir + "/vel_only.vdb", openvdb::GridPtrVec{vel}, openvdb::io::COMPRESS_NONE);

        // 90 degrees about +y (index x -> world -z, index z -> world +x), voxel 2,
        // translation (1, 2, 3). OpenVDB multiplies row vectors: world = idx * M.
        openvdb::Mat4d m = openvdb::Mat4d::identity();
        m.setToRotation(openvdb::math::Y_AXIS, M_PI / 2);
        m.preScale(openvdb::Vec3d(2, 2, 2));
        m.setTranslation(openvdb::Vec3d(1, 2, 3));
        auto rot = make_density(openvdb::math::Transform::createLinearTransform(m));
        write_vdb(dir + "/rotated.vdb", openvdb::GridPtrVec{rot}, openvdb::io::COMPRESS_NONE);

        openvdb::Mat4d s = openvdb::Mat4d::identity();
        s.preScale(openvdb::Vec3d(1, 2, 1));
        auto nonuni = make_density(openvdb::math::Transform::createLinearTransform(s));
        write_vdb(dir + "/nonuniform.vdb", openvdb::GridPtrVec{nonuni}, openvdb::io::COMPRESS_NONE);

        auto neg = make_density(xf);
        neg->tree().setValue(openvdb::Coord(5, 5, 5), -1.0f);
        write_vdb(dir + "/negative.vdb", openvdb::GridPtrVec{neg}, openvdb::io::COMPRESS_NONE);

        auto fr = make_density(openvdb::math::Transform::createFrustumTransform(
            openvdb::BBoxd(openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(10, 10, 10)), 0.5, 10.0, 1.0));
        write_vdb(dir + "/frustum.vdb", openvdb::GridPtrVec{fr}, openvdb::io::COMPRESS_NONE);

        // Two float grids with the same name (OpenVDB gives them unique names in the file).
        auto c1 = openvdb::FloatGrid::create(0.0f), c2 = openvdb::FloatGrid::create(0.0f);
        c1->setName("cloud");
        c2->setName("cloud");
        c1->setTransform(xf);
        c2->setTransform(xf);
        c1->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
        c2->tree().setValue(openvdb::Coord(1, 0, 0), 2.0f);
        write_vdb(dir + "/dup_names.vdb", openvdb::GridPtrVec{c1, c2}, openvdb::io::COMPRESS_NONE);

        // NanoVDB: the same density, alone and with a second grid; rotated.
        nanovdb::io::writeGrid(dir + "/small.nvdb", nanovdb::openToNanoVDB(*density));
        std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
        handles.push_back(nanovdb::openToNanoVDB(*temperature));
        handles.push_back(nanovdb::openToNanoVDB(*density));
        nanovdb::io::writeGrids<nanovdb::HostBuffer, std::vector>(dir + "/two.nvdb", handles);
        nanovdb::io::writeGrid(dir + "/rotated.nvdb", nanovdb::openToNanoVDB(*rot));
        nanovdb::io::writeGrid(dir + "/nonuniform.nvdb", nanovdb::openToNanoVDB(*nonuni));
        nanovdb::io::writeGrid(dir + "/negative.nvdb", nanovdb::openToNanoVDB(*neg));
        nanovdb::io::writeGrid(dir + "/fp16.nvdb",
                               nanovdb::openToNanoVDB<nanovdb::HostBuffer, openvdb::FloatTree, nanovdb::Fp16>(*density));
    } catch (const std::exception &e) {
        std::fprintf(stderr, "make_vdb_fixtures: %s\n", e.what());
        return 1;
    }
    std::printf("make_vdb_fixtures: wrote fixtures to %s\n", dir.c_str());
    return 0;
}
