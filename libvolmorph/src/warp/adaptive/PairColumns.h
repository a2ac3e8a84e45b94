// The pairs at time t as columns, one per quantity, for the vector loops of the lattice's sums
// and the error bound.
#pragma once

#include <volmorph/Warp.h>

#include <vector>

namespace volmorph::detail {

/// The pairs, one column per quantity, padded to a multiple of 8 (the bound's loops take 8 pairs
/// at a time in single precision, the exact sums 4 at a time in double; padding lanes compute
/// harmless values that are never read, or are masked by `live`). Stored in groups of one
/// vector's lanes, all columns of a group together (see PairBounds).
template <class Real>
struct PairColumns {
    static constexpr size_t kLanes = 32 / sizeof(Real);
    enum Column {
        Origin = 0,  ///< + k: the element's origin, index axes
        Axis = 3,    ///< + 3 k + a: component a of the frame's axis k
        Half = 12,   ///< + k: half the scale along axis k, 0 where the type does not extend
        Reach = 15,  ///< + k: half the extent along axis k of a unit axis-aligned cube
        Box = 18,    ///< 1 for boxes
        Live = 19,   ///< 1 for the pairs, 0 for the padding
        Affine = 20, ///< + 12 side + 3 column + a: the affine maps (column 3: offset)
        Count = 44
    };
    struct Group {
        Real v[Count][kLanes];
    };
    size_t padded = 0;
    std::vector<Group> groups;
    Real get(int c, size_t i) const { return groups[i / kLanes].v[c][i % kLanes]; }

    PairColumns(const InverseWarp& warp, const std::vector<InverseWarp::Affine> maps[2]);
};

/// Both precisions' columns, and the slopes between pairs.
struct WarpColumns {
    WarpColumns(const InverseWarp& warp, const std::vector<InverseWarp::Affine> maps[2]);

    PairColumns<double> exact; ///< for the lattice's exact sums
    PairColumns<float> bound;  ///< for the bound (analyze())
    /// [j * padded + i]: |M_i - M_j| (Frobenius), the larger side: how fast the residual
    /// R_i = A_i - A_j of pair i against pair j changes per voxel (the bound's).
    std::vector<float> slope;
};

} // namespace volmorph::detail
