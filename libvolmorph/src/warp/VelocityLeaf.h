// The velocity of the material each side shows at the voxels of one output leaf: v = -J^-1 dW/dt
// of the exact warp (InverseWarp::derivatives, 8 points to a vector: warp/VelocityKernel.h), in
// index units per unit of t.
//
// Evaluating it at every voxel costs O(pairs) per voxel. Velocity is smooth wherever the warp is
// (it has the warp's own scale of variation, the distance to the nearest element), so a leaf takes
// it exactly at a lattice 4 voxels apart (27 points, corners shared with nothing: each leaf is
// independent, so the result does not depend on threads) and interpolates trilinearly between
// them. The interpolant is checked at each of the eight 4^3 sub-cubes' centres, where its error is
// largest for a smooth field, against the exact velocity there; a sub-cube whose check is off by
// more than the tolerance (relative to the largest speed on the leaf's lattice) but at most 8
// times it goes to a lattice 2 voxels apart (19 more exact points; its 8 cells checked at their
// centres the same way), and one that misses by more, or has no more active voxels than those 27
// evaluations, or whose fine cell misses, is evaluated exactly at its active voxels; so is a whole
// leaf whose lattice touches a fold of the warp (J singular) or that has no more active voxels than
// the lattice and check together. The check is a posteriori: between its points the error is
// estimated, not bounded.
#pragma once

#include "warp/VelocityKernel.h"

#include <volmorph/core/Math.h>
#include <volmorph/Warp.h>

#include <openvdb/openvdb.h>

#include <cstdint>
#include <memory>

namespace volmorph::detail {

struct VelocityLattice; // VelocityLeaf.cpp: both sides' velocities at a leaf's points 4 voxels
                        // apart

class VelocityLeaf {
public:
    /// Where a pair's d + offset is under this many voxels, the exact velocity is taken in double
    /// precision (VelocityKernel).
    static constexpr double kExactWithin = 1.0;

    /// `warp` maps output index space at the frame's t (built with unit 1 / voxel size).
    /// tolerance: the check's allowed error, relative to the leaf's largest lattice speed.
    explicit VelocityLeaf(const InverseWarp& warp, double tolerance = 2e-3)
        : mOwned(std::make_shared<const VelocityKernel>(warp, kExactWithin)), mPoints(*mOwned),
          mTolerance(tolerance)
    {
    }
    /// The same from any warp's velocities at points (a frame's warp under a timing: TimedWarp).
    explicit VelocityLeaf(const PointVelocities& points, double tolerance = 2e-3)
        : mPoints(points), mTolerance(tolerance)
    {
    }

    /// Both sides' velocities at the voxels `on` of the leaf at `origin` (index units per unit t,
    /// voxel n = (i * 8 + j) * 8 + k); returns how many of the 8 sub-cubes were interpolated.
    int fill(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on, Vec3f source[512],
             Vec3f target[512]) const;

private:
    void fillExact(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on,
                   Vec3f source[512], Vec3f target[512]) const;
    /// The voxels `on` of the sub-cubes that did not pass (`miss`: their checks' errors in
    /// tolerances): on a finer lattice, or exactly.
    void finishFailed(const openvdb::Coord& origin, const openvdb::util::NodeMask<3>& on,
                      const bool passed[8], const double miss[8], double speed,
                      const VelocityLattice& lattice, Vec3f source[512], Vec3f target[512]) const;
    /// Sub-cube c's voxels `on` interpolated on a lattice 2 voxels apart (its 8 cells checked at
    /// their centres against the tolerance times `speed`; a cell that misses, or a fold, exactly).
    void refine(const openvdb::Coord& origin, int c, double speed, const VelocityLattice& coarse,
                const openvdb::util::NodeMask<3>& on, Vec3f source[512], Vec3f target[512]) const;

    std::shared_ptr<const VelocityKernel> mOwned; ///< when built from an InverseWarp
    const PointVelocities& mPoints;
    double mTolerance;
};

} // namespace volmorph::detail
