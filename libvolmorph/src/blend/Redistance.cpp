#include "blend/Redistance.h"

#include <volmorph/core/Math.h>
#include <volmorph/Voxelize.h>

#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

namespace volmorph::detail {
namespace {

using openvdb::Coord;
using FloatTree = openvdb::FloatTree;
using Leaf = FloatTree::LeafNodeType;

/// One leaf of the redistancing: reads the blend (the leaf's buffer and its neighbours'), writes
/// the distances into `out`, the band into `band`, and returns the leaf's fog.
class LeafRedistance {
public:
    LeafRedistance(const openvdb::FloatGrid& values, const RedistanceBands& bands, float ramp)
        : mAcc(values.getConstAccessor()), mBands(bands), mRamp(ramp),
          // Central differences as math::GradStencil takes them.
          mInv2dx(float(0.5 / values.voxelSize()[0]))
    {
    }

    std::unique_ptr<Leaf> operator()(const Leaf& leaf, float* out, Leaf::NodeMaskType& band)
    {
        const Coord origin = leaf.origin();
        // Per face (+x, -x, +y, -y, +z, -z): the neighbouring leaf's values.
        for (int f = 0; f < 6; ++f) {
            const int axis = f / 2, sign = f % 2 ? -1 : 1;
            Coord o = origin;
            o[axis] += 8 * sign;
            const Leaf* next = mAcc.probeConstLeaf(o);
            mAcross[f] = next ? next->buffer().data() : nullptr;
        }
        // Only voxels within the leaf's kept band can come within the width of the zero set.
        const float keep = mBands.keepAt(origin);
        const float width = mBands.width;
        const float* in = leaf.buffer().data();
        auto fog = std::make_unique<Leaf>(origin, 0.0f, false);
        for (openvdb::Index n = 0; n < Leaf::SIZE; ++n) {
            const float b = in[n];
            float dist = width;
            if (leaf.isValueOn(n) && std::abs(b) < keep) dist = distance(leaf, in, n, b);
            const float d = b < 0.0f ? -dist : dist;
            const bool on = dist < width;
            out[n] = d;
            band.set(n, on);
            const float density = fogOfLevelSet(d, on, mRamp);
            if (density > 0.0f) fog->setValueOn(n, density);
        }
        return fog;
    }

private:
    /// Voxel n's distance to the zero set (at most the width), from its six neighbours: read from
    /// the leaf's buffer, or from the buffer of the neighbouring leaf across that face, or, where
    /// there is none (a tile), through the accessor.
    float distance(const Leaf& leaf, const float* in, openvdb::Index n, float b)
    {
        // The step of the voxel index inside a leaf and across the face.
        constexpr int kStep[6] = {64, -64, 8, -8, 1, -1}, kWrap[6] = {-448, 448, -56, 56, -7, 7};
        const int ijk[3] = {int(n >> 6), int((n >> 3) & 7), int(n & 7)};
        float e[6]; // +x, -x, +y, -y, +z, -z
        for (int f = 0; f < 6; ++f) {
            const int c = ijk[f / 2];
            if (f % 2 ? c > 0 : c < 7)
                e[f] = in[int(n) + kStep[f]];
            else if (mAcross[f])
                e[f] = mAcross[f][int(n) + kWrap[f]];
            else {
                Coord q = leaf.origin().offsetBy(ijk[0], ijk[1], ijk[2]);
                q[f / 2] += f % 2 ? -1 : 1;
                e[f] = mAcc.getValue(q);
            }
        }
        const Vec3f gradient = Vec3f(e[0] - e[1], e[2] - e[3], e[4] - e[5]) * mInv2dx;
        const float g = gradient.length(); // world-space, 1 for a distance
        float dist = mBands.width;
        if (g > 1e-6f) dist = std::abs(b) / g;
        for (float v : e)
            if ((v < 0.0f) != (b < 0.0f))
                dist = std::min(dist, mBands.voxel * std::abs(b) / (std::abs(b) + std::abs(v)));
        return std::min(dist, mBands.width);
    }

    openvdb::FloatGrid::ConstAccessor mAcc;
    const RedistanceBands& mBands;
    float mRamp;
    float mInv2dx;
    const float* mAcross[6] = {};
};

/// Every leaf value is now in the band or +/- the width. Inactive tiles hold +/- the width already
/// (the grid was made so); active ones, if any, are deep inside or outside and become so too. The
/// tiles inside are the fog's interior tiles: they are looked for in each internal node's own
/// tile table, which is much cheaper than the tree's iterator.
void settleTiles(FloatTree& tree, FloatTree& fog, float width)
{
    auto active = tree.beginValueOn();
    active.setMaxDepth(active.getLeafDepth() - 1);
    for (; active; ++active) {
        active.setValue(*active < 0.0f ? -width : width);
        active.setValueOff();
    }
    auto insideTiles = [&fog](const auto& nodes) {
        for (const auto* node : nodes)
            for (auto it = node->cbeginValueAll(); it; ++it) // tiles, not children
                if (*it < 0.0f) fog.addTile(node->LEVEL, it.getCoord(), 1.0f, true);
    };
    std::vector<const FloatTree::RootNodeType::ChildNodeType*> upper;
    std::vector<const FloatTree::RootNodeType::ChildNodeType::ChildNodeType*> lower;
    tree.getNodes(upper);
    tree.getNodes(lower);
    insideTiles(upper);
    insideTiles(lower);
    for (auto it = tree.root().cbeginValueAll(); it; ++it)
        if (*it < 0.0f) fog.addTile(FloatTree::RootNodeType::LEVEL, it.getCoord(), 1.0f, true);
}

} // namespace

openvdb::FloatGrid::Ptr redistance(openvdb::FloatGrid& values, const RedistanceBands& bands,
                                   float rampWorld)
{
    openvdb::tree::LeafManager<FloatTree> leaves(values.tree(), 1);
    std::vector<Leaf::NodeMaskType> masks(leaves.leafCount());
    std::vector<std::unique_ptr<Leaf>> fogs(leaves.leafCount());
    // Only the aux buffers are written here, so every read sees the blend.
    leaves.foreach ([&](Leaf& leaf, size_t index) {
        LeafRedistance one(values, bands, rampWorld);
        fogs[index] = one(leaf, leaves.getBuffer(index, 1).data(), masks[index]);
    });
    leaves.swapLeafBuffer(1);
    leaves.foreach ([&masks](Leaf& leaf, size_t index) { leaf.setValueMask(masks[index]); });
    openvdb::FloatGrid::Ptr density = openvdb::FloatGrid::create(0.0f);
    FloatTree& fog = density->tree();
    for (auto& leaf : fogs) fog.addLeaf(leaf.release());
    FloatTree& tree = values.tree();
    if (!openvdb::math::isExactlyEqual(tree.background(), bands.width))
        throw std::logic_error("redistance: the grid's background must be the band's width");
    settleTiles(tree, fog, bands.width);
    openvdb::tools::prune(fog);
    openvdb::tools::pruneLevelSet(tree);
    return density;
}

} // namespace volmorph::detail
