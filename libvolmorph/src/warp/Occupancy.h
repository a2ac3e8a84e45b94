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
    /// True when any block overlapping `box` (index space of the grid) is occupied. Inline: the
    /// warp's domain test asks it several times per leaf.
    bool anyIn(const openvdb::CoordBBox& box) const
    {
        // Block coordinates: floor division by 8 (an arithmetic shift, also below zero).
        const openvdb::Coord lo(box.min().x() >> 3, box.min().y() >> 3, box.min().z() >> 3);
        const openvdb::Coord hi(box.max().x() >> 3, box.max().y() >> 3, box.max().z() >> 3);
        if (mPrefix.empty()) return scan(lo, hi);
        // Inclusion-exclusion over the summed-volume table, the box clamped to its bounds.
        const openvdb::Coord a = openvdb::Coord::maxComponent(lo, mLo) - mLo;
        const openvdb::Coord c =
            openvdb::Coord::minComponent(hi, mLo + mDim - openvdb::Coord(1)) - mLo;
        if (a.x() > c.x() || a.y() > c.y() || a.z() > c.z()) return false;
        const size_t sy = size_t(mDim.z() + 1), sx = sy * size_t(mDim.y() + 1);
        const uint32_t* p = mPrefix.data();
        const size_t x0 = size_t(a.x()) * sx, x1 = size_t(c.x() + 1) * sx;
        const size_t y0 = size_t(a.y()) * sy, y1 = size_t(c.y() + 1) * sy;
        const size_t z0 = size_t(a.z()), z1 = size_t(c.z() + 1);
        const int64_t count = int64_t(p[x1 + y1 + z1]) - p[x0 + y1 + z1] - p[x1 + y0 + z1] -
                              p[x1 + y1 + z0] + p[x0 + y0 + z1] + p[x0 + y1 + z0] +
                              p[x1 + y0 + z0] - p[x0 + y0 + z0];
        return count > 0;
    }
    /// Index-space bounds of the occupied blocks (empty when nothing is).
    openvdb::CoordBBox bounds() const;

private:
    /// anyIn by the tree, for grids too large for the table (block coordinates, inclusive).
    bool scan(const openvdb::Coord& lo, const openvdb::Coord& hi) const;

    openvdb::MaskTree mBlocks;
    // The same blocks as a summed-volume table over their bounds, for box queries in O(1)
    // (empty when that table would be too large; then the tree is scanned).
    openvdb::Coord mLo, mDim;      ///< block coordinates of the table's first cell, cells per axis
    std::vector<uint32_t> mPrefix; ///< (mDim + 1)^3 counts of occupied blocks below each corner
};

} // namespace volmorph::detail
