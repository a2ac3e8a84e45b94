// One frame's warp as the blend methods read it (src/blend/): the exact map at single points (the
// leaves' classification), the approximated map leaf by leaf (AdaptiveWarp's traversal), and both
// sides' velocities at points (for VelocityLeaf). Two kinds: every place at the frame's t
// (PlainWarp, below), and each place at its own local time under a timing (TimedWarp.h).
// Output index space in, each side's index space out; velocities in index units per unit t.
#pragma once

#include "warp/AdaptiveWarp.h"
#include "warp/VelocityKernel.h"
#include "warp/VelocityLeaf.h"

#include <volmorph/Warp.h>

namespace volmorph::detail {

class FrameWarp {
public:
    virtual ~FrameWarp() = default;

    /// Pairs of the warp (0: the identity).
    virtual size_t pairCount() const = 0;
    /// The exact warp at output index point p.
    virtual void map(const Vec3d& p, Vec3d& source, Vec3d& target) const = 0;
    /// As AdaptiveWarp::forEachLeaf: fn, in parallel, for every leaf of `box` that the
    /// occupancies may reach (nullptr on both: every leaf) and `wanted` accepts, its points within
    /// the tolerance the warp was made with.
    virtual void forEachLeaf(const openvdb::CoordBBox& box, const Occupancy* source,
                             const Occupancy* target, const AdaptiveWarp::LeafFunction& fn,
                             AdaptiveWarpStats* stats, Interrupter* interrupter,
                             const AdaptiveWarp::CellFilter* wanted = nullptr) const = 0;
    /// Both sides' velocities at points.
    virtual const PointVelocities& velocities() const = 0;
};

/// Every place at the frame's t: the inverse warp, its approximation and its velocity kernel.
class PlainWarp final : public FrameWarp {
public:
    /// `warp` must outlive this (built with unit 1 / voxel size); tolerance in voxels (0: exact).
    PlainWarp(const InverseWarp& warp, double toleranceVoxels)
        : mWarp(warp), mAdaptive(warp, toleranceVoxels), mKernel(warp, VelocityLeaf::kExactWithin)
    {
    }

    size_t pairCount() const override { return mWarp.pairCount(); }
    void map(const Vec3d& p, Vec3d& source, Vec3d& target) const override
    {
        mWarp.map(p, source, target);
    }
    void forEachLeaf(const openvdb::CoordBBox& box, const Occupancy* source,
                     const Occupancy* target, const AdaptiveWarp::LeafFunction& fn,
                     AdaptiveWarpStats* stats, Interrupter* interrupter,
                     const AdaptiveWarp::CellFilter* wanted = nullptr) const override
    {
        mAdaptive.forEachLeaf(box, source, target, fn, stats, interrupter, wanted);
    }
    const PointVelocities& velocities() const override { return mKernel; }

private:
    const InverseWarp& mWarp;
    AdaptiveWarp mAdaptive;
    VelocityKernel mKernel;
};

} // namespace volmorph::detail
