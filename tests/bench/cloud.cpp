// A procedural cumulus cloud as a fog .vdb with a temperature grid (issue 33's second scene against
// Cycles; scenes/volumes/cloud.vdb), from the test data generator
// (tests/unit/support/ProceduralCloud.h). Deterministic: the same arguments give the same file.
// usage: volmorph_bench_cloud OUT.vdb [VOXEL_SIZE (world units, default 0.01)]
#include "support/ProceduralCloud.h"

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s OUT.vdb [VOXEL_SIZE]\n", argv[0]);
        return 2;
    }
    const double voxel = argc > 2 ? std::atof(argv[2]) : 0.01;
    if (!(voxel > 0.0)) {
        std::fprintf(stderr, "%s: the voxel size must be a positive number\n", argv[0]);
        return 2;
    }
    openvdb::initialize();
    openvdb::FloatGrid::Ptr temperature;
    const openvdb::FloatGrid::Ptr grid = volmorph::test::cloud::make(
        openvdb::math::Transform::createLinearTransform(voxel), &temperature);
    openvdb::io::File(argv[1]).write({grid, temperature});
    std::printf("%s: %zu active voxels, voxel %g\n", argv[1], size_t(grid->activeVoxelCount()),
                voxel);
    return 0;
}
