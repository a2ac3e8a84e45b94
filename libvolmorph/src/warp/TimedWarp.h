// The warp under a timing (LocalTime.h): each output place p takes the features at its own local
// time, W(p, tau(p, t)), so the warp travels with the morph as the blends do.
//
// The warp at a given tau does not depend on the frame, so it is tabulated once per morph at
// levels tau_0 = 0 < ... < tau_K = 1 (TauTable), and a place between two levels takes the linear
// blend of their maps, W~(p, tau) = (1 - f) W_k(p) + f W_k+1(p), f = (tau - tau_k) / h_k:
// continuous in p and in t. The levels start at sixteenths and are halved, down to sixty-fourths at
// most, until at every interval's midpoint the warp is within a quarter of the tolerance of its
// ends' blend at sample points: a lattice over the morph's candidate box, and on and about each
// interpolated element at the interval's ends and middle. Each level's approximated warp
// (AdaptiveWarp) keeps its a-priori bound within the other three quarters. The table's error is
// measured, not bounded, and where an element's edge sweeps over a place the weights have a kink in
// tau, which halving shrinks only linearly: there the table errs most (TauTable::error: 1.6 voxels
// for the default scene's pairs, within the weights' offset of an element's path; far less
// elsewhere), and the frame's stats add it to the warp's bound. A leaf is filled at every level its
// voxels' taus reach (one where they all sit at a level, as before a place begins or after it ends;
// about two to five across the ramp), each level through its own traversal of a list of leaves, a
// chunk of leaves at a time, and its voxels blended. Before any of that, a cube of 64 and then each
// leaf is dropped when its image, at every level its places' local times can reach, misses both
// sides' occupied blocks (the box of the pairs' affine images: a level's map is a convex
// combination of them, the table's of two levels'): in density mode most of the candidate box is
// empty (dino-to-eight swept: 2,020 of 76,670 leaves used, the frame 1.67 s -> 0.72 s). With
// tolerance 0 every voxel is mapped exactly at its own tau (the tests' reference).
//
// The velocity is that of the map as made: with the slope S = (W_k+1 - W_k) / h_k,
//   dW~/dp = (1 - f) J_k + f J_k+1 + S (grad tau)^T,   dW~/dt = S tau_t,
// v = -(dW~/dp)^-1 dW~/dt, per side (exactly: J(tau) + W_tau (grad tau)^T and W_tau tau_t, the
// chain rule through tau(p, t)); 0 where tau is clamped (a place not begun, or done).
// Output index space in, each side's index space out; velocities in index units per unit t.
#pragma once

#include "warp/FrameWarp.h"

#include <volmorph/FeaturePair.h>
#include <volmorph/LocalTime.h>
#include <volmorph/WarpSettings.h>

#include <openvdb/math/Transform.h>

#include <memory>
#include <vector>

namespace volmorph::detail {

struct TauTable {
    std::vector<double> levels{0.0, 1.0}; ///< increasing, from 0 to 1
    double error = 0.0;                   ///< the largest midpoint deviation measured (voxels)

    /// The levels for `pairs` (the warp in index units: unit = 1 / voxel size), sampled over
    /// `region` (output index space), within a quarter of `toleranceVoxels` (0: of 0.25 voxels).
    static TauTable make(const std::vector<FeaturePairSpec>& pairs, const WarpSpec& spec,
                         double unit, const openvdb::CoordBBox& region, double toleranceVoxels);
    /// The interval k holding tau (levels[k] <= tau <= levels[k + 1]) and f in [0, 1] along it.
    size_t interval(double tau, double& f) const;
};

class TimedWarp final : public FrameWarp, private PointVelocities {
public:
    /// The frame at t: `table`, `local` and `xform` (the output's index-to-world transform) must
    /// outlive this; tolerance in voxels (0: exact).
    TimedWarp(const std::vector<FeaturePairSpec>& pairs, const WarpSpec& spec, double unit,
              const TauTable& table, const LocalTime& local, const openvdb::math::Transform& xform,
              double t, double toleranceVoxels);
    ~TimedWarp() override;

    size_t pairCount() const override { return mPairs.size(); }
    void map(const Vec3d& p, Vec3d& source, Vec3d& target) const override;
    void forEachLeaf(const openvdb::CoordBBox& box, const Occupancy* source,
                     const Occupancy* target, const AdaptiveWarp::LeafFunction& fn,
                     AdaptiveWarpStats* stats, Interrupter* interrupter,
                     const AdaptiveWarp::CellFilter* wanted = nullptr) const override;
    const PointVelocities& velocities() const override { return *this; }

    /// The local time at output index point p, its gradient per index unit.
    LocalTau tauAt(const Vec3d& p) const;

private:
    void velocities(const Vec3d* p, size_t n, Vec3d* source, Vec3d* target,
                    bool* regular) const override;
    /// One point's velocities, both sides, from the exact warp at its tau; false at a fold.
    bool exactVelocity(const Vec3d& p, Vec3d& source, Vec3d& target) const;
    /// The table's velocities at points whose local times are `local`, all in interval k.
    void tableVelocities(const Vec3d* p, const LocalTau* local, size_t n, size_t k, Vec3d* source,
                         Vec3d* target, bool* regular) const;
    /// The exact warp at tau (a level's when tau is one).
    std::shared_ptr<const InverseWarp> warpAt(double tau) const;
    /// The leaves of `box` that `wanted` accepts and whose image may come near an occupied block
    /// of either side (mayTouch; every leaf when both are null), in order.
    std::vector<openvdb::Coord> candidates(const openvdb::CoordBBox& box, const Occupancy* source,
                                           const Occupancy* target,
                                           const AdaptiveWarp::CellFilter* wanted) const;
    /// Whether the cube's image, at any local time its places can have, may come near an
    /// occupied block (the box of the pairs' affine images at the levels those times reach).
    bool mayTouch(const openvdb::CoordBBox& cube, const Occupancy* source,
                  const Occupancy* target) const;
    struct Chunk;
    /// Fills a chunk's leaves: at their levels and blended, or exactly.
    void fillChunk(Chunk& chunk, AdaptiveWarpStats& stats, Interrupter* interrupter) const;
    void fillExact(Chunk& chunk, AdaptiveWarpStats& stats) const;

    const std::vector<FeaturePairSpec>& mPairs;
    const WarpSpec& mSpec;
    double mUnit;
    const TauTable& mTable;
    const LocalTime& mLocal;
    const openvdb::math::Transform& mXform;
    double mT, mTolerance, mVoxel;
    std::vector<std::shared_ptr<const InverseWarp>> mWarps; ///< at each level
    /// Each level's pairs' affine maps, source and target (for the domain test).
    std::vector<std::pair<std::vector<InverseWarp::Affine>, std::vector<InverseWarp::Affine>>>
        mAffines;
    std::vector<std::unique_ptr<AdaptiveWarp>> mAdaptive;  ///< each level's, approximated
    std::vector<std::unique_ptr<VelocityKernel>> mKernels; ///< each level's jets
};

} // namespace volmorph::detail
