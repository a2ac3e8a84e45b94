#include "blend/ExtendedDistance.h"

#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/Prune.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <memory>
#include <stdexcept>
#include <utility>

namespace volmorph::detail {

using openvdb::Coord;
using openvdb::CoordBBox;

ExtendedDistance::ExtendedDistance(openvdb::FloatGrid::ConstPtr band, const CoordBBox& box)
    : mBand(std::move(band))
{
    mVoxel = float(mBand->voxelSize()[0]);
    if (box.empty()) return;
    auto floorDiv = [](int v) { return v >= 0 ? v / kCoarse : -((-v + kCoarse - 1) / kCoarse); };
    const CoordBBox coarse(
        Coord(floorDiv(box.min().x()), floorDiv(box.min().y()), floorDiv(box.min().z())),
        Coord(floorDiv(box.max().x()) + 1, floorDiv(box.max().y()) + 1,
              floorDiv(box.max().z()) + 1));
    const openvdb::FloatGrid::Ptr lattice = seeds(coarse);
    openvdb::BoolGrid mask(false);
    mask.setTransform(lattice->transform().copy());
    mask.sparseFill(coarse, true, true);
    openvdb::FloatGrid::Ptr wide =
        openvdb::tools::maskSdf(*lattice, mask, /*ignoreActiveTiles*/ false, /*nIter*/ 1);
    if (!wide)
        throw std::runtime_error(
            "sdf blend: fast sweeping could not extend a signed distance field");
    makeDense(*wide, coarse);
    measureErrors();
}

openvdb::FloatGrid::Ptr ExtendedDistance::seeds(const CoordBBox& coarse) const
{
    const float background = mBand->background();
    openvdb::FloatGrid::Ptr seeds = openvdb::FloatGrid::create(background);
    seeds->setTransform(openvdb::math::Transform::createLinearTransform(kCoarse * double(mVoxel)));
    seeds->setGridClass(openvdb::GRID_LEVEL_SET);
    // Lattice values, in parallel over slabs of x one leaf thick; each slab fills its own tree,
    // and the slabs' leaves are disjoint, so merging moves nodes.
    const int x0 = coarse.min().x() & ~7, slabCount = (coarse.max().x() - x0) / 8 + 1;
    std::vector<openvdb::FloatTree::Ptr> slabs(static_cast<size_t>(slabCount));
    tbb::parallel_for(tbb::blocked_range<int>(0, slabCount), [&](const tbb::blocked_range<int>& r) {
        auto fine = mBand->getConstAccessor();
        for (int i = r.begin(); i != r.end(); ++i) {
            auto tree = std::make_shared<openvdb::FloatTree>(background);
            openvdb::tree::ValueAccessor<openvdb::FloatTree> acc(*tree);
            for (int x = std::max(x0 + 8 * i, coarse.min().x());
                 x <= std::min(x0 + 8 * i + 7, coarse.max().x()); ++x)
                for (int y = coarse.min().y(); y <= coarse.max().y(); ++y)
                    for (int z = coarse.min().z(); z <= coarse.max().z(); ++z) {
                        const Coord fineXyz(x * kCoarse, y * kCoarse, z * kCoarse);
                        float value;
                        if (fine.probeValue(fineXyz, value))
                            acc.setValueOn(Coord(x, y, z), value);
                        else if (value < 0.0f)
                            acc.setValueOff(Coord(x, y, z), -background);
                    }
            slabs[size_t(i)] = tree;
        }
    });
    for (const auto& slab : slabs) seeds->tree().merge(*slab, openvdb::MERGE_NODES);
    openvdb::tools::pruneLevelSet(seeds->tree());
    return seeds;
}

void ExtendedDistance::makeDense(const openvdb::FloatGrid& wide, const CoordBBox& coarse)
{
    DenseField& d = mCoarse;
    d.origin = coarse.min();
    d.dim = coarse.dim();
    d.values.resize(size_t(d.dim.x()) * d.dim.y() * d.dim.z());
    tbb::parallel_for(tbb::blocked_range<int>(0, d.dim.x()), [&](const tbb::blocked_range<int>& r) {
        auto acc = wide.getConstAccessor();
        for (int x = r.begin(); x != r.end(); ++x)
            for (int y = 0; y < d.dim.y(); ++y)
                for (int z = 0; z < d.dim.z(); ++z)
                    d.values[d.index(x, y, z)] = acc.getValue(d.origin.offsetBy(x, y, z));
    });
}

void ExtendedDistance::measureErrors()
{
    // How far the coarse field strays from the band where both are defined (voxels): over the
    // whole band, so that a point whose coarse value is beyond kFar + that needs no fine read; and
    // where the coarse field is used (|band| >= kNear), which bounds how much the extended field
    // can change beyond a distance's 1 per voxel.
    std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
    mBand->tree().getNodes(leaves);
    using Errors = std::pair<float, float>;
    const Errors errors = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, leaves.size()), Errors(0.0f, 0.0f),
        [&](const tbb::blocked_range<size_t>& r, Errors worst) {
            for (size_t i = r.begin(); i != r.end(); ++i)
                for (auto it = leaves[i]->cbeginValueOn(); it; ++it) {
                    const float e = std::abs(coarseAt(it.getCoord().asVec3d()) - *it);
                    worst.first = std::max(worst.first, e);
                    if (std::abs(*it) >= kNear * mVoxel) worst.second = std::max(worst.second, e);
                }
            return worst;
        },
        [](Errors a, Errors b) {
            return Errors(std::max(a.first, b.first), std::max(a.second, b.second));
        });
    mCoarseError = errors.first / mVoxel;
    mTransitionError = errors.second / mVoxel;
}

} // namespace volmorph::detail
