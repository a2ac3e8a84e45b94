// The sdf blend's sparse domain: which 8^3 blocks (leaves) of a frame's box can hold the blended
// band, from the blend at their centres. |grad blend| <= G (the warp's stretch; the distances are
// 1-Lipschitz), so a block whose centre value is beyond G (r + width) + slack holds no value
// within `width` of zero and takes its centre's sign throughout (r: the distance from the centre
// to a corner voxel).
#pragma once

#include <volmorph/core/Math.h>

#include <openvdb/Types.h>

#include <cstdint>
#include <vector>

namespace volmorph::detail {

struct BlockClasses {
    openvdb::CoordBBox leaves;  ///< in leaf coordinates (index >> 3)
    std::vector<int8_t> kind;   ///< per leaf: 0 evaluate, +1 outside, -1 inside
    std::vector<float> stretch; ///< per leaf: G there
    std::vector<float> band;    ///< per leaf: the compute band there (world units; SdfFrame)
    double maxStretch = 1.0;    ///< G over the box

    size_t index(const openvdb::Coord& leaf) const
    {
        const openvdb::Coord d = leaf - leaves.min(), n = leaves.dim();
        return (size_t(d.x()) * n.y() + d.y()) * n.z() + d.z();
    }

    int8_t at(const openvdb::Coord& leaf) const { return kind[index(leaf)]; }
    /// Does `cells` (index space) overlap a leaf to evaluate?
    bool anyToEvaluate(const openvdb::CoordBBox& cells) const;
};

/// The largest of `values` over each leaf's 3^3 neighbourhood within the box (`dim` leaves on a
/// side, indexed as BlockClasses::index does).
std::vector<float> neighbourhoodMax(const std::vector<float>& values, const openvdb::Coord& dim);

/// The warp's stretch per leaf of a box of `dim` leaves, from the warped centres `ps`, `pt` of
/// its leaves (indexed as BlockClasses::index does; index space) blended by `tau`: the spectral
/// norm of the Jacobian by differences between neighbouring centres, the largest over the 3^3
/// neighbourhood, with a margin of 1.25 for what varies between centres, and at least 1.
std::vector<float> leafStretch(const std::vector<Vec3d>& ps, const std::vector<Vec3d>& pt,
                               const openvdb::Coord& dim, float tau);

} // namespace volmorph::detail
