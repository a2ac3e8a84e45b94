#include "blend/Islands.h"

#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tree/LeafManager.h>
#include <openvdb/util/Util.h>

#include <tbb/parallel_invoke.h>

#include <memory>
#include <vector>

namespace volmorph::detail {
namespace {

using Pieces = std::vector<openvdb::BoolTree::Ptr>;

/// The lattice points within `depth` of the origin.
int ballCount(int depth)
{
    int ball = 0;
    for (int x = -depth; x <= depth; ++x)
        for (int y = -depth; y <= depth; ++y)
            for (int z = -depth; z <= depth; ++z) ball += x * x + y * y + z * z <= depth * depth;
    return ball;
}

class Islands {
public:
    Islands(openvdb::FloatGrid& values, int minVoxels, float outside, int depth)
        : mValues(values), mAcc(values.getAccessor()), mMin(minVoxels), mOutside(outside),
          mDeepIsLarge(minVoxels <= ballCount(depth))
    {
    }

    size_t run()
    {
        // Both segmentations at once (each is partly serial); the exterior's again only when
        // removing islands changed the values it was taken from.
        Pieces islands, gaps;
        tbb::parallel_invoke([&] { islands = pieces(true); }, [&] { gaps = pieces(false); });
        size_t changed = 0;
        for (size_t i = mAnyDeep ? 0 : 1; i < islands.size(); ++i)
            if (islands[i]->activeVoxelCount() < openvdb::Index64(mMin) &&
                !(mAnyDeep && touchesDeep(*islands[i]))) {
                set(*islands[i], mOutside);
                ++changed;
            }
        if (changed > 0) gaps = pieces(false);
        for (const openvdb::BoolTree::Ptr& gap : gaps)
            if (gap->activeVoxelCount() < openvdb::Index64(mMin) && enclosed(*gap)) {
                set(*gap, -mOutside);
                ++changed;
            }
        return changed;
    }

private:
    /// The face-connected pieces, largest first, of the interior (negative values: every one, or
    /// the active ones) or of the exterior candidates (positive active values; the far exterior
    /// is background).
    Pieces pieces(bool negative)
    {
        openvdb::BoolTree::Ptr mask;
        if (negative && !mDeepIsLarge) {
            mask = openvdb::tools::sdfInteriorMask(mValues, 0.0f)->treePtr();
        } else {
            mask =
                std::make_shared<openvdb::BoolTree>(mValues.tree(), false, openvdb::TopologyCopy());
            openvdb::tree::LeafManager<openvdb::BoolTree> leaves(*mask);
            const openvdb::FloatGrid& values = mValues;
            leaves.foreach ([&values, negative](openvdb::BoolTree::LeafNodeType& leaf, size_t) {
                const auto* source = values.tree().probeConstLeaf(leaf.origin());
                if (!source) return;
                const float* v = source->buffer().data();
                openvdb::BoolTree::LeafNodeType::NodeMaskType sign; // on where negative
                for (openvdb::Index n = 0; n < openvdb::BoolTree::LeafNodeType::SIZE; ++n)
                    if (v[n] < 0.0f) sign.setOn(n);
                leaf.setValueMask(leaf.getValueMask() & (negative ? sign : !sign));
            });
            if (negative)
                for (auto it = mValues.tree().cbeginValueOff(); it && !mAnyDeep; ++it)
                    mAnyDeep = *it < 0.0f;
        }
        Pieces out;
        openvdb::tools::segmentActiveVoxels(*mask, out); // largest first
        return out;
    }

    void set(const openvdb::BoolTree& piece, float value)
    {
        for (auto it = piece.cbeginValueOn(); it; ++it)
            for (auto c = it.getBoundingBox().begin(); c; ++c) mAcc.setValue(*c, value);
    }

    bool touchesDeep(const openvdb::BoolTree& piece)
    {
        for (auto it = piece.cbeginValueOn(); it; ++it)
            for (int k = 0; k < 6; ++k) { // the face neighbours
                const openvdb::Coord n = it.getCoord() + openvdb::util::COORD_OFFSETS[k];
                if (!mAcc.isValueOn(n) && mAcc.getValue(n) < 0.0f) return true;
            }
        return false;
    }

    /// No face neighbour of the gap is positive and inactive (the far exterior).
    bool enclosed(const openvdb::BoolTree& gap)
    {
        for (auto it = gap.cbeginValueOn(); it; ++it)
            for (auto c = it.getBoundingBox().begin(); c; ++c)
                for (int k = 0; k < 6; ++k) {
                    const openvdb::Coord n = *c + openvdb::util::COORD_OFFSETS[k];
                    if (!(mAcc.isValueOn(n) || mAcc.getValue(n) < 0.0f)) return false;
                }
        return true;
    }

    openvdb::FloatGrid& mValues;
    openvdb::FloatGrid::Accessor mAcc;
    int mMin;
    float mOutside;
    bool mDeepIsLarge;
    bool mAnyDeep = false;
};

} // namespace

size_t dropIslands(openvdb::FloatGrid& values, int minVoxels, float outside, int depth)
{
    if (minVoxels <= 0) return 0;
    return Islands(values, minVoxels, outside, depth).run();
}

} // namespace volmorph::detail
