#include "blend/SdfBlend.h"

#include "blend/ExtendedDistance.h"
#include "blend/ExtraGrids.h"
#include "blend/IdentityDistances.h"
#include "blend/Islands.h"
#include "blend/Redistance.h"
#include "blend/SdfFrame.h"
#include "blend/SdfVelocity.h"
#include "blend/WithSampler.h"

#include <volmorph/core/Interrupter.h>
#include <volmorph/Schedule.h>

#include <openvdb/tools/Interpolation.h>

#include <tbb/parallel_invoke.h>

#include <stdexcept>

namespace volmorph::detail {

using openvdb::Coord;
using openvdb::CoordBBox;

namespace {

template <typename Sampler>
class SdfBlend final : public TwoSidedBlend {
public:
    explicit SdfBlend(const BlendSetup& setup) : TwoSidedBlend(setup)
    {
        if (!mSource.sdf || !mTarget.sdf)
            throw std::invalid_argument("sdf blending needs sdf grids on both sides");
        const CoordBBox box = ExtendedDistance::boxFor(*mSource.sdf, *mTarget.sdf, setup.pairCount);
        // Both at once: fast sweeping is partly serial.
        tbb::parallel_invoke(
            [&] { mFarSource = ExtendedDistance::make(mSource.sdf, box, setup.interrupter); },
            [&] { mFarTarget = ExtendedDistance::make(mTarget.sdf, box, setup.interrupter); });
        if (setup.pairCount == 0)
            mIdentity = std::make_unique<IdentityDistances>(
                setup.candidates,
                size_t(setup.memoryLimitBytes / 4 / sizeof(IdentityDistances::Leaf)));
    }

    BlendedFrame frame(const BlendRequest& r, OutputLeaves& leaves) const override
    {
        const openvdb::math::Transform& xform = mSource.density->transform();
        const BlendTime sdfTime(mSpec.sdf, r.t, r.localTime, xform);
        const BlendTime colorTime(mSpec.color, r.t, r.localTime, xform);
        SdfFrame<Sampler> blend(mSource, mTarget, *mFarSource, *mFarTarget, *r.warp, sdfTime,
                                colorTime, leaves.background(), r.toleranceVoxels);
        // With no pairs (and pruning), distances are read from those kept across frames.
        IdentityDistances* const kept =
            r.prune && r.warp->pairCount() == 0 ? mIdentity.get() : nullptr;
        blend.classify(r.box, r.prune, kept);
        BlendedFrame out;
        const ExtraGrids extras(mSource, mTarget, mSpec, r.t, r.localTime);
        const std::vector<Coord> evaluate = sortLeaves(blend.classes(), kept != nullptr, leaves);
        const bool velocity = r.velocityScale > 0.0;
        if (kept) {
            fromKeptDistances(blend, *kept, evaluate, extras, velocity, leaves, r.interrupter);
            out.warp.leaves = evaluate.size();
        } else {
            throughWarp(blend, r, extras, velocity, leaves, out.warp);
        }
        DistanceTrees distances;
        assemble(blend, extras, leaves, velocity ? &distances : nullptr, out);
        if (velocity) {
            const SdfVelocity v(*r.warp, r.velocityScale, sdfTime,
                                kSdfRampVoxels * float(mSource.voxelSize()),
                                float(mSource.voxelSize()));
            out.grids.velocity = v.make(distances.source, distances.target, r.velocityReachSeconds,
                                        mSource.voxelSize());
            out.velocityInterpolated = v.interpolatedCubes();
            out.velocityExact = v.exactCubes();
        }
        return out;
    }

private:
    using ValueLeaf = OutputLeaves::ValueLeaf;
    /// Each side's distance at the warped points of the voxels blended (for the velocity).
    struct DistanceTrees {
        openvdb::FloatTree source, target;
    };
    struct DistanceLeaves {
        std::unique_ptr<ValueLeaf> source, target;
        DistanceLeaves(bool wanted, const Coord& origin)
        {
            if (!wanted) return;
            source = std::make_unique<ValueLeaf>(origin, 0.0f, false);
            target = std::make_unique<ValueLeaf>(origin, 0.0f, false);
        }
        typename SdfFrame<Sampler>::Distances record() const
        {
            return {source.get(), target.get()};
        }
    };

    /// Leaves inside as a whole become inside tiles. With kept distances, returns the leaves to
    /// evaluate (the warp's traversal finds them itself otherwise).
    static std::vector<Coord> sortLeaves(const BlockClasses& classes, bool listThem,
                                         OutputLeaves& leaves)
    {
        std::vector<Coord> evaluate;
        for (int x = classes.leaves.min().x(); x <= classes.leaves.max().x(); ++x)
            for (int y = classes.leaves.min().y(); y <= classes.leaves.max().y(); ++y)
                for (int z = classes.leaves.min().z(); z <= classes.leaves.max().z(); ++z) {
                    const int8_t kind = classes.at(Coord(x, y, z));
                    if (kind < 0)
                        leaves.insideTile(Coord(x * 8, y * 8, z * 8));
                    else if (kind == 0 && listThem)
                        evaluate.emplace_back(x * 8, y * 8, z * 8);
                }
        return evaluate;
    }

    /// Keeps a filled leaf, with the extras on its kept band (where it has colour), or makes it
    /// an inside tile, or drops it (outside).
    template <typename Points>
    static void settle(int whole, const Coord& origin, std::unique_ptr<ValueLeaf> value,
                       std::unique_ptr<OutputLeaves::ColorLeaf> color, DistanceLeaves distances,
                       const ExtraGrids& extras, const Points& points, OutputLeaves& leaves)
    {
        if (whole == 0) {
            ExtraLeaves e = extras.make(origin);
            extras.fill<Sampler>(color->getValueMask(), points, e);
            e.distances[0] = std::move(distances.source);
            e.distances[1] = std::move(distances.target);
            leaves.keep(std::move(value), std::move(color), std::move(e));
        } else if (whole < 0) {
            leaves.insideTile(origin);
        }
    }

    /// The leaves `evaluate`, from the distances kept across frames (no pairs).
    void fromKeptDistances(const SdfFrame<Sampler>& blend, IdentityDistances& kept,
                           const std::vector<Coord>& evaluate, const ExtraGrids& extras,
                           bool velocity, OutputLeaves& leaves, Interrupter* interrupter) const
    {
        const float band = blend.computeBand();
        std::atomic<bool> stopped{false};
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, evaluate.size(), 8),
            [&](const tbb::blocked_range<size_t>& r) {
                if (stopped || (interrupter && interrupter->wasInterrupted(
                                                   int(100 * r.begin() / evaluate.size())))) {
                    stopped = true;
                    return;
                }
                typename ExtendedDistance::template Reader<Sampler> a(*mFarSource), b(*mFarTarget);
                auto scratch = std::make_unique<IdentityDistances::Leaf>();
                uint64_t computed = 0;
                for (size_t i = r.begin(); i != r.end(); ++i) {
                    const auto& distances =
                        kept.get<Sampler>(evaluate[i], a, b, *scratch, computed);
                    auto [value, color] = leaves.make(evaluate[i], band);
                    DistanceLeaves recorded(velocity, evaluate[i]);
                    const int whole =
                        blend(evaluate[i], distances, *value, *color, recorded.record());
                    // The identity warp: each voxel's points are the voxel itself.
                    const auto atVoxel = [&origin = evaluate[i]](openvdb::Index n) {
                        const openvdb::Vec3R p =
                            (origin + OutputLeaves::ValueLeaf::offsetToLocalCoord(n)).asVec3d();
                        return std::pair{p, p};
                    };
                    settle(whole, evaluate[i], std::move(value), std::move(color),
                           std::move(recorded), extras, atVoxel, leaves);
                }
                blend.addSamples(computed);
            });
        if (stopped) throw Interrupted();
    }

    /// The leaves the warp's traversal visits (those the classes want, when pruning).
    void throughWarp(const SdfFrame<Sampler>& blend, const BlendRequest& r,
                     const ExtraGrids& extras, bool velocity, OutputLeaves& leaves,
                     AdaptiveWarpStats& stats) const
    {
        const float band = blend.computeBand();
        const BlockClasses& classes = blend.classes();
        const AdaptiveWarp::CellFilter wanted = [&classes](const CoordBBox& cells) {
            return classes.anyToEvaluate(cells);
        };
        r.warp->forEachLeaf(
            r.box, nullptr, nullptr,
            [&](const WarpLeaf& w) {
                auto [value, color] = leaves.make(w.origin, band);
                DistanceLeaves recorded(velocity, w.origin);
                const int whole = blend(w, *value, *color, recorded.record());
                settle(whole, w.origin, std::move(value), std::move(color), std::move(recorded),
                       extras, WarpedPoints{w}, leaves);
            },
            &stats, r.interrupter, r.prune ? &wanted : nullptr);
    }

    /// The grids from the leaves: tiles and the background take the output band's values at once
    /// (+/- its width); the leaves' values beyond the compute band are rewritten by redistance().
    /// The recorded distances go into `distances` when given.
    void assemble(const SdfFrame<Sampler>& blend, const ExtraGrids& extras, OutputLeaves& leaves,
                  DistanceTrees* distances, BlendedFrame& out) const
    {
        openvdb::FloatGrid::Ptr values = openvdb::FloatGrid::create(blend.width());
        values->setTransform(mSource.density->transform().copy());
        values->setGridClass(openvdb::GRID_LEVEL_SET);
        out.grids.color = openvdb::Vec3SGrid::create(leaves.background());
        out.keptLeaves = leaves.size();
        ExtraGrids::Outputs carried = extras.outputs();
        if (distances) {
            carried.trees.distances[0] = &distances->source;
            carried.trees.distances[1] = &distances->target;
        }
        leaves.moveInto(values->tree(), out.grids.color->tree(), -blend.width(), carried.trees);
        out.grids.extras = std::move(carried.grids);
        dropIslands(*values, mSpec.minIslandVoxels, blend.computeBand(), blend.deepVoxels());
        const float voxel = float(mSource.voxelSize());
        RedistanceBands bands{voxel, blend.width(),
                              [&blend](const Coord& origin) { return blend.keepBandAt(origin); }};
        out.grids.density = redistance(*values, bands, kSdfRampVoxels * voxel);
        out.grids.sdf = values;
        out.blendSamples = blend.samples();
    }

    std::unique_ptr<const ExtendedDistance> mFarSource, mFarTarget;
    /// With no pairs: both extended distances at the output voxels, kept per leaf across frames
    /// (the identity warp does not change with t). Bounded by a quarter of the memory limit.
    std::unique_ptr<IdentityDistances> mIdentity;
};

} // namespace

std::unique_ptr<const BlendMethod> makeSdfBlend(const BlendSetup& setup)
{
    return withSampler<SdfBlend>(setup);
}

} // namespace volmorph::detail
