// The exact warp's sums on the lattice of the candidate leaves' corners (8 voxels apart), from
// which the far pairs' sums are interpolated (AdaptiveWarp.h, step 1).
#pragma once

#include <volmorph/core/Math.h>

#include <openvdb/Types.h>

#include <memory>
#include <type_traits>

namespace volmorph::detail {

/// The exact sums at the corners of the candidate leaves: a lattice 8 voxels apart over the
/// leaves' bounding box (index space / 8), evaluated only where a candidate leaf needs it.
/// Left uninitialized until evaluated (only the wanted points are, and only they are read): the
/// whole lattice is allocated per call, and zeroing it was a serial cost (BENCHMARKS.md).
struct alignas(64) LatticePoint { // one cache line each
    double w;                     ///< sum w_i
    Vec3d s, t;                   ///< sum w_i A_i, source and target side
    bool ok;                      ///< false: on an element with a zero offset
};

struct Lattice {
    using Point = LatticePoint;
    static_assert(std::is_trivially_default_constructible_v<Point>, "allocated uninitialized");
    openvdb::Coord lo;  ///< lattice coordinates of point 0 (leaf coordinates)
    openvdb::Coord dim; ///< points along each axis
    std::unique_ptr<Point[]> points;
    size_t count = 0;
    size_t index(const openvdb::Coord& leafCoord) const
    {
        const openvdb::Coord c = leafCoord - lo;
        return (size_t(c.x()) * dim.y() + c.y()) * dim.z() + c.z();
    }
};

} // namespace volmorph::detail
