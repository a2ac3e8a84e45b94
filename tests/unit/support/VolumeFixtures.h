// Fixtures of the volume input tests: the test data generator's cloud written as .vdb files, and a
// comparison of two fogs.
#pragma once

#include "support/ProceduralCloud.h"
#include "support/WarpFixtures.h"

#include <filesystem>
#include <unistd.h>

namespace volmorph::test {
namespace cloud {

/// The test data generator's cloud, written once per test binary: on a 0.04 lattice (`cloud.vdb`)
/// and on a 0.03 lattice turned 30 degrees about y and 20 about x (`cloud_rotated.vdb`), each
/// with its temperature grid.
struct CloudFiles {
    std::filesystem::path dir, plain, rotated;
    CloudFiles()
    {
        dir = std::filesystem::temp_directory_path() /
              ("volmorph-volume-test-" + std::to_string(getpid()));
        std::filesystem::create_directories(dir);
        plain = dir / "cloud.vdb";
        rotated = dir / "cloud_rotated.vdb";
        write(plain, openvdb::math::Transform::createLinearTransform(0.04));
        openvdb::math::Transform::Ptr turned =
            openvdb::math::Transform::createLinearTransform(0.03);
        turned->postRotate(30.0 * M_PI / 180.0, openvdb::math::Y_AXIS);
        turned->postRotate(20.0 * M_PI / 180.0, openvdb::math::X_AXIS);
        write(rotated, turned);
    }
    ~CloudFiles() { std::filesystem::remove_all(dir); }

    static void write(const std::filesystem::path& path, const openvdb::math::Transform::Ptr& xform)
    {
        openvdb::FloatGrid::Ptr temperature;
        const openvdb::FloatGrid::Ptr density = make(xform, &temperature);
        openvdb::io::File(path.string()).write({density, temperature});
    }
};

inline const CloudFiles& clouds()
{
    openvdb::initialize();
    static const CloudFiles files;
    return files;
}

} // namespace cloud

/// sum |a - b| / sum a over the union of the active voxels of two float grids on one transform.
inline double relativeL1(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b)
{
    double diff = 0.0, mass = 0.0;
    auto aa = a.getConstAccessor(), ba = b.getConstAccessor();
    for (auto it = a.cbeginValueOn(); it; ++it)
        for (auto c = it.getBoundingBox().begin(); c; ++c) {
            diff += std::abs(double(aa.getValue(*c)) - double(ba.getValue(*c)));
            mass += double(aa.getValue(*c));
        }
    for (auto it = b.cbeginValueOn(); it; ++it)
        for (auto c = it.getBoundingBox().begin(); c; ++c)
            if (!aa.isValueOn(*c)) diff += std::abs(double(ba.getValue(*c)));
    return diff / mass;
}

} // namespace volmorph::test
