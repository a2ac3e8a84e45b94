// Which 8^3 blocks of a grid hold anything a trilinear sample could read: the domain test of the
// approximated warp asks it whether a box of warped points can touch source or target.
#pragma once

#include <openvdb/openvdb.h>

#include <cstdint>
#include <vector>

namespace volmorph::detail {

/// "Might a sample here be non-zero?" at the resolution of 8^3 blocks: the blocks holding active
/// voxels or tiles of a grid (whose inactive values are zero). A sampler reads beyond the point:
/// callers widen their boxes by its reach.
class Occupancy {
public:
    explicit Occupancy(const openvdb::FloatTree& tree);
    /// True when any block overlapping `box` (index space of the grid) is occupied.
    bool anyIn(const openvdb::CoordBBox& box) const;
    /// Index-space bounds of the occupied blocks (empty when nothing is).
    openvdb::CoordBBox bounds() const;

private:
    openvdb::MaskTree mBlocks;
    // The same blocks as a summed-volume table over their bounds, for box queries in O(1)
    // (empty when that table would be too large; then the tree is scanned).
    openvdb::Coord mLo, mDim;           ///< block coordinates of the table's first cell, cells per axis
    std::vector<uint32_t> mPrefix;      ///< (mDim + 1)^3 counts of occupied blocks below each corner
};

} // namespace volmorph::detail
