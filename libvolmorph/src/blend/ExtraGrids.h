// The other grids the sides carry (temperature, flame, ...; VolumeSet::extras): each read at both
// warped points as Cd is, and mixed by its own schedule (blend.grids, else the density's), where
// the in-between keeps colour: every active density voxel in density mode, the kept band in sdf
// mode. A grid one side lacks reads as the other side's background there: the blend of a
// temperature the target lacks falls to its background as tau rises. Values are mixed plainly (not
// weighted by density as colour is), so that a grid keeps its own meaning (a temperature of 0 at
// t = 0.5 halfway to an absent side is half the source's).
#pragma once

#include "blend/OutputLeaves.h"
#include "blend/Sample.h"
#include "warp/AdaptiveWarp.h"

#include <volmorph/BlendSettings.h>
#include <volmorph/LocalTime.h>
#include <volmorph/Schedule.h>
#include <volmorph/VolumeSet.h>

#include <openvdb/openvdb.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace volmorph::detail {

/// A warped leaf's points of voxel n, source then target (index space), for ExtraGrids::fill.
struct WarpedPoints {
    const WarpLeaf& w;
    std::pair<openvdb::Vec3R, openvdb::Vec3R> operator()(openvdb::Index n) const
    {
        return {openvdb::Vec3R(w.source(n)), openvdb::Vec3R(w.target(n))};
    }
};

class ExtraGrids {
public:
    /// The extras of both sides at morph time t, paired by name; under `local` (may be null)
    /// each voxel takes its grid's schedule at its own local time.
    ExtraGrids(const VolumeSet& source, const VolumeSet& target, const BlendSpec& spec, double t,
               const LocalTime* local = nullptr);

    /// Throws UserError when a grid has one type on one side and another on the other, or when
    /// blend.grids names a grid neither side carries.
    static void check(const VolumeSet& source, const VolumeSet& target, const BlendSpec& spec);
    /// The bytes one output leaf of every extra takes.
    static uint64_t bytesPerLeaf(const VolumeSet& source, const VolumeSet& target);

    bool empty() const { return mFloats.empty() && mVectors.empty(); }

    /// An inactive leaf of each extra at `origin`, at its output background.
    ExtraLeaves make(const openvdb::Coord& origin) const;

    /// Fills the voxels `on` of each extra's leaf: the blend of both sides at the warped points
    /// points(n) (a pair of index-space points, source then target).
    template <typename Sampler, typename Points>
    void fill(const openvdb::util::NodeMask<3>& on, const Points& points, ExtraLeaves& out) const
    {
        for (size_t i = 0; i < mFloats.size(); ++i)
            fillOne<Sampler>(mFloats[i], on, points, *out.floats[i]);
        for (size_t i = 0; i < mVectors.size(); ++i)
            fillOne<Sampler>(mVectors[i], on, points, *out.vectors[i]);
    }

    /// Empty output grids, named, classed and typed as the inputs, at their blended backgrounds,
    /// with the trees that the kept leaves go into (in the order of ExtraLeaves).
    struct Outputs {
        std::map<std::string, openvdb::GridBase::Ptr> grids;
        ExtraTrees trees; ///< the extras' floats and vectors
    };
    Outputs outputs() const;

private:
    template <typename GridT>
    struct Extra {
        std::string name;
        typename GridT::ConstPtr source, target; ///< null where a side lacks it
        typename GridT::ValueType sourceBackground, targetBackground;
        float tau = 0.0f;                       ///< at t, everywhere without a timing
        const ScheduleSpec* schedule = nullptr; ///< its schedule (blend.grids', or the density's)
        openvdb::GridBase::ConstPtr like;       ///< whose metadata the output copies
    };

    template <typename Sampler, typename GridT, typename Points>
    void fillOne(const Extra<GridT>& e, const openvdb::util::NodeMask<3>& on, const Points& points,
                 typename GridT::TreeType::LeafNodeType& leaf) const
    {
        using Value = typename GridT::ValueType;
        auto a = e.source ? e.source->getConstAccessor() : e.target->getConstAccessor();
        auto b = e.target ? e.target->getConstAccessor() : e.source->getConstAccessor();
        for (auto it = on.beginOn(); it; ++it) {
            const auto [ps, pt] = points(openvdb::Index(it.pos()));
            const Value va = e.source ? Value(sample<Sampler>(a, ps)) : e.sourceBackground;
            const Value vb = e.target ? Value(sample<Sampler>(b, pt)) : e.targetBackground;
            const float tau =
                mLocal ? localTau(*e.schedule, leaf.offsetToGlobalCoord(it.pos())) : e.tau;
            leaf.setValueOn(it.pos(), Value((1.0f - tau) * va + tau * vb));
        }
    }

    /// A schedule at the local time of output voxel ijk.
    float localTau(const ScheduleSpec& schedule, const openvdb::Coord& ijk) const
    {
        return float(scheduleValue(schedule, mLocal->at(mXform->indexToWorld(ijk), mT).tau));
    }

    template <typename GridT>
    static std::vector<Extra<GridT>> pair(const VolumeSet& source, const VolumeSet& target,
                                          const BlendSpec& spec, double t);

    std::vector<Extra<openvdb::FloatGrid>> mFloats;
    std::vector<Extra<openvdb::Vec3SGrid>> mVectors;
    double mT;
    const LocalTime* mLocal;              ///< null: every voxel at t
    openvdb::math::Transform::Ptr mXform; ///< the output's
};

} // namespace volmorph::detail
