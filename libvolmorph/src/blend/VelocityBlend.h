// The in-between's velocity, the `vel` grid: each side's warp velocity at the output voxel
// (warp/VelocityLeaf.h), mixed as the density blend weights the sides,
//   v = ((1 - tau) rho_S v_S + tau rho_T v_T) / ((1 - tau) rho_S + tau rho_T),
// rho the side's density at its warped point (where both are empty: (1 - tau) v_S + tau v_T),
// tau each voxel's under a timing.
// World units per second: the warp's index units per unit t, times the voxel size, over the
// seconds one unit of t lasts.
#pragma once

#include "blend/BlendTime.h"
#include "warp/FrameWarp.h"
#include "warp/VelocityLeaf.h"

#include <openvdb/openvdb.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <memory>
#include <vector>

namespace volmorph::detail {

class VelocityBlend {
public:
    using Leaf = openvdb::Vec3STree::LeafNodeType;

    /// worldPerSecond: world units per second of one index unit per unit t (0: no velocity);
    /// time: the density schedule's tau at each voxel (it must outlive this, as `warp` must).
    VelocityBlend(const FrameWarp& warp, double worldPerSecond, const BlendTime& time)
        : mLeaf(warp.velocities()), mScale(float(worldPerSecond)), mTime(time)
    {
    }

    bool enabled() const { return mScale > 0.0f; }

    /// The velocity leaf at the voxels `on` of the output leaf at origin; a, b: each side's
    /// density at the voxel's warped points (512 each).
    std::unique_ptr<Leaf> leaf(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on,
                               const float a[512], const float b[512]) const
    {
        Vec3f vs[512], vt[512];
        count(mLeaf.fill(origin, on, vs, vt));
        auto out = std::make_unique<Leaf>(origin, Vec3f(0.0f), false);
        for (auto it = on.beginOn(); it; ++it) {
            const openvdb::Index n = it.pos();
            const float tau = tauAt(origin, n);
            const float wa = (1.0f - tau) * std::max(a[n], 0.0f), wb = tau * std::max(b[n], 0.0f);
            const Vec3f v = wa + wb > 0.0f ? (wa * vs[n] + wb * vt[n]) / (wa + wb)
                                           : (1.0f - tau) * vs[n] + tau * vt[n];
            out->setValueOn(n, v * mScale);
        }
        return out;
    }

    static constexpr int kMaxReach = 64; ///< voxels (VelocityReach)

    /// The warp's own velocity where both sides are empty, (1 - tau) v_S + tau v_T (index units
    /// per unit t), at the voxels `on` of the leaf at `origin`.
    void emptySides(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on,
                    Vec3f out[512]) const
    {
        Vec3f vs[512], vt[512];
        mLeaf.fill(origin, on, vs, vt);
        for (auto it = on.beginOn(); it; ++it) {
            const float tau = tauAt(origin, it.pos());
            out[it.pos()] = (1.0f - tau) * vs[it.pos()] + tau * vt[it.pos()];
        }
    }
    /// World units per second of one index unit per unit t.
    float scale() const { return mScale; }

    /// The speed the reach is made for: the fastest but for the fastest 1% of leaves. Near a fold
    /// of the warp, or where sdf mode's surface splits or closes (its normal speed unbounded
    /// there), the speed spikes at a few voxels, 100 times the motion's elsewhere in the default
    /// scene; a reach made for it would cost the frame many times over (VelocityReach's layers
    /// around those voxels), for the blur of those few voxels' density alone.
    static double reachSpeed(const openvdb::Vec3SGrid& velocity)
    {
        openvdb::tree::LeafManager<const openvdb::Vec3STree> leaves(velocity.tree());
        std::vector<float> fastest(leaves.leafCount(), 0.0f);
        leaves.foreach ([&](const Leaf& leaf, size_t i) {
            for (auto it = leaf.cbeginValueOn(); it; ++it)
                fastest[i] = std::max(fastest[i], it->lengthSqr());
        });
        if (fastest.empty()) return 0.0;
        const auto kept = fastest.begin() + std::ptrdiff_t((fastest.size() - 1) * 99 / 100);
        std::nth_element(fastest.begin(), kept, fastest.end());
        return std::sqrt(double(*kept));
    }

    /// Sub-cubes (4^3 voxels) whose warp velocity was interpolated, and evaluated exactly, so far.
    uint64_t interpolatedCubes() const { return mInterpolated; }
    uint64_t exactCubes() const { return mExact; }
    /// Counts a leaf's sub-cubes, `interpolated` of its 8 (VelocityLeaf::fill).
    void count(int interpolated) const
    {
        mInterpolated += uint64_t(interpolated);
        mExact += uint64_t(8 - interpolated);
    }
    const VelocityLeaf& warpVelocity() const { return mLeaf; }

private:
    float tauAt(const openvdb::Coord& origin, openvdb::Index n) const
    {
        return mTime.uniform() ? mTime.atAll().tau
                               : mTime.at(origin + Leaf::offsetToLocalCoord(n)).tau;
    }

    VelocityLeaf mLeaf;
    float mScale;
    const BlendTime& mTime;
    mutable std::atomic<uint64_t> mInterpolated{0}, mExact{0};
};

} // namespace volmorph::detail
