// Issue 38: does an in-between at a fine voxel size agree with the same frame at a coarser one?
// Reads the `sdf` grid of two .vdb files (frames `volmorph morph` wrote) and prints
//   - the symmetric Hausdorff distance between their zero level sets, in the first file's voxels:
//     each grid's zero crossings (between neighbouring voxels, linearly placed) measured with the
//     other grid's distance, trilinearly (exact enough within its narrow band, which at 3 voxels
//     half-width covers more than the 1 voxel the issue allows; crossings where it reads its
//     background are counted as beyond the band), with where the worst lies and how many
//     crossings are over 1 voxel;
//   - the IoU of their interiors, sdf < 0, at the first file's voxel centres over both boxes.
//
// usage: volmorph_bench_surfaces COARSE.vdb FINE.vdb
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace {

using openvdb::Coord;
using openvdb::FloatGrid;
using openvdb::Vec3d;

FloatGrid::Ptr readSdf(const std::string& path)
{
    openvdb::io::File file(path);
    file.open();
    for (const char* name : {"sdf", "surface"})
        if (file.hasGrid(name)) return openvdb::gridPtrCast<FloatGrid>(file.readGrid(name));
    throw std::runtime_error(path + ": no sdf grid");
}

struct Crossings {
    double worst = 0.0; ///< the largest |distance in the other grid| (world units)
    Vec3d where{0.0};   ///< at this world point
    size_t count = 0;   ///< crossings
    size_t over = 0;    ///< farther than `limit`
    size_t beyond = 0;  ///< where the other grid reads its band's background (at least that far)
};

/// `grid`'s zero crossings measured with `other`'s distance.
Crossings farthestCrossing(const FloatGrid& grid, const FloatGrid& other, double limit)
{
    const float background = std::abs(other.background());
    tbb::combinable<Crossings> found;
    openvdb::tree::LeafManager<const openvdb::FloatTree> leaves(grid.tree());
    leaves.foreach ([&](const openvdb::FloatTree::LeafNodeType& leaf, size_t) {
        auto acc = grid.getConstAccessor();
        openvdb::tools::GridSampler<FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sample(
            other.getConstAccessor(), other.transform());
        for (auto it = leaf.cbeginValueOn(); it; ++it) {
            const Coord c = it.getCoord();
            const float a = *it;
            for (int axis = 0; axis < 3; ++axis) {
                Coord n = c;
                n[axis] += 1;
                const float b = acc.getValue(n);
                if ((a < 0.0f) == (b < 0.0f)) continue;
                Vec3d p = c.asVec3d();
                p[axis] += double(a) / double(a - b);
                const Vec3d w = grid.indexToWorld(p);
                const double d = std::abs(sample.wsSample(w));
                Crossings& f = found.local();
                ++f.count;
                f.over += d > limit;
                f.beyond += d >= background * 0.999;
                if (d > f.worst) {
                    f.worst = d;
                    f.where = w;
                }
            }
        }
    });
    return found.combine([](Crossings a, const Crossings& b) {
        if (b.worst > a.worst) {
            a.worst = b.worst;
            a.where = b.where;
        }
        a.count += b.count;
        a.over += b.over;
        a.beyond += b.beyond;
        return a;
    });
}

/// IoU of the interiors (sdf < 0) at `grid`'s voxel centres over both grids' active boxes.
double interiorIoU(const FloatGrid& grid, const FloatGrid& other)
{
    openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    const openvdb::CoordBBox ob = other.evalActiveVoxelBoundingBox();
    box.expand(grid.transform().worldToIndexCellCentered(other.indexToWorld(ob.min())));
    box.expand(grid.transform().worldToIndexCellCentered(other.indexToWorld(ob.max())));
    tbb::combinable<std::pair<size_t, size_t>> counts(
        [] { return std::make_pair(size_t(0), size_t(0)); });
    tbb::parallel_for(
        tbb::blocked_range<int>(box.min().x(), box.max().x() + 1),
        [&](const tbb::blocked_range<int>& xs) {
            auto acc = grid.getConstAccessor();
            openvdb::tools::GridSampler<FloatGrid::ConstAccessor, openvdb::tools::BoxSampler>
                sample(other.getConstAccessor(), other.transform());
            auto& [both, either] = counts.local();
            for (int x = xs.begin(); x != xs.end(); ++x)
                for (int y = box.min().y(); y <= box.max().y(); ++y)
                    for (int z = box.min().z(); z <= box.max().z(); ++z) {
                        const Coord c(x, y, z);
                        const bool a = acc.getValue(c) < 0.0f;
                        const bool b = sample.wsSample(grid.indexToWorld(c)) < 0.0;
                        both += a && b;
                        either += a || b;
                    }
        });
    const auto total = counts.combine(
        [](auto p, auto q) { return std::make_pair(p.first + q.first, p.second + q.second); });
    return total.second ? double(total.first) / double(total.second) : 1.0;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s COARSE.vdb FINE.vdb\n", argv[0]);
        return 2;
    }
    openvdb::initialize();
    try {
        const FloatGrid::Ptr coarse = readSdf(argv[1]), fine = readSdf(argv[2]);
        const double voxel = coarse->voxelSize()[0];
        const Crossings a = farthestCrossing(*coarse, *fine, voxel);
        const Crossings b = farthestCrossing(*fine, *coarse, voxel);
        std::printf("Hausdorff distance: %.3f coarse voxels\n", std::max(a.worst, b.worst) / voxel);
        for (const auto& [name, c] :
             {std::make_pair("coarse -> fine", a), std::make_pair("fine -> coarse", b)})
            std::printf("  %s: %.3f voxels at (%.4f, %.4f, %.4f); %zu of %zu crossings over 1 "
                        "voxel, %zu beyond the other's band\n",
                        name, c.worst / voxel, c.where.x(), c.where.y(), c.where.z(), c.over,
                        c.count, c.beyond);
        std::printf("IoU of the interiors: %.5f\n", interiorIoU(*coarse, *fine));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
