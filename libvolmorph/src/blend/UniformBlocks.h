// Where a warped leaf reads one value: density mode's interiors. When every point of an output leaf
// warps into blocks of a side that hold one tile value (no leaf), every sample there is that value,
// and the output leaf is one value too: the blend keeps a tile instead of 512 samples.
#pragma once

#include "warp/AdaptiveWarp.h"

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>

namespace volmorph::detail {

/// The index box that samples at a side's warped points (`p`: x, y and z of 512 points) read:
/// their bounding box, widened for trilinear and triquadratic support.
inline openvdb::CoordBBox warpedBox(const float (&p)[3][512])
{
    openvdb::Coord lo, hi;
    for (int c = 0; c < 3; ++c) {
        const auto [mn, mx] = std::minmax_element(p[c], p[c] + 512);
        lo[c] = int(std::floor(*mn)) - 1;
        hi[c] = int(std::floor(*mx)) + 2;
    }
    return openvdb::CoordBBox(lo, hi);
}

/// Whether the tree behind `acc` holds one value over `box` (index space), with no leaf in the 8^3
/// blocks it touches; `value` gets it. Boxes over more than `kMaxBlocks` blocks are not examined.
template <typename Accessor>
bool uniformOver(Accessor& acc, const openvdb::CoordBBox& box, typename Accessor::ValueType& value)
{
    constexpr int kMaxBlocks = 64;
    const openvdb::Coord lo(box.min().x() & ~7, box.min().y() & ~7, box.min().z() & ~7);
    const openvdb::Coord blocks((box.max().x() - lo.x()) / 8 + 1, (box.max().y() - lo.y()) / 8 + 1,
                                (box.max().z() - lo.z()) / 8 + 1);
    if (int64_t(blocks.x()) * blocks.y() * blocks.z() > kMaxBlocks) return false;
    bool first = true;
    for (int x = lo.x(); x <= box.max().x(); x += 8)
        for (int y = lo.y(); y <= box.max().y(); y += 8)
            for (int z = lo.z(); z <= box.max().z(); z += 8) {
                const openvdb::Coord ijk(x, y, z);
                if (acc.probeConstLeaf(ijk)) return false;
                const auto v = acc.getValue(ijk);
                if (first)
                    value = v;
                else if (!(v == value))
                    return false;
                first = false;
            }
    return true;
}

} // namespace volmorph::detail
