// The approximated inverse warp and the sparse output domain, found together.
//
// Space is cut into cells aligned to a power-of-two lattice in output index space (64 voxels at the
// top). The exact warp is evaluated at a cell's 8 corners and at the 19 other points of the next
// finer lattice (edge midpoints, face centres, centre); the largest distance between the exact
// value and the corners' trilinear interpolation there is the cell's measured error, in voxels.
// A cell whose error is within the tolerance is locked: every voxel inside it is interpolated from
// its corners (Lerios et al. 1995, with a power-of-two octree instead of their adaptive grid).
// Otherwise it is split into 8 and each child reuses 8 of the 27 points as its corners, down to
// 4^3 cells; a 4^3 cell that fails is evaluated exactly, voxel by voxel.
//
// The lattice check cannot see what is smaller than its spacing: the weights (d + epsilon)^-2 bend
// the warp on the scale of d + epsilon around each element, and the distance d has a kink on the
// element's boundary. So a cell is only interpolated when it is small next to its distance to
// every element: size <= kappa * (d_min + epsilon), d_min a lower bound of the distance from the
// cell to the element (cells wholly inside a box element, where d = 0 and the weight is constant,
// are exempt).
//
// The same points bound the domain: a cell is dropped when the bounding box of its images on the
// source side, widened by twice its error and by the sampler's reach, touches no block of the
// source's active voxels, and likewise on the target side. Interpolated positions lie in the
// convex hull of their corners, so for locked cells that box is exact. Cells whose error is
// larger than themselves (a folding warp) are never dropped; their leaves are computed and
// dropped only when they turn out empty.
#pragma once

#include <volmorph/Interrupter.h>
#include <volmorph/Mesh.h>
#include <volmorph/Warp.h>

#include <openvdb/openvdb.h>

#include <array>
#include <atomic>
#include <functional>

namespace volmorph::detail {

/// "Might a trilinear sample here be non-zero?" at the resolution of 8^3 blocks: the blocks holding
/// active voxels or tiles of a grid, dilated by one block.
class Occupancy {
public:
    explicit Occupancy(const openvdb::FloatTree& tree);
    /// True when any block overlapping `box` (index space of the grid) is occupied.
    bool anyIn(const openvdb::CoordBBox& box) const;
    /// Index-space bounds of the occupied blocks (empty when nothing is).
    openvdb::CoordBBox bounds() const;

private:
    openvdb::MaskTree mBlocks;
};

/// Warped positions of one output leaf's 8^3 voxels, in the index space of source and target.
/// Voxel (i, j, k) of the leaf is at [(i * 8 + j) * 8 + k], as in OpenVDB's leaf nodes.
struct WarpLeaf {
    openvdb::Coord origin;
    std::array<Vec3f, 512> source, target;
};

struct AdaptiveWarpStats {
    double maxErrorVoxels = 0.0;   ///< the largest error measured in a locked cell
    uint64_t exactEvaluations = 0;
    uint64_t leaves = 0;           ///< leaves visited (the candidate domain)
};

class AdaptiveWarp {
public:
    /// `warp` must map output index space to source and target index space. Tolerance 0 means
    /// exact: every voxel is evaluated.
    /// `epsilonVoxels` is the warp's epsilon in index space.
    AdaptiveWarp(const InverseWarp& warp, double toleranceVoxels, double epsilonVoxels);

    using LeafFunction = std::function<void(const WarpLeaf&)>;
    /// "Is any leaf of this cell (output index space) wanted?"; cells answered no are skipped
    /// before any of their points is evaluated.
    using CellFilter = std::function<bool(const openvdb::CoordBBox&)>;

    /// Calls fn, in parallel, for every leaf in `box` (output index space) that may be non-empty
    /// by the occupancies (nullptr on both: every leaf of the box) and that `wanted` (if given)
    /// accepts. Deterministic: each leaf's positions depend only on the leaf, not on threads or
    /// order.
    void forEachLeaf(const openvdb::CoordBBox& box, const Occupancy* source, const Occupancy* target,
                     const LeafFunction& fn, AdaptiveWarpStats* stats = nullptr,
                     Interrupter* interrupter = nullptr, const CellFilter* wanted = nullptr) const;

    /// Every top cell is this many voxels on a side.
    static constexpr int kTopCell = 64;

private:
    struct Corners {
        Vec3d s[8], t[8];  ///< corner bit 0: +x, bit 1: +y, bit 2: +z
    };
    struct Context;
    void cell(Context& ctx, const openvdb::Coord& origin, int size, const Corners& corners, bool locked) const;
    void quarter(Context& ctx, const openvdb::Coord& origin, const Corners& corners) const;
    void exactBlock(Context& ctx, const openvdb::Coord& origin, int size) const;
    void fillTrilinear(Context& ctx, const openvdb::Coord& origin, int size, const Corners& corners) const;
    /// No pairs: the warp is the identity on both sides.
    void fillIdentity(Context& ctx, const openvdb::Coord& origin) const;
    /// True when the cell is too large next to some element to be interpolated, whatever the
    /// lattice check says.
    bool nearElement(const openvdb::Coord& origin, int size) const;

    const InverseWarp& mWarp;
    double mTolerance;
    double mEpsilon;   ///< the warp's epsilon, index space
};

} // namespace volmorph::detail
