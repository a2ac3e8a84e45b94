#include "blend/VelocityReach.h"

#include "blend/LeafApron.h"

#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>
#include <limits>

namespace volmorph::detail {

/// One layer: the voxels kept (active in `reach`, with their r in voxels), and the tree that holds
/// their corrections (null: none). The band, layer 0, has no reach tree: its voxels are the band
/// mask's and its r the velocity's own reach.
struct VelocityReach::Layer {
    std::unique_ptr<openvdb::FloatTree> reach;
    const openvdb::Vec3STree* corrections = nullptr;
    uint64_t kept = 0;
};

namespace {

using openvdb::Coord;
using openvdb::Index;

/// A read-only accessor that caches its path and is not registered with the tree (one per task).
template <typename TreeT>
using Accessor = openvdb::tree::ValueAccessor<const TreeT, false>;

/// What a voxel of the next layer reads of its 26 neighbours in the last one.
struct Neighbours {
    float reach = -std::numeric_limits<float>::infinity(); ///< their largest r
    Vec3f sum{0.0f};                                       ///< the sum of their corrections
    int count = 0;
};

/// The band as the first layer reads it: the voxels `visited` held before the candidates were
/// added, r their own reach, the correction theirs (none without a tree).
class BandSource {
public:
    BandSource(const openvdb::MaskTree& visited, const openvdb::MaskTree& candidates,
               const openvdb::Vec3STree& velocity, const openvdb::Vec3STree* corrections,
               float perSpeed)
        : mVisited(visited), mCandidates(candidates), mVelocity(velocity),
          mCorrections(corrections ? *corrections : velocity), mWithFixes(corrections != nullptr),
          mPerSpeed(perSpeed)
    {
    }
    bool bind(const Coord& origin)
    {
        mIn = mVisited.probeConstLeaf(origin);
        mFresh = mCandidates.probeConstLeaf(origin);
        mSpeed = mVelocity.probeConstLeaf(origin);
        mFix = mWithFixes ? mCorrections.probeConstLeaf(origin) : nullptr;
        return mIn && mSpeed;
    }
    bool at(Index n, float& r, Vec3f& fix) const
    {
        if (!mIn->isValueOn(n) || (mFresh && mFresh->isValueOn(n))) return false;
        r = mSpeed->getValue(n).length() * mPerSpeed;
        fix = mFix ? mFix->getValue(n) : Vec3f(0.0f);
        return true;
    }

private:
    Accessor<openvdb::MaskTree> mVisited, mCandidates;
    Accessor<openvdb::Vec3STree> mVelocity, mCorrections;
    bool mWithFixes;
    float mPerSpeed;
    const openvdb::MaskTree::LeafNodeType *mIn = nullptr, *mFresh = nullptr;
    const openvdb::Vec3STree::LeafNodeType *mSpeed = nullptr, *mFix = nullptr;
};

/// A grown layer as the next reads it: its kept voxels, r one less than theirs.
class LayerSource {
public:
    LayerSource(const openvdb::FloatTree& reach, const openvdb::Vec3STree* corrections)
        : mReach(reach), mCorrections(corrections), mFixes(corrections ? *corrections : mEmpty)
    {
    }
    bool bind(const Coord& origin)
    {
        mLeaf = mReach.probeConstLeaf(origin);
        mFix = mCorrections ? mFixes.probeConstLeaf(origin) : nullptr;
        return mLeaf != nullptr;
    }
    bool at(Index n, float& r, Vec3f& fix) const
    {
        if (!mLeaf->isValueOn(n)) return false;
        r = mLeaf->getValue(n) - 1.0f;
        fix = mFix ? mFix->getValue(n) : Vec3f(0.0f);
        return true;
    }

private:
    Accessor<openvdb::FloatTree> mReach;
    const openvdb::Vec3STree* mCorrections;
    inline static const openvdb::Vec3STree mEmpty{};
    Accessor<openvdb::Vec3STree> mFixes;
    const openvdb::FloatTree::LeafNodeType* mLeaf = nullptr;
    const openvdb::Vec3STree::LeafNodeType* mFix = nullptr;
};

/// The last layer around one leaf of the next, dense (LeafApron.h).
class Halo {
public:
    template <typename Source>
    void load(const Coord& origin, Source& source)
    {
        std::fill(std::begin(mKept), std::end(mKept), false);
        apron::gather(
            origin, [&](const Coord& leaf) { return source.bind(leaf); },
            [&](Index n, int i) { mKept[i] = source.at(n, mReach[i], mFix[i]); });
    }

    /// The neighbours of the leaf's voxel n, in the order x, y, z from -1 to 1.
    Neighbours around(Index n) const
    {
        const int centre = apron::index(n);
        Neighbours out;
        for (const int d : apron::neighbours()) {
            const int i = centre + d;
            if (!mKept[i]) continue;
            out.reach = std::max(out.reach, mReach[i]);
            out.sum += mFix[i];
            ++out.count;
        }
        return out;
    }

private:
    bool mKept[apron::kCount];
    float mReach[apron::kCount];
    Vec3f mFix[apron::kCount];
};

} // namespace

VelocityReach::Layer VelocityReach::next(openvdb::Vec3STree& velocity, openvdb::MaskTree& visited,
                                         const Layer& last) const
{
    using namespace openvdb;
    const bool fromBand = !last.reach;
    // The candidates: the last layer's kept voxels' neighbours that no layer has had yet.
    MaskTree candidates(fromBand ? visited : MaskTree(*last.reach, false, TopologyCopy()));
    tools::dilateActiveValues(candidates, 1, tools::NN_FACE_EDGE_VERTEX, tools::IGNORE_TILES);
    candidates.topologyDifference(visited);
    tools::pruneInactive(candidates); // leaves that only the kept voxels' neighbours had
    visited.topologyUnion(candidates);
    velocity.topologyUnion(candidates); // no leaf is made while the layer is written

    Layer out;
    out.reach = std::make_unique<FloatTree>(candidates, 0.0f, TopologyCopy());
    out.corrections = last.corrections ? &velocity : nullptr;
    const float perSpeed = float(mSeconds / mVoxel); // voxels reached per world unit a second
    std::atomic<uint64_t> kept{0};
    tree::LeafManager<FloatTree> leaves(*out.reach);
    // Each voxel reads only the last layer's voxels, which no thread writes; each thread writes
    // its own leaves of both trees.
    const auto layer = [&](auto& source, const tree::LeafManager<FloatTree>::LeafRange& range) {
        Halo halo;
        uint64_t here = 0;
        for (auto reach = range.begin(); reach; ++reach) {
            if (reach->isEmpty()) continue;
            VectorLeaf& v = *velocity.probeLeaf(reach->origin());
            halo.load(reach->origin(), source);
            for (auto it = reach->beginValueOn(); it; ++it) {
                const Neighbours n = halo.around(it.pos());
                if (!(n.reach > 0.0f)) {
                    it.setValueOff();
                    v.setValueOff(it.pos());
                    continue;
                }
                it.setValue(n.reach);
                v.setValueOnly(it.pos(), n.count > 0 ? n.sum / float(n.count) : Vec3f(0.0f));
                ++here;
            }
        }
        kept += here;
    };
    tbb::parallel_for(
        leaves.leafRange(), [&](const tree::LeafManager<FloatTree>::LeafRange& range) {
            if (fromBand) {
                BandSource band(visited, candidates, velocity, last.corrections, perSpeed);
                layer(band, range);
            } else {
                LayerSource grown(*last.reach, last.corrections);
                layer(grown, range);
            }
        });
    out.kept = kept;
    return out;
}

void VelocityReach::addWarp(openvdb::Vec3STree& velocity, const openvdb::MaskTree& band,
                            bool corrected) const
{
    const float scale = mBlend.scale();
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(velocity);
    leaves.foreach ([&](VectorLeaf& v, size_t) {
        openvdb::util::NodeMask<3> grown = v.getValueMask();
        if (const auto* b = band.probeConstLeaf(v.origin())) grown -= b->getValueMask();
        if (grown.isOff()) return;
        Vec3f warp[512];
        mBlend.emptySides(v.origin(), grown, warp);
        for (auto it = grown.beginOn(); it; ++it) {
            const Vec3f w = warp[it.pos()] * scale;
            v.setValueOnly(it.pos(), corrected ? w + v.getValue(it.pos()) * scale : w);
        }
    });
}

int VelocityReach::grow(openvdb::Vec3SGrid& velocity,
                        std::unique_ptr<openvdb::Vec3STree> correction) const
{
    if (!(mSeconds > 0.0)) return 0;
    const double voxels = std::ceil(VelocityBlend::reachSpeed(velocity) * mSeconds / mVoxel);
    const int layers = voxels > 0.0 ? int(std::min(voxels, double(VelocityBlend::kMaxReach))) : 0;
    if (layers <= 0) return 0;
    openvdb::Vec3STree& tree = velocity.tree();
    const openvdb::MaskTree band(tree, false, openvdb::TopologyCopy());
    openvdb::MaskTree visited(band);
    const bool corrected = correction != nullptr;
    Layer last;
    last.corrections = correction.get();
    int grown = 0;
    while (grown < layers) {
        Layer layer = next(tree, visited, last);
        ++grown;
        last = std::move(layer);
        correction.reset(); // the first layer has read it
        if (last.kept == 0) break;
    }
    openvdb::tools::pruneInactive(tree);
    addWarp(tree, band, corrected);
    return grown;
}

} // namespace volmorph::detail
