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

/// The warp's stretch per block of a box of `dim` blocks `spacing` voxels apart, from the warped
/// centres `ps`, `pt` of its blocks (indexed as BlockClasses::index does; index space) blended by
/// `tau` (the larger of both sides' where tau is negative: under a timing, each place its own): the
/// spectral norm of the Jacobian by differences between neighbouring centres, the largest over the
/// 3^3 neighbourhood, with a margin of 1.25 for what varies between centres, and at least 1.
/// `known`, unless empty: the blocks whose centres were warped (differences are one-sided beside
/// the others, and a block with neither neighbour known along an axis has none along it).
std::vector<float> leafStretch(const std::vector<Vec3d>& ps, const std::vector<Vec3d>& pt,
                               const openvdb::Coord& dim, float tau, double spacing = 8.0,
                               const std::vector<uint8_t>& known = {});

/// The coarse pass of the classification: blocks of kLeaves^3 leaves, judged as leaves are (from
/// the blend at their centres and the warp's stretch between them) with the stretch doubled, since
/// differences 32 voxels apart see less of the warp's variation than 8 apart. Leaves in a block
/// that cannot hold the band take its sign and are not warped one by one: the leaves warped
/// number with the surface, not the box.
struct CoarseBlocks {
    static constexpr int kLeaves = 4;
    static constexpr float kSafety = 2.0f;
    openvdb::Coord dim{0};      ///< blocks on a side
    std::vector<int8_t> kind;   ///< per block: 0 refine, +1 outside, -1 inside
    std::vector<float> stretch; ///< per block: G there, the safety included
    std::vector<float> band;    ///< per block: the compute band of its leaves (world units)

    bool empty() const { return kind.empty(); }
    /// The block of a leaf (leaf coordinates relative to the box's first leaf).
    size_t of(const openvdb::Coord& leaf) const
    {
        const openvdb::Coord b(leaf.x() / kLeaves, leaf.y() / kLeaves, leaf.z() / kLeaves);
        return (size_t(b.x()) * dim.y() + b.y()) * dim.z() + b.z();
    }
    /// Per leaf of a box of `leaves` leaves on a side: 1 where its centre is to be warped (leaves
    /// of blocks to refine and the two leaves around them that their stretch reads).
    std::vector<uint8_t> wanted(const openvdb::Coord& leaves) const;
};

} // namespace volmorph::detail
